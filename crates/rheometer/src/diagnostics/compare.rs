//! Model vs measurement: per experiment and measurement point the measured and simulated
//! diameters, `1/d²`, the relative residual `r = (d_model − d_meas)/d_meas` and the local
//! strain rate, temperature and speed of the model; summary statistics that say whether the
//! misfit is noise or systematic, and where.
//!
//! ```no_run
//! use rheometer::diagnostics::{compare_set, CompareOptions, ModelSetup};
//! use rheometer::data::input::load_experiments;
//! use rheometer::model::Physics;
//! use std::path::Path;
//! let set = load_experiments(Path::new("data/hidden_radiation/experiments.toml"))?;
//! let physics = || Physics::paper();
//! let setup = ModelSetup::carreau([0.8, 11.71], &physics).take_up_from_data();
//! let cmp = compare_set(&set, &setup, &CompareOptions::default())?;
//! println!("{}", cmp.to_text());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! **Statistics** (all on the relative residuals):
//! * the *noise model* ([`NoiseModel`], the project's one estimator): a robust noise scale
//!   from second differences along `s`, the noise scale along the line `σ(s/L)`, gross
//!   outliers by experiment and position, the lag-1 autocorrelation and `RMS/noise`;
//! * *noise level* `σ`: the one noise level of the model on these data
//!   (`NoiseSummary`): the fit's when a fit is compared ([`CompareOptions::fit_noise`]),
//!   else the data set's `relative_uncertainty` if given (or
//!   [`CompareOptions::relative_uncertainty`]), else the noise model's estimate;
//! * `χ² = Σ r²/σᵢ²` over the points that are not outliers, with `σᵢ = σ` if given, else the
//!   local `σ(sᵢ/L)` (so a noisier take-up region does not pass for a misfit), and
//!   `dof = N − outliers − p` (`p` fitted parameters);
//! * whiteness: the Wald–Wolfowitz runs test on the residual signs ([`RunsTest`]) and the noise
//!   model's lag-1 autocorrelation, per experiment and pooled; where the noise model finds the
//!   noise correlated along the line, the lag-1 autocorrelation against the noise's own and no
//!   runs test (it assumes independent signs);
//! * where: systematic segments of the pooled residual profile (`segments`), pooled over all
//!   experiments and per experiment;
//! * trends: Spearman rank correlations of the residual with strain rate, temperature, speed.

pub(crate) mod compare_figures;
pub(crate) mod model_runs;
pub(crate) mod segments;
pub(crate) mod summary_text;

pub(crate) use crate::data::statistics::RunsTest;
pub use model_runs::{compare_set, simulate_experiments, MissingTakeUp, ModelSetup};
pub(crate) use segments::Segment;
pub(crate) use segments::SegmentOptions;
pub(crate) use segments::Station;

pub(crate) use crate::data::noise_model::{NoiseModel, NoiseOptions, ResidualSeries};
pub(crate) use crate::data::noise_summary::NoiseSummary;
use crate::data::smoothing::SmoothingError;
use crate::data::statistics;
use crate::error::FiberError;
use crate::model::simulate::Profiles;
use crate::report::output_files::OutputError;
use crate::report::output_files::OutputFile;
use crate::report::plot::PlotError;
use serde::{Deserialize, Serialize};
use std::path::Path;
use thiserror::Error;

/// What can go wrong in a comparison.
#[derive(Debug, Error)]
pub enum CompareError {
    /// Unusable input (named).
    #[error("{0}")]
    Data(String),
    /// An experiment has no take-up condition and none is taken from the data (a workflow
    /// says which input gives one in its door's words).
    #[error(
        "experiment {experiment} has no take-up condition: give take_up_diameter_m or \
         take_up_velocity_m_s in the TOML, or take it from the data"
    )]
    NoTakeUp {
        /// Experiment name.
        experiment: String,
    },
    /// Smoothing an experiment's data (for its take-up diameter) failed.
    #[error("experiment {experiment}: smoothing the measurements failed: {source}")]
    Smoothing {
        /// Experiment name.
        experiment: String,
        /// Cause.
        source: SmoothingError,
    },
    /// Setting up or solving an experiment's model failed.
    #[error("experiment {experiment}: {source}")]
    Simulation {
        /// Experiment name.
        experiment: String,
        /// Cause.
        source: FiberError,
    },
    /// Writing an output failed.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// Drawing a figure failed.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// Writing a figure failed.
    #[error(transparent)]
    Figure(#[from] crate::report::figures::FigureError),
    /// Serialising the JSON summary failed.
    #[error("cannot serialise the comparison: {0}")]
    Json(#[from] serde_json::Error),
}

/// One experiment's measurements and its simulation.
#[derive(Debug, Clone)]
pub struct SimulatedExperiment {
    /// Experiment name.
    pub name: String,
    /// Measurement positions `s` (m).
    pub positions: Vec<f64>,
    /// Measured diameters (m).
    pub measured: Vec<f64>,
    /// Model profiles at the measurement positions.
    pub at_measurements: Profiles,
    /// Model profiles on a fine grid, for figures (may be empty).
    pub curve: Profiles,
}

/// Settings of [`compare`].
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct CompareOptions {
    /// Relative measurement uncertainty `σ` \[-\]; overrides the data set's value. `None`: the
    /// data set's, else estimated from the data.
    pub relative_uncertainty: Option<f64>,
    /// Number of parameters fitted to these data (for `dof = N − p`; default 0).
    pub fitted_parameters: usize,
    /// Thresholds of the segment search.
    pub segments: SegmentOptions,
    /// Settings of the noise model.
    #[serde(default)]
    pub noise: NoiseOptions,
    /// The noise summary of the fit being compared (same model and data): used as this
    /// comparison's noise, so that a fit and its comparison report one noise level.
    #[serde(skip)]
    pub fit_noise: Option<NoiseSummary>,
}

/// One measurement point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ComparedPoint {
    /// Position `s` (m).
    pub position_m: f64,
    /// Measured diameter (m).
    pub d_meas_m: f64,
    /// Simulated diameter (m).
    pub d_model_m: f64,
    /// Relative residual `(d_model − d_meas)/d_meas` \[-\].
    pub residual: f64,
    /// `1/d_meas²` (1/m²).
    pub inv_d2_meas: f64,
    /// `1/d_model²` (1/m²).
    pub inv_d2_model: f64,
    /// Model strain rate `u'` (1/s).
    pub strain_rate_1_s: f64,
    /// Model temperature (K).
    pub temperature_k: f64,
    /// Model fiber speed (m/s).
    pub speed_m_s: f64,
    /// Whether the noise model flags the point as a gross outlier.
    #[serde(default)]
    pub outlier: bool,
}

/// The comparison of one experiment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ComparedExperiment {
    /// Experiment name.
    pub name: String,
    /// The measurement points, in order along `s`.
    pub points: Vec<ComparedPoint>,
    /// Model curve positions (m) for figures.
    #[serde(skip)]
    pub curve_position_m: Vec<f64>,
    /// Model curve diameters (m) for figures.
    #[serde(skip)]
    pub curve_diameter_m: Vec<f64>,
    /// RMS of the relative residuals \[-\].
    pub rms: f64,
    /// Mean relative residual \[-\].
    pub mean: f64,
    /// `Σ r²/σᵢ²` of this experiment, outliers excluded.
    pub chi2: f64,
    /// Runs test on the residual signs.
    pub runs: RunsTest,
    /// Lag-1 autocorrelation of the noise-normalised residuals about zero, outliers excluded
    /// ([`NoiseModel::lag1_per_experiment`]).
    pub lag1: f64,
    /// Systematic segments of this experiment alone.
    pub segments: Vec<Segment>,
}

/// Rank correlation of the residual with a local model quantity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trend {
    /// `"strain_rate"`, `"temperature"` or `"speed"`.
    pub quantity: String,
    /// Spearman rank correlation over all points \[-\].
    pub spearman: f64,
}

/// The result of a comparison.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// Per experiment.
    pub experiments: Vec<ComparedExperiment>,
    /// The noise level `σ` used and the noise model of the residuals (scale along the line,
    /// outliers, lag-1, RMS/noise): the fit's when the comparison is of a fit
    /// ([`CompareOptions::fit_noise`]), else from these residuals.
    pub noise: NoiseSummary,
    /// Number of measurement points `N`.
    pub points: usize,
    /// Number of fitted parameters `p`.
    pub fitted_parameters: usize,
    /// `χ² = Σ r²/σᵢ²` over the points that are not outliers.
    pub chi2: f64,
    /// `dof = N − outliers − p`.
    pub dof: usize,
    /// `χ²/dof`.
    pub chi2_per_dof: f64,
    /// RMS of all relative residuals \[-\].
    pub rms: f64,
    /// Pooled runs test.
    pub runs: RunsTest,
    /// Pooled lag-1 autocorrelation ([`NoiseModel::lag1`]).
    pub lag1: f64,
    /// `z` of the lag-1 autocorrelation against the noise's own ([`NoiseModel::lag1_z`]:
    /// `ρ₁ √pairs` for white noise).
    pub lag1_z: f64,
    /// The pooled residual profile.
    pub stations: Vec<Station>,
    /// Systematic segments of the pooled residual.
    pub segments: Vec<Segment>,
    /// Rank correlations of the residual with local model quantities.
    pub trends: Vec<Trend>,
    /// The segment thresholds used.
    pub segment_options: SegmentOptions,
}

/// Compares the simulations with the measurements. `set_uncertainty` is the data set's
/// relative measurement uncertainty (used unless the options give one).
pub fn compare(
    runs: &[SimulatedExperiment],
    set_uncertainty: Option<f64>,
    options: &CompareOptions,
) -> Result<Comparison, CompareError> {
    if runs.is_empty() {
        return Err(CompareError::Data("no experiments to compare".into()));
    }
    let mut experiments = Vec::with_capacity(runs.len());
    for run in runs {
        experiments.push(compared_experiment(run)?);
    }
    let series: Vec<(Vec<f64>, Vec<f64>)> = experiments
        .iter()
        .map(|e| {
            (
                e.points.iter().map(|p| p.position_m).collect(),
                e.points.iter().map(|p| p.residual).collect(),
            )
        })
        .collect();
    let noise = noise_of(runs, &series, set_uncertainty, options)?;
    let sigma = noise.level;
    let n_points: usize = experiments.iter().map(|e| e.points.len()).sum();
    let (mut sum2, mut chi2) = (0.0, 0.0);
    for (k, (e, (s, r))) in experiments.iter_mut().zip(&series).enumerate() {
        e.chi2 = 0.0;
        for (i, p) in e.points.iter_mut().enumerate() {
            p.outlier = noise.is_outlier(k, i);
            if p.outlier {
                continue;
            }
            let sd = noise.sigma_at(k, p.position_m);
            e.chi2 += (p.residual / sd).powi(2);
        }
        chi2 += e.chi2;
        sum2 += r.iter().map(|v| v * v).sum::<f64>();
        e.lag1 = noise
            .model
            .as_ref()
            .and_then(|m| m.lag1_per_experiment.get(k).copied())
            .unwrap_or(f64::NAN);
        e.segments = segments::find_segments(&[(s.clone(), r.clone())], sigma, &options.segments);
    }
    let n_outliers = noise.model.as_ref().map_or(0, |m| m.outliers.len());
    let dof = n_points
        .saturating_sub(n_outliers)
        .saturating_sub(options.fitted_parameters);
    let runs_each: Vec<RunsTest> = experiments.iter().map(|e| e.runs).collect();
    let (lag1, lag1_z) = noise
        .model
        .as_ref()
        .map_or((f64::NAN, f64::NAN), |m| (m.lag1, m.lag1_z));
    let trends = residual_trends(&experiments);
    Ok(Comparison {
        points: n_points,
        fitted_parameters: options.fitted_parameters,
        chi2,
        dof,
        chi2_per_dof: if dof > 0 { chi2 / dof as f64 } else { f64::NAN },
        rms: (sum2 / n_points.max(1) as f64).sqrt(),
        runs: RunsTest::pooled(&runs_each),
        lag1,
        lag1_z,
        noise,
        stations: segments::station_profile(&series, sigma),
        segments: segments::find_segments(&series, sigma, &options.segments),
        trends,
        segment_options: options.segments,
        experiments,
    })
}

/// The noise of the residual `series` of `runs`: the fit's if the options carry it, else
/// estimated from the series (with the options' or the data set's relative uncertainty);
/// an error if its level is not a positive number.
fn noise_of(
    runs: &[SimulatedExperiment],
    series: &[(Vec<f64>, Vec<f64>)],
    set_uncertainty: Option<f64>,
    options: &CompareOptions,
) -> Result<NoiseSummary, CompareError> {
    let input: Vec<ResidualSeries> = runs
        .iter()
        .zip(series)
        .map(|(run, (s, r))| ResidualSeries {
            name: run.name.clone(),
            positions_m: s.clone(),
            residuals: r.clone(),
            measured_m: run.measured.clone(),
            length_m: run.curve.position.last().copied().filter(|l| *l > 0.0),
        })
        .collect();
    let noise = match &options.fit_noise {
        Some(n) => n.clone(),
        None => NoiseSummary::of(
            &input,
            options.relative_uncertainty.or(set_uncertainty),
            &options.noise,
        )
        .map_err(CompareError::Data)?,
    };
    let sigma = noise.level;
    if !(sigma > 0.0 && sigma.is_finite()) {
        return Err(CompareError::Data(format!(
            "cannot estimate the noise level from the data (estimate {sigma}); give \
             relative_uncertainty in the experiments TOML"
        )));
    }
    Ok(noise)
}

/// The rank correlations of the pooled residual of `experiments` with the local strain rate,
/// temperature and speed.
fn residual_trends(experiments: &[ComparedExperiment]) -> Vec<Trend> {
    let all = |f: fn(&ComparedPoint) -> f64| -> Vec<f64> {
        experiments
            .iter()
            .flat_map(|e| e.points.iter().map(f))
            .collect()
    };
    let residuals = all(|p| p.residual);
    [
        ("strain_rate", all(|p| p.strain_rate_1_s)),
        ("temperature", all(|p| p.temperature_k)),
        ("speed", all(|p| p.speed_m_s)),
    ]
    .into_iter()
    .map(|(q, x)| Trend {
        quantity: q.into(),
        spearman: statistics::spearman(&x, &residuals),
    })
    .collect()
}

fn compared_experiment(run: &SimulatedExperiment) -> Result<ComparedExperiment, CompareError> {
    let n = run.positions.len();
    let p = &run.at_measurements;
    if run.measured.len() != n
        || p.diameter.len() != n
        || p.strain_rate.len() != n
        || p.temperature.len() != n
        || p.velocity.len() != n
    {
        return Err(CompareError::Data(format!(
            "experiment {}: {} positions, {} measured diameters and {} model values do not match",
            run.name,
            n,
            run.measured.len(),
            p.diameter.len()
        )));
    }
    if n == 0 {
        return Err(CompareError::Data(format!(
            "experiment {} has no measurements",
            run.name
        )));
    }
    let mut points = Vec::with_capacity(n);
    for i in 0..n {
        // the model's value is what the gauge reads (as in the fit's residuals)
        let model_d = p.gauge_reading.as_ref().unwrap_or(&p.diameter);
        let (dm, dd) = (run.measured[i], model_d[i]);
        if !(dm > 0.0 && dd > 0.0 && dm.is_finite() && dd.is_finite()) {
            return Err(CompareError::Data(format!(
                "experiment {} at s = {} m: diameters must be positive (measured {dm} m, model {dd} m)",
                run.name, run.positions[i]
            )));
        }
        points.push(ComparedPoint {
            position_m: run.positions[i],
            d_meas_m: dm,
            d_model_m: dd,
            residual: dd / dm - 1.0,
            inv_d2_meas: 1.0 / (dm * dm),
            inv_d2_model: 1.0 / (dd * dd),
            strain_rate_1_s: p.strain_rate[i],
            temperature_k: p.temperature[i],
            speed_m_s: p.velocity[i],
            outlier: false,
        });
    }
    let r: Vec<f64> = points.iter().map(|p| p.residual).collect();
    let m = n as f64;
    Ok(ComparedExperiment {
        name: run.name.clone(),
        curve_position_m: run.curve.position.clone(),
        curve_diameter_m: run
            .curve
            .gauge_reading
            .clone()
            .unwrap_or_else(|| run.curve.diameter.clone()),
        rms: (r.iter().map(|v| v * v).sum::<f64>() / m).sqrt(),
        mean: r.iter().sum::<f64>() / m,
        chi2: f64::NAN,
        runs: RunsTest::of(&r),
        lag1: f64::NAN,
        segments: Vec::new(),
        points,
    })
}

/// Output image format of the figures (the plotting module's).
pub(crate) use crate::report::plot::FigureFormat;

impl Comparison {
    /// The JSON summary (all numbers, per point), stamped as a
    /// [`ReportKind::Comparison`](crate::report::report_json::ReportKind::Comparison) report.
    pub fn to_json(&self) -> Result<String, CompareError> {
        Ok(crate::report::report_json::to_report_json(
            crate::report::report_json::ReportKind::Comparison,
            self,
        )?)
    }

    /// The per-point table as CSV.
    pub fn to_csv(&self) -> String {
        let mut s = String::from(
            "experiment,position_m,d_meas_m,d_model_m,relative_residual,inv_d2_meas_1_m2,\
             inv_d2_model_1_m2,strain_rate_1_s,temperature_K,speed_m_s\n",
        );
        for e in &self.experiments {
            for p in &e.points {
                s.push_str(&format!(
                    "{},{},{:.8e},{:.8e},{:.6e},{:.8e},{:.8e},{:.6e},{:.6e},{:.6e}\n",
                    e.name,
                    p.position_m,
                    p.d_meas_m,
                    p.d_model_m,
                    p.residual,
                    p.inv_d2_meas,
                    p.inv_d2_model,
                    p.strain_rate_1_s,
                    p.temperature_k,
                    p.speed_m_s
                ));
            }
        }
        s
    }

    /// The names of the files `Comparison::write` writes for `experiments` experiments in
    /// `format` (so that a program can check them all before the work).
    pub fn file_names(experiments: usize, format: FigureFormat) -> Vec<String> {
        let mut v: Vec<String> = Self::TEXT_FILES.iter().map(|s| s.to_string()).collect();
        v.extend(compare_figures::figure_names(experiments, format));
        v
    }

    /// The text files of [`Comparison::write`].
    const TEXT_FILES: [&'static str; 3] =
        ["compare_summary.txt", "compare.json", "compare_points.csv"];

    /// The files of a comparison in `dir`, rendered in memory: `compare_summary.txt`,
    /// `compare.json`, `compare_points.csv` and the figures (see
    /// `compare_figures::render_figures`), for the caller to write (a command through its
    /// checked outputs, a library user with [`OutputFile::save`]).
    pub fn files(&self, dir: &Path, format: FigureFormat) -> Result<Vec<OutputFile>, CompareError> {
        let texts = [self.to_text(), self.to_json()?, self.to_csv()];
        let mut files: Vec<OutputFile> = Self::TEXT_FILES
            .into_iter()
            .zip(texts)
            .map(|(name, text)| OutputFile::new(dir.join(name), text))
            .collect();
        files.extend(compare_figures::render_figures(self, dir, format)?);
        Ok(files)
    }
}

//! Identification of `(n, κ)`: the prepared data, the start heuristic (paper Algorithm 2) and
//! the bounded trust-region Gauss–Newton fit on the [`Objective`].
//!
//! Every evaluation solves the `M` fiber BVPs in parallel (rayon), each warm-started from its
//! last accepted solution (no continuation inside the fit, as in the paper), and builds the exact
//! residual Jacobian from forward sensitivities (one extra solve with the kept factorisation per
//! experiment). A BVP that fails at a trial point makes the whole trial point fail, which the
//! driver treats as a rejected step.

use super::estimator::Estimator;
use super::layout::{EffectSlot, FitStart};
use super::objective::Objective;
use super::report::{FitWarning, WarningCode};
use crate::fiber::diagnostics::candidates::{LawChoice, ModelSpec};
use crate::fiber::diagnostics::compare::residual_stats::median;
use crate::fiber::error::FiberError;
use crate::fiber::material_law::CarreauLike;
use crate::fiber::model::FiberModel;
use crate::fiber::setup::{Air, Experiment, ExperimentSet, Material, Measurements, TakeUp};
use crate::fiber::simulate::SimulateOptions;
use crate::fiber::smoothing::{smooth, SmoothFit, SmoothingError};
use crate::least_squares::{fit, FitError, FitOptions, FitResult};
use crate::solution::Solution;
use std::time::Instant;
use thiserror::Error;

/// The fiber model the rheometer identifies: Carreau-type law (a Newtonian model is `n = 1`),
/// the paper's physics plus the effects of its [`ModelSpec`].
pub type CarreauFiber = FiberModel<CarreauLike>;

/// What can go wrong in the rheometer.
#[derive(Debug, Error)]
pub enum RheometerError {
    /// Unusable data.
    #[error("{0}")]
    Data(String),
    /// Smoothing an experiment's data failed.
    #[error("experiment {experiment}: {source}")]
    Smoothing {
        /// Experiment name.
        experiment: String,
        /// Cause.
        source: SmoothingError,
    },
    /// A fiber simulation failed.
    #[error("experiment {experiment}: simulation at (n, κ) = ({n}, {kappa}) failed: {source}")]
    Simulation {
        /// Experiment name.
        experiment: String,
        /// Power index.
        n: f64,
        /// κ = ln K.
        kappa: f64,
        /// Cause.
        source: FiberError,
    },
    /// The least-squares fit could not run.
    #[error("fit: {0}")]
    Fit(#[from] FitError),
}

/// Options of the identification.
#[derive(Debug, Clone)]
pub struct IdentifyOptions {
    /// The cost to minimise.
    pub estimator: Estimator,
    /// Regular optimisation points per experiment for the paper's cost (`n_o`, default 20).
    pub n_opt_points: usize,
    /// BVP settings (tolerance 1e-6 by default).
    pub simulate: SimulateOptions,
    /// Lower bounds of `(n, κ)` (default `(0, 7)`, the paper's Ω).
    pub lower: [f64; 2],
    /// Upper bounds of `(n, κ)` (default `(1, 20)`).
    pub upper: [f64; 2],
    /// Bounds of the take-up factors `φ_k = d_out,k / d_fit,k(L)` (principled estimator;
    /// default `(0.5, 1.5)`).
    pub take_up_bounds: [f64; 2],
    /// Gauss–Newton iteration limit (default 100).
    pub max_iterations: usize,
    /// Relative measurement uncertainty σ of the diameters; `None`: the data set's value, or 1.
    pub relative_uncertainty: Option<f64>,
}

impl Default for IdentifyOptions {
    fn default() -> Self {
        let simulate = SimulateOptions {
            factor_at_solution: true,
            ..SimulateOptions::default()
        };
        IdentifyOptions {
            estimator: Estimator::Principled,
            n_opt_points: 20,
            simulate,
            lower: [0.0, 7.0],
            upper: [1.0, 20.0],
            take_up_bounds: [0.5, 1.5],
            max_iterations: 100,
            relative_uncertainty: None,
        }
    }
}

impl IdentifyOptions {
    /// Default options with the given estimator.
    pub fn with_estimator(estimator: Estimator) -> Self {
        IdentifyOptions {
            estimator,
            ..Default::default()
        }
    }
}

/// The eleven start points `(n, κ)` of the paper's Table 3 (κ = ln 10⁴, ln 10⁵, ln 10⁶).
pub const PAPER_TABLE3_STARTS: [[f64; 2]; 11] = [
    [0.5, 9.21],
    [0.7, 9.21],
    [0.9, 9.21],
    [0.3, 11.51],
    [0.5, 11.51],
    [0.7, 11.51],
    [0.9, 11.51],
    [0.3, 13.82],
    [0.5, 13.82],
    [0.7, 13.82],
    [0.9, 13.82],
];

/// Prepared data: smoothed measurements and one fiber model per experiment.
#[derive(Debug)]
pub struct Rheometer {
    /// The polymer.
    pub material: Material,
    /// The air.
    pub air: Air,
    /// Experiments (take-up condition set to `d_fit(L)` where the data set gives none).
    pub experiments: Vec<Experiment>,
    /// Raw measurements.
    pub measurements: Vec<Measurements>,
    /// Ansatz fits of the measurements.
    pub smoothing: Vec<SmoothFit>,
    /// One model per experiment.
    pub models: Vec<CarreauFiber>,
    /// Relative measurement uncertainty from the data set, if given.
    pub relative_uncertainty: Option<f64>,
    /// The model: law, effects, neutral candidates.
    pub spec: ModelSpec,
}

impl Rheometer {
    /// Smooths every experiment's data and builds its model (the paper's: Carreau-type law,
    /// no extra effects). Experiments without measurements are an error (the rheometer needs
    /// data for each).
    pub fn new(set: &ExperimentSet) -> Result<Self, RheometerError> {
        Self::with_spec(set, ModelSpec::default())
    }

    /// As [`new`](Self::new) with the model `spec` (law, effects fitted or fixed, neutral
    /// candidates).
    pub fn with_spec(set: &ExperimentSet, spec: ModelSpec) -> Result<Self, RheometerError> {
        spec.validate().map_err(RheometerError::Data)?;
        if set.experiments.is_empty() {
            return Err(RheometerError::Data(
                "the data set has no experiments".into(),
            ));
        }
        let mut experiments = Vec::new();
        let mut measurements = Vec::new();
        let mut smoothing = Vec::new();
        let mut models = Vec::new();
        for (e, m) in set.experiments.iter().zip(&set.measurements) {
            let m = m.as_ref().ok_or_else(|| {
                RheometerError::Data(format!("experiment {} has no measurements", e.name))
            })?;
            let f =
                smooth(&m.positions, &m.diameters).map_err(|source| RheometerError::Smoothing {
                    experiment: e.name.clone(),
                    source,
                })?;
            let mut e = e.clone();
            if e.take_up.is_none() {
                e.take_up = Some(TakeUp::Diameter(f.diameter(e.spinline_length)));
            }
            let model = FiberModel::new(
                &set.material,
                &set.air,
                &e,
                CarreauLike::new(),
                spec.physics(),
            )
            .map_err(|source| RheometerError::Simulation {
                experiment: e.name.clone(),
                n: f64::NAN,
                kappa: f64::NAN,
                source,
            })?;
            experiments.push(e);
            measurements.push(m.clone());
            smoothing.push(f);
            models.push(model);
        }
        Ok(Rheometer {
            material: set.material.clone(),
            air: set.air.clone(),
            experiments,
            measurements,
            smoothing,
            models,
            relative_uncertainty: set.relative_uncertainty,
            spec,
        })
    }

    /// Number of experiments.
    pub fn len(&self) -> usize {
        self.models.len()
    }

    /// Whether there are no experiments.
    pub fn is_empty(&self) -> bool {
        self.models.is_empty()
    }

    /// An objective at start point `(n, κ)` (cold starts of all experiments, in parallel).
    pub fn objective(
        &self,
        start: [f64; 2],
        options: &IdentifyOptions,
    ) -> Result<Objective<'_>, RheometerError> {
        Objective::new(self, &FitStart::at(start), options)
    }

    /// An objective for a general start (free candidates, start strengths, warm starts).
    pub fn objective_from(
        &self,
        start: &FitStart,
        options: &IdentifyOptions,
    ) -> Result<Objective<'_>, RheometerError> {
        Objective::new(self, start, options)
    }

    /// Runs the identification from `start = (n, κ)`.
    pub fn identify(
        &self,
        start: [f64; 2],
        options: &IdentifyOptions,
    ) -> Result<Identification, RheometerError> {
        self.identify_from(&FitStart::at(start), options)
    }

    /// Runs the identification from a general start.
    pub fn identify_from(
        &self,
        start: &FitStart,
        options: &IdentifyOptions,
    ) -> Result<Identification, RheometerError> {
        let t0 = Instant::now();
        let mut obj = self.objective_from(start, options)?;
        let p0 = obj.initial_parameters();
        let (lower, upper) = obj.bounds();
        let fo = FitOptions {
            initial_radius: 0.3,
            max_radius: 1.0,
            max_iterations: options.max_iterations,
            ..FitOptions::with_bounds(lower.clone(), upper.clone())
        };
        let fit_result = fit(&mut obj, &p0, &fo)?;
        let solutions: Vec<Solution> = obj.solutions();
        let rms = self.rms_relative_residual(&solutions);
        let ns = obj.layout.num_shared();
        let residual_profiles = solutions
            .iter()
            .enumerate()
            .map(|(k, sol)| {
                (
                    self.measurements[k].positions.clone(),
                    self.relative_residuals(k, sol),
                )
            })
            .collect();
        let local = obj.layout.local(
            &fit_result.p[..ns],
            1.0,
            self.models[0].take_up_factor_index(),
        );
        Ok(Identification {
            estimator: options.estimator,
            start: start.law,
            n: local[1],
            kappa: local[2],
            take_up_factors: if options.estimator == Estimator::Principled {
                fit_result.p[ns..].to_vec()
            } else {
                vec![1.0; self.len()]
            },
            names: obj.layout.names.clone(),
            effects: obj.layout.effects.clone(),
            local_params: local,
            rms_relative_residual: rms,
            law: self.spec.law,
            experiment_names: self.experiments.iter().map(|e| e.name.clone()).collect(),
            lower,
            upper,
            residual_profiles,
            relative_uncertainty: options.relative_uncertainty.or(self.relative_uncertainty),
            data_warnings: self.data_warnings(),
            solutions,
            fit: fit_result,
            wall_time_s: t0.elapsed().as_secs_f64(),
        })
    }

    /// Paper Algorithm 2: with `n = n_init` (0.5), walk κ down from the upper bound in steps of
    /// 1 until the cost differs from the Newtonian cost by more than 10%.
    pub fn start_heuristic(&self, options: &IdentifyOptions) -> Result<StartPoint, RheometerError> {
        let n_init = 0.5;
        let (k_lo, k_hi) = (options.lower[1], options.upper[1]);
        let mut obj = self.objective([1.0, k_hi], options)?;
        let j1 = obj.cost_at(1.0, k_hi)?;
        let mut kappa = k_hi;
        let mut j2 = obj.cost_at(n_init, kappa)?;
        let mut trace = vec![(kappa, j2)];
        while ((j1 - j2) / j1).abs() < 0.1 && kappa > k_lo {
            kappa = (kappa - 1.0).max(k_lo);
            j2 = obj.cost_at(n_init, kappa)?;
            trace.push((kappa, j2));
        }
        Ok(StartPoint {
            start: [n_init, kappa],
            newtonian_cost: j1,
            trace,
        })
    }

    /// Checks of the measured data that the model cannot describe, one warning per experiment:
    /// the spin-line model draws the fiber down, so its diameter decreases along the spin line;
    /// measured diameters whose last third lies above their first third (median against median)
    /// cannot be fitted (reversed positions, a swapped column or the wrong file).
    pub fn data_warnings(&self) -> Vec<FitWarning> {
        let mut out = Vec::new();
        for (e, m) in self.experiments.iter().zip(&self.measurements) {
            let d = &m.diameters;
            let third = d.len() / 3;
            if third == 0 {
                continue;
            }
            let first = median(&mut d[..third].to_vec());
            let last = median(&mut d[d.len() - third..].to_vec());
            if last >= first {
                out.push(FitWarning::new(
                    WarningCode::DataTrend,
                    format!(
                        "experiment {}: the measured diameters do not decrease along the spin \
                         line (median {:.4e} m over the first third of the points, {:.4e} m over \
                         the last third); a drawn fiber thins towards the take-up, so the model \
                         cannot describe these data: check the data file (reversed positions, \
                         swapped columns, wrong file)",
                        e.name, first, last
                    ),
                ));
            }
        }
        out
    }

    /// RMS of `(d_model − d_meas)/d_meas` over all measurements for the given solutions.
    pub fn rms_relative_residual(&self, solutions: &[Solution]) -> f64 {
        let (mut sum, mut count) = (0.0, 0usize);
        for (k, sol) in solutions.iter().enumerate() {
            for r in self.relative_residuals(k, sol) {
                sum += r * r;
                count += 1;
            }
        }
        (sum / count.max(1) as f64).sqrt()
    }

    /// `(d_model − d_meas)/d_meas` at the measurement positions of experiment `k`.
    pub fn relative_residuals(&self, k: usize, sol: &Solution) -> Vec<f64> {
        let model = &self.models[k];
        let lo = model.scaling.reference.length;
        let m = &self.measurements[k];
        let mut y = [0.0; 4];
        let mut yp = [0.0; 4];
        m.positions
            .iter()
            .zip(&m.diameters)
            .map(|(&s, &d)| {
                sol.eval_into(s / lo, &mut y, &mut yp);
                let dm = model.diameter(y[0], model.density(y[2])) * model.scaling.diameter();
                dm / d - 1.0
            })
            .collect()
    }
}

/// Result of the start heuristic.
#[derive(Debug, Clone)]
pub struct StartPoint {
    /// The start point `(n_init, κ)`.
    pub start: [f64; 2],
    /// The Newtonian reference cost `J(1, κ_upper)`.
    pub newtonian_cost: f64,
    /// `(κ, J(n_init, κ))` for every κ tried.
    pub trace: Vec<(f64, f64)>,
}

/// Result of an identification.
#[derive(Debug, Clone)]
pub struct Identification {
    /// The estimator used.
    pub estimator: Estimator,
    /// Start point `(n, κ)`.
    pub start: [f64; 2],
    /// Identified power index `n` \[-\].
    pub n: f64,
    /// Identified `κ = ln(K / 1 Pa)` \[-\].
    pub kappa: f64,
    /// Take-up factors `φ_k = d_out,k / d_fit,k(L)` (all 1 for the paper's estimator).
    pub take_up_factors: Vec<f64>,
    /// Names of the shared fitted parameters (the first entries of `fit.p`; the take-up factors
    /// follow).
    pub names: Vec<String>,
    /// The model's effects (fixed or fitted) and where their strengths sit.
    pub effects: Vec<EffectSlot>,
    /// The fitted local model parameters `[c, n, κ, strengths..., φ = 1]`.
    pub local_params: Vec<f64>,
    /// RMS of `(d_model − d_meas)/d_meas` over all raw measurements \[-\].
    pub rms_relative_residual: f64,
    /// Final fiber solutions, one per experiment.
    pub solutions: Vec<Solution>,
    /// The least-squares result (cost, Jacobian, iterations, termination).
    pub fit: FitResult,
    /// Wall time \[s\], including the cold starts.
    pub wall_time_s: f64,
    /// The viscosity law of the model (what was fitted; never inferred from the values).
    pub law: LawChoice,
    /// Experiment names, in the order of `take_up_factors` and `solutions`.
    pub experiment_names: Vec<String>,
    /// Lower bounds of `fit.p` (shared parameters in model units, then take-up factors).
    pub lower: Vec<f64>,
    /// Upper bounds of `fit.p`.
    pub upper: Vec<f64>,
    /// Per experiment: measurement positions \[m\] and relative residuals
    /// `(d_model − d_meas)/d_meas` \[-\] at the optimum.
    pub residual_profiles: Vec<(Vec<f64>, Vec<f64>)>,
    /// Declared relative measurement uncertainty (options, else the data set), if any.
    pub relative_uncertainty: Option<f64>,
    /// Warnings about the data found before fitting ([`Rheometer::data_warnings`]).
    pub data_warnings: Vec<FitWarning>,
}

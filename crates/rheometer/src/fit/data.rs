//! The prepared data of the rheometer ([`Rheometer`]): the measurements, their smoothing and
//! one fiber model per experiment, and the residuals of a set of solutions against the data.

use super::options::{CarreauFiber, FitWarning, RheometerError, WarningCode};
use crate::data::noise_model::{NoiseModel, NoiseOptions, ResidualSeries};
use crate::data::noise_summary::NoiseSummary;
use crate::data::smoothing::{smooth, SmoothFit};
use crate::data::statistics::median;
use crate::data::take_up::{resolve_take_up, MissingTakeUp};
use crate::model::bvp::FiberModel;
use crate::model::effects::ModelSpec;
use crate::model::material_law::CarreauLike;
use crate::model::setup::{Air, Experiment, ExperimentSet, Material, Measurements};
use diffbvp::solution::Solution;

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
            let resolved = resolve_take_up(&e, Some(m), MissingTakeUp::FromData, Some(&f))
                .map_err(|err| RheometerError::Data(format!("experiment {}: {err}", e.name)))?;
            e.take_up = Some(resolved.take_up);
            let model = spec
                .physics()
                .and_then(|physics| {
                    FiberModel::new(&set.material, &set.air, &e, CarreauLike::new(), physics)
                })
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

    /// The same data, experiments and smoothing (no new smoothing, take-up conditions as
    /// resolved) with the models rebuilt for `spec` (e.g. a candidate effect added or fixed).
    pub fn respecified(&self, spec: ModelSpec) -> Result<Rheometer, RheometerError> {
        spec.validate().map_err(RheometerError::Data)?;
        let models = self
            .experiments
            .iter()
            .map(|e| {
                spec.physics()
                    .and_then(|physics| {
                        FiberModel::new(&self.material, &self.air, e, CarreauLike::new(), physics)
                    })
                    .map_err(|source| RheometerError::Simulation {
                        experiment: e.name.clone(),
                        n: f64::NAN,
                        kappa: f64::NAN,
                        source,
                    })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Rheometer {
            material: self.material.clone(),
            air: self.air.clone(),
            experiments: self.experiments.clone(),
            measurements: self.measurements.clone(),
            smoothing: self.smoothing.clone(),
            models,
            relative_uncertainty: self.relative_uncertainty,
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

    /// The robust noise scale of the data \[-\] (relative): the [`NoiseModel`] `σ` of
    /// `d_fit(s)/d_meas − 1` about each experiment's smoothing ansatz (second differences, so
    /// the ansatz's own misfit hardly enters). The default soft margin of a robust loss.
    pub fn data_noise_scale(&self) -> Result<f64, RheometerError> {
        let profiles: Vec<(Vec<f64>, Vec<f64>)> = self
            .measurements
            .iter()
            .zip(&self.smoothing)
            .map(|(m, f)| {
                let r = m
                    .positions
                    .iter()
                    .zip(&m.diameters)
                    .map(|(&s, &d)| f.diameter(s) / d - 1.0)
                    .collect();
                (m.positions.clone(), r)
            })
            .collect();
        let nm = NoiseModel::from_profiles(&profiles, &NoiseOptions::default())
            .map_err(RheometerError::Data)?;
        if nm.sigma > 0.0 && nm.sigma.is_finite() {
            Ok(nm.sigma)
        } else {
            Err(RheometerError::Data(format!(
                "cannot estimate the noise scale of the data (got {}); give f_scale",
                nm.sigma
            )))
        }
    }

    /// The residual profiles of a fit (`(positions [m], relative residuals [-])`, one per
    /// experiment in order) as the noise model's series: experiment names, measured diameters
    /// and spin-line lengths from the data.
    pub fn residual_series(
        &self,
        residual_profiles: &[(Vec<f64>, Vec<f64>)],
    ) -> Result<Vec<ResidualSeries>, RheometerError> {
        if residual_profiles.len() != self.len() {
            return Err(RheometerError::Data(format!(
                "{} residual profiles for {} experiments",
                residual_profiles.len(),
                self.len()
            )));
        }
        Ok(residual_profiles
            .iter()
            .enumerate()
            .map(|(k, (s, r))| ResidualSeries {
                name: self.experiments[k].name.clone(),
                positions_m: s.clone(),
                residuals: r.clone(),
                measured_m: self.measurements[k].diameters.clone(),
                length_m: Some(self.experiments[k].spinline_length),
            })
            .collect())
    }

    /// The one noise summary of a fit's residual profiles (see
    /// `noise_summary`): the declared relative uncertainty
    /// (`declared`, else the data set's), else the noise model's estimate.
    pub fn noise_summary(
        &self,
        residual_profiles: &[(Vec<f64>, Vec<f64>)],
        declared: Option<f64>,
    ) -> Result<NoiseSummary, RheometerError> {
        let series = self.residual_series(residual_profiles)?;
        NoiseSummary::of(
            &series,
            declared.or(self.relative_uncertainty),
            &NoiseOptions::default(),
        )
        .map_err(RheometerError::Data)
    }

    /// `(d_model − d_meas)/d_meas` at the measurement positions of experiment `k`; `d_model` is
    /// the gauge's reading of the model diameter ([`FiberModel::observed_diameter`] with the
    /// solution's parameters, so instrument effects enter).
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
                let dm = model.observed_diameter(&y, &sol.params) * model.scaling.diameter();
                dm / d - 1.0
            })
            .collect()
    }
}

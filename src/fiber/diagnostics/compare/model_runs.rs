//! Simulating every experiment of a data set for a comparison: the law parameters, the take-up
//! conditions (from the data set, from the smoothed data, or as fitted) and the physics.

use super::{compare, CompareError, CompareOptions, Comparison, SimulatedExperiment};
use crate::fiber::material_law::CarreauLike;
use crate::fiber::model::FiberModel;
use crate::fiber::setup::{ExperimentSet, TakeUp};
use crate::fiber::simulate::{simulate_params, SimulateOptions};
use crate::fiber::smoothing::smooth;
use crate::fiber::Physics;
use crate::mesh::linspace;
use rayon::prelude::*;

/// What to do for an experiment whose data set gives no take-up condition.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MissingTakeUp {
    /// An error naming the experiment.
    Error,
    /// `d_fit(L)` of the smoothed measurements (the rheometer's convention).
    FromData,
    /// This take-up diameter (m).
    Diameter(f64),
}

/// The model to compare with: Carreau-type law parameters, take-up conditions and physics.
pub struct ModelSetup<'a> {
    /// `(n, κ)` of the Carreau-type law (`n = 1`: Newtonian).
    pub law_params: [f64; 2],
    /// Take-up factors `φ_k` multiplying each experiment's take-up condition (as fitted by the
    /// principled estimator; `None`: all 1).
    pub take_up_factors: Option<Vec<f64>>,
    /// Experiments without a take-up condition in the data set.
    pub missing_take_up: MissingTakeUp,
    /// Builds the physics of each experiment's model (called once per experiment).
    pub physics: &'a (dyn Fn() -> Physics + Sync),
    /// BVP settings (cold start per experiment).
    pub simulate: SimulateOptions,
    /// Points of the fine model curve for figures (default 201).
    pub curve_points: usize,
}

impl<'a> ModelSetup<'a> {
    /// The Carreau-type law at `(n, κ)`, take-up conditions from the data set only.
    pub fn carreau(law_params: [f64; 2], physics: &'a (dyn Fn() -> Physics + Sync)) -> Self {
        ModelSetup {
            law_params,
            take_up_factors: None,
            missing_take_up: MissingTakeUp::Error,
            physics,
            simulate: SimulateOptions::default(),
            curve_points: 201,
        }
    }

    /// Missing take-up conditions from the smoothed data (`d_fit(L)`).
    pub fn take_up_from_data(mut self) -> Self {
        self.missing_take_up = MissingTakeUp::FromData;
        self
    }
}

/// Simulates every experiment of `set` with `setup` (in parallel) and evaluates the model at
/// the measurement positions. Experiments without measurements are an error.
pub fn simulate_experiments(
    set: &ExperimentSet,
    setup: &ModelSetup<'_>,
) -> Result<Vec<SimulatedExperiment>, CompareError> {
    if set.experiments.is_empty() {
        return Err(CompareError::Data("the data set has no experiments".into()));
    }
    if let Some(f) = &setup.take_up_factors {
        if f.len() != set.experiments.len() {
            return Err(CompareError::Data(format!(
                "{} take-up factors for {} experiments",
                f.len(),
                set.experiments.len()
            )));
        }
        if let Some(v) = f.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
            return Err(CompareError::Data(format!(
                "take-up factor {v} is not a positive number"
            )));
        }
    }
    set.experiments
        .par_iter()
        .enumerate()
        .map(|(k, e)| {
            let sim_err = |source| CompareError::Simulation {
                experiment: e.name.clone(),
                source,
            };
            let m = set.measurements[k].as_ref().ok_or_else(|| {
                CompareError::Data(format!(
                    "experiment {} has no measurements (no data file)",
                    e.name
                ))
            })?;
            let mut e = e.clone();
            if e.take_up.is_none() {
                e.take_up = Some(match setup.missing_take_up {
                    MissingTakeUp::Error => {
                        return Err(CompareError::Data(format!(
                            "experiment {} has no take-up condition: give take_up_diameter_m \
                             or take_up_velocity_m_s in the TOML, or take it from the data",
                            e.name
                        )))
                    }
                    MissingTakeUp::Diameter(d) => TakeUp::Diameter(d),
                    MissingTakeUp::FromData => {
                        let f = smooth(&m.positions, &m.diameters).map_err(|source| {
                            CompareError::Smoothing {
                                experiment: e.name.clone(),
                                source,
                            }
                        })?;
                        let d = f.diameter(e.spinline_length);
                        if !(d.is_finite() && d > 0.0) {
                            return Err(CompareError::Data(format!(
                                "experiment {}: the take-up diameter d_fit(L) = {d} m of the \
                                 smoothed measurements is not a positive number; give \
                                 take_up_diameter_m in the TOML",
                                e.name
                            )));
                        }
                        TakeUp::Diameter(d)
                    }
                });
            }
            let model = FiberModel::new(
                &set.material,
                &set.air,
                &e,
                CarreauLike::new(),
                (setup.physics)(),
            )
            .map_err(sim_err)?;
            let mut p = model.parameters(1.0, &setup.law_params).map_err(sim_err)?;
            if let Some(f) = &setup.take_up_factors {
                p[model.take_up_factor_index()] = f[k];
            }
            let sol = simulate_params(&model, &p, None, &setup.simulate).map_err(sim_err)?;
            let curve = if setup.curve_points >= 2 {
                sol.profiles(
                    &model,
                    &linspace(0.0, e.spinline_length, setup.curve_points),
                )
            } else {
                Default::default()
            };
            Ok(SimulatedExperiment {
                name: e.name.clone(),
                positions: m.positions.clone(),
                measured: m.diameters.clone(),
                at_measurements: sol.profiles(&model, &m.positions),
                curve,
            })
        })
        .collect()
}

/// Simulates every experiment of `set` with `setup` and compares with the measurements
/// (the noise level from `options`, else the data set's `relative_uncertainty`, else
/// estimated).
pub fn compare_set(
    set: &ExperimentSet,
    setup: &ModelSetup<'_>,
    options: &CompareOptions,
) -> Result<Comparison, CompareError> {
    let runs = simulate_experiments(set, setup)?;
    compare(&runs, set.relative_uncertainty, options)
}

/// The parts of a fit report (`rheometer fit --json`, [`FitReport`](crate::fiber::rheometer::FitReport))
/// a comparison needs; other fields are ignored (so missing standard errors, written as `null`,
/// do not matter).
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
pub struct FitParameters {
    /// The estimator of the fit.
    pub estimator: crate::fiber::rheometer::Estimator,
    /// Power index `n` \[-\].
    pub n: f64,
    /// `κ = ln(K / 1 Pa)` \[-\].
    pub kappa: f64,
    /// Take-up factors `φ_k`, in the experiment order of the data set.
    #[serde(default)]
    pub take_up_factors: Vec<f64>,
    /// The extra effects of the fitted model with their strengths (empty for the paper's
    /// model).
    #[serde(default)]
    pub effects: Vec<FittedEffect>,
}

/// An effect of a fitted model as read from a fit report.
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
pub struct FittedEffect {
    /// Canonical name (e.g. `"radiation"`).
    pub effect: String,
    /// Strength in the effect's unit.
    pub strength: f64,
    /// Whether the strength was fitted (else fixed).
    #[serde(default)]
    pub fitted: bool,
}

impl FitParameters {
    /// Parses the JSON text of a fit report; `source` names it in errors.
    pub fn from_json(text: &str, source: &str) -> Result<Self, CompareError> {
        let p: FitParameters = serde_json::from_str(text).map_err(|e| {
            CompareError::Data(format!(
                "{source} is not a fit report as written by `rheometer fit --json`: {e}"
            ))
        })?;
        if !(p.n.is_finite() && p.kappa.is_finite()) {
            return Err(CompareError::Data(format!(
                "{source}: n = {} and kappa = {} must be finite",
                p.n, p.kappa
            )));
        }
        Ok(p)
    }

    /// Number of parameters the fit adjusted to the data: `(n, κ)` and, for the principled
    /// estimator, one take-up factor per experiment.
    pub fn fitted_parameters(&self) -> usize {
        match self.estimator {
            crate::fiber::rheometer::Estimator::Principled => 2 + self.take_up_factors.len(),
            crate::fiber::rheometer::Estimator::Paper => 2,
        }
        .saturating_add(self.effects.iter().filter(|e| e.fitted).count())
    }

    /// Applies the fit to `setup`: law parameters, take-up factors (principled estimator;
    /// checked against `experiments`, the number of experiments) and the rheometer's take-up
    /// convention (`d_fit(L)` where the data set gives none).
    pub fn apply(
        &self,
        setup: &mut ModelSetup<'_>,
        experiments: usize,
        source: &str,
    ) -> Result<(), CompareError> {
        setup.law_params = [self.n, self.kappa];
        setup.missing_take_up = MissingTakeUp::FromData;
        setup.take_up_factors = None;
        if self.estimator == crate::fiber::rheometer::Estimator::Principled {
            if self.take_up_factors.len() != experiments {
                return Err(CompareError::Data(format!(
                    "{source}: {} take-up factors for {experiments} experiments; was the fit made \
                     on this data set?",
                    self.take_up_factors.len()
                )));
            }
            setup.take_up_factors = Some(self.take_up_factors.clone());
        }
        Ok(())
    }
}

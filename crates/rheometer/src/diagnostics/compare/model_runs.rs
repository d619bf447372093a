//! Simulating every experiment of a data set for a comparison: the law parameters, the take-up
//! conditions (from the data set, from the smoothed data, or as fitted) and the physics.

use super::{compare, CompareError, CompareOptions, Comparison, SimulatedExperiment};
pub use crate::data::take_up::MissingTakeUp;
use crate::data::take_up::{resolve_take_up, TakeUpError};
use crate::fit::FitSummary;
use crate::in_order::CollectInOrder;
use crate::model::bvp::FiberModel;
use crate::model::contributions::Physics;
use crate::model::material_law::CarreauLike;
use crate::model::setup::ExperimentSet;
use crate::model::simulate::{simulate_params, SimulateOptions};
use diffbvp::mesh::linspace;
use rayon::prelude::*;

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
            let resolved = resolve_take_up(&e, Some(m), setup.missing_take_up, None).map_err(
                |err| match err {
                    TakeUpError::Smoothing(source) => CompareError::Smoothing {
                        experiment: e.name.clone(),
                        source,
                    },
                    TakeUpError::Missing | TakeUpError::NoMeasurements => CompareError::NoTakeUp {
                        experiment: e.name.clone(),
                    },
                },
            )?;
            if let Some(d) = resolved.from_data {
                if !(d.is_finite() && d > 0.0) {
                    return Err(CompareError::Data(format!(
                        "experiment {}: the take-up diameter d_fit(L) = {d} m of the \
                         smoothed measurements is not a positive number; give \
                         take_up_diameter_m in the TOML",
                        e.name
                    )));
                }
            }
            e.take_up = Some(resolved.take_up);
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
                p[model.param_layout().take_up_factor()] = f[k];
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
        .collect_in_order()
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

impl ModelSetup<'_> {
    /// Applies the fit `fit` (read from `source`) to the setup: its law parameters, its
    /// take-up factors (principled estimator; checked against `experiments`, the number of
    /// experiments) and the rheometer's take-up convention (`d_fit(L)` where the data set gives
    /// none). The effects are the physics' (see [`FitSummary::model_effects`]).
    pub fn apply_fit(
        &mut self,
        fit: &FitSummary,
        experiments: usize,
        source: &str,
    ) -> Result<(), CompareError> {
        self.law_params = fit.law_params();
        self.missing_take_up = MissingTakeUp::FromData;
        self.take_up_factors = fit
            .take_up_for(experiments, source)
            .map_err(CompareError::Data)?;
        Ok(())
    }
}

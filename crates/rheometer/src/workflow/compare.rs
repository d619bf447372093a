//! The `compare` workflow: the model of a fit (or given law parameters), with effects added or
//! overridden, simulated for every experiment and compared with the measurements.

use crate::data::input::LoadedExperiments;
use crate::diagnostics::compare::{
    compare as compare_runs, simulate_experiments, CompareError, CompareOptions, Comparison,
    MissingTakeUp, ModelSetup,
};
use crate::fit::FitSummary;
use crate::model::contributions::Physics;
use crate::model::effects::{physics_with, Effect, EffectSetting};
use crate::model::simulate::SimulateOptions;
use crate::workflow::request::{in_words_of, Door};

/// What to compare.
#[derive(Debug, Clone)]
pub struct CompareRequest {
    /// The fit to compare (its law, effects with their fitted shapes, take-up factors and —
    /// when nothing is changed — its noise level), and the name of its file for messages.
    pub fit: Option<(FitSummary, String)>,
    /// `(n, κ)` without a fit (`n = 1`: Newtonian).
    pub law: [f64; 2],
    /// Effects added to the model or overriding the fit's (`EFFECT=VALUE`; `EFFECT` alone takes
    /// the strength from the fit).
    pub with: Vec<EffectSetting>,
    /// Experiments without a take-up condition in the data set (a fit implies `FromData`).
    pub missing_take_up: MissingTakeUp,
    /// Relative measurement uncertainty \[-\] overriding the data set's.
    pub relative_uncertainty: Option<f64>,
    /// BVP settings.
    pub simulate: SimulateOptions,
    /// The door the request came through: its messages name the inputs in its words.
    pub door: Door,
}

impl CompareRequest {
    /// The comparison of the Carreau-type law at `law = (n, κ)` with the paper's physics.
    pub fn at(law: [f64; 2]) -> Self {
        CompareRequest {
            fit: None,
            law,
            with: Vec::new(),
            missing_take_up: MissingTakeUp::Error,
            relative_uncertainty: None,
            simulate: SimulateOptions::default(),
            door: Door::Cli,
        }
    }

    /// The comparison of a fit (read from `source`).
    pub fn of_fit(fit: FitSummary, source: &str) -> Self {
        CompareRequest {
            law: fit.law_params(),
            fit: Some((fit, source.to_string())),
            ..CompareRequest::at([1.0, 0.0])
        }
    }

    /// The effects of the compared model: those of the fit, overridden or extended by `with`.
    pub fn effects(&self) -> Result<Vec<(Effect, f64)>, String> {
        let mut out: Vec<(Effect, f64)> = match &self.fit {
            Some((f, _)) => f.model_effects()?,
            None => Vec::new(),
        };
        for w in &self.with {
            let name = w.effect.name();
            let value = match (w.value, out.iter().find(|(e, _)| e.id() == w.effect.id())) {
                (Some(v), _) => v,
                (None, Some((_, v))) => *v,
                (None, None) => {
                    return Err(format!(
                        "--with {name}: give its strength as --with {name}=VALUE (the fit file \
                         has none)"
                    ))
                }
            };
            out.retain(|(e, _)| e.name() != name);
            out.push((w.effect.clone(), value));
        }
        Ok(out)
    }
}

/// Compares `request`'s model with `data`'s measurements. A fit compared as it is (no effect
/// added or overridden, no other noise level) keeps its one noise level.
pub fn compare(
    data: &LoadedExperiments,
    request: &CompareRequest,
) -> Result<Comparison, CompareError> {
    let set = &data.set;
    let effects = request.effects().map_err(CompareError::Data)?;
    // validated once here; the closure rebuilds the same physics per experiment
    physics_with(&effects).map_err(CompareError::Data)?;
    let physics = || physics_with(&effects).unwrap_or_else(|_| Physics::paper());
    let mut setup = ModelSetup::carreau(request.law, &physics);
    setup.simulate = request.simulate.clone();
    setup.missing_take_up = request.missing_take_up;
    let mut options = CompareOptions {
        relative_uncertainty: request.relative_uncertainty,
        ..Default::default()
    };
    if let Some((fit, source)) = &request.fit {
        fit.check_experiments(&set.names(), source)
            .map_err(CompareError::Data)?;
        setup.apply_fit(fit, set.experiments.len(), source)?;
        options.fitted_parameters = fit.fitted_parameters();
        let known = fit.noise.level > 0.0 && fit.noise.level.is_finite();
        if known && request.with.is_empty() && request.relative_uncertainty.is_none() {
            options.fit_noise = Some(fit.noise.clone());
        }
    }
    let runs = simulate_experiments(set, &setup).map_err(|e| match e {
        CompareError::NoTakeUp { experiment } => CompareError::Data(in_words_of(
            &format!(
                "experiment {experiment} has no take-up condition: give take_up_diameter_m or \
                 take_up_velocity_m_s in {}, or take it from the data \
                 (@take_up_from_data=True@)",
                data.path.display()
            ),
            request.door,
        )),
        e => e,
    })?;
    compare_runs(&runs, set.relative_uncertainty, &options)
}

//! The `simulate` workflow: every experiment of a data set at given law parameters (and fixed
//! effect strengths), with the take-up rule for experiments without a take-up condition, each
//! result handed to the caller as soon as it is finished (so that a long run can be written
//! and stopped experiment by experiment), optionally with the exact sensitivities of the
//! profiles ([`profile_sensitivities`]).

use crate::data::input::{LoadedExperiments, Location};
use crate::data::take_up::{resolve_take_up, MissingTakeUp, TakeUpError};
use crate::model::effects::{physics_with, Effect};
use crate::model::profile_sensitivities::{profile_sensitivities, ProfileSensitivities};
use crate::model::simulate::{simulate, Profiles, SimulateOptions};
use crate::workflow::failure_hints::ExperimentFailure;
use crate::{model::bvp::FiberModel, model::material_law::CarreauLike};
use std::fmt;
use std::ops::ControlFlow;
use std::path::PathBuf;

/// What to simulate.
#[derive(Debug, Clone)]
pub struct SimulateRequest {
    /// `(n, κ)` of the Carreau-type law (`n = 1`: Newtonian).
    pub law: [f64; 2],
    /// Experiments without a take-up condition in the data set.
    pub missing_take_up: MissingTakeUp,
    /// Uniform output positions per experiment (≥ 2).
    pub points: usize,
    /// BVP settings.
    pub simulate: SimulateOptions,
    /// The experiments file, for the location of a failed experiment.
    pub source: PathBuf,
    /// Effects added to the paper's physics with fixed strengths (each in its effect's unit;
    /// empty: the paper's model).
    pub effects: Vec<(Effect, f64)>,
    /// Output positions \[m\] used for every experiment instead of `points` uniform ones.
    pub positions: Option<Vec<f64>>,
    /// The door the request came through (the words of its messages).
    pub door: super::request::Door,
    /// Also compute the exact sensitivities of the profiles with respect to `n`, `κ` and the
    /// effects' strengths (`SimulatedProfile::sensitivities`).
    pub sensitivities: bool,
}

impl SimulateRequest {
    /// The paper's model at `law = (n, κ)`, 101 uniform positions, default BVP settings, no
    /// take-up rule (an experiment without a take-up condition is an error); `source` names
    /// the experiments file in messages.
    pub fn new(law: [f64; 2], source: PathBuf) -> Self {
        SimulateRequest {
            law,
            missing_take_up: MissingTakeUp::Error,
            points: 101,
            simulate: SimulateOptions::default(),
            source,
            effects: Vec::new(),
            positions: None,
            door: super::request::Door::Cli,
            sensitivities: false,
        }
    }
}

/// One experiment's simulation.
#[derive(Debug, Clone)]
pub struct SimulatedProfile {
    /// Experiment name.
    pub name: String,
    /// Profiles at uniform positions along the line (SI units).
    pub profiles: Profiles,
    /// Mesh nodes of the solution.
    pub nodes: usize,
    /// The take-up diameter \[m\] taken from the smoothed measurements, if it was.
    pub take_up_from_data: Option<f64>,
    /// Exact `d(profile)/d(n, κ, strengths)` at the profiles' positions
    /// ([`SimulateRequest::sensitivities`]).
    pub sensitivities: Option<ProfileSensitivities>,
}

/// Why the `simulate` workflow stopped.
#[derive(Debug)]
pub enum SimulateError {
    /// An experiment has no usable take-up condition (in words, naming it and what to do).
    TakeUp(String),
    /// The effects cannot be combined into a model (in words).
    Effects(String),
    /// An experiment's model failed (named, with its TOML line and likely causes; boxed: the
    /// failure is large).
    Experiment(Box<ExperimentFailure>),
    /// The caller stopped the run after `done` experiments.
    Stopped {
        /// Experiments finished.
        done: usize,
    },
}

impl fmt::Display for SimulateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimulateError::TakeUp(m) | SimulateError::Effects(m) => f.write_str(m),
            SimulateError::Experiment(e) => write!(f, "{e}"),
            SimulateError::Stopped { done } => write!(f, "stopped after {done} experiments"),
        }
    }
}

impl std::error::Error for SimulateError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SimulateError::Experiment(e) => Some(e.as_ref()),
            _ => None,
        }
    }
}

/// Simulates every experiment of `data` in order; `each(k, profile)` is called after each
/// one and may stop the run (`ControlFlow::Break`). Returns all profiles.
pub fn simulate_experiments(
    data: &LoadedExperiments,
    request: &SimulateRequest,
    mut each: impl FnMut(usize, &SimulatedProfile) -> ControlFlow<()>,
) -> Result<Vec<SimulatedProfile>, SimulateError> {
    let set = &data.set;
    physics_with(&request.effects).map_err(SimulateError::Effects)?;
    let mut out = Vec::with_capacity(set.experiments.len());
    for k in 0..set.experiments.len() {
        let p = simulate_one(data, request, k)?;
        let flow = each(k, &p);
        out.push(p);
        if flow.is_break() && k + 1 < set.experiments.len() {
            return Err(SimulateError::Stopped { done: k + 1 });
        }
    }
    Ok(out)
}

fn location(data: &LoadedExperiments, request: &SimulateRequest, k: usize) -> Location {
    Location {
        path: request.source.clone(),
        line: data.details.get(k).and_then(|d| d.line),
    }
}

/// Experiment `k` at the request's law.
fn simulate_one(
    data: &LoadedExperiments,
    request: &SimulateRequest,
    k: usize,
) -> Result<SimulatedProfile, SimulateError> {
    let set = &data.set;
    let mut e = set.experiments[k].clone();
    let resolved = resolve_take_up(
        &e,
        set.measurements[k].as_ref(),
        request.missing_take_up,
        None,
    )
    .map_err(|err| {
        SimulateError::TakeUp(match err {
            TakeUpError::NoMeasurements => format!(
                "experiment {}: a take-up diameter from the data needs measurements",
                e.name
            ),
            TakeUpError::Smoothing(err) => format!(
                "experiment {} ({}): the take-up diameter from the data: smoothing the \
                 measurements failed: {err}",
                e.name,
                location(data, request, k)
            ),
            TakeUpError::Missing => super::request::in_words_of(
                &format!(
                    "experiment {} has no take-up condition: give take_up_diameter_m or \
                     take_up_velocity_m_s in {}, or a take-up diameter (@take_up_diameter@) \
                     or take it from the data (@take_up_from_data@)",
                    e.name,
                    request.source.display()
                ),
                request.door,
            ),
        })
    })?;
    let from_data = resolved.from_data;
    e.take_up = Some(resolved.take_up);
    // a failure names the experiment, its TOML line and likely causes
    let failed = |source: crate::FiberError| {
        let mut f = ExperimentFailure::new(
            &e,
            &set.material,
            location(data, request, k),
            Some(request.law),
            Box::new(source),
        );
        if let Some(d) = from_data {
            f.hints.push(super::request::in_words_of(
                &format!(
                    "the take-up diameter {d:.4e} m is d_fit(L) of the smoothed measurements \
                     (@take_up_from_data@; in the library MissingTakeUp::FromData)"
                ),
                request.door,
            ));
        }
        SimulateError::Experiment(Box::new(f))
    };
    // checked in `simulate_experiments`
    let physics = physics_with(&request.effects).map_err(SimulateError::Effects)?;
    let model = FiberModel::new(&set.material, &set.air, &e, CarreauLike::new(), physics)
        .map_err(failed)?;
    let sol = simulate(&model, &request.law, &request.simulate).map_err(failed)?;
    let profiles = match &request.positions {
        Some(p) => sol.profiles(&model, p),
        None => sol.uniform_profiles(&model, request.points),
    };
    let sensitivities = if request.sensitivities {
        Some(profile_sensitivities(&model, &sol, &profiles.position).map_err(failed)?)
    } else {
        None
    };
    Ok(SimulatedProfile {
        name: e.name.clone(),
        profiles,
        nodes: sol.nodes(),
        take_up_from_data: from_data,
        sensitivities,
    })
}

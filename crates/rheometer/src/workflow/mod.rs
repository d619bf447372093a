//! Workflows as library calls: what each `rheometer` subcommand does, on a loaded data set,
//! returning values. The program parses its arguments, calls one of these, and renders the
//! result; a Rust or Python user gets exactly what the command line gets.
//!
//! | subcommand | call | result |
//! |---|---|---|
//! | `simulate` | [`simulate_experiments`] | profiles per experiment |
//! | `fit` | [`fit()`] | [`FitRun`] (its [`FitSummary`](crate::fit::FitSummary)) |
//! | `compare` | [`compare()`] | [`Comparison`](crate::diagnostics::compare::Comparison) |
//! | `diagnose` | [`diagnose()`] | [`DiagnosisRun`] |
//! | `landscape` | [`landscape()`] | [`LandscapeRun`] |
//! | `design` | [`design()`] | `DesignRun` (its [`Design`](crate::design::Design)) |
//! | `design --discriminate` | [`discriminate()`] | `DiscriminationRun` (its [`Discrimination`](crate::design::Discrimination)) |
//!
//! ```no_run
//! use rheometer::data::input::{load_experiments_with, LoadOptions};
//! use rheometer::fit::IdentifyOptions;
//! use rheometer::workflow::{fit, FitRequest};
//! use std::path::Path;
//! let path = Path::new("data/pmma7n_synthetic/experiments.toml");
//! let data = load_experiments_with(path, &LoadOptions::default())?;
//! let run = fit(&data, &FitRequest::new(IdentifyOptions::default()))?;
//! println!("{}", run.summary().to_text());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod compare;
mod design;
pub mod failure_hints;
mod fit;
pub mod request;
mod simulate;

pub use compare::{compare, CompareRequest};
pub use design::{design, design_with_estimate, discriminate, discriminate_with_estimate};
pub use fit::{fit, FitRequest, FitRun};
pub use simulate::{simulate_experiments, SimulateError, SimulateRequest};

use crate::data::input::LoadedExperiments;
use crate::diagnostics::diagnose::{diagnose as run_diagnosis, DiagnoseOptions};
use crate::diagnostics::diagnosis::DiagnosisRun;
use crate::fit::{FarRule, IdentifyOptions, LandscapeRun, Rheometer, RheometerError};
use crate::model::effects::ModelSpec;
use std::sync::atomic::AtomicBool;

/// Diagnoses which candidate effect is missing from `model` on `data` (see
/// [`diagnose`](crate::diagnostics::diagnose)).
pub fn diagnose(
    data: &LoadedExperiments,
    model: &ModelSpec,
    options: &DiagnoseOptions,
) -> Result<DiagnosisRun, RheometerError> {
    model.validate().map_err(RheometerError::Data)?;
    run_diagnosis(&data.set, model, options)
}

/// A cost landscape: the grid and the cost's settings.
#[derive(Debug, Clone)]
pub struct LandscapeRequest {
    /// `n` values of the grid \[-\].
    pub n: Vec<f64>,
    /// `κ` values of the grid \[-\].
    pub kappa: Vec<f64>,
    /// The estimator whose cost is mapped, and the BVP settings.
    pub identify: IdentifyOptions,
    /// The accuracy of the points far from their row's minimum (`None`:
    /// [`FarRule::for_tol`] of `identify`'s tolerance; [`FarRule::uniform`]: every point at
    /// that tolerance).
    pub far: Option<FarRule>,
}

/// The cost `J(n, κ)` of the paper's model on `request`'s grid; `progress(points done)` is
/// called as points finish, and `cancel` stops the run between points (the points not
/// reached are marked).
pub fn landscape(
    data: &LoadedExperiments,
    request: &LandscapeRequest,
    progress: impl FnMut(usize) + Send,
    cancel: &AtomicBool,
) -> Result<LandscapeRun, RheometerError> {
    let rh = Rheometer::new(&data.set)?;
    let far = request
        .far
        .unwrap_or_else(|| FarRule::for_tol(request.identify.simulate.tol));
    rh.landscape_ruled(
        &request.n,
        &request.kappa,
        &request.identify,
        far,
        progress,
        cancel,
    )
}

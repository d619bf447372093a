//! The simulation-based elongational rheometer: identification of the Carreau-type law
//! `(n, κ = ln K)` from measured diameter profiles of many spinning experiments (paper Sec. 3–4).
//!
//! * `estimator`: the two cost functions — the paper's strain-rate-weighted distance to the
//!   smoothed data, and the statistically principled relative least squares against the raw
//!   measurements with the take-up diameters as nuisance parameters;
//! * `options`: what the modules share (the model type, the error, the options of an
//!   identification, the warnings of a fit, the side of a bound);
//! * `data`: the prepared data ([`Rheometer`]: smoothed measurements, one model per
//!   experiment);
//! * `identify`: the identification itself — `identify::gauss_newton`, the start-point
//!   heuristic (paper Algorithm 2) and the bounded trust-region Gauss–Newton fit, its result a
//!   value of its own, `identify::identification` ([`Identification`]);
//!   `identify::accuracy`, the fit's BVPs solved only as accurately as the noise needs, and the
//!   proof; `identify::nested`, a fit with effects that never ends worse than the model
//!   without them (also started from the plain model's optimum);
//! * `objective`: the least-squares objective over all experiments (solved in parallel,
//!   warm-started, exact Jacobians from forward sensitivities);
//! * `layout`: which parameters are fitted (law, effect strengths, take-up factors);
//! * `plan`: the time and memory a fit will take, measured on one experiment before it starts;
//! * `landscape`: the cost on a grid (paper Fig. 4);
//! * `uncertainty`: what the estimates are worth — [`error_budget()`] (in
//!   `uncertainty::error_budget`): what the data cannot identify (process conditions, instrument,
//!   material data) propagated through exact sensitivities into a systematic uncertainty;
//! * `summary`: the outcome of a fit as one value, [`FitSummary`] (named estimates with
//!   standard errors and 95% confidence intervals, covariance, the one noise level, warnings),
//!   rendered as text and JSON and read back by the next step;
//! * `uncertainty::flow_curve`: the identified law as `η_E(ε̇)` at a temperature, with its
//!   statistical and systematic bands and the strain rates the data cover; the values it
//!   yields, [`FlowCurve`] and `StrainRateCoverage`, are in `values::curve` and
//!   `values::coverage`;
//! * `uncertainty::profile`: profile-likelihood intervals, one-sided bounds at a bound, and the
//!   likelihood-ratio test against the nested Newtonian law; the values it yields
//!   (`ProfileInterval`, `NewtonianTest`) are in `values::likelihood`;
//! * `summary::checks`: the checks of a fit (estimates at bounds, misfit, huge errors, data
//!   the model cannot describe), their thresholds in `values::thresholds`.
//!
//! The values a [`FitSummary`] holds (in `values`: `budget`, `curve`, `coverage`,
//! `likelihood`) sit below it and the steps that compute them above it, so that no two files
//! import each other (the order is in the Layers section of the crate's documentation).

pub(crate) mod data;
pub(crate) mod estimator;
pub(crate) mod identify;
pub(crate) mod landscape;
pub(crate) mod layout;
mod lr_calibration;
pub(crate) mod objective;
pub(crate) mod options;
pub(crate) mod plan;
pub(crate) mod summary;
pub(crate) mod uncertainty;
pub(crate) mod values;

pub use estimator::RelativeResidual;
pub use objective::Objective;

pub use data::Rheometer;
pub use estimator::Estimator;
pub(crate) use identify::gauss_newton::StartPoint;
pub use identify::gauss_newton::PAPER_TABLE3_STARTS;
pub use identify::identification::Identification;
pub use identify::nested::NestedStart;
pub use landscape::{FarRule, Landscape, LandscapeRun, LandscapeSample, PointStatus};
pub use layout::{FitStart, Layout};
pub(crate) use options::CarreauFiber;
pub use options::{BoundSide, FitProgress, IdentifyOptions, ProgressHook, RheometerError};
pub use summary::read::{data_digest, ContinuedEffects, DataCheck};
pub use summary::{
    AtBound, Covariance, EffectEstimate, Estimate, FitSummary, FitWarning, SolverRecord,
    WarningCode,
};
pub use uncertainty::error_budget::{error_budget, BudgetEntry, ErrorBudget, SourceStatus};
pub(crate) use uncertainty::flow_curve::FlowCurveOptions;
pub(crate) use values::curve::FlowPoint;
pub use values::curve::{BandMethod, FlowCurve};
pub use values::likelihood::ProfilePoint;
pub(crate) use values::parameter_shift::ParameterShift;

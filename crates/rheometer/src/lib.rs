//! # rheometer — a simulation-based high-speed elongational rheometer
//!
//! The stationary melt-spinning fiber model and the rheometer built on it: from fiber diameters
//! measured along a spinning line it identifies the strain-rate-dependent elongational
//! viscosity, diagnoses where and why the model misses the data, and designs the next
//! experiment. A *user* of the generic toolkit [`diffbvp`]: the toolkit knows nothing of fibers.
//!
//! * [`plot`], [`html_page`], [`output_files`]: figures, the printable report page and the
//!   output layer every file goes through;
//! * [`setup`]: SI inputs (material, air, experiment);
//! * [`input`]: loading experiments from the project's TOML + CSV format;
//! * [`scaling`]: non-dimensionalisation (paper Table 2);
//! * [`material_law`]: elongational viscosity laws (Newtonian, Carreau-type, Carreau–Yasuda);
//! * [`catalog`]: one descriptor per candidate effect (name, unit, ranges, shapes, category,
//!   remedy, error-budget source, how it enters the model), data only;
//! * [`contributions`]: named force and heat terms, air environment, Nusselt law;
//! * [`effects`]: the candidate effects (a descriptor plus its settings, or a user's descriptor
//!   and term) and the model specification (law + effects) a rheometer fit uses;
//! * [`model`]: the strain-rate formulation as a [`Bvp`](diffbvp::Bvp);
//! * [`cold_start`]: continuation from the stress-free fiber;
//! * [`failure_hints`]: simulation failures naming their experiment, with likely causes;
//! * [`mod@simulate`]: the user-facing API with SI profiles;
//! * [`profile_sensitivities`]: exact derivatives of the SI profiles with respect to the law
//!   parameters and the effects' strengths;
//! * [`smoothing`]: the velocity-ansatz smoothing of measured diameters (paper eq. 5);
//! * [`fit`]: identification of the elongational viscosity from diameter profiles;
//! * [`figures`]: profile, fit and landscape figures (PNG/SVG);
//! * [`flow_curve_figure`]: the flow curve `η_E(ε̇)` with its bands (PNG/SVG);
//! * [`fit_html`]: the HTML report of a fit (self-contained page, from the fit's values);
//! * [`statistics`]: noise estimates, runs test, autocorrelation and rank correlation of
//!   residuals;
//! * [`take_up`]: the take-up condition a model uses (the data set's, a given diameter, or
//!   `d_fit(L)` of the smoothed data);
//! * [`synthetic`]: reproducible measurement noise for synthetic data sets;
//! * [`diagnostics`]: model vs measurement comparison (where and how the model misses the data);
//! * [`design`]: which experiment next (optimal experimental design from the exact
//!   sensitivities);
//! * [`workflow`]: what each `rheometer` subcommand does, as library calls returning values.
//!
//! ## Layers
//!
//! Each module imports only from its own layer's peers without cycles and from the layers below
//! it (checked by `python3 .ci/import-graph.py`, which reads this list); the toolkit `diffbvp`
//! is a dependency, never the other way round. Bottom to top:
//!
//! 0. `plot`, `html_page`, `output_files` (the output layer: checks of every output before the
//!    work, temporary-then-rename writing of regular files, special files written in place);
//! 1. `setup`, `error`, `scaling`, `material_law`, `format` (numbers for people), `serde_nan`,
//!    `report_json` (the stamp of every JSON report: schema version, kind, program),
//!    `environment` (the `DIFFBVP_*` variables and the thread count, checked),
//!    `in_order` (the first failure of a parallel loop in the experiments' order);
//! 2. `catalog` (one descriptor per effect), `contributions` (force and heat terms) and
//!    `effects` (the candidate effects vocabulary);
//! 3. `model` (the BVP);
//! 4. `cold_start`, `simulate`, `profile_sensitivities`;
//! 5. `smoothing`, `synthetic`, `input`, `output`, `statistics`, `noise_model`,
//!    `noise_summary` (the one noise level), `take_up`, `uncertainty`;
//! 6. `fit` (the identification; inside, bottom to top: `estimator` → `options` → `data`,
//!    `layout`, `parameter_shift` and the values `thresholds`, `budget`, `curve`,
//!    `likelihood` → `coverage`, `objective`, `plan`, `landscape` → `summary` (the record of a
//!    fit: the value, then what reads it, `checks`, `text`, `read`, then `build`),
//!    `identification` → `accuracy` → `identify` → `nested`, `profile`, `flow_curve`,
//!    `error_budget` → `summary::finding`);
//! 7. `figures`, `flow_curve_figure`, `fit_html` (the HTML report of a fit);
//! 8. `diagnostics` (`compare`, `candidate` → `ties`, `calibration`, `diagnose` (its stages),
//!    `diagnosis`, `report`);
//! 9. `failure_hints`, `design` (inside: `information`, `criteria`, `candidates` →
//!    `estimation` → `report`);
//! 10. `workflow` (what each `rheometer` subcommand does, as library calls).
#![warn(missing_docs)]
// Numerical kernels index several arrays with the same loop variable, as the formulas do.
#![allow(clippy::needless_range_loop)]

pub mod catalog;
pub mod cold_start;
pub mod contributions;
pub mod design;
pub mod diagnostics;
pub mod effects;
pub mod environment;
pub(crate) mod error;
pub mod failure_hints;
pub mod figures;
pub mod fit;
pub mod fit_html;
pub mod flow_curve_figure;
pub mod format;
pub mod html_page;
pub(crate) mod in_order;
pub mod input;
pub mod material_law;
pub mod model;
pub mod noise_model;
pub(crate) mod noise_summary;
pub mod output;
pub mod output_files;
pub mod plot;
pub mod profile_sensitivities;
pub mod report_json;
pub mod scaling;
pub(crate) mod serde_nan;
pub mod setup;
pub mod simulate;
pub mod smoothing;
pub mod statistics;
pub mod synthetic;
pub mod take_up;
pub mod uncertainty;
pub mod workflow;

pub use contributions::{
    Balance, FiberTerm, InclinedChurchillBernstein, NusseltLaw, Physics, SiState, Strength,
    StrengthPlan,
};
pub use error::FiberError;
pub use material_law::{CarreauLike, CarreauYasuda, Newtonian, ViscosityLaw};
pub use model::{FiberModel, ParamLayout};
pub use scaling::{ReferenceValues, Scaling};
pub use simulate::{simulate, simulate_from, FiberSolution, Profiles, SimulateOptions, Simulator};

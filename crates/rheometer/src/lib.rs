//! # rheometer — a simulation-based high-speed elongational rheometer
//!
//! The stationary melt-spinning fiber model and the rheometer built on it: from fiber diameters
//! measured along a spinning line it identifies the strain-rate-dependent elongational
//! viscosity, diagnoses where and why the model misses the data, and designs the next
//! experiment. A *user* of the generic toolkit [`diffbvp`]: the toolkit knows nothing of fibers.
//!
//! The folders follow the method, data → model → fit → diagnose and design → report, with the
//! subcommands on top:
//!
//! * [`data`]: the measured experiments — [`data::input`] (loading the project's TOML + CSV
//!   format), [`data::uncertainty`] (declared standard uncertainties), [`data::smoothing`]
//!   (the velocity-ansatz smoothing of measured diameters, paper eq. 5), [`data::take_up`]
//!   (the take-up condition a model uses), [`data::statistics`] and [`data::noise_model`]
//!   (noise estimates, runs test, autocorrelation, rank correlation, the noise along the spin
//!   line, the one noise level), [`data::synthetic`] (reproducible measurement noise);
//! * [`model`]: the fiber model — `model::setup` (SI inputs: material, air, experiment),
//!   `model::scaling` (non-dimensionalisation, paper Table 2), `model::material_law`
//!   (elongational viscosity laws: Newtonian, Carreau-type, Carreau–Yasuda),
//!   `model::catalog` (one descriptor per candidate effect: name, unit, ranges, shapes,
//!   category, remedy, error-budget source, how it enters the model; data only),
//!   `model::contributions` (named force and heat terms, air environment, Nusselt law),
//!   `model::effects` (the candidate effects and the model specification, law + effects, a
//!   rheometer fit uses), `model::bvp` (the strain-rate formulation as a
//!   [`Bvp`](diffbvp::Bvp)), `model::cold_start` (continuation from the stress-free fiber),
//!   `model::simulate` (the user-facing API with SI profiles) and
//!   [`model::profile_sensitivities`] (exact derivatives of the SI profiles with respect to
//!   the law parameters and the effects' strengths);
//! * [`fit`]: identification of the elongational viscosity from diameter profiles;
//! * [`diagnostics`]: model vs measurement comparison (where and how the model misses the data);
//! * [`design`]: which experiment next (optimal experimental design from the exact
//!   sensitivities);
//! * [`report`]: what the program writes — [`report::plot`] and the figures
//!   ([`report::figures`], [`report::flow_curve_figure`]), the HTML page
//!   ([`report::html_page`]) and the report of a fit ([`report::fit_html`]), numbers for
//!   people ([`report::format`](mod@report::format)), the stamp of JSON reports
//!   ([`report::report_json`]), and the output layer every file goes through
//!   ([`report::output_files`], [`report::output`]);
//! * [`workflow`]: what each `rheometer` subcommand does, as library calls returning values,
//!   and [`workflow::failure_hints`] (simulation failures naming their experiment, with likely
//!   causes);
//! * [`environment`]: the `DIFFBVP_*` variables and the thread count, checked.
//!
//! ## Layers
//!
//! Each module imports only from its own layer's peers without cycles and from the layers below
//! it (checked by `python3 .ci/import-graph.py`, which reads this list); the toolkit `diffbvp`
//! is a dependency, never the other way round. A folder whose modules sit on different layers
//! (`model`, `data`, `report`) is listed module by module. Bottom to top:
//!
//! 0. `report::plot`, `report::html_page`, `report::output_files` (the output layer: checks of
//!    every output before the work, temporary-then-rename writing of regular files, special
//!    files written in place);
//! 1. `model::setup`, `error`, `model::scaling`, `model::material_law`, `report::format`
//!    (numbers for people), `report::serde_nan`, `report::report_json` (the stamp of every JSON
//!    report: schema version, kind, program), `environment` (the `DIFFBVP_*` variables and the
//!    thread count, checked), `in_order` (the first failure of a parallel loop in the
//!    experiments' order);
//! 2. `model::catalog` (one descriptor per effect), `model::contributions` (force and heat
//!    terms) and `model::effects` (the candidate effects vocabulary);
//! 3. `model::bvp` (the BVP);
//! 4. `model::cold_start`, `model::simulate`, `model::profile_sensitivities`;
//! 5. `data::smoothing`, `data::synthetic`, `data::input`, `report::output`,
//!    `data::statistics`, `data::noise_model`, `data::noise_summary` (the one noise level),
//!    `data::take_up`, `data::uncertainty`;
//! 6. `fit` (the identification; inside, bottom to top: `estimator` → `options` → `data`,
//!    `layout` and `values` (`parameter_shift`, `thresholds`, `budget`, `curve`, `likelihood`
//!    → `coverage`) → `objective`, `plan`, `landscape` → `summary` (the record of a fit: the
//!    value, then what reads it, `checks`, `text`, `read`, then `build`) → `identify`
//!    (`identification` → `accuracy` → `gauss_newton` → `nested`) → `lr_calibration` (the
//!    Newtonian test's calibrated p) → `uncertainty` (`profile`, `flow_curve`, `error_budget`)
//!    → `summary::finding`);
//! 7. `report::figures`, `report::flow_curve_figure`, `report::fit_html` (the HTML report of
//!    a fit);
//! 8. `diagnostics` (`compare`, `refits` (`scan`, `pair`, `consistency`), `candidate` →
//!    `ties`, `calibration`, `diagnose` (its stages), `diagnosis`, `report`);
//! 9. `workflow::failure_hints`, `design` (inside: `information`, `criteria`, `candidates` →
//!    `estimation` → `report`);
//! 10. `workflow` (what each `rheometer` subcommand does, as library calls).
#![warn(missing_docs)]
// Numerical kernels index several arrays with the same loop variable, as the formulas do.
#![allow(clippy::needless_range_loop)]

pub mod data;
pub mod design;
pub mod diagnostics;
pub mod environment;
pub(crate) mod error;
pub mod fit;
pub(crate) mod in_order;
pub mod model;
pub mod report;
pub mod workflow;

pub use error::FiberError;

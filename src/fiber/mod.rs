//! The stationary melt-spinning fiber model and the rheometer built on it.
//!
//! A *user* of the generic toolkit: nothing in the solver core refers to this module.
//!
//! * [`setup`]: SI inputs (material, air, experiment);
//! * [`input`]: loading experiments from the project's TOML + CSV format;
//! * [`scaling`]: non-dimensionalisation (paper Table 2);
//! * [`material_law`]: elongational viscosity laws (Newtonian, Carreau-type, Carreau–Yasuda);
//! * [`catalog`]: one descriptor per candidate effect (name, unit, ranges, shapes, category,
//!   remedy, error-budget source, how it enters the model), data only;
//! * [`contributions`]: named force and heat terms, air environment, Nusselt law;
//! * [`effects`]: the candidate effects (a descriptor plus its settings, or a user's descriptor
//!   and term) and the model specification (law + effects) a rheometer fit uses;
//! * [`model`]: the strain-rate formulation as a [`Bvp`](crate::Bvp);
//! * [`cold_start`]: continuation from the stress-free fiber;
//! * [`failure_hints`]: simulation failures naming their experiment, with likely causes;
//! * [`mod@simulate`]: the user-facing API with SI profiles;
//! * [`profile_sensitivities`]: exact derivatives of the SI profiles with respect to the law
//!   parameters and the effects' strengths;
//! * [`smoothing`]: the velocity-ansatz smoothing of measured diameters (paper eq. 5);
//! * [`rheometer`]: identification of the elongational viscosity from diameter profiles;
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

pub mod catalog;
pub mod cold_start;
pub mod contributions;
pub mod design;
pub mod diagnostics;
pub mod effects;
pub mod error;
pub mod failure_hints;
pub mod figures;
pub mod fit_html;
pub mod flow_curve_figure;
pub mod format;
pub(crate) mod in_order;
pub mod input;
pub mod material_law;
pub mod model;
pub mod noise_model;
pub mod noise_summary;
pub mod output;
pub mod profile_sensitivities;
pub mod rheometer;
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

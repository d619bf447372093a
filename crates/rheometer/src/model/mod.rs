//! The model: the fiber's inputs in SI, its scaling, the material law, the candidate effects
//! and their terms, the boundary value problem, and its solution with SI profiles.
//!
//! * `setup`: SI inputs (material, air, experiment);
//! * `scaling`: non-dimensionalisation (paper Table 2);
//! * `material_law`: elongational viscosity laws (Newtonian, Carreau-type, Carreau–Yasuda);
//! * `catalog`: one descriptor per candidate effect (name, unit, ranges, shapes, category,
//!   remedy, error-budget source, how it enters the model), data only;
//! * `contributions`: named force and heat terms, air environment, Nusselt law;
//! * `effects`: the candidate effects (a descriptor plus its settings, or a user's descriptor
//!   and term) and the model specification (law + effects) a rheometer fit uses;
//! * `bvp`: the strain-rate formulation as a [`Bvp`](diffbvp::Bvp);
//! * `cold_start`: continuation from the stress-free fiber;
//! * `simulate`: the user-facing API with SI profiles;
//! * `profile_sensitivities`: exact derivatives of the SI profiles with respect to the law
//!   parameters and the effects' strengths.
//!
//! The files are private; what a user names is re-exported here (`rheometer::model::FiberModel`,
//! `rheometer::model::simulate`, …), one path per item.

pub(crate) mod bvp;
pub(crate) mod catalog;
pub(crate) mod cold_start;
pub(crate) mod contributions;
pub(crate) mod effects;
pub(crate) mod material_law;
pub(crate) mod profile_sensitivities;
pub(crate) mod scaling;
pub(crate) mod setup;
pub(crate) mod simulate;

pub use bvp::{DimensionlessTakeUp, FiberModel, ParamLayout};
pub use catalog::{
    builtin, Category, EffectDescriptor, Scope, ShapeParameter, ALL_NAMES, BUILTIN_NAMES,
    STRAIN_THINNING_REFERENCE_KAPPA,
};
pub use cold_start::{PathOptions, StepControl};
pub use contributions::{
    Balance, Coefficients, FiberTerm, InclinedChurchillBernstein, LocalState, NusseltLaw, Physics,
    ProcessFactors, SiScales, SiState, Strength, StrengthPlan, Term, TermKind, STEFAN_BOLTZMANN,
};
pub use effects::{physics_with, Effect, EffectSetting, LawChoice, ModelSpec, UserEffect};
pub use material_law::{
    viscosity, CarreauLike, CarreauYasuda, LawInputs, Newtonian, ViscosityLaw, ZeroRateViscosity,
};
pub use profile_sensitivities::{profile_sensitivities, ProfileSensitivities};
pub use scaling::{stokes_tangential_resistance, ReferenceValues, Scaling};
pub use setup::{Air, Experiment, ExperimentSet, Inlet, Material, Measurements, TakeUp};
pub use simulate::{
    simulate, simulate_from, simulate_params, FiberSolution, Profiles, SimulateOptions, Simulator,
};

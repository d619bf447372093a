//! The model: the fiber's inputs in SI, its scaling, the material law, the candidate effects
//! and their terms, the boundary value problem, and its solution with SI profiles.
//!
//! * [`setup`]: SI inputs (material, air, experiment);
//! * [`scaling`]: non-dimensionalisation (paper Table 2);
//! * [`material_law`]: elongational viscosity laws (Newtonian, Carreau-type, Carreau–Yasuda);
//! * [`catalog`]: one descriptor per candidate effect (name, unit, ranges, shapes, category,
//!   remedy, error-budget source, how it enters the model), data only;
//! * [`contributions`]: named force and heat terms, air environment, Nusselt law;
//! * [`effects`]: the candidate effects (a descriptor plus its settings, or a user's descriptor
//!   and term) and the model specification (law + effects) a rheometer fit uses;
//! * [`bvp`]: the strain-rate formulation as a [`Bvp`](diffbvp::Bvp);
//! * [`cold_start`]: continuation from the stress-free fiber;
//! * [`mod@simulate`]: the user-facing API with SI profiles;
//! * [`profile_sensitivities`]: exact derivatives of the SI profiles with respect to the law
//!   parameters and the effects' strengths.

pub mod bvp;
pub mod catalog;
pub mod cold_start;
pub mod contributions;
pub mod effects;
pub mod material_law;
pub mod profile_sensitivities;
pub mod scaling;
pub mod setup;
pub mod simulate;

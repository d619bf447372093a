//! The stationary melt-spinning fiber model and the rheometer built on it.
//!
//! A *user* of the generic toolkit: nothing in the solver core refers to this module.

pub mod input;
pub mod setup;
pub mod smoothing;

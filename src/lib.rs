//! diffbvp (work in progress)
// Numerical kernels index several arrays with the same loop variable, as the formulas do.
#![allow(clippy::needless_range_loop)]
mod collocation;
pub mod continuation;
mod dual_jacobian;
pub mod error;
mod error_control;
pub mod fiber;
pub mod inspect;
pub mod linear;
pub mod mesh;
mod newton;
pub mod problem;
pub mod sensitivity;
pub mod solution;
pub mod solve;
pub use error::BvpError;
pub use linear::Factorization;
pub use num_dual::DualNum;
pub use problem::Bvp;
pub use solution::{Solution, SolveStats};
pub use solve::{solve, Guess, ResidualScale, SolveOptions, Solver};

//! diffbvp (work in progress)
mod collocation;
mod dual_jacobian;
pub mod error;
mod error_control;
pub mod fiber;
pub mod linear;
pub mod mesh;
mod newton;
pub mod plot;
pub mod problem;
pub mod solution;
pub mod solve;
pub use error::BvpError;
pub use linear::Factorization;
pub use num_dual::DualNum;
pub use problem::Bvp;
pub use solution::{Solution, SolveStats};
pub use solve::{solve, Guess, ResidualScale, SolveOptions, Solver};

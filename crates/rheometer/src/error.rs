//! Errors of the fiber model.

use diffbvp::error::BvpError;
use thiserror::Error;

/// Why a fiber simulation could not be set up or solved.
#[derive(Debug, Clone, Error)]
pub enum FiberError {
    /// An input value is out of range or not finite.
    #[error("invalid fiber input: {0}")]
    InvalidInput(String),
    /// The experiment has no take-up condition (`Experiment::take_up` is `None`).
    #[error("experiment '{0}' has no take-up condition (diameter or velocity at s = L)")]
    MissingTakeUp(String),
    /// The boundary value solver failed.
    #[error("fiber solve failed: {0}")]
    Solver(#[from] BvpError),
}

/// A number as a reader would write it: plain for ordinary magnitudes, in exponent notation for
/// very large or small ones (`1e308`, not 309 digits).
pub struct Readable(pub f64);

impl std::fmt::Display for Readable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() || (1e-4..1e6).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

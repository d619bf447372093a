//! Errors of the fiber model.

use crate::error::BvpError;
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

//! The `design` workflow: fit the model to the data (no error budget, no profile intervals:
//! the design needs the estimate, its solutions and its noise level), then predict, for every
//! candidate experiment, the uncertainty after adding it ([`design_for_estimation`]).

use super::fit::{fit, FitRequest, FitRun};
use crate::fiber::design::{design_for_estimation, Design, DesignRequest};
use crate::fiber::input::LoadedExperiments;
use crate::fiber::rheometer::profile::ProfileMode;
use crate::fiber::rheometer::RheometerError;

/// The outcome of the `design` workflow.
#[derive(Debug)]
pub struct DesignRun {
    /// The fit the design starts from.
    pub fit: FitRun,
    /// The ranked candidates.
    pub design: Design,
}

/// Fits `fit_request`'s model to `data` (error budget and profile intervals off) and designs
/// the next experiment by `request`.
pub fn design(
    data: &LoadedExperiments,
    fit_request: &FitRequest,
    request: &DesignRequest,
) -> Result<DesignRun, RheometerError> {
    request.grid.validate().map_err(RheometerError::Data)?;
    let mut fr = fit_request.clone();
    fr.error_budget = false;
    fr.profile = ProfileMode::Never;
    fr.baseline = false;
    fr.newtonian_reference = false;
    let run = fit(data, &fr)?;
    let design = design_for_estimation(&run.rheometer, &run.identification, request)?;
    Ok(DesignRun { fit: run, design })
}

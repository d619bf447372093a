//! What a fit's estimates are worth, computed after the identification: profile-likelihood
//! intervals and the test against the Newtonian law (`profile`), the flow curve with its
//! statistical and systematic bands (`flow_curve`), and the error budget of what the data
//! cannot identify (`error_budget`).

pub(crate) mod error_budget;
pub(crate) mod flow_curve;
pub(crate) mod profile;

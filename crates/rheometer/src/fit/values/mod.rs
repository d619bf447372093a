//! The values a fit yields, below the steps that compute them: the thresholds of its checks,
//! the error budget's entries, the flow curve and the strain rates the data cover, the
//! profile-likelihood intervals and tests, and the shift of a parameter.

pub(crate) mod budget;
pub(crate) mod coverage;
pub(crate) mod curve;
pub(crate) mod likelihood;
pub(crate) mod parameter_shift;
pub(crate) mod thresholds;

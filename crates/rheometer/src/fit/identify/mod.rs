//! The identification itself: its result as a value of its own (`identification`), the fit's
//! BVPs solved only as accurately as the noise needs (`accuracy`), the start-point heuristic
//! and the bounded trust-region Gauss–Newton fit (`gauss_newton`), and the nested fit with
//! effects that never ends worse than the model without them (`nested`).

pub(crate) mod accuracy;
pub(crate) mod gauss_newton;
pub(crate) mod identification;
pub(crate) mod nested;

//! Missing-physics diagnostics: which physical effect is missing from a user's model, adding
//! it, and watching the error fall.
//!
//! * [`candidates`]: the candidate effects (canonical names, strength parameters, neutral
//!   values), the model specification (law + effects) a rheometer fit uses;
//! * [`diagnose`]: ranking the candidates by the excess misfit they explain (linearised scores,
//!   refits, information criteria) and the report in words.

pub mod candidates;
pub mod diagnose;
pub mod report;
pub mod scores;

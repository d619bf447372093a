//! Diagnostics of a fitted fiber model against measurements: where and how the model misses
//! the data.
//!
//! * [`compare`]: measured vs simulated diameters per experiment, residual statistics
//!   (noise level, χ²/dof, runs test, lag-1 autocorrelation), systematic segments along the
//!   spin line, text/JSON summaries and figures.

pub mod compare;

//! `diffbvp._native`: the thin Rust layer of the Python package `diffbvp`.
//!
//! Each function checks its arguments as the `rheometer` program checks its flags, calls the
//! library's workflow ([`rheometer::workflow`]: fit, simulate, compare, diagnose, design,
//! landscape) and hands its result to Python through the result's serde JSON form (one path:
//! [`convert::report_to_py`]; dicts, lists, floats) plus numpy arrays for array-valued data;
//! the Python result classes in `python/diffbvp/` wrap those dicts. Long calls run with the GIL released and stop
//! on Ctrl-C ([`run`]). Errors become `diffbvp.errors` exceptions with the CLI's messages
//! ([`errors`]).

mod bvp;
mod compare;
mod convert;
mod dataset;
mod design;
mod diagnose;
mod errors;
mod fit;
mod landscape;
mod options;
mod run;
mod simulate;

use pyo3::prelude::*;

/// The version of the Rust library the module was built from.
#[pyfunction]
fn library_version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

/// The Rust layer of `diffbvp` (use the `diffbvp` package, not this module).
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<dataset::Dataset>()?;
    m.add_class::<bvp::ExprProblem>()?;
    m.add_class::<bvp::BvpSolution>()?;
    m.add_function(wrap_pyfunction!(fit::fit, m)?)?;
    m.add_function(wrap_pyfunction!(fit::check_fit_summary, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(compare::compare, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose::diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(landscape::landscape, m)?)?;
    m.add_function(wrap_pyfunction!(design::design, m)?)?;
    m.add_function(wrap_pyfunction!(library_version, m)?)?;
    m.add_function(wrap_pyfunction!(run::set_threads, m)?)?;
    m.add_function(wrap_pyfunction!(run::threads, m)?)?;
    Ok(())
}

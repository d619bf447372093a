//! Library errors as Python exceptions of the `diffbvp.errors` hierarchy (`DiffbvpError` >
//! `InputError`, `SimulationError`, `FitError`), with the CLI's text: the message, its causes
//! (`caused by: ...`) and the hints of a failed simulation (`hint: ...`), each on its own line.

use diffbvp::least_squares::FitError;
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError};
use pyo3::prelude::*;
use pyo3::types::PyType;
use rheometer::data::input::{InputError, LoadedExperiments};
use rheometer::diagnostics::CompareError;
use rheometer::fit::RheometerError;
use rheometer::workflow::failure_hints::{failed_experiment, name_experiment, ExperimentFailure};
use std::error::Error;
use std::path::Path;

/// An exception of class `kind` (`"InputError"`, `"SimulationError"`, `"FitError"`,
/// `"DiffbvpError"`) from `diffbvp.errors` with `message`.
pub fn diffbvp_error(py: Python<'_>, kind: &str, message: String) -> PyErr {
    let class = py
        .import("diffbvp.errors")
        .and_then(|m| m.getattr(kind))
        .and_then(|c| c.cast_into::<PyType>().map_err(PyErr::from));
    match class {
        Ok(c) => PyErr::from_type(c, message),
        Err(_) => PyRuntimeError::new_err(message),
    }
}

/// An `InputError` (a bad argument or input value).
pub fn input_error(message: String) -> PyErr {
    Python::attach(|py| diffbvp_error(py, "InputError", message))
}

/// The CLI's text of an error: the message, then `caused by:` lines for causes whose text the
/// message does not already quote, then the hints of a failed simulation.
pub fn cli_text(e: &(dyn Error + 'static)) -> String {
    let mut out = e.to_string();
    let mut printed = out.clone();
    let mut src = e.source();
    while let Some(s) = src {
        let text = s.to_string();
        if !printed.contains(&text) {
            out.push_str(&format!("\n  caused by: {text}"));
        }
        printed = text;
        src = s.source();
    }
    if let Some(f) = e.downcast_ref::<ExperimentFailure>() {
        for h in &f.hints {
            out.push_str(&format!("\n  hint: {h}"));
        }
    }
    out
}

/// Whether the error chain holds a cancelled fit (Ctrl-C).
fn cancelled(e: &(dyn Error + 'static)) -> bool {
    let mut cur: Option<&(dyn Error + 'static)> = Some(e);
    while let Some(x) = cur {
        if let Some(FitError::Cancelled { .. }) = x.downcast_ref::<FitError>() {
            return true;
        }
        if let Some(RheometerError::Fit(FitError::Cancelled { .. })) =
            x.downcast_ref::<RheometerError>()
        {
            return true;
        }
        cur = x.source();
    }
    false
}

/// The exception class for an error: input and data problems are `InputError`, failed
/// simulations `SimulationError`, failed fits `FitError`.
fn kind_of(e: &(dyn Error + 'static)) -> &'static str {
    if e.downcast_ref::<InputError>().is_some() {
        return "InputError";
    }
    if e.downcast_ref::<ExperimentFailure>().is_some() || failed_experiment(e).is_some() {
        return "SimulationError";
    }
    if let Some(r) = e.downcast_ref::<RheometerError>() {
        return match r {
            RheometerError::Data(_) => "InputError",
            RheometerError::Smoothing { .. } | RheometerError::Simulation { .. } => {
                "SimulationError"
            }
            RheometerError::Fit(_) | RheometerError::NotEvaluable { .. } => "FitError",
        };
    }
    if let Some(c) = e.downcast_ref::<CompareError>() {
        return match c {
            CompareError::Data(_) => "InputError",
            _ => "SimulationError",
        };
    }
    if e.downcast_ref::<rheometer::FiberError>().is_some() {
        return "SimulationError";
    }
    if e.downcast_ref::<FitError>().is_some() {
        return "FitError";
    }
    "InputError"
}

/// A library error as a Python exception; a failed simulation is first named with its
/// experiment and TOML line (the library's [`name_experiment`], as the CLI does), and the
/// exception gets the attributes `experiment`, `path`, `line` and `hints` where known. A
/// cancelled fit is a `KeyboardInterrupt`.
pub fn to_py_err(
    py: Python<'_>,
    e: Box<dyn Error + 'static>,
    data: Option<(&LoadedExperiments, &Path)>,
    law: Option<[f64; 2]>,
) -> PyErr {
    if cancelled(e.as_ref()) {
        return PyKeyboardInterrupt::new_err("interrupted");
    }
    let e = match data {
        Some((loaded, path)) => name_experiment(e, loaded, path, law),
        None => e,
    };
    let err = diffbvp_error(py, kind_of(e.as_ref()), cli_text(e.as_ref()));
    if let Some(f) = e.downcast_ref::<ExperimentFailure>() {
        let v = err.value(py);
        let _ = v.setattr("experiment", f.experiment.clone());
        let _ = v.setattr("path", f.at.path.display().to_string());
        let _ = v.setattr("line", f.at.line);
        let _ = v.setattr("hints", f.hints.clone());
    }
    err
}

/// An error captured on a worker thread in a form that may cross back to Python's thread
/// (the library's errors hold `Box<dyn Error>` causes, which are not `Send`): the exception
/// kind, the CLI's text and, for a failed experiment, its name, place and hints.
pub struct CapturedError {
    kind: &'static str,
    text: String,
    experiment: Option<(String, String, Option<usize>, Vec<String>)>,
}

impl CapturedError {
    /// Captures `e` (after naming its experiment as [`to_py_err`] does).
    pub fn capture(e: &(dyn Error + 'static)) -> Self {
        CapturedError {
            kind: kind_of(e),
            text: cli_text(e),
            experiment: e.downcast_ref::<ExperimentFailure>().map(|f| {
                (
                    f.experiment.clone(),
                    f.at.path.display().to_string(),
                    f.at.line,
                    f.hints.clone(),
                )
            }),
        }
    }

    /// The Python exception.
    pub fn into_py(self, py: Python<'_>) -> PyErr {
        let err = diffbvp_error(py, self.kind, self.text);
        if let Some((experiment, path, line, hints)) = self.experiment {
            let v = err.value(py);
            let _ = v.setattr("experiment", experiment);
            let _ = v.setattr("path", path);
            let _ = v.setattr("line", line);
            let _ = v.setattr("hints", hints);
        }
        err
    }
}

//! `simulate`: the library's simulate workflow ([`workflow::simulate_experiments`]) — every
//! experiment at given law parameters and fixed effect strengths, profiles as numpy arrays,
//! optionally with the exact forward sensitivities of the profiles.

use crate::convert::array2;
use crate::dataset::Dataset;
use crate::errors::{input_error, CapturedError};
use crate::fit::profiles_dict;
use crate::options;
use crate::run::interruptible;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rheometer::data::take_up::MissingTakeUp;
use rheometer::model::physics_with;
use rheometer::model::ProfileSensitivities;
use rheometer::workflow::request;
use rheometer::workflow::{self, SimulateError, SimulateRequest};
use std::ops::ControlFlow;
use std::sync::atomic::Ordering;

/// Sensitivities as `{"parameters": [names], "diameter_m": (positions × parameters), ...}`.
fn sensitivities_dict<'py>(
    py: Python<'py>,
    s: &ProfileSensitivities,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("parameters", s.parameters.clone())?;
    let (rows, cols) = (s.positions.len(), s.parameters.len());
    for (key, v) in [
        ("diameter_m", &s.diameter),
        ("velocity_m_s", &s.velocity),
        ("force_N", &s.force),
        ("temperature_K", &s.temperature),
        ("strain_rate_1_s", &s.strain_rate),
    ] {
        d.set_item(key, array2(py, v, rows, cols)?)?;
    }
    Ok(d)
}

/// Simulates every experiment at `(n, κ)`. Returns `{"law", "effects", "experiments": [{"name",
/// "nodes", "take_up_from_data_m", "profiles": {...}, "sensitivities": {...} | None}]}`.
#[pyfunction]
#[pyo3(signature = (dataset, n, kappa, *, effects=Vec::new(), take_up_diameter=None,
    take_up_from_data=false, points=101, positions=None, sensitivities=false, tol=None,
    max_nodes=None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    dataset: &Dataset,
    n: f64,
    kappa: f64,
    effects: Vec<String>,
    take_up_diameter: Option<f64>,
    take_up_from_data: bool,
    points: i128,
    positions: Option<Vec<f64>>,
    sensitivities: bool,
    tol: Option<f64>,
    max_nodes: Option<i128>,
) -> PyResult<Bound<'py, PyDict>> {
    let law = [options::check_n(n)?, options::check_kappa(kappa)?];
    let mut fixed = Vec::new();
    for w in options::effects(&effects)? {
        let v = w.value.ok_or_else(|| {
            input_error(format!(
                "effects: give {0}'s strength as \"{0}=VALUE\" (a simulation fits nothing)",
                w.effect.name()
            ))
        })?;
        fixed.push((w.effect, v));
    }
    physics_with(&fixed).map_err(|e| input_error(format!("effects: {e}")))?;
    let missing = match (take_up_diameter, take_up_from_data) {
        (Some(d), _) if !(1e-7..=0.02).contains(&d) => {
            return Err(input_error(format!(
                "a take-up diameter must lie in [1e-7, 0.02] m (got {d} m; the unit is metres)"
            )))
        }
        (Some(d), _) => MissingTakeUp::Diameter(d),
        (None, true) => MissingTakeUp::FromData,
        (None, false) => MissingTakeUp::Error,
    };
    let points = request::points(points).map_err(options::refused)?;
    let (loaded, path) = dataset.data();
    if let Some(p) = &positions {
        request::positions(p, loaded).map_err(options::refused)?;
    }
    let mut request = SimulateRequest::new(law, path.to_path_buf());
    request.door = request::Door::Python;
    request.missing_take_up = missing;
    request.points = points;
    request.positions = positions;
    request.effects = fixed;
    request.sensitivities = sensitivities;
    request.simulate.max_nodes = options::max_nodes(max_nodes)?;
    if let Some(t) = options::tol(tol)? {
        request.simulate.tol = t;
    }
    // stops between experiments once Ctrl-C has set the flag
    let out = interruptible(py, |cancel| {
        workflow::simulate_experiments(loaded, &request, |_, _| {
            if cancel.load(Ordering::SeqCst) {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
        // the failure crosses back from the worker thread as text and attributes
        .map_err(|e| match e {
            SimulateError::Experiment(f) => Err(Box::new(CapturedError::capture(f.as_ref()))),
            SimulateError::Stopped { .. } => Ok(None),
            other => Ok(Some(other.to_string())),
        })
    })?;
    let runs = out.map_err(|e| match e {
        Err(captured) => (*captured).into_py(py),
        Ok(None) => pyo3::exceptions::PyKeyboardInterrupt::new_err("interrupted"),
        Ok(Some(message)) => input_error(message),
    })?;
    let d = PyDict::new(py);
    d.set_item("law", (law[0], law[1]))?;
    d.set_item("effects", effects)?;
    let list = PyList::empty(py);
    for r in &runs {
        let e = PyDict::new(py);
        e.set_item("name", &r.name)?;
        e.set_item("nodes", r.nodes)?;
        e.set_item("take_up_from_data_m", r.take_up_from_data)?;
        e.set_item("profiles", profiles_dict(py, &r.profiles)?)?;
        match &r.sensitivities {
            Some(s) => e.set_item("sensitivities", sensitivities_dict(py, s)?)?,
            None => e.set_item("sensitivities", py.None())?,
        }
        list.append(e)?;
    }
    d.set_item("experiments", list)?;
    Ok(d)
}

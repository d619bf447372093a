//! `landscape`: the cost `J(n, κ)` on a grid (paper Fig. 4), the library's landscape workflow
//! ([`workflow::landscape`]) as `rheometer landscape` runs it, without files; Ctrl-C stops it
//! between grid points.

use crate::convert::{array1, array2};
use crate::dataset::Dataset;
use crate::errors::to_py_err;
use crate::options;
use crate::run::interruptible;
use diffbvp::mesh::linspace;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rheometer::fit::{FarRule, IdentifyOptions, PointStatus};
use rheometer::workflow::request::{self, Arg};
use rheometer::workflow::{self, LandscapeRequest};

/// Computes `J(n, κ)` on a `grid = (number of n values, number of κ values)` grid. Returns
/// `{"n", "kappa", "cost": (κ × n) array, "status": (κ × n) array of 0 ok / 1 failed / 2 not
/// computed, "point_tol": (κ × n) array of each cost's BVP tolerance (NaN where none),
/// "estimator", "tol", "minimum": (n, κ, J) | None, "cancelled"}`. `uniform_tol`: every point at `tol` (default: points far from
/// their row's minimum at ten times `tol`, at most 1e-3, as `rheometer landscape`).
#[pyfunction]
#[pyo3(signature = (dataset, *, grid=(41, 41), n_range=(0.0, 1.0), kappa_range=(9.0, 16.0),
    estimator="paper", tol=1e-4, max_nodes=None, uniform_tol=false))]
#[allow(clippy::too_many_arguments)]
pub fn landscape<'py>(
    py: Python<'py>,
    dataset: &Dataset,
    grid: (i128, i128),
    n_range: (f64, f64),
    kappa_range: (f64, f64),
    estimator: &str,
    tol: f64,
    max_nodes: Option<i128>,
    uniform_tol: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let mut opts = IdentifyOptions::with_estimator(options::estimator(estimator)?);
    options::check_range(Arg::NRange, "n", n_range, [opts.lower[0], opts.upper[0]])?;
    options::check_range(
        Arg::KappaRange,
        "kappa",
        kappa_range,
        [opts.lower[1], opts.upper[1]],
    )?;
    let (a, b) =
        request::grid(grid.0, grid.1, request::MAX_GRID_POINTS).map_err(options::refused)?;
    options::tol(Some(tol))?;
    opts.simulate.tol = tol;
    opts.simulate.max_nodes = request::landscape_max_nodes(max_nodes).map_err(options::refused)?;
    let request = LandscapeRequest {
        n: linspace(n_range.0, n_range.1, a),
        kappa: linspace(kappa_range.0, kappa_range.1, b),
        identify: opts,
        far: uniform_tol.then(FarRule::uniform),
    };
    let (loaded, path) = dataset.data();
    let out = interruptible(py, |cancel| {
        workflow::landscape(loaded, &request, |_| {}, &cancel)
    })?;
    let run = out.map_err(|e| to_py_err(py, Box::new(e), Some((loaded, path)), None))?;
    let l = &run.landscape;
    let status: Vec<f64> = run
        .status
        .iter()
        .map(|s| match s {
            PointStatus::Computed => 0.0,
            PointStatus::Failed => 1.0,
            PointStatus::NotReached => 2.0,
        })
        .collect();
    let d = PyDict::new(py);
    d.set_item("n", array1(py, &l.n))?;
    d.set_item("kappa", array1(py, &l.kappa))?;
    d.set_item("cost", array2(py, &l.cost, l.kappa.len(), l.n.len())?)?;
    d.set_item(
        "status",
        array2(py, &status, l.kappa.len(), l.n.len())?.call_method1("astype", ("int8",))?,
    )?;
    d.set_item("point_tol", array2(py, &run.tol, l.kappa.len(), l.n.len())?)?;
    d.set_item("estimator", estimator)?;
    d.set_item("tol", tol)?;
    d.set_item("minimum", l.minimum())?;
    d.set_item("cancelled", run.cancelled)?;
    Ok(d)
}

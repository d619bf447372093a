//! `design`: which experiment next, as `rheometer design` (the library's design workflows,
//! [`workflow::design`] and [`workflow::discriminate`]); the design goes to Python through
//! the same serde JSON form `rheometer design --json` writes.

use crate::convert::report_to_py;
use crate::dataset::Dataset;
use crate::errors::{input_error, to_py_err};
use crate::options;
use crate::run::interruptible;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rheometer::design::{Criterion, DesignRequest, DiscriminationRequest};
use rheometer::fit::{Estimator, IdentifyOptions};
use rheometer::model::Effect;
use rheometer::report::report_json::ReportKind;
use rheometer::workflow::request::{self, DesignRanges};
use rheometer::workflow::{self, FitRequest};

/// Ranks candidate experiments (a grid of mass flows x take-up values, copies of `template`)
/// by how much each would shrink the uncertainty of (n, κ) (`criterion` "d", "a" or "e"), or,
/// with `discriminate` (two or more effect names), by how well it tells those rival
/// explanations apart. Ranges are `(min, max)` pairs in the units of the TOML keys (mass flow
/// kg/s, stencil velocity mm/s, take-up diameter m, take-up velocity m/s), within the same
/// plausible ranges; `None` takes the default range from the data set. Returns
/// `{"design": dict, "text": str, "csv": str}`: the dict is what `rheometer design --json`
/// writes, the text its report, the CSV every candidate.
#[pyfunction]
#[pyo3(signature = (dataset, *, template=None, mass_flow=None, stencil_velocity=None,
    take_up_diameter=None, take_up_velocity=None, grid=(9, 9), criterion="d",
    discriminate=None, start=None, noise=None, tol=1e-6, max_nodes=None))]
#[allow(clippy::too_many_arguments)]
pub fn design<'py>(
    py: Python<'py>,
    dataset: &Dataset,
    template: Option<String>,
    mass_flow: Option<(f64, f64)>,
    stencil_velocity: Option<(f64, f64)>,
    take_up_diameter: Option<(f64, f64)>,
    take_up_velocity: Option<(f64, f64)>,
    grid: (i128, i128),
    criterion: &str,
    discriminate: Option<Vec<String>>,
    start: Option<(f64, f64)>,
    noise: Option<f64>,
    tol: f64,
    max_nodes: Option<i128>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut opts = IdentifyOptions::with_estimator(Estimator::Principled);
    opts.simulate.max_nodes = options::max_nodes(max_nodes)?;
    if let Some(s) = start {
        options::check_start(s, &opts)?;
    }
    let tol = request::tol(tol).map_err(options::refused)?;
    let noise = noise
        .map(request::noise)
        .transpose()
        .map_err(options::refused)?;
    let grid = request::grid(grid.0, grid.1, request::MAX_GRID_POINTS).map_err(options::refused)?;
    let criterion =
        Criterion::parse(criterion).map_err(|e| input_error(format!("criterion: {e}")))?;
    let rivals = match discriminate {
        None => None,
        Some(names) => {
            let effects = names
                .iter()
                .map(|s| {
                    s.trim()
                        .parse::<Effect>()
                        .map_err(|e| input_error(format!("discriminate: \"{s}\": {e}")))
                })
                .collect::<PyResult<Vec<_>>>()?;
            Some(request::rivals(effects).map_err(options::refused)?)
        }
    };
    let ranges = DesignRanges {
        template,
        mass_flow,
        stencil_velocity,
        take_up_diameter,
        take_up_velocity,
        grid,
    };
    let (loaded, path) = dataset.data();
    let candidate_grid = request::design_grid(&ranges, loaded).map_err(options::refused)?;
    let mut fit_request = FitRequest::new(opts);
    fit_request.start = start.map(|(n, k)| [n, k]);
    let max_nodes = fit_request.identify.simulate.max_nodes;
    let d = PyDict::new(py);
    match rivals {
        Some(effects) => {
            let mut request = DiscriminationRequest::new(candidate_grid);
            request.simulate.tol = tol;
            request.simulate.max_nodes = max_nodes;
            request.noise = noise;
            let out = interruptible(py, |_cancel| {
                workflow::discriminate(loaded, &fit_request, &effects, &request)
            })?;
            let run = out.map_err(|e| to_py_err(py, Box::new(e), Some((loaded, path)), None))?;
            d.set_item(
                "design",
                report_to_py(py, ReportKind::Discrimination, &run.design)?,
            )?;
            d.set_item("text", run.design.to_text())?;
            d.set_item("csv", run.design.to_csv())?;
        }
        None => {
            let mut request = DesignRequest::new(candidate_grid, criterion);
            request.simulate.tol = tol;
            request.simulate.max_nodes = max_nodes;
            request.noise = noise;
            let out = interruptible(py, |_cancel| {
                workflow::design(loaded, &fit_request, &request)
            })?;
            let run = out.map_err(|e| to_py_err(py, Box::new(e), Some((loaded, path)), None))?;
            d.set_item("design", report_to_py(py, ReportKind::Design, &run.design)?)?;
            d.set_item("text", run.design.to_text())?;
            d.set_item("csv", run.design.to_csv())?;
        }
    }
    Ok(d)
}

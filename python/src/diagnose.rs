//! `diagnose`: which physical effect is missing from the model (candidates scanned and refitted,
//! ranked by ΔBIC, ties and outliers), as `rheometer diagnose` without files.

use crate::convert::{array1, serde_to_py};
use crate::dataset::Dataset;
use crate::errors::{input_error, to_py_err, BoxError};
use crate::fit::identification_arrays;
use crate::options;
use crate::run::interruptible;
use diffbvp::fiber::diagnostics::diagnose::{diagnose as run_diagnose, DiagnoseOptions};
use diffbvp::fiber::effects::{Effect, ModelSpec};
use diffbvp::fiber::rheometer::FitReport;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Residual profiles (name → (positions, residuals)) as name → {position_m, relative_residual}.
fn residuals_dict<'py>(
    py: Python<'py>,
    r: &[(String, Vec<(f64, f64)>)],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, pts) in r {
        let e = PyDict::new(py);
        let pos: Vec<f64> = pts.iter().map(|p| p.0).collect();
        let res: Vec<f64> = pts.iter().map(|p| p.1).collect();
        e.set_item("position_m", array1(py, &pos))?;
        e.set_item("relative_residual", array1(py, &res))?;
        d.set_item(name, e)?;
    }
    Ok(d)
}

/// Searches every candidate effect for what the model misses. Returns `{"diagnosis": dict,
/// "text": str, "base_fit": {...}, "best_fit": {...} | None, "residuals_before": {...},
/// "residuals_after": {...} | None}` (fits in the form of `fit`'s result).
#[pyfunction]
#[pyo3(signature = (dataset, *, model="carreau", effects=Vec::new(), candidates=None,
    refit_top=None, start=None, max_nodes=None))]
#[allow(clippy::too_many_arguments)]
pub fn diagnose<'py>(
    py: Python<'py>,
    dataset: &Dataset,
    model: &str,
    effects: Vec<String>,
    candidates: Option<Vec<String>>,
    refit_top: Option<usize>,
    start: Option<(f64, f64)>,
    max_nodes: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let spec = ModelSpec {
        law: options::law(model)?,
        effects: options::effects(&effects)?,
        candidates: Vec::new(),
    };
    spec.validate()
        .map_err(|e| input_error(format!("effects: {e}")))?;
    let mut opts = DiagnoseOptions::default();
    if let Some(c) = candidates {
        opts.candidates = c
            .iter()
            .map(|s| {
                s.parse::<Effect>()
                    .map_err(|e| input_error(format!("candidates: \"{s}\": {e}")))
            })
            .collect::<PyResult<_>>()?;
    }
    if let Some(k) = refit_top {
        let most = opts.candidates.len().max(1);
        if !(1..=most).contains(&k) {
            return Err(input_error(format!(
                "refit_top: give 1 to {most} (the number of candidate effects) candidates to \
                 refit (got {k})"
            )));
        }
        opts.refit_top = k;
    }
    if let Some(s) = start {
        options::check_start(s, &opts.identify)?;
        opts.start = Some([s.0, s.1]);
    }
    opts.identify.simulate.max_nodes = options::max_nodes(max_nodes)?;
    let set = &dataset.inner.loaded.set;
    // TODO(restructure): call the library's diagnose workflow (options, spec and run in one)
    let out = interruptible(py, |cancel| -> Result<_, BoxError> {
        let mut opts = opts;
        opts.identify.cancel = Some(cancel);
        Ok(run_diagnose(set, &spec, &opts)?)
    })?;
    let run = out.map_err(|e| to_py_err(py, e, Some(dataset.data()), None))?;
    let d = PyDict::new(py);
    d.set_item("diagnosis", serde_to_py(py, &run.diagnosis)?)?;
    d.set_item("text", run.diagnosis.to_text())?;
    // TODO(restructure): the diagnosis will hold FitSummary values; serialise those instead of
    // building FitReports from the identifications here
    let fit_dict =
        |id: &diffbvp::fiber::rheometer::Identification| -> PyResult<Bound<'py, PyDict>> {
            let rep = FitReport::new(id);
            let f = PyDict::new(py);
            f.set_item("report", serde_to_py(py, &rep)?)?;
            f.set_item("text", rep.to_text())?;
            f.set_item("arrays", identification_arrays(py, id, None)?)?;
            f.set_item("notes", Vec::<String>::new())?;
            Ok(f)
        };
    d.set_item("base_fit", fit_dict(&run.base)?)?;
    match &run.best {
        Some(b) => d.set_item("best_fit", fit_dict(b)?)?,
        None => d.set_item("best_fit", py.None())?,
    }
    d.set_item(
        "residuals_before",
        residuals_dict(py, &run.residuals_before)?,
    )?;
    match &run.residuals_after {
        Some(r) => d.set_item("residuals_after", residuals_dict(py, r)?)?,
        None => d.set_item("residuals_after", py.None())?,
    }
    Ok(d)
}

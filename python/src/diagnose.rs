//! `diagnose`: the library's diagnose workflow ([`workflow::diagnose`]); the [`Diagnosis`]
//! (base fit, candidates with their refit summaries, found effects, final fit, verdict,
//! calibration) goes to Python through its serde JSON form, with the residual arrays of the
//! base and the final fit besides.
//!
//! [`Diagnosis`]: rheometer::diagnostics::Diagnosis

use crate::convert::report_to_py;
use crate::dataset::Dataset;
use crate::errors::{input_error, to_py_err};
use crate::fit::identification_arrays;
use crate::options;
use crate::run::interruptible;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rheometer::diagnostics::DiagnoseOptions;
use rheometer::model::{Effect, ModelSpec};
use rheometer::report::report_json::ReportKind;
use rheometer::workflow::{
    self,
    request::{self, Arg},
};

/// Searches the candidate effects for what the model misses, as `rheometer diagnose`.
/// Returns `{"diagnosis": Diagnosis as dict, "text": the report, "base_arrays": {...},
/// "final_arrays": {...} | None}` (arrays as in `fit`'s result, without profiles).
#[pyfunction]
#[pyo3(signature = (dataset, *, model=None, effects=Vec::new(), candidates=None,
    refit_top=None, start=None, loss="linear", f_scale=None, tol=None, max_nodes=None,
    start_from=None))]
#[allow(clippy::too_many_arguments)]
pub fn diagnose<'py>(
    py: Python<'py>,
    dataset: &Dataset,
    model: Option<&str>,
    effects: Vec<String>,
    candidates: Option<Vec<String>>,
    refit_top: Option<i128>,
    start: Option<(f64, f64)>,
    loss: &str,
    f_scale: Option<f64>,
    tol: Option<f64>,
    max_nodes: Option<i128>,
    start_from: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let (loaded, path) = dataset.data();
    let mut opts = DiagnoseOptions::default();
    let continued = options::continued(
        start_from.as_deref(),
        options::effects(&effects)?,
        start,
        model,
        &opts.identify,
        &loaded.set.names(),
    )?;
    opts.start_strengths = continued.starts;
    let start = continued.start;
    let law = continued.law;
    let spec = ModelSpec {
        law,
        effects: continued.effects,
        candidates: Vec::new(),
    };
    spec.validate()
        .map_err(|e| input_error(format!("effects: {e}")))?;
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
        opts.refit_top = options::count(
            Arg::RefitTop,
            k,
            1,
            most,
            "candidates to refit (the number of candidate effects is the most)",
        )?;
    }
    if let Some(s) = start {
        options::check_start(s, &opts.identify)?;
        opts.start = Some([s.0, s.1]);
    }
    options::robust_loss(&mut opts.identify, loss, f_scale)?;
    opts.identify.simulate.max_nodes = options::max_nodes(max_nodes)?;
    request::given_tol(&mut opts.identify, tol).map_err(options::refused)?;
    let out = interruptible(py, |cancel| {
        let mut opts = opts;
        opts.identify.cancel = Some(cancel);
        workflow::diagnose(loaded, &spec, &opts)
    })?;
    let run = out.map_err(|e| to_py_err(py, Box::new(e), Some((loaded, path)), None))?;
    let d = PyDict::new(py);
    d.set_item(
        "diagnosis",
        report_to_py(py, ReportKind::Diagnosis, &run.diagnosis.json())?,
    )?;
    d.set_item("text", run.diagnosis.to_text())?;
    d.set_item("base_arrays", identification_arrays(py, &run.base, None)?)?;
    match &run.best {
        Some(b) => d.set_item("final_arrays", identification_arrays(py, b, None)?)?,
        None => d.set_item("final_arrays", py.None())?,
    }
    Ok(d)
}

//! `compare`: the library's compare workflow ([`workflow::compare`]) — the model of a fit (its
//! [`FitSummary`], read back from the dict `fit` returned) or of given law parameters against
//! the measurements; the `Comparison` goes to Python through its serde JSON form.

use crate::convert::{from_py, report_to_py};
use crate::dataset::Dataset;
use crate::errors::{input_error, to_py_err};
use crate::options;
use crate::run::interruptible;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rheometer::data::take_up::MissingTakeUp;
use rheometer::fit::FitSummary;
use rheometer::report::report_json::ReportKind;
use rheometer::workflow::request::Door;
use rheometer::workflow::{self, CompareRequest};

/// How a fit given from Python is named in messages.
const FIT_SOURCE: &str = "the fit";

/// Compares the model with the measurements, as `rheometer compare`. The model comes from a
/// fit summary (`fit`: the dict of `FitResult.summary`, or the JSON of `rheometer fit --json`
/// loaded as a dict; read and checked as `--fit` reads its file) or from `n`/`kappa`. Returns
/// `{"comparison": dict, "text": str}`.
#[pyfunction]
#[pyo3(signature = (dataset, fit=None, *, n=None, kappa=None, newtonian=false,
    take_up_from_data=false, effects=Vec::new(), relative_uncertainty=None, tol=None,
    max_nodes=None))]
#[allow(clippy::too_many_arguments)]
pub fn compare<'py>(
    py: Python<'py>,
    dataset: &Dataset,
    fit: Option<&Bound<'py, PyAny>>,
    n: Option<f64>,
    kappa: Option<f64>,
    newtonian: bool,
    take_up_from_data: bool,
    effects: Vec<String>,
    relative_uncertainty: Option<f64>,
    tol: Option<f64>,
    max_nodes: Option<i128>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut request = match fit {
        Some(f) => {
            if n.is_some() || kappa.is_some() || newtonian {
                return Err(input_error(
                    "give either fit or n/kappa/newtonian, not both".into(),
                ));
            }
            let text = serde_json::to_string(&from_py(f, "fit")?)
                .map_err(|e| input_error(format!("fit: {e}")))?;
            let summary = FitSummary::from_json(&text, FIT_SOURCE).map_err(input_error)?;
            CompareRequest::of_fit(summary, FIT_SOURCE)
        }
        None => {
            let k = kappa.ok_or_else(|| {
                input_error(
                    "give the parameters: fit=FitResult (from diffbvp.fit) or kappa=K with n=N \
                     or newtonian=True"
                        .into(),
                )
            })?;
            let n = match (newtonian, n) {
                (true, _) => 1.0,
                (false, Some(n)) => n,
                (false, None) => {
                    return Err(input_error(
                        "give n=N (or newtonian=True) together with kappa".into(),
                    ))
                }
            };
            let mut r = CompareRequest::at([options::check_n(n)?, options::check_kappa(k)?]);
            if take_up_from_data {
                r.missing_take_up = MissingTakeUp::FromData;
            }
            r
        }
    };
    request.door = Door::Python;
    request.with = options::effects(&effects)?;
    request.relative_uncertainty = options::fraction(relative_uncertainty)?;
    request.simulate.max_nodes = options::max_nodes(max_nodes)?;
    if let Some(t) = options::tol(tol)? {
        request.simulate.tol = t;
    }
    // the effects of the compared model, checked before any work
    request.effects().map_err(input_error)?;
    let (loaded, path) = dataset.data();
    // the comparison checks no cancellation flag: Ctrl-C is raised once it has finished
    let out = interruptible(py, |_cancel| workflow::compare(loaded, &request))?;
    let cmp =
        out.map_err(|e| to_py_err(py, Box::new(e), Some((loaded, path)), Some(request.law)))?;
    let d = PyDict::new(py);
    d.set_item(
        "comparison",
        report_to_py(py, ReportKind::Comparison, &cmp)?,
    )?;
    d.set_item("text", cmp.to_text())?;
    Ok(d)
}

//! `fit`: the library's fit workflow ([`workflow::fit`]); its outcome, the [`FitSummary`]
//! (`FitRun::summary`), goes to Python through its serde JSON form, with the arrays a notebook
//! plots besides (residuals at the measurement positions, fitted profiles).

use crate::convert::{array1, report_to_py};
use crate::dataset::Dataset;
use crate::errors::to_py_err;
use crate::options;
use crate::run::interruptible;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rheometer::fit::{Identification, IdentifyOptions, Rheometer};
use rheometer::model::{FiberSolution, Profiles};
use rheometer::model::{LawChoice, ModelSpec};
use rheometer::report::report_json::ReportKind;
use rheometer::workflow::request::{self, Arg};
use rheometer::workflow::{self, FitRequest};

/// Profiles as a dict of numpy arrays (SI units in the key names), the named terms under
/// `terms`.
pub fn profiles_dict<'py>(py: Python<'py>, p: &Profiles) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("position_m", array1(py, &p.position))?;
    d.set_item("velocity_m_s", array1(py, &p.velocity))?;
    d.set_item("force_N", array1(py, &p.force))?;
    d.set_item("temperature_K", array1(py, &p.temperature))?;
    d.set_item("strain_rate_1_s", array1(py, &p.strain_rate))?;
    d.set_item("diameter_m", array1(py, &p.diameter))?;
    if let Some(g) = &p.gauge_reading {
        // what the gauge reads, with the model's gauge effects
        d.set_item("gauge_reading_m", array1(py, g))?;
    }
    d.set_item("viscosity_Pa_s", array1(py, &p.viscosity))?;
    let terms = PyDict::new(py);
    for (name, balance, v) in &p.terms {
        let unit = match balance {
            rheometer::model::Balance::Momentum => "N_m",
            rheometer::model::Balance::Energy => "W_m",
        };
        terms.set_item(format!("{name}_{unit}"), array1(py, v))?;
    }
    d.set_item("terms", terms)?;
    Ok(d)
}

/// An identification's arrays: `residual_profiles` (name → `position_m`, `relative_residual`
/// at the measurement positions) and, with `profiles = Some((rheometer, points))`, the fitted
/// `profiles` (name → profiles on `points` uniform positions).
pub fn identification_arrays<'py>(
    py: Python<'py>,
    id: &Identification,
    profiles: Option<(&Rheometer, usize)>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let names = &id.summary.experiments;
    let res = PyDict::new(py);
    for (name, (pos, r)) in names.iter().zip(&id.residual_profiles) {
        let e = PyDict::new(py);
        e.set_item("position_m", array1(py, pos))?;
        e.set_item("relative_residual", array1(py, r))?;
        res.set_item(name, e)?;
    }
    d.set_item("residual_profiles", res)?;
    if let Some((rh, points)) = profiles {
        let pd = PyDict::new(py);
        for ((name, sol), model) in names.iter().zip(&id.solutions).zip(&rh.models) {
            let fs = FiberSolution {
                solution: sol.clone(),
            };
            pd.set_item(
                name,
                profiles_dict(py, &fs.uniform_profiles(model, points))?,
            )?;
        }
        d.set_item("profiles", pd)?;
    }
    Ok(d)
}

/// Identifies `(n, κ)` (and the strengths of fitted effects): the library's fit workflow, as
/// `rheometer fit`. Returns `{"summary": FitSummary as dict, "text": the report, "arrays":
/// {"residual_profiles", "profiles"}, "notes": [str]}`.
#[pyfunction]
#[pyo3(signature = (dataset, *, start=None, estimator="principled", model=None,
    effects=Vec::new(), loss="linear", f_scale=None, relative_uncertainty=None,
    error_budget=true, tol=None, max_nodes=None, profile_points=101, start_from=None))]
#[allow(clippy::too_many_arguments)]
pub fn fit<'py>(
    py: Python<'py>,
    dataset: &Dataset,
    start: Option<(f64, f64)>,
    estimator: &str,
    model: Option<&str>,
    effects: Vec<String>,
    loss: &str,
    f_scale: Option<f64>,
    relative_uncertainty: Option<f64>,
    error_budget: bool,
    tol: Option<f64>,
    max_nodes: Option<i128>,
    profile_points: i128,
    start_from: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut opts = IdentifyOptions::with_estimator(options::estimator(estimator)?);
    options::robust_loss(&mut opts, loss, f_scale)?;
    opts.relative_uncertainty = options::fraction(relative_uncertainty)?;
    opts.simulate.max_nodes = options::max_nodes(max_nodes)?;
    request::given_tol(&mut opts, tol).map_err(options::refused)?;
    if let Some(s) = start {
        options::check_start(s, &opts)?;
    }
    let profile_points = options::count(
        Arg::ProfilePoints,
        profile_points,
        2,
        options::MAX_POINTS,
        "positions per profile",
    )?;
    let (loaded, path) = dataset.data();
    let continued = options::continued(
        start_from.as_deref(),
        options::effects(&effects)?,
        start,
        model,
        &opts,
        &loaded.set.names(),
    )?;
    let start = continued.start;
    let law = continued.law;
    let spec = ModelSpec {
        law,
        effects: continued.effects,
        candidates: Vec::new(),
    };
    request::newtonian_start(spec.law == LawChoice::Newtonian, start).map_err(options::refused)?;
    let request = FitRequest {
        model: spec,
        start: start.map(|(n, k)| [n, k]),
        start_strengths: continued.starts,
        error_budget,
        ..FitRequest::new(opts)
    };
    let out = interruptible(py, |cancel| {
        let mut request = request;
        request.identify.cancel = Some(cancel);
        workflow::fit(loaded, &request)
    })?;
    let run = out.map_err(|e| to_py_err(py, Box::new(e), Some((loaded, path)), None))?;
    let d = PyDict::new(py);
    d.set_item("summary", report_to_py(py, ReportKind::Fit, run.summary())?)?;
    d.set_item("text", run.summary().to_text())?;
    d.set_item(
        "arrays",
        identification_arrays(
            py,
            &run.identification,
            Some((&run.rheometer, profile_points)),
        )?,
    )?;
    let notes: Vec<String> = run
        .budget_error
        .iter()
        .map(|e| format!("error budget not computed: {e}"))
        .collect();
    d.set_item("notes", notes)?;
    Ok(d)
}

/// Checks a fit summary or a diagnosis given as JSON text (the dict of a `FitResult` or a
/// `Diagnosis`, e.g. from a pickle) with the library's reader of fit reports, the one
/// `rheometer fit --from` uses: every field's type and range, an error naming the field's
/// path (`n.value`) and `what` (the object it came from).
#[pyfunction]
pub fn check_fit_summary(text: &str, what: &str) -> PyResult<()> {
    rheometer::fit::FitSummary::from_fit_or_diagnosis_json(text, what)
        .map(|_| ())
        .map_err(crate::errors::input_error)
}

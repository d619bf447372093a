//! `fit`: identify the law (and effect strengths) with uncertainties, the error budget and the
//! arrays a notebook plots (residuals, fitted profiles, covariance).

use crate::convert::{array1, array2, serde_to_py};
use crate::dataset::Dataset;
use crate::errors::{to_py_err, BoxError};
use crate::options;
use crate::run::interruptible;
use diffbvp::fiber::effects::{LawChoice, ModelSpec, STRAIN_THINNING_REFERENCE_KAPPA};
use diffbvp::fiber::rheometer::{
    error_budget, FitReport, Identification, IdentifyOptions, Rheometer,
};
use diffbvp::fiber::{FiberSolution, Profiles};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Everything one fit hands back to Python.
pub struct FitOutcome {
    /// The report (serialised to the result dict).
    pub report: FitReport,
    /// The identification (arrays).
    pub id: Identification,
    /// Fitted profiles per experiment on `profile_points` uniform positions.
    pub profiles: Vec<Profiles>,
    /// Why the error budget is missing, if it is.
    pub budget_error: Option<String>,
}

/// The fit settings of one call.
pub struct FitSettings {
    pub start: Option<(f64, f64)>,
    pub opts: IdentifyOptions,
    pub spec: ModelSpec,
    pub with_budget: bool,
    pub profile_points: usize,
}

/// What `rheometer fit` does, without its files: start heuristic (unless a start is given),
/// identification, error budget (a budget that cannot be computed does not fail the fit),
/// report, and the fitted profiles.
// TODO(restructure): call the library's fit workflow (returning a FitSummary) instead.
pub fn fit_workflow(dataset: &Dataset, s: &FitSettings) -> Result<FitOutcome, BoxError> {
    let loaded = &dataset.inner.loaded;
    let rh = Rheometer::with_spec(&loaded.set, s.spec.clone())?;
    let law_fitted = s.spec.law == LawChoice::Carreau
        || s.spec
            .effects
            .iter()
            .any(|w| w.effect.name() == "strain_thinning" && w.value.is_none());
    let start = match s.start {
        Some((n, k)) => [n, k],
        None if !law_fitted => [1.0, STRAIN_THINNING_REFERENCE_KAPPA],
        None => rh.start_heuristic(&s.opts)?.start,
    };
    let id = rh.identify(start, &s.opts)?;
    let (report, budget_error) = if s.with_budget {
        match error_budget(&rh, &id, &loaded.uncertainty, &s.opts) {
            Ok(budget) => (FitReport::new(&id).with_error_budget(budget), None),
            Err(e) => (FitReport::new(&id), Some(e.to_string())),
        }
    } else {
        (FitReport::new(&id), None)
    };
    let profiles = id
        .solutions
        .iter()
        .zip(&rh.models)
        .map(|(sol, model)| {
            FiberSolution {
                solution: sol.clone(),
            }
            .uniform_profiles(model, s.profile_points)
        })
        .collect();
    Ok(FitOutcome {
        report,
        id,
        profiles,
        budget_error,
    })
}

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
    d.set_item("viscosity_Pa_s", array1(py, &p.viscosity))?;
    let terms = PyDict::new(py);
    for (name, balance, v) in &p.terms {
        let unit = match balance {
            diffbvp::fiber::Balance::Momentum => "N_m",
            diffbvp::fiber::Balance::Energy => "W_m",
        };
        terms.set_item(format!("{name}_{unit}"), array1(py, v))?;
    }
    d.set_item("terms", terms)?;
    Ok(d)
}

/// The arrays of an identification: parameter names and covariance of the fit vector, the
/// relative residuals at the measurement positions and (if given) the fitted profiles, per
/// experiment.
pub fn identification_arrays<'py>(
    py: Python<'py>,
    id: &Identification,
    profiles: Option<&[Profiles]>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let mut names = id.names.clone();
    let np = id.fit.p.len();
    for e in &id.experiment_names {
        if names.len() >= np {
            break;
        }
        names.push(format!("take_up_factor[{e}]"));
    }
    d.set_item("parameter_names", names)?;
    d.set_item("parameters", array1(py, &id.fit.p))?;
    match id.fit.covariance() {
        Some(c) => d.set_item("covariance", array2(py, &c, np, np)?)?,
        None => d.set_item("covariance", py.None())?,
    }
    let res = PyDict::new(py);
    for (name, (pos, r)) in id.experiment_names.iter().zip(&id.residual_profiles) {
        let e = PyDict::new(py);
        e.set_item("position_m", array1(py, pos))?;
        e.set_item("relative_residual", array1(py, r))?;
        res.set_item(name, e)?;
    }
    d.set_item("residual_profiles", res)?;
    if let Some(profiles) = profiles {
        let pd = PyDict::new(py);
        for (name, p) in id.experiment_names.iter().zip(profiles) {
            pd.set_item(name, profiles_dict(py, p)?)?;
        }
        d.set_item("profiles", pd)?;
    }
    Ok(d)
}

/// A fit outcome as `{"report": dict, "arrays": dict, "notes": [str]}`.
// TODO(restructure): serialise the FitSummary (report, covariance, flow curve) instead.
pub fn outcome_to_py<'py>(py: Python<'py>, o: &FitOutcome) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("report", serde_to_py(py, &o.report)?)?;
    d.set_item("text", o.report.to_text())?;
    d.set_item(
        "arrays",
        identification_arrays(py, &o.id, Some(&o.profiles))?,
    )?;
    let mut notes = Vec::new();
    if let Some(e) = &o.budget_error {
        notes.push(format!("error budget not computed: {e}"));
    }
    d.set_item("notes", notes)?;
    Ok(d)
}

/// Identifies `(n, κ)` (and the strengths of fitted effects) from the measurements: the
/// `rheometer fit` workflow. Returns `{"report", "text", "arrays", "notes"}`.
#[pyfunction]
#[pyo3(signature = (dataset, *, start=None, estimator="principled", model="carreau",
    effects=Vec::new(), loss="linear", f_scale=None, relative_uncertainty=None,
    error_budget=true, max_nodes=None, profile_points=101))]
#[allow(clippy::too_many_arguments)]
pub fn fit<'py>(
    py: Python<'py>,
    dataset: &Dataset,
    start: Option<(f64, f64)>,
    estimator: &str,
    model: &str,
    effects: Vec<String>,
    loss: &str,
    f_scale: Option<f64>,
    relative_uncertainty: Option<f64>,
    error_budget: bool,
    max_nodes: Option<usize>,
    profile_points: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let mut opts = IdentifyOptions::with_estimator(options::estimator(estimator)?);
    opts.loss = options::loss(loss)?;
    opts.f_scale = options::f_scale(f_scale)?;
    opts.relative_uncertainty = match relative_uncertainty {
        Some(v) if !(v > 0.0 && v < 1.0) => {
            return Err(crate::errors::input_error(format!(
                "relative_uncertainty must lie in (0, 1) like the TOML key (got {v}; 0.01 is 1 %)"
            )))
        }
        other => other,
    };
    opts.simulate.max_nodes = options::max_nodes(max_nodes)?;
    if let Some(s) = start {
        options::check_start(s, &opts)?;
    }
    if !(2..=100_000).contains(&profile_points) {
        return Err(crate::errors::input_error(format!(
            "profile_points: give 2 to 100000 positions per profile (got {profile_points})"
        )));
    }
    let spec = ModelSpec {
        law: options::law(model)?,
        effects: options::effects(&effects)?,
        candidates: Vec::new(),
    };
    let settings = FitSettings {
        start,
        opts,
        spec,
        with_budget: error_budget,
        profile_points,
    };
    let out = interruptible(py, |cancel| {
        let mut s = settings;
        s.opts.cancel = Some(cancel);
        fit_workflow(dataset, &s)
    })?;
    match out {
        Ok(o) => outcome_to_py(py, &o),
        Err(e) => Err(to_py_err(py, e, Some(dataset.data()), None)),
    }
}

//! `compare`: the model against the measurements (residuals along the spin line, χ²/dof
//! against the noise, runs test, systematic segments), as `rheometer compare` without files.

use crate::convert::from_py;
use crate::convert::serde_to_py;
use crate::dataset::Dataset;
use crate::errors::{input_error, to_py_err, BoxError};
use crate::options;
use crate::run::interruptible;
use diffbvp::fiber::diagnostics::compare::{
    compare as compare_runs, simulate_experiments, CompareOptions, Comparison, FitParameters,
    MissingTakeUp, ModelSetup,
};
use diffbvp::fiber::effects::{physics_with, Effect, EffectSetting};
use diffbvp::fiber::Physics;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The effects of a compared model: those of the fit, overridden or extended by `effects`
/// (the CLI's `compare_effects`).
// TODO(restructure): call the library's compare workflow instead.
fn compare_effects(
    fit: Option<&FitParameters>,
    with: &[EffectSetting],
) -> Result<Vec<(Effect, f64)>, String> {
    let mut out: Vec<(Effect, f64)> = Vec::new();
    if let Some(f) = fit {
        for e in &f.effects {
            out.push((e.to_effect()?, e.strength));
        }
    }
    for w in with {
        let name = w.effect.name();
        let value = match (w.value, out.iter().find(|(e, _)| e.name() == name)) {
            (Some(v), _) => v,
            (None, Some((_, v))) => *v,
            (None, None) => {
                return Err(format!(
                    "effects: give {name}'s strength as \"{name}=VALUE\" (the fit has none)"
                ))
            }
        };
        out.retain(|(e, _)| e.name() != name);
        out.push((w.effect.clone(), value));
    }
    Ok(out)
}

/// Compares the model with the measurements. The parameters come from a fit report (`fit`:
/// the dict of `FitResult.report`, read as `rheometer compare --fit` reads its JSON) or from
/// `n`/`kappa`. Returns `{"comparison": dict, "text": str, "warnings": [str]}`.
#[pyfunction]
#[pyo3(signature = (dataset, fit=None, *, n=None, kappa=None, newtonian=false,
    take_up_from_data=false, effects=Vec::new(), relative_uncertainty=None, max_nodes=None))]
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
    max_nodes: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let set = &dataset.inner.loaded.set;
    let source = "the fit";
    let fit_params = match fit {
        Some(f) => {
            if n.is_some() || kappa.is_some() || newtonian {
                return Err(input_error(
                    "give either fit or n/kappa/newtonian, not both".into(),
                ));
            }
            let text = serde_json::to_string(&from_py(f, "fit")?)
                .map_err(|e| input_error(format!("fit: {e}")))?;
            Some(
                FitParameters::from_json(&text, source)
                    .map_err(|e| to_py_err(py, Box::new(e), None, None))?,
            )
        }
        None => None,
    };
    let with = options::effects(&effects)?;
    let fixed = compare_effects(fit_params.as_ref(), &with).map_err(input_error)?;
    physics_with(&fixed).map_err(|e| input_error(format!("effects: {e}")))?;
    if let Some(v) = relative_uncertainty {
        if !(v > 0.0 && v < 1.0) {
            return Err(input_error(format!(
                "relative_uncertainty must lie in (0, 1) like the TOML key (got {v}; 0.01 is 1 %)"
            )));
        }
    }
    let max_nodes = options::max_nodes(max_nodes)?;
    let law: [f64; 2];
    let take_up_factors: Option<Vec<f64>> = None;
    let mut missing = MissingTakeUp::Error;
    let mut fitted = 0;
    let mut warnings = Vec::new();
    if let Some(rep) = &fit_params {
        let names: Vec<String> = set.experiments.iter().map(|e| e.name.clone()).collect();
        rep.check_experiments(&names, source)
            .map_err(|e| to_py_err(py, Box::new(e), None, None))?;
        // resolved into the setup inside the worker (the setup borrows the physics closure)
        law = [rep.n, rep.kappa];
        fitted = rep.fitted_parameters();
        for w in &rep.warnings {
            warnings.push(format!(
                "the fit carries a warning: [{}] {}",
                w.code.name(),
                w.message
            ));
        }
    } else {
        let k = kappa.ok_or_else(|| {
            input_error(
                "give the parameters: fit=FitResult (from diffbvp.fit) or kappa=K with n=N or \
                 newtonian=True"
                    .into(),
            )
        })?;
        let n = if newtonian {
            1.0
        } else {
            n.ok_or_else(|| input_error("give n=N (or newtonian=True) together with kappa".into()))?
        };
        law = [options::check_n(n)?, options::check_kappa(k)?];
        if take_up_from_data {
            missing = MissingTakeUp::FromData;
        }
    }
    let opts = CompareOptions {
        relative_uncertainty,
        fitted_parameters: fitted,
        ..Default::default()
    };
    let run = |_cancel| -> Result<Comparison, BoxError> {
        let physics = || physics_with(&fixed).unwrap_or_else(|_| Physics::paper());
        let mut setup = ModelSetup::carreau(law, &physics);
        setup.simulate.max_nodes = max_nodes;
        setup.missing_take_up = missing;
        setup.take_up_factors = take_up_factors.clone();
        if let Some(rep) = &fit_params {
            rep.apply(&mut setup, set.experiments.len(), source)?;
        }
        let runs = simulate_experiments(set, &setup)?;
        Ok(compare_runs(&runs, set.relative_uncertainty, &opts)?)
    };
    let out = interruptible(py, run)?;
    let cmp = out.map_err(|e| to_py_err(py, e, Some(dataset.data()), Some(law)))?;
    let d = PyDict::new(py);
    d.set_item("comparison", serde_to_py(py, &cmp)?)?;
    d.set_item("text", cmp.to_text())?;
    d.set_item("warnings", warnings)?;
    Ok(d)
}

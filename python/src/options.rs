//! Arguments shared by the bindings, checked as the CLI checks its flags (same ranges, same
//! words in the messages).

use crate::errors::input_error;
use diffbvp::least_squares::Loss;
use pyo3::prelude::*;
use rheometer::effects::{EffectSetting, LawChoice};
use rheometer::rheometer::{Estimator, FitSummary, IdentifyOptions};

/// Smallest `max_nodes` (the cold start begins on a mesh of 21 nodes).
pub const MIN_MAX_NODES: usize = 50;
/// Largest `max_nodes`.
pub const MAX_MAX_NODES: usize = 1_000_000;
/// Default mesh limit of the solves of `simulate`, `fit`, `diagnose` and `compare`.
pub const DEFAULT_MAX_NODES: usize = 20_000;
/// Largest |κ| (K = e^κ Pa stays a finite positive number).
pub const MAX_ABS_KAPPA: f64 = 700.0;
/// Largest number of output positions per profile.
pub const MAX_POINTS: usize = 100_000;
/// Range of a BVP tolerance \[-\].
pub const TOL_RANGE: (f64, f64) = (1e-12, 0.1);

/// A BVP tolerance `tol` in [`TOL_RANGE`] (or none).
pub fn tol(v: Option<f64>) -> PyResult<Option<f64>> {
    match v {
        Some(t) if !(TOL_RANGE.0..=TOL_RANGE.1).contains(&t) => Err(input_error(format!(
            "tol: the tolerance must lie in [{:e}, {}] (got {t})",
            TOL_RANGE.0, TOL_RANGE.1
        ))),
        other => Ok(other),
    }
}

/// A relative uncertainty `name` in (0, 1) like the TOML key (or none).
pub fn fraction(name: &str, v: Option<f64>) -> PyResult<Option<f64>> {
    match v {
        Some(v) if !(v > 0.0 && v < 1.0) => Err(input_error(format!(
            "{name} must lie in (0, 1) like the TOML key relative_uncertainty (got {v}; 0.01 is \
             1 %)"
        ))),
        other => Ok(other),
    }
}

/// `max_nodes`: `MIN_MAX_NODES..=MAX_MAX_NODES`, default [`DEFAULT_MAX_NODES`].
pub fn max_nodes(v: Option<usize>) -> PyResult<usize> {
    match v {
        None => Ok(DEFAULT_MAX_NODES),
        Some(v) if (MIN_MAX_NODES..=MAX_MAX_NODES).contains(&v) => Ok(v),
        Some(v) => Err(input_error(format!(
            "max_nodes: the mesh limit must lie in {MIN_MAX_NODES}..={MAX_MAX_NODES} nodes \
             (got {v}; default {DEFAULT_MAX_NODES})"
        ))),
    }
}

/// The estimator by name: `"principled"` or `"paper"`.
pub fn estimator(name: &str) -> PyResult<Estimator> {
    match name.trim() {
        "principled" => Ok(Estimator::Principled),
        "paper" => Ok(Estimator::Paper),
        other => Err(input_error(format!(
            "estimator: \"{other}\" is not an estimator; use \"principled\" (relative least \
             squares against the raw data) or \"paper\" (the paper's weighted cost)"
        ))),
    }
}

/// The viscosity law by name: `"carreau"` or `"newtonian"`.
pub fn law(name: &str) -> PyResult<LawChoice> {
    name.parse::<LawChoice>()
        .map_err(|e| input_error(format!("model: {e}")))
}

/// Effects in the CLI's `--with` syntax (`"radiation"`, `"radiation=0.9"`,
/// `"air_coflow=40:decay_length=0.2"`).
pub fn effects(items: &[String]) -> PyResult<Vec<EffectSetting>> {
    items
        .iter()
        .map(|s| {
            s.parse::<EffectSetting>()
                .map_err(|e| input_error(format!("effects: \"{s}\": {e}")))
        })
        .collect()
}

/// The loss by name (`"linear"`, `"soft_l1"`, `"huber"`, `"cauchy"`).
fn loss(name: &str) -> PyResult<Loss> {
    Loss::parse(name).map_err(|e| input_error(format!("loss: {e}")))
}

/// Sets the loss (by name) and its soft margin `f_scale` of `opts`, as `fit` and `diagnose`
/// take them. Errors: an unknown loss, a margin outside (0, 1), a margin without a robust
/// loss.
pub fn robust_loss(opts: &mut IdentifyOptions, name: &str, margin: Option<f64>) -> PyResult<()> {
    let l = loss(name)?;
    let c = f_scale(margin)?;
    if c.is_some() && l.is_linear() {
        return Err(input_error(
            "f_scale: a soft margin needs a robust loss, but loss is \"linear\" (least \
             squares); give loss=\"soft_l1\" (or \"huber\", \"cauchy\"), or drop f_scale"
                .to_string(),
        ));
    }
    opts.loss = l;
    opts.f_scale = c;
    Ok(())
}

/// `f_scale`: a relative residual in (0, 1).
fn f_scale(v: Option<f64>) -> PyResult<Option<f64>> {
    match v {
        Some(v) if !(v > 0.0 && v < 1.0) => Err(input_error(format!(
            "f_scale is a relative residual in (0, 1) (got {v}; 0.02 is 2 %)"
        ))),
        other => Ok(other),
    }
}

/// `n`: the Carreau-type law's domain (finite, >= 0).
pub fn check_n(v: f64) -> PyResult<f64> {
    if !(v >= 0.0 && v.is_finite()) {
        return Err(input_error(format!(
            "the power index n must be >= 0 (the Carreau-type law's domain; 1 is Newtonian), \
             got {v}"
        )));
    }
    Ok(v)
}

/// `kappa`: finite with |κ| <= [`MAX_ABS_KAPPA`].
pub fn check_kappa(v: f64) -> PyResult<f64> {
    if v.is_nan() || v.abs() > MAX_ABS_KAPPA {
        return Err(input_error(format!(
            "kappa = ln(K / 1 Pa) must lie in [-{MAX_ABS_KAPPA}, {MAX_ABS_KAPPA}] (K = e^kappa \
             overflows beyond; the fit searches [7, 20]), got {v}"
        )));
    }
    Ok(v)
}

/// `start = (n, κ)` within the fit's bounds.
pub fn check_start((n, kappa): (f64, f64), opts: &IdentifyOptions) -> PyResult<()> {
    let inside = |v: f64, i: usize| v >= opts.lower[i] && v <= opts.upper[i];
    if !inside(n, 0) || !inside(kappa, 1) {
        return Err(input_error(format!(
            "start = ({n}, {kappa}): the start must lie within the fit's bounds n in [{}, {}] \
             and kappa in [{}, {}]",
            opts.lower[0], opts.upper[0], opts.lower[1], opts.upper[1]
        )));
    }
    Ok(())
}

/// `(lo, hi)` increasing and within `[min, max]` (the fit's bounds of `name`).
pub fn check_range(
    arg: &str,
    name: &str,
    (lo, hi): (f64, f64),
    [min, max]: [f64; 2],
) -> PyResult<()> {
    if lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
        return Err(input_error(format!(
            "{arg} = ({lo}, {hi}): give (MIN, MAX) with MIN < MAX"
        )));
    }
    if lo < min || hi > max {
        return Err(input_error(format!(
            "{arg} = ({lo}, {hi}): {name} must lie within the fit's bounds [{min}, {max}]"
        )));
    }
    Ok(())
}

/// A fit or diagnosis to continue from (`start_from`): the model's law and effects and where
/// the fit starts.
pub struct Continued {
    /// The law: `model`'s, else the previous fit's, else Carreau-type.
    pub law: LawChoice,
    /// The previous fit's effects (fitted strengths and shapes free), then `effects`.
    pub effects: Vec<EffectSetting>,
    /// The start `(n, κ)`: the previous law where both are Carreau-type, else the given
    /// `start`.
    pub start: Option<(f64, f64)>,
    /// Start values of the previous fit's fitted strengths and shapes.
    pub starts: Vec<(String, f64)>,
}

/// `start_from` (the JSON text of a fit report or a diagnosis, as `rheometer fit --from`
/// reads it) joined with `effects`, the law `model` (default: the previous fit's) and the
/// given `start`; checked against the data set's experiment `names` and the fit's bounds in
/// `opts`.
pub fn continued(
    start_from: Option<&str>,
    effects: Vec<EffectSetting>,
    start: Option<(f64, f64)>,
    model: Option<&str>,
    opts: &IdentifyOptions,
    names: &[String],
) -> PyResult<Continued> {
    let given = model.map(law).transpose()?;
    let Some(text) = start_from else {
        return Ok(Continued {
            law: given.unwrap_or_default(),
            effects,
            start,
            starts: Vec::new(),
        });
    };
    if start.is_some() {
        return Err(input_error(
            "start and start_from: the fit starts from start_from's law; give one of them".into(),
        ));
    }
    let previous =
        FitSummary::from_fit_or_diagnosis_json(text, "start_from").map_err(input_error)?;
    previous
        .check_experiments(names, "start_from")
        .map_err(input_error)?;
    let c = previous
        .continued_with(effects, "effects", "start_from")
        .map_err(input_error)?;
    let law = given.unwrap_or(previous.law);
    // a Newtonian fit's n = 1 is no start of a Carreau-type fit (the heuristic is)
    let carreau = law == LawChoice::Carreau && previous.law == LawChoice::Carreau;
    let start = carreau.then_some((previous.n.value, previous.kappa.value));
    if let Some(s) = start {
        check_start(s, opts)?;
    }
    Ok(Continued {
        law,
        effects: c.effects,
        start,
        starts: c.starts,
    })
}

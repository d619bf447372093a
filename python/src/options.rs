//! Arguments shared by the bindings, checked as the CLI checks its flags (same ranges, same
//! words in the messages).

use crate::errors::input_error;
use diffbvp::least_squares::Loss;
use pyo3::prelude::*;
use rheometer::fit::{Estimator, FitSummary, IdentifyOptions};
use rheometer::model::{EffectSetting, LawChoice};

pub use rheometer::workflow::request::MAX_POINTS;
use rheometer::workflow::request::{self, Arg, Door, Refusal};

/// A refusal of the library's request rules in Python's words (argument names, not flags).
pub fn refused(r: Refusal) -> PyErr {
    input_error(r.message(Door::Python))
}

/// A BVP tolerance `tol` in the request's range (or none).
pub fn tol(v: Option<f64>) -> PyResult<Option<f64>> {
    v.map(request::tol).transpose().map_err(refused)
}

/// The relative uncertainty (or none) in (0, 1), like the TOML key.
pub fn fraction(v: Option<f64>) -> PyResult<Option<f64>> {
    v.map(request::relative_uncertainty)
        .transpose()
        .map_err(refused)
}

/// `max_nodes` (a Python int, any sign): the request's range, default
/// [`request::DEFAULT_MAX_NODES`].
pub fn max_nodes(v: Option<i128>) -> PyResult<usize> {
    match v {
        None => Ok(request::DEFAULT_MAX_NODES),
        Some(v) => request::max_nodes(v).map_err(refused),
    }
}

/// A count `v` of `arg` in `lo..=hi` (a Python int, any sign); `what` says what is counted.
pub fn count(arg: Arg, v: i128, lo: usize, hi: usize, what: &str) -> PyResult<usize> {
    request::count_in(arg, v, lo, hi, what).map_err(refused)
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
/// loss, a robust loss with the paper's estimator (of `opts`).
pub fn robust_loss(opts: &mut IdentifyOptions, name: &str, margin: Option<f64>) -> PyResult<()> {
    let (l, c) = request::robust_loss(loss(name)?, margin).map_err(refused)?;
    request::loss_for(l, opts.estimator).map_err(refused)?;
    opts.loss = l;
    opts.f_scale = c;
    Ok(())
}

/// `n`: the Carreau-type law's domain (finite, >= 0).
pub fn check_n(v: f64) -> PyResult<f64> {
    request::n(v).map_err(refused)
}

/// `kappa`: finite with |κ| within the request's bound.
pub fn check_kappa(v: f64) -> PyResult<f64> {
    request::kappa(v).map_err(refused)
}

/// `start = (n, κ)` within the fit's bounds.
pub fn check_start(s: (f64, f64), opts: &IdentifyOptions) -> PyResult<()> {
    request::start(s, opts).map(|_| ()).map_err(refused)
}

/// `(lo, hi)` of `arg` increasing and within `[min, max]` (the fit's bounds of `name`).
pub fn check_range(arg: Arg, name: &str, range: (f64, f64), bounds: [f64; 2]) -> PyResult<()> {
    request::range(arg, name, range, bounds)
        .map(|_| ())
        .map_err(refused)
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

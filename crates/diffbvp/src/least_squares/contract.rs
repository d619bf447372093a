//! The input contract of [`fit`](super::fit): options and start point checked before any
//! evaluation, and every [`evaluate`](super::LeastSquaresProblem::evaluate) result checked where
//! it comes back (lengths, finite values), so that nothing reaches the linear algebra that would
//! panic there or turn into a NaN cost or zero standard errors.

use super::{Accuracy, AccuracySchedule, FitError, FitOptions, Jacobian};

/// Checks the start point, the bounds and the options for a problem of `np` parameters. The
/// error names the option (or parameter) and its value.
pub(super) fn check_options(
    np: usize,
    p0: &[f64],
    options: &FitOptions,
) -> Result<Option<AccuracySchedule>, FitError> {
    if p0.len() != np || options.lower.len() != np || options.upper.len() != np {
        return Err(FitError::InvalidInput(format!(
            "{np} parameters, but start has {}, lower {}, upper {}",
            p0.len(),
            options.lower.len(),
            options.upper.len()
        )));
    }
    for i in 0..np {
        let (l, u, x) = (options.lower[i], options.upper[i], p0[i]);
        let valid = l < u && x >= l && x <= u && x.is_finite();
        if !valid {
            return Err(FitError::InvalidInput(format!(
                "parameter {i}: start {x} must lie in [{l}, {u}] with lower < upper"
            )));
        }
    }
    for (name, v, strictly) in [
        ("initial_radius", options.initial_radius, true),
        ("max_radius", options.max_radius, true),
        ("gtol", options.gtol, false),
        ("xtol", options.xtol, false),
        ("ftol", options.ftol, false),
        ("f_scale", options.f_scale, true),
    ] {
        let valid = v.is_finite() && if strictly { v > 0.0 } else { v >= 0.0 };
        if !valid {
            let rule = if strictly { "positive" } else { "non-negative" };
            return Err(FitError::InvalidInput(format!(
                "FitOptions::{name} must be {rule} and finite, got {v}"
            )));
        }
    }
    if !options.x_scale.is_empty() && options.x_scale.len() != np {
        return Err(FitError::InvalidInput(format!(
            "FitOptions::x_scale has {} entries for {np} parameters: give one scale per \
             parameter, or none (every scale 1)",
            options.x_scale.len()
        )));
    }
    if let Some((i, v)) = options
        .x_scale
        .iter()
        .enumerate()
        .find(|(_, v)| !(v.is_finite() && **v > 0.0))
    {
        return Err(FitError::InvalidInput(format!(
            "FitOptions::x_scale[{i}] must be positive and finite, got {v}: it is parameter \
             {i}'s characteristic scale in its own unit"
        )));
    }
    if let Some(v) = options.relative_offset {
        if !(v.is_finite() && v > 0.0 && v < 1.0) {
            return Err(FitError::InvalidInput(format!(
                "FitOptions::relative_offset must lie in (0, 1), got {v}: it compares the \
                 Gauss-Newton step with the residuals' scatter (Bates and Watts use 1e-3); \
                 None turns the test off"
            )));
        }
    }
    // relative tolerances: 1 or more stops at the first step whatever it does
    for (name, v) in [("xtol", options.xtol), ("ftol", options.ftol)] {
        if v >= 1.0 {
            return Err(FitError::InvalidInput(format!(
                "FitOptions::{name} must be below 1, got {v:e}: it is a relative tolerance, and 1 \
                 or more ends the fit at its first step; typical values are 1e-8 to 1e-12"
            )));
        }
    }
    if options.max_iterations == 0 {
        return Err(FitError::InvalidInput(
            "FitOptions::max_iterations must be at least 1, got 0: a fit of no iterations \
             returns its start point"
                .into(),
        ));
    }
    match options.accuracy {
        Accuracy::Fixed => Ok(None),
        Accuracy::Scheduled(s) => {
            for (name, v) in [
                ("fraction", s.fraction),
                ("switch_below", s.switch_below),
                ("negligible_step", s.negligible_step),
            ] {
                if !(v.is_finite() && v >= 0.0) {
                    return Err(FitError::InvalidInput(format!(
                        "AccuracySchedule::{name} must be non-negative and finite, got {v}"
                    )));
                }
            }
            Ok(Some(s))
        }
    }
}

/// What is wrong with one [`evaluate`](super::LeastSquaresProblem::evaluate) result.
pub(super) enum Breach {
    /// Mis-sized residuals or Jacobian: the problem breaks its contract (a programming error;
    /// the fit stops with [`FitError::InvalidInput`]).
    Size(String),
    /// A non-finite residual or Jacobian entry: the model failed at this point (at a trial
    /// point a rejected step; at the start point an error).
    NonFinite(String),
}

/// Checks the residuals `r` and the row-major Jacobian `jac` returned for a problem of `np`
/// parameters: `expected` residuals (if known, i.e. after the start point), `r.len() * np`
/// Jacobian entries, every value finite. The messages name the index and the lengths.
pub(super) fn check_evaluation(
    r: &[f64],
    jac: &Jacobian,
    np: usize,
    expected: Option<usize>,
) -> Result<(), Breach> {
    let nr = r.len();
    if let Some(e) = expected {
        if nr != e {
            return Err(Breach::Size(format!(
                "evaluate() returned {nr} residuals, but {e} at the start point; the number of \
                 residuals must not change between evaluations"
            )));
        }
    }
    let jac = match jac {
        Jacobian::Dense(j) => j,
        Jacobian::Blocks(b) => return check_blocks(r, b, np),
    };
    if jac.len() != nr * np {
        return Err(Breach::Size(format!(
            "evaluate() returned a Jacobian of {} entries, expected {nr} residuals x {np} \
             parameters = {} (row-major)",
            jac.len(),
            nr * np
        )));
    }
    if let Some(i) = r.iter().position(|v| !v.is_finite()) {
        return Err(Breach::NonFinite(format!(
            "evaluate() returned a non-finite residual: r[{i}] = {}",
            r[i]
        )));
    }
    if let Some(k) = jac.iter().position(|v| !v.is_finite()) {
        let (row, col) = (k / np.max(1), k % np.max(1));
        return Err(Breach::NonFinite(format!(
            "evaluate() returned a non-finite Jacobian entry: J[{row}][{col}] = d r[{row}] / d \
             p[{col}] = {}",
            jac[k]
        )));
    }
    Ok(())
}

/// [`check_evaluation`] of a block-arrow Jacobian: its shape and finite entries.
fn check_blocks(r: &[f64], b: &super::BlockJacobian, np: usize) -> Result<(), Breach> {
    let nr = r.len();
    let s = b.structure();
    if s.num_residuals() != nr || s.num_params() != np {
        return Err(Breach::Size(format!(
            "evaluate_jacobian() returned a block Jacobian of {} residuals x {} parameters, \
             expected {nr} x {np}",
            s.num_residuals(),
            s.num_params()
        )));
    }
    if let Some(i) = r.iter().position(|v| !v.is_finite()) {
        return Err(Breach::NonFinite(format!(
            "evaluate_jacobian() returned a non-finite residual: r[{i}] = {}",
            r[i]
        )));
    }
    if !b.is_finite() {
        return Err(Breach::NonFinite(
            "evaluate_jacobian() returned a block Jacobian with a non-finite entry".into(),
        ));
    }
    Ok(())
}

/// Checks the start point's evaluation: any breach is an error
/// ([`FitError::InvalidInput`]), since there is no accepted point to fall back on.
pub(super) fn check_start(r: &[f64], jac: &Jacobian, np: usize, p: &[f64]) -> Result<(), FitError> {
    match check_evaluation(r, jac, np, None) {
        Ok(()) => Ok(()),
        Err(Breach::Size(m)) => Err(FitError::InvalidInput(format!(
            "at the start point {p:?}: {m}"
        ))),
        Err(Breach::NonFinite(m)) => Err(FitError::InvalidInput(format!(
            "at the start point {p:?}: {m}; the residuals and the Jacobian must be finite where \
             the fit starts (check the model there or start elsewhere)"
        ))),
    }
}

/// Checks a trial point's evaluation: `Ok(Ok(..))` the values to use, `Ok(Err(message))` a
/// failed evaluation (an error of the problem or non-finite values: a rejected step), `Err` a
/// broken contract (mis-sized values) that ends the fit.
#[allow(clippy::type_complexity)]
pub(super) fn check_trial<E: std::fmt::Display>(
    evaluated: Result<(Vec<f64>, Jacobian), E>,
    np: usize,
    nr: usize,
    p: &[f64],
) -> Result<Result<(Vec<f64>, Jacobian), String>, FitError> {
    match evaluated {
        Err(e) => Ok(Err(e.to_string())),
        Ok((r, jac)) => match check_evaluation(&r, &jac, np, Some(nr)) {
            Ok(()) => Ok(Ok((r, jac))),
            Err(Breach::NonFinite(m)) => Ok(Err(m)),
            Err(Breach::Size(m)) => Err(FitError::InvalidInput(format!("at {p:?}: {m}"))),
        },
    }
}

//! Accuracy matched to the noise: a fit solves its boundary-value problems only as accurately
//! as the data need, and proves it.
//!
//! The measurement noise (≈ 1–2 % of the diameter) makes every estimate uncertain by its
//! standard error; a discretisation error of the BVPs moves the estimate too. The fit runs at
//! [`IdentifyOptions::simulate`](super::IdentifyOptions::simulate)`.tol` (default 1e-4) and
//! then checks the shift: the residuals at the optimum are recomputed with every experiment
//! re-solved [`CHECK_FACTOR`] times more accurately (warm-started from the fit's solutions),
//! and the optimum's first-order move `Δθ = −(JᵀJ)⁻¹ Jᵀ (r_fine − r)` is compared with the
//! standard errors. Above [`IdentifyOptions::max_discretisation_shift`](super::IdentifyOptions::max_discretisation_shift)
//! (default 0.01 standard errors) the fit is refined at a tolerance ten times tighter and
//! checked again. The measured shift and the tolerances are in the fit's
//! [`SolverRecord`](super::SolverRecord).

use super::data::Rheometer;
use super::identification::{Identification, WarmFit};
use super::layout::FitStart;
use super::options::{IdentifyOptions, RheometerError};

/// The check re-solves this many times more accurately than the fit.
pub const CHECK_FACTOR: f64 = 100.0;

/// The tightest tolerance the refinement goes to \[-\].
pub const TIGHTEST_TOLERANCE: f64 = 1e-9;

/// The check never solves tighter than this \[-\] (a fit at 1e-9 is checked at 1e-10).
pub const TIGHTEST_CHECK: f64 = 1e-10;

/// The largest shift \[standard errors\] of a fitted shared parameter (`n`, `κ`, strengths,
/// shapes) when the BVPs are solved [`CHECK_FACTOR`] times more accurately at the optimum, and
/// the tolerance of that check.
pub(crate) fn discretisation_shift(
    rh: &Rheometer,
    start: &FitStart,
    options: &IdentifyOptions,
    id: &Identification,
) -> Result<(f64, f64), RheometerError> {
    let check_tol = (options.simulate.tol / CHECK_FACTOR).max(TIGHTEST_CHECK);
    let mut fine = options.clone();
    fine.simulate.tol = check_tol;
    // residuals only: no linearisation kept per experiment
    fine.simulate.factor_at_solution = false;
    fine.loose_tolerance = None;
    // the check is part of the fit already reported, not a fit of its own
    fine.progress = None;
    // the objective solves every experiment when it is built: at the optimum, so that the
    // evaluation below starts from those fine solutions (built at the fit's own start law, it
    // solved a far-away point first and re-solved the optimum from there: 2.3 times the cost)
    let fs = at_optimum(start, id);
    let mut obj = rh.objective_from(&fs, &fine)?;
    let r_fine = obj.residuals_only(&id.fit.p)?;
    let r = &id.fit.residuals;
    if r_fine.len() != r.len() {
        return Err(RheometerError::Data(format!(
            "discretisation check: {} residuals at the fine tolerance, {} in the fit",
            r_fine.len(),
            r.len()
        )));
    }
    let dr: Vec<f64> = r_fine.iter().zip(r).map(|(a, b)| a - b).collect();
    let q = id.fit.p.len();
    // through the Schur complement for a block-arrow fit: linear in the experiments
    let shift = id.fit.linear_response(&dr).ok_or_else(|| {
        RheometerError::Data(
            "JᵀJ of the fit is singular (the fit's parameters are not determined)".into(),
        )
    })?;
    let se = id
        .fit
        .standard_errors()
        .unwrap_or_else(|| vec![f64::NAN; q]);
    let worst = (0..id.names.len())
        .map(|c| (shift[c] / se[c]).abs())
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    Ok((worst, check_tol))
}

/// `start` moved to the optimum of `id`: its law and fitted strengths, warm from its solutions
/// (what the check and a refinement of `id` start from).
fn at_optimum(start: &FitStart, id: &Identification) -> FitStart {
    FitStart {
        law: id.law(),
        strengths: id.fitted_strengths(),
        warm: Some(id.solutions.clone()),
        ..start.clone()
    }
}

/// The fit `id` (started from `start`) checked and, where the discretisation moves an estimate
/// by more than the options allow, refined at tighter tolerances until it does not.
pub(crate) fn matched(
    rh: &Rheometer,
    start: &FitStart,
    options: &IdentifyOptions,
    mut id: Identification,
) -> Result<Identification, RheometerError> {
    let Some(limit) = options.max_discretisation_shift else {
        return Ok(id);
    };
    let mut opts = options.clone();
    // progress is reported for the fit itself; its checks and refinements run silently
    opts.progress = None;
    loop {
        // a check that cannot run (a singular JᵀJ, a solve failing at the finer tolerance)
        // leaves the fit as it is, unchecked (NaN in the record)
        let Ok((shift, check_tol)) = discretisation_shift(rh, start, &opts, &id) else {
            return Ok(id);
        };
        id.summary.solver.discretisation_shift_se = shift;
        id.summary.solver.check_tolerance = check_tol;
        if shift <= limit || opts.simulate.tol <= TIGHTEST_TOLERANCE {
            return Ok(id);
        }
        // refine: a tighter tolerance, warm from this fit
        opts.simulate.tol = (opts.simulate.tol / 10.0).max(TIGHTEST_TOLERANCE);
        let next = at_optimum(start, &id);
        let warm = WarmFit {
            take_up: id.take_up_factors().to_vec(),
            stop_tolerance: None,
            solve_at_take_up: true,
        };
        let wall = id.summary.solver.wall_time_s;
        let Ok(mut refined) = rh.identify_unchecked(&next, &opts, &warm) else {
            // the tighter fit failed: keep the checked one, with its measured shift
            return Ok(id);
        };
        refined.summary.start = id.summary.start;
        refined.summary.solver.wall_time_s += wall;
        id = refined;
    }
}

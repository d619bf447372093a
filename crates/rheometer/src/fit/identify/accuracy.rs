//! Accuracy matched to the noise: a fit solves its boundary-value problems only as accurately
//! as the data need, and proves it.
//!
//! The measurement noise (≈ 1–2 % of the diameter) makes every estimate uncertain by its
//! standard error; a discretisation error of the BVPs moves the estimate too. The fit runs at
//! [`IdentifyOptions::simulate`](crate::fit::IdentifyOptions::simulate)`.tol` (default 1e-4) and
//! then checks the shift by Richardson extrapolation: every experiment is re-solved at the
//! optimum on its mesh with every interval halved ([`SimulateOptions::halve_start_mesh`]:
//! a fixed mesh, warm from the fit's solution), and the discretisation error of the fit's
//! residuals is `e ≈ (r_half − r) · 16/15` (the collocation is of order 4: halving divides
//! the error by 16). The optimum's first-order move `Δθ = −(JᵀJ)⁻¹ Jᵀ e` is compared with the
//! standard errors. Above
//! [`IdentifyOptions::max_discretisation_shift`](crate::fit::IdentifyOptions::max_discretisation_shift)
//! (default 0.01 standard errors) the fit is refined at a tolerance ten times tighter and checked
//! again. The measured shift and the check's node counts are in the fit's
//! [`SolverRecord`](crate::fit::SolverRecord).
//!
//! The check re-solves on the halved fixed mesh rather than 100 times more accurately on an
//! adaptive mesh: both estimate the same shift, and the fixed mesh costs much less.

use super::identification::{Identification, WarmFit};
use crate::fit::data::Rheometer;
use crate::fit::estimator::Estimator;
use crate::fit::layout::FitStart;
use crate::fit::options::{IdentifyOptions, RheometerError};
#[cfg(doc)]
use crate::model::simulate::SimulateOptions;

/// The tightest tolerance the refinement goes to \[-\].
pub const TIGHTEST_TOLERANCE: f64 = 1e-9;

pub use diffbvp::solve::RICHARDSON_FACTOR;

/// The largest shift \[standard errors\] of a fitted shared parameter (`n`, `κ`, strengths,
/// shapes) by the discretisation error of the fit's BVPs (Richardson, see the
/// [module](self)), and the nodes of each experiment's halved mesh.
pub(crate) fn discretisation_shift(
    rh: &Rheometer,
    start: &FitStart,
    options: &IdentifyOptions,
    id: &Identification,
) -> Result<(f64, Vec<usize>), RheometerError> {
    let (r_half, nodes) = residuals_resolved(rh, start, &halved(options), id)?;
    let shift = shift_se(id, &r_half, RICHARDSON_FACTOR)?;
    let worst = shift
        .iter()
        .map(|v| v.abs())
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    Ok((worst, nodes))
}

/// How far below the fit's tolerance Newton on the halved meshes stops (collocation and
/// boundary residuals): its algebraic error is then far below the discretisation error it
/// measures.
const HALVED_NEWTON_FACTOR: f64 = 100.0;

/// The tightest tolerance of Newton on the halved meshes \[-\] (a fit at 1e-9 is checked with
/// Newton to 1e-10).
const TIGHTEST_HALVED_NEWTON: f64 = 1e-10;

/// The options of the check's re-solve of a fit solved with `options`: every experiment on its
/// mesh with every interval halved, Newton [`HALVED_NEWTON_FACTOR`] times below the fit's
/// tolerance (at least [`TIGHTEST_HALVED_NEWTON`]).
fn halved(options: &IdentifyOptions) -> IdentifyOptions {
    let mut o = options.clone();
    o.simulate.tol = (options.simulate.tol / HALVED_NEWTON_FACTOR).max(TIGHTEST_HALVED_NEWTON);
    o.simulate.halve_start_mesh = true;
    o
}

/// The fit's residuals at its optimum with every experiment re-solved with `options` (warm
/// from the fit's solutions), and the nodes of those solutions.
fn residuals_resolved(
    rh: &Rheometer,
    start: &FitStart,
    options: &IdentifyOptions,
    id: &Identification,
) -> Result<(Vec<f64>, Vec<usize>), RheometerError> {
    let mut o = options.clone();
    o.simulate.growth_limit = None;
    // residuals only: no linearisation kept per experiment
    o.simulate.factor_at_solution = false;
    o.loose_tolerance = None;
    // the check is part of the fit already reported, not a fit of its own
    o.progress = None;
    // the objective solves every experiment when it is built: at the optimum (its law, its
    // strengths and, principled, its take-up factors), so that the evaluation below only
    // recomputes the residuals there (built at the fit's own start law, it would solve a
    // far-away point first and then re-solve the optimum)
    let fs = at_optimum(start, id);
    let take_up: &[f64] = match options.estimator {
        Estimator::Principled => id.take_up_factors(),
        Estimator::Paper => &[],
    };
    let mut obj = rh.objective_at_take_up(&fs, &o, take_up, true)?;
    let r = obj.residuals_only(&id.fit.p)?;
    if r.len() != id.fit.residuals.len() {
        return Err(RheometerError::Data(format!(
            "discretisation check: {} residuals re-solved, {} in the fit",
            r.len(),
            id.fit.residuals.len()
        )));
    }
    let nodes = obj.nodes();
    Ok((r, nodes))
}

/// The first-order move of every fitted shared parameter \[its standard errors\] when the
/// fit's residuals change by `factor · (r_other − r)`: `−(JᵀJ)⁻¹ Jᵀ` of it, through the Schur
/// complement for a block-arrow fit (linear in the experiments).
fn shift_se(id: &Identification, r_other: &[f64], factor: f64) -> Result<Vec<f64>, RheometerError> {
    let dr: Vec<f64> = r_other
        .iter()
        .zip(&id.fit.residuals)
        .map(|(a, b)| (a - b) * factor)
        .collect();
    let shift = id.fit.linear_response(&dr).ok_or_else(|| {
        RheometerError::Data(
            "JᵀJ of the fit is singular (the fit's parameters are not determined)".into(),
        )
    })?;
    let se = id
        .fit
        .standard_errors()
        .unwrap_or_else(|| vec![f64::NAN; id.fit.p.len()]);
    Ok((0..id.names.len()).map(|c| shift[c] / se[c]).collect())
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
        let Ok((shift, check_nodes)) = discretisation_shift(rh, start, &opts, &id) else {
            return Ok(id);
        };
        id.summary.solver.discretisation_shift_se = shift;
        id.summary.solver.check_nodes = check_nodes;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::input::load_experiments;
    use crate::model::effects::{Effect, EffectSetting, ModelSpec};
    use std::path::Path;

    /// Richardson's estimate of the discretisation shift (the check's own options) against the
    /// shift measured with every experiment re-solved at 1e-9 at the same parameters (adaptive
    /// meshes, about 22 times the halved meshes' nodes): the same vector to 4 % of its largest
    /// component (the factor 16/15 is needed for that bound), on two data
    /// sets and both estimators, with a fitted effect in one.
    #[test]
    fn the_halved_mesh_estimates_the_shift_a_tight_solve_measures() {
        for (file, spec) in [
            (
                "data/pmma7n_synthetic/experiments.toml",
                ModelSpec::default(),
            ),
            (
                "data/hidden_radiation/experiments.toml",
                ModelSpec::default().with(EffectSetting::fitted(Effect::Radiation)),
            ),
        ] {
            // the shipped data sets live at the workspace root, two folders above this crate
            let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
            let set = load_experiments(&root.join(file)).unwrap();
            let rh = Rheometer::with_spec(&set, spec).unwrap();
            for est in [Estimator::Paper, Estimator::Principled] {
                let mut o = IdentifyOptions::with_estimator(est);
                o.max_discretisation_shift = None;
                let start = FitStart::at([0.7, 11.51]);
                let id = rh.identify_from(&start, &o).unwrap();
                let (r_half, nodes_half) =
                    residuals_resolved(&rh, &start, &halved(&o), &id).unwrap();
                let estimate = shift_se(&id, &r_half, RICHARDSON_FACTOR).unwrap();
                let mut tight = o.clone();
                tight.simulate.tol = 1e-9;
                let (r_tight, nodes_tight) = residuals_resolved(&rh, &start, &tight, &id).unwrap();
                let measured = shift_se(&id, &r_tight, 1.0).unwrap();
                let largest = measured.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                assert!(
                    largest > 1e-6,
                    "{file} {est:?}: nothing to measure ({largest:e})"
                );
                for (c, (e, m)) in estimate.iter().zip(&measured).enumerate() {
                    assert!(
                        (e - m).abs() <= 0.04 * largest,
                        "{file} {est:?}: {}: estimate {e:.3e} SE, measured {m:.3e} SE",
                        id.names[c]
                    );
                }
                let sum = |v: &[usize]| v.iter().sum::<usize>();
                assert_eq!(
                    sum(&nodes_half),
                    2 * sum(&id.summary.solver.nodes) - rh.len()
                );
                let show = |v: &[f64]| v.iter().map(|x| format!("{x:.3e}")).collect::<Vec<_>>();
                eprintln!(
                    "{file} {est:?}: estimate {:?}, measured {:?} SE; nodes \
                     {} fit, {} halved, {} at 1e-9",
                    show(&estimate),
                    show(&measured),
                    sum(&id.summary.solver.nodes),
                    sum(&nodes_half),
                    sum(&nodes_tight)
                );
            }
        }
    }
}

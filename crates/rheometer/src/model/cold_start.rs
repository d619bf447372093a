//! Cold start: natural-parameter continuation in `c` from the stress-free fiber (`c = 0`) to the
//! full model (`c = 1`), paper Sec. 2.2 / App. B.
//!
//! The path is the toolkit's [`solve_by_continuation`] with one of two step controls
//! ([`StepControl`]):
//!
//! * [`StepControl::Simple`] (default): enlarge the step on success, shrink it on failure, give
//!   up below a minimum step. One solve per step.
//! * [`StepControl::Adapter`]: the paper's Algorithm 1 (Adapter): every step is solved as one
//!   full and two half steps and the step adapted from their costs. About three solves per
//!   step, so it is slower on the fiber model (see `benches/README.md`), but it is the paper's
//!   method.
//!
//! Intermediate steps are solved at a loose tolerance ([`PathOptions::intermediate_tol`]); the
//! final `c = 1` solve uses the caller's options.

pub use diffbvp::continuation::{PathOptions, StepControl};

use diffbvp::continuation::{follow, solve_by_continuation};
use diffbvp::error::BvpError;
use diffbvp::problem::Bvp;
use diffbvp::solution::Solution;
use diffbvp::solve::{Guess, SolveOptions, Solver};

/// Continuation in `p[index]` from 0 to 1 starting from `guess`, which must (nearly) solve the
/// problem at `p[index] = 0`. `params` holds the other model parameters (its entry `index` is
/// overwritten). Returns the solution at `p[index] = 1`, solved with `options` (intermediate
/// steps at the looser `path.intermediate_tol`). The solver's workspace (and its cached
/// symbolic factorisations) is reused for every step; its own options are not used.
pub(crate) fn continuation_in_c<P: Bvp>(
    solver: &mut Solver<'_, P>,
    params: &[f64],
    index: usize,
    guess: &Guess,
    path: &PathOptions,
    options: &SolveOptions,
) -> Result<Solution, BvpError> {
    let p = with_value(params, index, 0.0);
    solve_by_continuation(solver, &p, index, 1.0, guess, path, options)
}

/// `params` with entry `index` set to `value` (an index out of range is left to the caller's
/// continuation routine to refuse).
fn with_value(params: &[f64], index: usize, value: f64) -> Vec<f64> {
    let mut p = params.to_vec();
    if let Some(c) = p.get_mut(index) {
        *c = value;
    }
    p
}

/// [`continuation_in_c`] that also returns the end point of the loose path: the solution at
/// `p[index] = 1` solved at the [`PathOptions::intermediate`] options of `options` (tolerance
/// `max(options.tol, path.intermediate_tol)`), from which the final solve at `final_options`
/// started (e.g. `options` with another mesh rule). Returns `(loose, final)`. A fit with loose
/// inner iterations uses the loose end point as its loose solve at the start parameters
/// instead of re-solving the final solution loosely.
pub(crate) fn continuation_in_c_with_loose<P: Bvp>(
    solver: &mut Solver<'_, P>,
    params: &[f64],
    index: usize,
    guess: &Guess,
    path: &PathOptions,
    options: &SolveOptions,
    final_options: &SolveOptions,
) -> Result<(Solution, Solution), BvpError> {
    path.step_control.validate()?;
    let loose = path.intermediate(options);
    let start = solver.solve_with(&with_value(params, index, 0.0), guess, &loose)?;
    let reached = follow(solver, &start, index, 1.0, &path.step_control, &loose)?.solution;
    let p = with_value(params, index, 1.0);
    let last = solver.solve_with(&p, &Guess::from(&reached), final_options)?;
    Ok((reached, last))
}

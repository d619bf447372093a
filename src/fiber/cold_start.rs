//! Cold start: natural-parameter continuation in `c` from the stress-free fiber (`c = 0`) to the
//! full model (`c = 1`), paper Sec. 2.2 / App. B.
//!
//! Two step controls ([`StepControl`]):
//!
//! * [`StepControl::Simple`] (default): enlarge the step on success, shrink it on failure, give
//!   up below a minimum step. One solve per step.
//! * [`StepControl::Adapter`]: the library's [`continuation()`](crate::continuation::continuation)
//!   with the paper's Algorithm 1 (Adapter): every step is solved as one full and two half steps
//!   and the step adapted from their costs. About three solves per step, so it is slower on
//!   the fiber model (see `benches/README.md`), but it is the paper's method.
//!
//! Intermediate steps are solved at a loose tolerance; the final `c = 1` solve uses the caller's
//! options.

use crate::continuation::{continuation, ContinuationOptions as AdapterOptions};
use crate::error::BvpError;
use crate::problem::Bvp;
use crate::solution::Solution;
use crate::solve::{Guess, SolveOptions, Solver};

/// How the continuation chooses its steps in `c`.
#[derive(Debug, Clone, PartialEq)]
pub enum StepControl {
    /// Grow the step by `grow` after a success, shrink it by `shrink` after a failure.
    Simple,
    /// The paper's Algorithm 1 (Adapter) with these options (`initial_step`, `min_step` and
    /// `max_steps` of [`ContinuationOptions`] are not used by it).
    Adapter(AdapterOptions),
}

/// Settings of the continuation in `c`.
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuationOptions {
    /// Step control (default [`StepControl::Simple`]).
    pub step_control: StepControl,
    /// First step `Δc` \[-\] (paper: 0.1).
    pub initial_step: f64,
    /// Factor applied to `Δc` after a successful step \[-\].
    pub grow: f64,
    /// Factor applied to `Δc` after a failed step \[-\].
    pub shrink: f64,
    /// Smallest admissible step \[-\]; below it the continuation fails.
    pub min_step: f64,
    /// Tolerance of the intermediate solves (the larger of this and the final tolerance).
    pub intermediate_tol: f64,
    /// Maximum number of steps (successful or not).
    pub max_steps: usize,
}

impl Default for ContinuationOptions {
    fn default() -> Self {
        ContinuationOptions {
            step_control: StepControl::Simple,
            initial_step: 0.25,
            grow: 2.0,
            shrink: 0.5,
            min_step: 1e-4,
            intermediate_tol: 1e-3,
            max_steps: 200,
        }
    }
}

/// Continuation in `p[index]` from 0 to 1 starting from `guess`, which must (nearly) solve the
/// problem at `p[index] = 0`. `params` holds the other model parameters (its entry `index` is
/// overwritten). Returns the solution at `p[index] = 1`, solved with the solver's options
/// (intermediate steps at the looser `cont.intermediate_tol`). The solver (and its cached
/// symbolic factorisations) is reused for every step; its options are restored on return.
pub fn continuation_in_c<P: Bvp>(
    solver: &mut Solver<'_, P>,
    params: &[f64],
    index: usize,
    guess: &Guess,
    cont: &ContinuationOptions,
) -> Result<Solution, BvpError> {
    let options = solver.options.clone();
    let result = continuation_steps(solver, params, index, guess, &options, cont);
    solver.options = options;
    result
}

fn continuation_steps<P: Bvp>(
    solver: &mut Solver<'_, P>,
    params: &[f64],
    index: usize,
    guess: &Guess,
    options: &SolveOptions,
    cont: &ContinuationOptions,
) -> Result<Solution, BvpError> {
    if index >= params.len() {
        return Err(BvpError::InvalidInput(format!(
            "continuation parameter index {index} out of range ({} parameters)",
            params.len()
        )));
    }
    if !(cont.initial_step > 0.0
        && cont.min_step > 0.0
        && cont.grow >= 1.0
        && cont.shrink < 1.0
        && cont.shrink > 0.0)
    {
        return Err(BvpError::InvalidInput(format!(
            "invalid continuation options {cont:?}"
        )));
    }
    let mut p = params.to_vec();
    p[index] = 0.0;
    let mut loose = options.clone();
    loose.tol = options.tol.max(cont.intermediate_tol);
    loose.bc_tol = Some(
        options
            .bc_tol
            .unwrap_or(options.tol)
            .max(cont.intermediate_tol),
    );
    loose.factor_at_solution = false;
    solver.options = loose;
    let mut sol = solver.solve(&p, guess)?;
    if let StepControl::Adapter(adapter) = &cont.step_control {
        let path = continuation(solver, &sol, index, 1.0, adapter)?;
        p[index] = 1.0;
        solver.options = options.clone();
        return solver.solve(&p, &Guess::from(&path.solution));
    }
    let mut c = 0.0;
    let mut step = cont.initial_step;
    let mut steps = 0;
    while c < 1.0 {
        steps += 1;
        let c_new = (c + step).min(1.0);
        p[index] = c_new;
        let result = if steps > cont.max_steps {
            Err(BvpError::InvalidInput(format!(
                "more than {} continuation steps",
                cont.max_steps
            )))
        } else {
            solver.solve(&p, &Guess::from(&sol))
        };
        match result {
            Ok(s) => {
                sol = s;
                c = c_new;
                step *= cont.grow;
            }
            Err(e) => {
                step *= cont.shrink;
                if step < cont.min_step || steps > cont.max_steps {
                    return Err(BvpError::ContinuationStalled {
                        reached: c,
                        target: 1.0,
                        step,
                        min_step: cont.min_step,
                        last_error: Box::new(e),
                    });
                }
            }
        }
    }
    solver.options = options.clone();
    solver.solve(&p, &Guess::from(&sol))
}

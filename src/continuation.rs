//! Homotopy continuation in one model parameter, with the step-size strategy of the paper's
//! Algorithm 1 ("Adapter"), and plain parameter sweeps.
//!
//! From a converged solution at `c_j`, Adapter solves the problem for `c_j + Δ` directly (cost
//! `F`, counted in right-hand-side evaluations) and in two half steps (`H₁ + H₂`). If a solve
//! diverges, `Δ` is divided by `μ = 2` and the step retried. Otherwise the two-half-step
//! solution is accepted and the step adapted: if the halves cost more than the full step, the
//! full step was easy and `Δ ← ν₁ Δ` (ν₁ = 3/2), else `Δ ← ν₂ Δ` (ν₂ = 2/3). Initial step 0.1.
//! Below `min_step` the path stops with an error that says which `c` was reached.
//!
//! Reading of the algorithm as printed: the adapted `Δ` applies to the *next* step (the new
//! point is `c_j + Δ_old`, where the solves were done); when the full step fails but both half
//! steps converge, the half-step solution is kept and `Δ` shrunk; when only the first half step
//! converges, it is kept (progress `Δ/2`) and `Δ` shrunk. The continuation parameter is an
//! ordinary model parameter (an index into `p`), not a field of the problem.

use crate::error::BvpError;
use crate::problem::Bvp;
use crate::solution::{Solution, SolveStats};
use crate::solve::{Guess, Solver};

/// Options of [`continuation`].
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuationOptions {
    /// Initial step `Δc₀` (paper: 0.1, relative to `|c₁ - c₀| = 1`; scaled by `|c₁ - c₀|`).
    pub initial_step: f64,
    /// Smallest step (relative to `|c₁ - c₀|`) before giving up (default 1e-4).
    pub min_step: f64,
    /// Largest step (relative, default 1).
    pub max_step: f64,
    /// Enlarging factor ν₁ (default 3/2).
    pub enlarge: f64,
    /// Shrinking factor ν₂ (default 2/3).
    pub shrink: f64,
    /// Divisor μ applied on divergence (default 2).
    pub divergence_divisor: f64,
    /// Maximum number of continuation steps (default 1000).
    pub max_steps: usize,
}

impl Default for ContinuationOptions {
    fn default() -> Self {
        ContinuationOptions {
            initial_step: 0.1,
            min_step: 1e-4,
            max_step: 1.0,
            enlarge: 1.5,
            shrink: 2.0 / 3.0,
            divergence_divisor: 2.0,
            max_steps: 1000,
        }
    }
}

impl ContinuationOptions {
    /// Checks the options: steps finite with `0 < min_step <= max_step`, `initial_step > 0`,
    /// `enlarge >= 1`, `0 < shrink < 1`, `divergence_divisor > 1`, `max_steps >= 1`. The error
    /// names the option and its value. [`continuation`] calls this before any solve.
    pub fn validate(&self) -> Result<(), BvpError> {
        let bad = |name: &str, value: f64, rule: &str| {
            Err(BvpError::InvalidInput(format!(
                "ContinuationOptions::{name} = {value} {rule}"
            )))
        };
        let positive = [
            ("initial_step", self.initial_step),
            ("min_step", self.min_step),
            ("max_step", self.max_step),
        ];
        for (name, v) in positive {
            if !(v > 0.0 && v.is_finite()) {
                return bad(name, v, "must be positive and finite");
            }
        }
        if self.min_step > self.max_step {
            return bad(
                "min_step",
                self.min_step,
                &format!("must not exceed max_step = {}", self.max_step),
            );
        }
        if !(self.enlarge >= 1.0 && self.enlarge.is_finite()) {
            return bad("enlarge", self.enlarge, "must be finite and at least 1");
        }
        if !(self.shrink > 0.0 && self.shrink < 1.0) {
            return bad("shrink", self.shrink, "must lie in (0, 1)");
        }
        if !(self.divergence_divisor > 1.0 && self.divergence_divisor.is_finite()) {
            return bad(
                "divergence_divisor",
                self.divergence_divisor,
                "must be finite and larger than 1",
            );
        }
        if self.max_steps == 0 {
            return Err(BvpError::InvalidInput(
                "ContinuationOptions::max_steps = 0 must be at least 1".into(),
            ));
        }
        Ok(())
    }
}

/// One attempted continuation step.
#[derive(Debug, Clone, PartialEq)]
pub struct StepRecord {
    /// Parameter value the step started from.
    pub from: f64,
    /// Step size tried (signed, in parameter units).
    pub step: f64,
    /// Parameter value reached (equal to `from` if rejected).
    pub reached: f64,
    /// Whether progress was made.
    pub accepted: bool,
    /// Right-hand-side evaluations of the full step (`None` if it diverged).
    pub cost_full: Option<usize>,
    /// Right-hand-side evaluations of the two half steps (`None` if one diverged).
    pub cost_halves: Option<usize>,
    /// The step proposed for the next attempt.
    pub next_step: f64,
}

/// The result of a continuation: final solution and path statistics.
#[derive(Debug, Clone)]
pub struct ContinuationPath {
    /// Solution at the target value.
    pub solution: Solution,
    /// Steps that made progress.
    pub steps_accepted: usize,
    /// Steps rejected because a solve diverged.
    pub steps_rejected: usize,
    /// Right-hand-side evaluations over all solves (values and dual passes).
    pub total_rhs_evaluations: usize,
    /// Summed solver statistics.
    pub stats: SolveStats,
    /// Every attempted step, in order.
    pub history: Vec<StepRecord>,
}

fn add_stats(total: &mut SolveStats, s: &SolveStats) {
    total.newton_iterations += s.newton_iterations;
    total.jacobian_factorizations += s.jacobian_factorizations;
    total.rhs_evaluations += s.rhs_evaluations;
    total.rhs_dual_evaluations += s.rhs_dual_evaluations;
    total.mesh_refinements += s.mesh_refinements;
    total.mesh_coarsenings += s.mesh_coarsenings;
    total.max_residual = s.max_residual;
    total.max_bc_residual = s.max_bc_residual;
}

/// Follows the path `params[index] = c` from `start` (a solution at `c = start.params[index]`)
/// to `c = target`, with Adapter step control. The other model parameters are taken from
/// `start.params`. Invalid options (see [`ContinuationOptions::validate`]), an index out of
/// range or a non-finite target are errors before any solve.
pub fn continuation<P: Bvp>(
    solver: &mut Solver<'_, P>,
    start: &Solution,
    index: usize,
    target: f64,
    options: &ContinuationOptions,
) -> Result<ContinuationPath, BvpError> {
    if index >= start.params.len() {
        return Err(BvpError::InvalidInput(format!(
            "continuation parameter index {index} out of range: the problem has {} model parameters",
            start.params.len()
        )));
    }
    if !target.is_finite() {
        return Err(BvpError::InvalidInput(format!(
            "continuation target {target} is not finite"
        )));
    }
    options.validate()?;
    let c0 = start.params[index];
    let span = target - c0;
    let mut path = ContinuationPath {
        solution: start.clone(),
        steps_accepted: 0,
        steps_rejected: 0,
        total_rhs_evaluations: 0,
        stats: SolveStats::default(),
        history: Vec::new(),
    };
    if span == 0.0 {
        return Ok(path);
    }
    let dir = span.signum();
    let total = span.abs();
    let mut step = (options.initial_step * total).min(options.max_step * total);
    let min_step = options.min_step * total;
    let mut current = start.clone();
    let mut c = c0;
    let mut params = start.params.clone();
    let mut last_error: Option<BvpError> = None;
    let mut attempts = 0;
    while (target - c) * dir > 0.0 {
        attempts += 1;
        if attempts > options.max_steps {
            return Err(BvpError::ContinuationStalled {
                reached: c,
                target,
                step,
                min_step,
                last_error: Box::new(last_error.unwrap_or_else(|| {
                    BvpError::InvalidInput(format!(
                        "more than {} continuation steps",
                        options.max_steps
                    ))
                })),
            });
        }
        if step < min_step {
            return Err(BvpError::ContinuationStalled {
                reached: c,
                target,
                step,
                min_step,
                last_error: Box::new(
                    last_error
                        .unwrap_or_else(|| BvpError::InvalidInput("step below minimum".into())),
                ),
            });
        }
        let h = step.min((target - c).abs());
        let c_full = if h == (target - c).abs() {
            target
        } else {
            c + dir * h
        };
        let c_half = c + dir * 0.5 * h;
        let guess = Guess::from(&current);
        let mut solve_at = |cv: f64, g: &Guess, path: &mut ContinuationPath| {
            params[index] = cv;
            let r = solver.solve(&params, g);
            if let Ok(s) = &r {
                add_stats(&mut path.stats, &s.stats);
                path.total_rhs_evaluations += s.stats.total_rhs_evaluations();
            }
            r
        };
        let full = solve_at(c_full, &guess, &mut path);
        let half1 = solve_at(c_half, &guess, &mut path);
        let half2 = match &half1 {
            Ok(s1) => solve_at(c_full, &Guess::from(s1), &mut path),
            Err(e) => Err(e.clone()),
        };
        let cost_full = full.as_ref().ok().map(|s| s.stats.total_rhs_evaluations());
        let mut record = StepRecord {
            from: c,
            step: dir * h,
            reached: c,
            accepted: false,
            cost_full,
            cost_halves: None,
            next_step: step,
        };
        match (full, half1, half2) {
            (Ok(f), Ok(s1), Ok(s2)) => {
                let halves = s1.stats.total_rhs_evaluations() + s2.stats.total_rhs_evaluations();
                record.cost_halves = Some(halves);
                let cf = f.stats.total_rhs_evaluations();
                step = if halves > cf {
                    (h * options.enlarge).min(options.max_step * total)
                } else {
                    h * options.shrink
                };
                current = s2;
                c = c_full;
                record.accepted = true;
            }
            (Err(e), Ok(_), Ok(s2)) => {
                last_error = Some(e);
                step = h * options.shrink;
                current = s2;
                c = c_full;
                record.accepted = true;
            }
            (_, Ok(s1), Err(e)) => {
                last_error = Some(e);
                step = 0.5 * h * options.shrink;
                current = s1;
                c = c_half;
                record.accepted = true;
            }
            (_, Err(e), _) => {
                last_error = Some(e);
                step = h / options.divergence_divisor;
            }
        }
        record.reached = c;
        record.next_step = step;
        if record.accepted {
            path.steps_accepted += 1;
        } else {
            path.steps_rejected += 1;
        }
        path.history.push(record);
    }
    path.solution = current;
    Ok(path)
}

/// Solves for each value of `params[index]` in `values`, warm-starting every solve from the
/// previous converged solution (the first from `start`). Failed solves are returned as errors
/// and do not interrupt the sweep; the next value starts from the last converged solution.
pub fn sweep<P: Bvp>(
    solver: &mut Solver<'_, P>,
    params: &[f64],
    index: usize,
    values: &[f64],
    start: &Guess,
) -> Vec<Result<Solution, BvpError>> {
    let mut p = params.to_vec();
    let mut guess = start.clone();
    let mut out = Vec::with_capacity(values.len());
    for &v in values {
        if index >= p.len() {
            out.push(Err(BvpError::InvalidInput(format!(
                "sweep parameter index {index} out of range ({} model parameters)",
                p.len()
            ))));
            continue;
        }
        p[index] = v;
        let r = solver.solve(&p, &guess);
        if let Ok(s) = &r {
            guess = Guess::from(s);
        }
        out.push(r);
    }
    out
}

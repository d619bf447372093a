//! Path following in one model parameter: homotopy continuation with the step-size strategy of
//! the paper's Algorithm 1 ("Adapter") or a simple grow/shrink step control, a secant predictor,
//! step bisection, and plain parameter sweeps. Every path-following loop of the crate lives
//! here; the fiber cold start and the rheometer's cost landscape call these functions.
//!
//! * [`continuation`]: Adapter with the solver's own options (the tutorial's entry point).
//! * [`follow`]: either step control ([`StepControl`]) with solve options passed per call.
//! * [`solve_by_continuation`]: a path from a guess at the start value, intermediate points at
//!   a loose tolerance ([`PathOptions`]), the last point solved again at the caller's options.
//! * [`secant_guess`]: the warm start extrapolated from the last two solutions of a path
//!   ([`try_secant_guess`]: the same with mismatched solutions reported as an error).
//! * [`bisect_step`]: a failed step retried in halves, with a stop check before every solve.
//! * [`sweep`]: one solve per parameter value, each warm-started from the previous one.
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
use crate::solve::{Guess, SolveOptions, Solver};

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
        let owner = "ContinuationOptions";
        let bad = |name: &str, value: f64, rule: &str| bad_option(owner, name, value, rule);
        check_positive(
            owner,
            &[
                ("initial_step", self.initial_step),
                ("min_step", self.min_step),
                ("max_step", self.max_step),
            ],
            true,
        )?;
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
        check_shrink(owner, self.shrink)?;
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
/// to `c = target`, with Adapter step control, every solve with the solver's
/// [`options`](Solver::options). The other model parameters are taken from `start.params`.
/// Invalid options (see [`ContinuationOptions::validate`]), an index out of range or a
/// non-finite target are errors before any solve. [`follow`] is the general form.
pub fn continuation<P: Bvp>(
    solver: &mut Solver<'_, P>,
    start: &Solution,
    index: usize,
    target: f64,
    options: &ContinuationOptions,
) -> Result<ContinuationPath, BvpError> {
    let solve_options = solver.options.clone();
    check_path(start, index, target)?;
    options.validate()?;
    adapter(solver, start, index, target, options, &solve_options)
}

/// The checks every path does before any solve: index in range, finite target.
fn check_path(start: &Solution, index: usize, target: f64) -> Result<(), BvpError> {
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
    Ok(())
}

/// A path that has not moved yet: `start` and no statistics.
fn empty_path(start: &Solution) -> ContinuationPath {
    ContinuationPath {
        solution: start.clone(),
        steps_accepted: 0,
        steps_rejected: 0,
        total_rhs_evaluations: 0,
        stats: SolveStats::default(),
        history: Vec::new(),
    }
}

/// Start value, direction (±1) and length of the path from `start` to `target`; `None` if the
/// path is empty.
fn span(start: &Solution, index: usize, target: f64) -> Option<(f64, f64, f64)> {
    let c0 = start.params[index];
    let span = target - c0;
    (span != 0.0).then(|| (c0, span.signum(), span.abs()))
}

/// Appends an attempted step that ended at `reached` and proposed `next_step`.
fn push_record(path: &mut ContinuationPath, mut record: StepRecord, reached: f64, next_step: f64) {
    record.reached = reached;
    record.next_step = next_step;
    if record.accepted {
        path.steps_accepted += 1;
    } else {
        path.steps_rejected += 1;
    }
    path.history.push(record);
}

/// Adds one converged solve to the path's statistics.
fn count_solve(path: &mut ContinuationPath, s: &Solution) {
    add_stats(&mut path.stats, &s.stats);
    path.total_rhs_evaluations += s.stats.total_rhs_evaluations();
}

/// The stall check before a step of [`adapter`]: an error once the `attempts` exceed
/// `max_steps` or the step falls below the minimum (`at = [c, target, step, min_step]`), with
/// the last failed solve (taken from `last_error`) as its cause.
fn check_stall(
    attempts: usize,
    max_steps: usize,
    [c, target, step, min_step]: [f64; 4],
    last_error: &mut Option<BvpError>,
) -> Result<(), BvpError> {
    if attempts > max_steps {
        return Err(BvpError::ContinuationStalled {
            reached: c,
            target,
            step,
            min_step,
            last_error: Box::new(last_error.take().unwrap_or_else(|| {
                BvpError::InvalidInput(format!("more than {max_steps} continuation steps"))
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
                    .take()
                    .unwrap_or_else(|| BvpError::InvalidInput("step below minimum".into())),
            ),
        });
    }
    Ok(())
}

/// The paper's Algorithm 1 (Adapter), options already checked.
fn adapter<P: Bvp>(
    solver: &mut Solver<'_, P>,
    start: &Solution,
    index: usize,
    target: f64,
    options: &ContinuationOptions,
    solve_options: &SolveOptions,
) -> Result<ContinuationPath, BvpError> {
    let mut path = empty_path(start);
    let Some((c0, dir, total)) = span(start, index, target) else {
        return Ok(path);
    };
    let mut step = (options.initial_step * total).min(options.max_step * total);
    let min_step = options.min_step * total;
    let mut current = start.clone();
    let mut c = c0;
    let mut params = start.params.clone();
    let mut last_error: Option<BvpError> = None;
    let mut attempts = 0;
    while (target - c) * dir > 0.0 {
        attempts += 1;
        check_stall(
            attempts,
            options.max_steps,
            [c, target, step, min_step],
            &mut last_error,
        )?;
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
            let r = solver.solve_with(&params, g, solve_options);
            if let Ok(s) = &r {
                count_solve(path, s);
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
        push_record(&mut path, record, c, step);
    }
    path.solution = current;
    Ok(path)
}

/// Options of the simple step control ([`StepControl::Simple`]): one solve per step, the step
/// enlarged by `grow` after a success and reduced by `shrink` after a failure. Steps are
/// relative to the path length `|target − start|`, as those of [`ContinuationOptions`].
#[derive(Debug, Clone, PartialEq)]
pub struct SimpleSteps {
    /// First step (relative, default 0.25).
    pub initial_step: f64,
    /// Factor applied to the step after a successful solve (default 2).
    pub grow: f64,
    /// Factor applied to the step after a failed solve (default 0.5).
    pub shrink: f64,
    /// Smallest step (relative, default 1e-4); a failure that shrinks the step below it ends
    /// the path.
    pub min_step: f64,
    /// Maximum number of steps, successful or not (default 200).
    pub max_steps: usize,
}

impl Default for SimpleSteps {
    fn default() -> Self {
        SimpleSteps {
            initial_step: 0.25,
            grow: 2.0,
            shrink: 0.5,
            min_step: 1e-4,
            max_steps: 200,
        }
    }
}

impl SimpleSteps {
    /// Checks the options: `initial_step > 0`, `min_step > 0`, `grow >= 1`, `0 < shrink < 1`
    /// (NaN fails every check), `max_steps >= 1`. The error names the option and its value.
    /// [`follow`] calls this before any solve.
    pub fn validate(&self) -> Result<(), BvpError> {
        let owner = "SimpleSteps";
        check_positive(
            owner,
            &[
                ("initial_step", self.initial_step),
                ("min_step", self.min_step),
            ],
            false,
        )?;
        if self.grow.is_nan() || self.grow < 1.0 {
            return bad_option(owner, "grow", self.grow, "must be at least 1");
        }
        if self.max_steps == 0 {
            return Err(BvpError::InvalidInput(
                "SimpleSteps::max_steps = 0 must be at least 1".into(),
            ));
        }
        check_shrink(owner, self.shrink)
    }
}

/// The error for the option `owner::name = value`, which breaks `rule`.
fn bad_option(owner: &str, name: &str, value: f64, rule: &str) -> Result<(), BvpError> {
    Err(BvpError::InvalidInput(format!(
        "{owner}::{name} = {value} {rule}"
    )))
}

/// Step options must be positive (and finite if `finite`).
fn check_positive(owner: &str, steps: &[(&str, f64)], finite: bool) -> Result<(), BvpError> {
    for &(name, v) in steps {
        if finite && !(v > 0.0 && v.is_finite()) {
            return bad_option(owner, name, v, "must be positive and finite");
        }
        if v.is_nan() || v <= 0.0 {
            return bad_option(owner, name, v, "must be positive");
        }
    }
    Ok(())
}

/// A shrinking factor lies in (0, 1).
fn check_shrink(owner: &str, shrink: f64) -> Result<(), BvpError> {
    if shrink > 0.0 && shrink < 1.0 {
        Ok(())
    } else {
        bad_option(owner, "shrink", shrink, "must lie in (0, 1)")
    }
}

/// How a path chooses its steps.
#[derive(Debug, Clone, PartialEq)]
pub enum StepControl {
    /// One solve per step, grow on success, shrink on failure ([`SimpleSteps`]).
    Simple(SimpleSteps),
    /// The paper's Algorithm 1 (Adapter): every step solved as one full and two half steps,
    /// the step adapted from their costs. About three solves per step.
    Adapter(ContinuationOptions),
}

impl Default for StepControl {
    /// [`StepControl::Simple`] with default [`SimpleSteps`].
    fn default() -> Self {
        StepControl::Simple(SimpleSteps::default())
    }
}

impl StepControl {
    /// Checks the options of the chosen step control.
    pub fn validate(&self) -> Result<(), BvpError> {
        match self {
            StepControl::Simple(s) => s.validate(),
            StepControl::Adapter(a) => a.validate(),
        }
    }
}

/// Follows the path `params[index] = c` from `start` (a solution at `c = start.params[index]`)
/// to `c = target` with the step control `control`, every solve with `options` (the solver's
/// own options are neither used nor changed; its workspace is reused). The other model
/// parameters are taken from `start.params`. Invalid options, an index out of range or a
/// non-finite target are errors before any solve; a path that cannot go on is
/// [`BvpError::ContinuationStalled`] with the value reached.
pub fn follow<P: Bvp>(
    solver: &mut Solver<'_, P>,
    start: &Solution,
    index: usize,
    target: f64,
    control: &StepControl,
    options: &SolveOptions,
) -> Result<ContinuationPath, BvpError> {
    check_path(start, index, target)?;
    control.validate()?;
    match control {
        StepControl::Simple(steps) => simple(solver, start, index, target, steps, options),
        StepControl::Adapter(a) => adapter(solver, start, index, target, a, options),
    }
}

/// The simple step control, options already checked.
fn simple<P: Bvp>(
    solver: &mut Solver<'_, P>,
    start: &Solution,
    index: usize,
    target: f64,
    control: &SimpleSteps,
    options: &SolveOptions,
) -> Result<ContinuationPath, BvpError> {
    let mut path = empty_path(start);
    let Some((c0, dir, total)) = span(start, index, target) else {
        return Ok(path);
    };
    let mut step = control.initial_step * total;
    let min_step = control.min_step * total;
    let mut current = start.clone();
    let mut params = start.params.clone();
    let mut c = c0;
    let mut steps = 0;
    while (target - c) * dir > 0.0 {
        steps += 1;
        let ahead = c + dir * step;
        let c_new = if (ahead - target) * dir >= 0.0 {
            target
        } else {
            ahead
        };
        params[index] = c_new;
        let result = if steps > control.max_steps {
            Err(BvpError::InvalidInput(format!(
                "more than {} continuation steps",
                control.max_steps
            )))
        } else {
            solver.solve_with(&params, &Guess::from(&current), options)
        };
        let mut record = StepRecord {
            from: c,
            step: c_new - c,
            reached: c,
            accepted: false,
            cost_full: None,
            cost_halves: None,
            next_step: step,
        };
        match result {
            Ok(s) => {
                count_solve(&mut path, &s);
                record.cost_full = Some(s.stats.total_rhs_evaluations());
                record.accepted = true;
                current = s;
                c = c_new;
                step *= control.grow;
            }
            Err(e) => {
                step *= control.shrink;
                if step < min_step || steps > control.max_steps {
                    return Err(BvpError::ContinuationStalled {
                        reached: c,
                        target,
                        step,
                        min_step,
                        last_error: Box::new(e),
                    });
                }
            }
        }
        push_record(&mut path, record, c, step);
    }
    path.solution = current;
    Ok(path)
}

/// Options of [`solve_by_continuation`]: the step control and the tolerance of the
/// intermediate points.
#[derive(Debug, Clone, PartialEq)]
pub struct PathOptions {
    /// Step control (default [`StepControl::Simple`] with default [`SimpleSteps`]).
    pub step_control: StepControl,
    /// Tolerance of the start and intermediate solves (the larger of this and the final
    /// tolerance is used, for the collocation and the boundary residuals; default 1e-3). No
    /// factorisation is kept at intermediate points.
    pub intermediate_tol: f64,
}

impl Default for PathOptions {
    fn default() -> Self {
        PathOptions {
            step_control: StepControl::default(),
            intermediate_tol: 1e-3,
        }
    }
}

impl PathOptions {
    /// Checks the options: the step control's ([`StepControl::validate`]) and
    /// `0 < intermediate_tol < 1` (a relative residual; NaN fails). The error names the option
    /// and its value. [`solve_by_continuation`] calls this before any solve.
    pub fn validate(&self) -> Result<(), BvpError> {
        self.step_control.validate()?;
        let t = self.intermediate_tol;
        if !(t > 0.0 && t < 1.0) {
            return bad_option(
                "PathOptions",
                "intermediate_tol",
                t,
                "must lie in (0, 1) (it bounds a relative residual, as SolveOptions::tol)",
            );
        }
        Ok(())
    }

    /// The solve options of the start and intermediate points for final options `options`:
    /// `tol` and `bc_tol` at least [`intermediate_tol`](Self::intermediate_tol), no
    /// factorisation at the solution.
    pub fn intermediate(&self, options: &SolveOptions) -> SolveOptions {
        let mut loose = options.clone();
        loose.tol = options.tol.max(self.intermediate_tol);
        loose.bc_tol = Some(
            options
                .bc_tol
                .unwrap_or(options.tol)
                .max(self.intermediate_tol),
        );
        loose.factor_at_solution = false;
        loose
    }
}

/// Solves at `params[index] = target` by continuation from `guess`, which must (nearly) solve
/// the problem at `params` (the start value is `params[index]`): the start and the intermediate
/// points are solved at [`PathOptions::intermediate`] options, the target once more at
/// `options`. The solver's own options are neither used nor changed; its workspace is reused
/// for every solve. Errors: invalid options or index before any solve, the start solve's error,
/// or [`BvpError::ContinuationStalled`].
pub fn solve_by_continuation<P: Bvp>(
    solver: &mut Solver<'_, P>,
    params: &[f64],
    index: usize,
    target: f64,
    guess: &Guess,
    path: &PathOptions,
    options: &SolveOptions,
) -> Result<Solution, BvpError> {
    if index >= params.len() {
        return Err(BvpError::InvalidInput(format!(
            "continuation parameter index {index} out of range ({} parameters)",
            params.len()
        )));
    }
    path.validate()?;
    let loose = path.intermediate(options);
    let start = solver.solve_with(params, guess, &loose)?;
    let reached = follow(solver, &start, index, target, &path.step_control, &loose)?;
    let mut p = params.to_vec();
    p[index] = target;
    solver.solve_with(&p, &Guess::from(&reached.solution), options)
}

/// Secant predictor: the warm start `a + t (a − b)` on the mesh of `a`, from the last two
/// solutions `a` and `b` of a path (`t = (c_new − c_a) / (c_a − c_b)` for a step to `c_new`);
/// `b` is evaluated through its interpolant at the nodes of `a`. Unknown parameters are
/// extrapolated alike when `a` and `b` have the same number of them, else those of `a` are
/// kept. On the fiber model it saves about a third of the Newton iterations of a warm start
/// from `a` itself.
///
/// It never panics: when `b` cannot be extrapolated from (another number of states than `a`,
/// or a non-finite `t`), the warm start is `a` itself, `Guess::from(a)`.
/// [`try_secant_guess`] reports those cases as errors instead.
pub fn secant_guess(a: &Solution, b: &Solution, t: f64) -> Guess {
    try_secant_guess(a, b, t).unwrap_or_else(|_| Guess::from(a))
}

/// [`secant_guess`] with checked input: `a` and `b` must have the same number of states and
/// `t` must be finite, else a [`BvpError::InvalidInput`] naming both dimensions (or `t`).
pub fn try_secant_guess(a: &Solution, b: &Solution, t: f64) -> Result<Guess, BvpError> {
    let n = a.n;
    if b.n != n {
        return Err(BvpError::InvalidInput(format!(
            "secant_guess: the solutions have different dimensions: a has {n} states, b has {}; \
             both must be solutions of the same problem",
            b.n
        )));
    }
    if !t.is_finite() {
        return Err(BvpError::InvalidInput(format!(
            "secant_guess: the extrapolation factor t = {t} is not finite"
        )));
    }
    let mut y = a.y.clone();
    if crate::mesh::regions(&a.x).len() > 1 {
        // a multipoint mesh: the left limit at an interface from b's left region
        let yb = crate::solve::resample_regions(&b.x, &b.y, &b.yp, n, &a.x);
        for ((v, &va), &vb) in y.iter_mut().zip(&a.y).zip(&yb) {
            *v = va + t * (va - vb);
        }
        return Ok(Guess {
            x: a.x.clone(),
            y,
            unknowns: secant_unknowns(a, b, t),
        });
    }
    let (mut yb, mut ypb) = (vec![0.0; n], vec![0.0; n]);
    for (i, &x) in a.x.iter().enumerate() {
        b.eval_into(x, &mut yb, &mut ypb);
        for c in 0..n {
            let k = i * n + c;
            y[k] = a.y[k] + t * (a.y[k] - yb[c]);
        }
    }
    Ok(Guess {
        x: a.x.clone(),
        y,
        unknowns: secant_unknowns(a, b, t),
    })
}

/// The secant predictor's unknowns: extrapolated when `a` and `b` have as many, else `a`'s.
fn secant_unknowns(a: &Solution, b: &Solution, t: f64) -> Vec<f64> {
    if a.unknowns.len() == b.unknowns.len() {
        a.unknowns
            .iter()
            .zip(&b.unknowns)
            .map(|(ua, ub)| ua + t * (ua - ub))
            .collect()
    } else {
        a.unknowns.clone()
    }
}

/// Reaches `to` from `from` with a solve at `to` and, if it fails, by recursively halving the
/// step up to `depth` times: the first half is reached the same way, then the second half.
/// `solve_at(c)` solves at `c` warm-started from the last success (the caller keeps that
/// state); `stop()` is checked before every solve, and `Some(error)` ends the walk with that
/// error (e.g. a cancellation flag). Returns the result of the solve at `to`, or the first
/// error that could not be bisected away.
pub fn bisect_step<T, E>(
    from: f64,
    to: f64,
    depth: u32,
    solve_at: &mut impl FnMut(f64) -> Result<T, E>,
    stop: &impl Fn() -> Option<E>,
) -> Result<T, E> {
    if let Some(e) = stop() {
        return Err(e);
    }
    match solve_at(to) {
        Ok(v) => Ok(v),
        Err(e) if depth == 0 => Err(e),
        Err(_) => {
            let mid = 0.5 * (from + to);
            bisect_step(from, mid, depth - 1, solve_at, stop)?;
            bisect_step(mid, to, depth - 1, solve_at, stop)
        }
    }
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

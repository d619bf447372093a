//! Damped Newton iteration on the global collocation system.
//!
//! Affine-invariant damping as in scipy's `solve_newton` (after Deuflhard and BVP_SOLVER): the
//! merit of a trial point is `‖J⁻¹ F(Y_trial)‖²` with the *current* factorisation, accepted when
//! it falls below `(1 - 2 α σ)` of the full-step value (σ = 0.2), otherwise `α` is halved (at
//! most four times). After a full step with good contraction (`‖Δ̄_{k+1}‖ ≤ ‖Δ_k‖/4`) the
//! factorisation is reused (simplified Newton); otherwise the Jacobian is recomputed. Iteration stops when the collocation residuals are
//! 1.5 orders of magnitude below the tolerance at the interval midpoints and the boundary
//! residuals below `bc_tol`, or when the Jacobian budget is spent. A start that already passes
//! this test (without a step criterion) is returned as it is: no Jacobian, no factorisation.

use crate::collocation::Collocation;
use crate::error::BvpError;
use crate::linear::{Factorization, LinearSystem};
use crate::problem::Bvp;

/// Settings of one Newton run.
pub(crate) struct NewtonSettings {
    pub tol: f64,
    pub bc_tol: f64,
    pub max_jacobians: usize,
    pub max_iterations: usize,
    /// If set, also require the last Newton correction to satisfy
    /// `‖ΔY‖∞ <= step_tol (1 + ‖Y‖∞)`.
    pub step_tol: Option<f64>,
    /// 0: silent, 1: one line per mesh, 2: also every Newton iteration (stderr).
    pub verbose: u8,
}

/// How the start of a Newton run is evaluated.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Start {
    /// The residual alone: a start that may already pass the termination test (a warm start,
    /// a coarsened mesh) costs no Jacobian.
    Lazy,
    /// The residual with the Jacobian in one dual-number pass: for a start that is unlikely to
    /// pass (values interpolated onto a refined mesh), whose Jacobian the first step needs.
    WithJacobian,
}

/// What a Newton run achieved.
pub(crate) struct NewtonReport {
    pub iterations: usize,
    pub converged: bool,
}

const SIGMA: f64 = 0.2;
const TAU: f64 = 0.5;
const N_TRIAL: usize = 4;
/// Squared contraction factor below which the factorisation is reused.
const CONTRACTION_SQ: f64 = 1.0 / 16.0;

/// Runs damped Newton from `y`, `p` (unknowns in `p[..k]` are updated). On return `col` holds the
/// residuals, node and midpoint values of the final iterate.
#[allow(clippy::too_many_arguments)]
pub(crate) fn newton<P: Bvp>(
    problem: &P,
    col: &mut Collocation,
    lin: &mut LinearSystem,
    y: &mut [f64],
    p: &mut [f64],
    scale: &[f64],
    settings: &NewtonSettings,
    work: &mut NewtonWork,
    initial: Option<&Factorization>,
    start: Start,
) -> Result<NewtonReport, BvpError> {
    let size = col.m() * col.n + col.k;
    // a factorisation from a nearby solution on this mesh (simplified Newton from its Jacobian)
    // is used until the contraction test asks for a fresh one
    let mut it = Iteration {
        borrowed: initial.filter(|f| f.size() == size),
        // the Jacobian of the start is only evaluated with it when it will be factored
        fresh_jacobian: false,
        recompute: true,
        cost: 0.0,
        njev: 0,
    };
    it.fresh_jacobian = start == Start::WithJacobian && it.borrowed.is_none();
    work.resize(size, col.m() * col.n, p.len());
    if evaluate_start(problem, col, y, p, scale, settings, it.fresh_jacobian)? {
        return Ok(NewtonReport {
            iterations: 0,
            converged: true,
        });
    }
    let mut iterations = 0;
    let mut converged = false;
    while iterations < settings.max_iterations {
        newton_step(problem, col, lin, y, p, work, &mut it)?;
        iterations += 1;
        let cost_prev = it.cost;
        let Some(alpha) = damped_step(problem, col, lin, y, p, scale, settings, work, &mut it)?
        else {
            // every trial point produced non-finite values: stay where we are
            col.residual(problem, y, p)?;
            return Ok(NewtonReport {
                iterations,
                converged: false,
            });
        };
        let step_inf = alpha * inf_norm(&work.step);
        if settings.verbose >= 2 {
            log_iteration(iterations, alpha, step_inf, it.cost);
        }
        y.copy_from_slice(&work.y_new);
        p[..col.k].copy_from_slice(&work.p_new[..col.k]);

        if terminates(col, y, &p[..col.k], step_inf, scale, settings) {
            converged = true;
            break;
        }
        if it.njev >= settings.max_jacobians {
            break;
        }
        // Keep the factorisation (simplified Newton) only after a full step with good
        // contraction, ‖Δ̄_{k+1}‖ <= ‖Δ_k‖ / 4; a stale Jacobian otherwise costs more
        // iterations than a new factorisation.
        if alpha == 1.0 && it.cost <= CONTRACTION_SQ * cost_prev {
            std::mem::swap(&mut work.step, &mut work.step_new);
            it.recompute = false;
        } else {
            it.recompute = true;
            it.borrowed = None;
        }
    }
    Ok(NewtonReport {
        iterations,
        converged,
    })
}

/// The state of a Newton run between its steps.
struct Iteration<'f> {
    /// A factorisation from a nearby solution on this mesh, used until the contraction test
    /// asks for a fresh one.
    borrowed: Option<&'f Factorization>,
    /// Whether `col` holds the Jacobian of the current iterate (evaluated with its residual).
    fresh_jacobian: bool,
    /// Whether the next step needs a new correction (else `work.step` holds it).
    recompute: bool,
    /// `‖J⁻¹ F‖²` at the current iterate.
    cost: f64,
    /// Jacobians factored so far.
    njev: usize,
}

/// Evaluates the start (with its Jacobian if `with_jacobian`) and returns whether it already
/// passes the termination test.
///
/// A start that passes (a warm start at the parameters it was solved for, or values
/// interpolated onto a refined mesh that already satisfy the collocation equations this well)
/// needs no Newton step: no Jacobian, no factorisation. Not with a step criterion, which needs
/// a step to measure.
fn evaluate_start<P: Bvp>(
    problem: &P,
    col: &mut Collocation,
    y: &[f64],
    p: &[f64],
    scale: &[f64],
    settings: &NewtonSettings,
    with_jacobian: bool,
) -> Result<bool, BvpError> {
    if with_jacobian {
        col.residual_and_jacobians(problem, y, p, col.k)?;
    } else {
        col.residual(problem, y, p)?;
    }
    Ok(settings.step_tol.is_none()
        && residuals_small(col, scale, settings.tol)
        && bc_small(col, settings.bc_tol))
}

/// The Newton correction `J⁻¹ F` at the current iterate into `work.step`, and its cost: with
/// the borrowed factorisation while it gives a finite correction, else from a new Jacobian
/// (factored here). Nothing to do when the last step's correction is kept.
fn newton_step<'f, P: Bvp>(
    problem: &P,
    col: &mut Collocation,
    lin: &mut LinearSystem,
    y: &[f64],
    p: &[f64],
    work: &mut NewtonWork,
    it: &mut Iteration<'f>,
) -> Result<(), BvpError> {
    if let (true, Some(f)) = (it.recompute, it.borrowed) {
        work.step.copy_from_slice(&col.res);
        f.solve_with_scratch(&mut work.step, 1, false, &mut work.solve_scratch)?;
        if work.step.iter().any(|v| !v.is_finite()) {
            // not usable here: factor the Jacobian of this iterate instead
            it.borrowed = None;
        } else {
            it.cost = dot(&work.step, &work.step);
            it.recompute = false;
        }
    }
    if it.recompute {
        if !it.fresh_jacobian {
            col.jacobians(problem, y, p, col.k)?;
        }
        it.fresh_jacobian = false;
        lin.factor(col)?;
        it.njev += 1;
        work.step.copy_from_slice(&col.res);
        lin.solve(&mut work.step);
        check_step(&work.step, col.n, col.k, &col.x)?;
        it.cost = dot(&work.step, &work.step);
    }
    Ok(())
}

/// The damped step along `work.step`: trial points `work.y_new`, `work.p_new` at `α = 1, τ,
/// τ², …` (at most [`N_TRIAL`] halvings) until the merit `‖J⁻¹ F(Y_trial)‖²` falls below
/// `(1 - 2 α σ)` of the current one (a full step that passes the termination test is taken as
/// it is). Returns `α` with `col` holding the residuals at the trial point and `it.cost` its
/// merit (that of the last trial when none decreased enough), or `None` when every trial
/// point was non-finite.
#[allow(clippy::too_many_arguments)]
fn damped_step<P: Bvp>(
    problem: &P,
    col: &mut Collocation,
    lin: &mut LinearSystem,
    y: &[f64],
    p: &[f64],
    scale: &[f64],
    settings: &NewtonSettings,
    work: &mut NewtonWork,
    it: &mut Iteration<'_>,
) -> Result<Option<f64>, BvpError> {
    let (k, mn) = (col.k, col.m() * col.n);
    let mut alpha = 1.0;
    let mut accepted_finite = false;
    for trial in 0..=N_TRIAL {
        work.set_trial(y, p, k, mn, alpha);
        match col.residual(problem, &work.y_new, &work.p_new) {
            Ok(()) => {
                // A full step that lands on a point passing the termination test is taken
                // as it is: the merit value (one more solve) would only decide on damping.
                if trial == 0
                    && terminates(
                        col,
                        &work.y_new,
                        &work.p_new[..k],
                        inf_norm(&work.step),
                        scale,
                        settings,
                    )
                {
                    accepted_finite = true;
                    break;
                }
                let cost_new = merit(col, lin, work, it.borrowed)?;
                accepted_finite = cost_new.is_finite();
                if accepted_finite && cost_new < (1.0 - 2.0 * alpha * SIGMA) * it.cost {
                    it.cost = cost_new;
                    break;
                }
                if accepted_finite && trial == N_TRIAL {
                    it.cost = cost_new;
                }
            }
            Err(BvpError::NonFinite { .. }) => accepted_finite = false,
            Err(e) => return Err(e),
        }
        if trial < N_TRIAL {
            alpha *= TAU;
        }
    }
    Ok(accepted_finite.then_some(alpha))
}

/// The merit `‖J⁻¹ F‖²` of the residuals in `col` with the current factorisation (the
/// borrowed one, else `lin`'s); the correction is left in `work.step_new`.
fn merit(
    col: &Collocation,
    lin: &mut LinearSystem,
    work: &mut NewtonWork,
    borrowed: Option<&Factorization>,
) -> Result<f64, BvpError> {
    work.step_new.copy_from_slice(&col.res);
    match borrowed {
        Some(f) => f.solve_with_scratch(&mut work.step_new, 1, false, &mut work.solve_scratch)?,
        None => lin.solve(&mut work.step_new),
    }
    Ok(dot(&work.step_new, &work.step_new))
}

/// One line per Newton iteration on stderr (verbose level 2).
fn log_iteration(iterations: usize, alpha: f64, step_inf: f64, cost: f64) {
    // a failed write to stderr must not panic
    use std::io::Write as _;
    let _ = writeln!(
        std::io::stderr(),
        "    newton {iterations:>3}: damping {alpha:<6} |step|_inf {step_inf:.3e} |J^-1 F|^2 {cost:.3e}"
    );
}

/// The termination test at the iterate `y`, unknowns `pk`, reached by a correction of infinity
/// norm `step_inf` (`col` holds its residuals): collocation and boundary residuals small, and
/// the correction small if a step criterion is set.
fn terminates(
    col: &Collocation,
    y: &[f64],
    pk: &[f64],
    step_inf: f64,
    scale: &[f64],
    settings: &NewtonSettings,
) -> bool {
    let mut ok = residuals_small(col, scale, settings.tol) && bc_small(col, settings.bc_tol);
    if let Some(st) = settings.step_tol {
        let ymax = inf_norm(y).max(inf_norm(pk));
        ok = ok && step_inf <= st * (1.0 + ymax);
    }
    ok
}

/// Buffers of the Newton iteration, kept between runs.
#[derive(Default)]
pub(crate) struct NewtonWork {
    step: Vec<f64>,
    step_new: Vec<f64>,
    y_new: Vec<f64>,
    p_new: Vec<f64>,
    /// Scratch of solves with a borrowed factorisation (grown once).
    solve_scratch: Vec<f64>,
}

impl NewtonWork {
    /// Sizes the buffers for `size` unknowns, `mn` node values and `np` parameters (no
    /// allocation once they are large enough).
    fn resize(&mut self, size: usize, mn: usize, np: usize) {
        self.step.resize(size, 0.0);
        self.step_new.resize(size, 0.0);
        self.y_new.resize(mn, 0.0);
        self.p_new.resize(np, 0.0);
    }

    /// The trial point `y − α Δy`, `p[..k] − α Δp` (the rest of `p` as it is) into `y_new`,
    /// `p_new`, with `Δ` = `step` (node values in its first `mn` entries).
    fn set_trial(&mut self, y: &[f64], p: &[f64], k: usize, mn: usize, alpha: f64) {
        for (i, v) in self.y_new.iter_mut().enumerate() {
            *v = y[i] - alpha * self.step[i];
        }
        self.p_new.copy_from_slice(p);
        for ((pn, pv), st) in self.p_new[..k]
            .iter_mut()
            .zip(&p[..k])
            .zip(&self.step[mn..])
        {
            *pn = pv - alpha * st;
        }
    }
}

/// scipy's termination test: `|r_i| < (2/3) h_i · 0.05 tol · (s_c + |f_mid|)`, i.e. the midpoint
/// residual `1.5 r_i / h_i` is 1.3 orders below `tol`.
fn residuals_small(col: &Collocation, scale: &[f64], tol: f64) -> bool {
    let n = col.n;
    for i in 0..col.m() - 1 {
        if col.is_interface(i) {
            // interface conditions are measured with the boundary conditions (`max_bc`)
            continue;
        }
        let tol_r = 2.0 / 3.0 * col.h[i] * 5e-2 * tol;
        let res_i = &col.res[i * n..(i + 1) * n];
        let fm_i = &col.f_mid[i * n..(i + 1) * n];
        for ((r, fm), sc) in res_i.iter().zip(fm_i).zip(scale) {
            let ok = r.abs() < tol_r * (sc + fm.abs());
            if !ok {
                return false;
            }
        }
    }
    true
}

pub(crate) fn bc_small(col: &Collocation, bc_tol: f64) -> bool {
    max_bc(col) < bc_tol
}

/// The largest boundary and interface residual.
pub(crate) fn max_bc(col: &Collocation) -> f64 {
    let (n, m) = (col.n, col.m());
    let off = (m - 1) * n;
    let ends = col.res[off..].iter().fold(0.0, |a: f64, v| a.max(v.abs()));
    (0..m - 1)
        .filter(|&i| col.is_interface(i))
        .flat_map(|i| &col.res[i * n..(i + 1) * n])
        .fold(ends, |a, v| a.max(v.abs()))
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn inf_norm(a: &[f64]) -> f64 {
    a.iter().fold(0.0, |acc: f64, v| acc.max(v.abs()))
}

/// A non-finite Newton step means an (exactly) singular Newton matrix. Report where the step is
/// undetermined: which state components over which part of the mesh, and which unknowns.
fn check_step(step: &[f64], n: usize, k: usize, x: &[f64]) -> Result<(), BvpError> {
    if step.iter().all(|v| v.is_finite()) {
        return Ok(());
    }
    let m = x.len();
    let mut parts = Vec::new();
    for c in 0..n {
        let bad: Vec<usize> = (0..m).filter(|&i| !step[i * n + c].is_finite()).collect();
        if let (Some(&first), Some(&last)) = (bad.first(), bad.last()) {
            parts.push(format!(
                "state component {c} at {} of {m} nodes (x in [{:e}, {:e}])",
                bad.len(),
                x[first],
                x[last]
            ));
        }
    }
    for j in 0..k {
        if !step[m * n + j].is_finite() {
            parts.push(format!("unknown parameter {j}"));
        }
    }
    Err(BvpError::SingularJacobian {
        detail: format!(
            "the Newton step is undetermined in {}; check that the boundary conditions fix every \
             state component and unknown parameter",
            parts.join(", ")
        ),
    })
}

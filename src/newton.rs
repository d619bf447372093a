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
    let (n, k, m) = (col.n, col.k, col.m());
    let size = m * n + k;
    // a factorisation from a nearby solution on this mesh (simplified Newton from its Jacobian)
    // is used until the contraction test asks for a fresh one
    let mut borrowed = initial.filter(|f| f.size() == size);
    work.step.resize(size, 0.0);
    work.step_new.resize(size, 0.0);
    work.y_new.resize(m * n, 0.0);
    work.p_new.resize(p.len(), 0.0);

    // the Jacobian of the start is only evaluated with it when it will be factored
    let mut fresh_jacobian = start == Start::WithJacobian && borrowed.is_none();
    if fresh_jacobian {
        col.residual_and_jacobians(problem, y, p, k)?;
    } else {
        col.residual(problem, y, p)?;
    }
    // A start that already passes the termination test (a warm start at the parameters it was
    // solved for, or values interpolated onto a refined mesh that already satisfy the
    // collocation equations this well) needs no Newton step: no Jacobian, no factorisation. Not
    // with a step criterion, which needs a step to measure.
    if settings.step_tol.is_none()
        && residuals_small(col, scale, settings.tol)
        && bc_small(col, settings.bc_tol)
    {
        return Ok(NewtonReport {
            iterations: 0,
            converged: true,
        });
    }
    let mut recompute = true;
    let mut cost = 0.0;
    let mut njev = 0;
    let mut iterations = 0;
    let mut converged = false;
    while iterations < settings.max_iterations {
        if let (true, Some(f)) = (recompute, borrowed) {
            work.step.copy_from_slice(&col.res);
            f.solve_with_scratch(&mut work.step, 1, false, &mut work.solve_scratch)?;
            if work.step.iter().any(|v| !v.is_finite()) {
                // not usable here: factor the Jacobian of this iterate instead
                borrowed = None;
            } else {
                cost = dot(&work.step, &work.step);
                recompute = false;
            }
        }
        if recompute {
            if !fresh_jacobian {
                col.jacobians(problem, y, p, k)?;
            }
            fresh_jacobian = false;
            lin.factor(col)?;
            njev += 1;
            work.step.copy_from_slice(&col.res);
            lin.solve(&mut work.step);
            check_step(&work.step, n, k, &col.x)?;
            cost = dot(&work.step, &work.step);
        }
        iterations += 1;
        let cost_prev = cost;
        let mut alpha = 1.0;
        let mut accepted_finite = false;
        for trial in 0..=N_TRIAL {
            for (i, v) in work.y_new.iter_mut().enumerate() {
                *v = y[i] - alpha * work.step[i];
            }
            work.p_new.copy_from_slice(p);
            for ((pn, pv), st) in work.p_new[..k]
                .iter_mut()
                .zip(&p[..k])
                .zip(&work.step[m * n..])
            {
                *pn = pv - alpha * st;
            }
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
                    work.step_new.copy_from_slice(&col.res);
                    match borrowed {
                        Some(f) => f.solve_with_scratch(
                            &mut work.step_new,
                            1,
                            false,
                            &mut work.solve_scratch,
                        )?,
                        None => lin.solve(&mut work.step_new),
                    }
                    let cost_new = dot(&work.step_new, &work.step_new);
                    accepted_finite = cost_new.is_finite();
                    if accepted_finite && cost_new < (1.0 - 2.0 * alpha * SIGMA) * cost {
                        cost = cost_new;
                        break;
                    }
                    if accepted_finite && trial == N_TRIAL {
                        cost = cost_new;
                    }
                }
                Err(BvpError::NonFinite { .. }) => accepted_finite = false,
                Err(e) => return Err(e),
            }
            if trial < N_TRIAL {
                alpha *= TAU;
            }
        }
        if !accepted_finite {
            // every trial point produced non-finite values: stay where we are
            col.residual(problem, y, p)?;
            return Ok(NewtonReport {
                iterations,
                converged: false,
            });
        }
        let step_inf = alpha * inf_norm(&work.step);
        if settings.verbose >= 2 {
            // a failed write to stderr must not panic
            use std::io::Write as _;
            let _ = writeln!(
                std::io::stderr(),
                "    newton {iterations:>3}: damping {alpha:<6} |step|_inf {step_inf:.3e} |J^-1 F|^2 {cost:.3e}"
            );
        }
        y.copy_from_slice(&work.y_new);
        p[..k].copy_from_slice(&work.p_new[..k]);

        if terminates(col, y, &p[..k], step_inf, scale, settings) {
            converged = true;
            break;
        }
        if njev >= settings.max_jacobians {
            break;
        }
        // Keep the factorisation (simplified Newton) only after a full step with good
        // contraction, ‖Δ̄_{k+1}‖ <= ‖Δ_k‖ / 4; a stale Jacobian otherwise costs more
        // iterations than a new factorisation.
        if alpha == 1.0 && cost <= CONTRACTION_SQ * cost_prev {
            std::mem::swap(&mut work.step, &mut work.step_new);
            recompute = false;
        } else {
            recompute = true;
            borrowed = None;
        }
    }
    Ok(NewtonReport {
        iterations,
        converged,
    })
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

/// scipy's termination test: `|r_i| < (2/3) h_i · 0.05 tol · (s_c + |f_mid|)`, i.e. the midpoint
/// residual `1.5 r_i / h_i` is 1.3 orders below `tol`.
fn residuals_small(col: &Collocation, scale: &[f64], tol: f64) -> bool {
    let n = col.n;
    for i in 0..col.m() - 1 {
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

pub(crate) fn max_bc(col: &Collocation) -> f64 {
    let off = (col.m() - 1) * col.n;
    col.res[off..].iter().fold(0.0, |a: f64, v| a.max(v.abs()))
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

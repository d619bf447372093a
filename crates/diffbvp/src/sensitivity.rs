//! Parameter sensitivities of a converged discrete solution (implicit function theorem).
//!
//! At a solution `S(Y, p) = 0` of the collocation system (`Y` = states at the nodes and the
//! unknown parameters, `p` = the fixed model parameters):
//!
//! * forward: `D_p Y = -(∂_Y S)⁻¹ ∂_p S` — one solve with `q` right-hand sides;
//! * adjoint: for `G(Y, p)`, `dG/dp = ∂_p G - λᵀ ∂_p S` with `(∂_Y S)ᵀ λ = (∂_Y G)ᵀ` — one
//!   transposed solve.
//!
//! `∂_p S`, `∂_Y S` and `∂G` come from dual numbers. The Jacobians at the solution and the
//! factorisation of `∂_Y S` are the solution's cached linearisation: computed by the solve
//! ([`SolveOptions::factor_at_solution`](crate::SolveOptions::factor_at_solution)) or by the
//! first derivative request, and shared by every later one (forward and adjoint alike).
//!
//! Values between nodes go through the C1 interpolant, whose node slopes `f(x_i, y_i, p)` depend
//! on `p` too; the derivatives here are those of the interpolated discrete solution, consistent
//! with it to round-off.
//!
//! Integral functionals `∫ g(x, y, p) dx + φ(y(a), y(b), p)` have their own entry points
//! ([`IntegralFunction`], [`integral_value`], [`integral_adjoint`], [`integral_forward`]).

use crate::dual_jacobian::{DualFn, DualJacobian};
use crate::error::BvpError;
use crate::linearization::Linearization;
use crate::problem::Bvp;
use crate::solution::{hermite_weights, interval_of, Solution};
use num_dual::DualNum;

mod integral;
pub use integral::{integral_adjoint, integral_forward, integral_value, IntegralFunction};

/// A scalar function `g(x, y, p)` of a point, the state there and all parameters
/// `p = (unknowns, model parameters)`, written generically over dual numbers. `index` numbers
/// the points of a functional or residual vector.
pub trait PointFunction {
    /// Value of the function at point number `index`, located at `x`.
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, index: usize, x: f64, y: &[D], p: &[D])
        -> D;
}

struct PointFn<'a, G> {
    g: &'a G,
    index: usize,
    x: f64,
    n: usize,
}

impl<G: PointFunction> DualFn for PointFn<'_, G> {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, input: &[D], out: &mut [D]) {
        let (y, p) = input.split_at(self.n);
        out[0] = self.g.eval(self.index, self.x, y, p);
    }
}

/// The solution's linearisation (cached in it, computed now if neither the solve nor an earlier
/// derivative request did), after checking that `sol` belongs to `problem`.
fn linearization<'s, P: Bvp>(
    problem: &P,
    sol: &'s Solution,
) -> Result<&'s Linearization, BvpError> {
    linearization_covering(problem, sol, 0..sol.params.len())
}

/// [`linearization`] seeded at least in the model parameters `model`.
fn linearization_covering<'s, P: Bvp>(
    problem: &P,
    sol: &'s Solution,
    model: impl IntoIterator<Item = usize>,
) -> Result<&'s Linearization, BvpError> {
    check_belongs(problem, sol)?;
    sol.linearization_covering(problem, model)
}

/// Errors unless `sol` has the dimensions of `problem`'s solutions.
fn check_belongs<P: Bvp>(problem: &P, sol: &Solution) -> Result<(), BvpError> {
    let (n, k, q) = (problem.dim(), problem.num_unknowns(), problem.num_params());
    if sol.n != n || sol.unknowns.len() != k || sol.params.len() != q {
        return Err(BvpError::InvalidInput(
            "the solution does not belong to this problem (dimensions differ)".into(),
        ));
    }
    Ok(())
}

/// Forward sensitivities `dy/dp` of a solution with respect to the fixed model parameters (all
/// of them, or the subset of [`Sensitivities::compute_for`]: column `j` then belongs to model
/// parameter [`columns`](Self::columns)`[j]`).
#[derive(Debug, Clone)]
pub struct Sensitivities {
    n: usize,
    q: usize,
    x: Vec<f64>,
    /// The model parameter of each column (`0..q` for all of them).
    columns: Vec<usize>,
    /// `∂y_{i,c}/∂p_j` at the nodes, index `(i n + c) q + j`.
    pub dy: Vec<f64>,
    /// Derivative of the node slopes `f(x_i, y_i, p)` (total), same layout.
    pub dyp: Vec<f64>,
    /// `∂(unknown l)/∂p_j`, index `l q + j`.
    pub d_unknowns: Vec<f64>,
}

impl Sensitivities {
    /// Computes `D_p Y` at `sol` with one solve of `q` right-hand sides, reusing the
    /// linearisation cached in `sol` (Jacobians and factorisation; computed once and cached if
    /// `sol` has none yet: one dual pass and one factorisation, no other evaluation).
    ///
    /// The solve takes one step of iterative refinement (the residual of the linear system
    /// formed from the Jacobian blocks, the correction solved with the same factors): the
    /// derivatives are then componentwise backward stable, and the structured and the sparse
    /// elimination agree to round-off even on badly scaled systems (fiber model: 1e-15; 3.5e-11
    /// without the step). [`Sensitivities::compute_unrefined`] skips the step.
    pub fn compute<P: Bvp>(problem: &P, sol: &Solution) -> Result<Self, BvpError> {
        Self::compute_with(problem, sol, true, None)
    }

    /// The sensitivities with respect to the model parameters `columns` only (indices into the
    /// model parameters, strictly increasing; column `j` of the result is `columns[j]`), one
    /// solve with `columns.len()` right-hand sides, without the refinement step (as
    /// [`compute_unrefined`](Self::compute_unrefined)). What a fit that frees a few of a
    /// model's parameters needs; with [`SolveOptions::linearization_params`](crate::SolveOptions::linearization_params)
    /// covering `columns`, the cached linearisation serves (otherwise the full one is computed
    /// once).
    pub fn compute_for<P: Bvp>(
        problem: &P,
        sol: &Solution,
        columns: &[usize],
    ) -> Result<Self, BvpError> {
        let q = problem.num_params();
        if !columns.windows(2).all(|w| w[0] < w[1]) || columns.last().is_some_and(|&j| j >= q) {
            return Err(BvpError::InvalidInput(format!(
                "Sensitivities::compute_for: columns must be strictly increasing indices of the \
                 {q} model parameters, got {columns:?}"
            )));
        }
        Self::compute_with(problem, sol, false, Some(columns))
    }

    /// [`Sensitivities::compute`] without the refinement step: one solve with the cached factors,
    /// accurate to about the system's condition number times `ε` and much cheaper than with the
    /// refinement step. What a Gauss–Newton Jacobian needs
    /// ([`BvpResiduals`](crate::least_squares::BvpResiduals) uses it).
    pub fn compute_unrefined<P: Bvp>(problem: &P, sol: &Solution) -> Result<Self, BvpError> {
        Self::compute_with(problem, sol, false, None)
    }

    fn compute_with<P: Bvp>(
        problem: &P,
        sol: &Solution,
        refine: bool,
        columns: Option<&[usize]>,
    ) -> Result<Self, BvpError> {
        let columns: Vec<usize> = match columns {
            Some(c) => c.to_vec(),
            None => (0..sol.params.len()).collect(),
        };
        let lz = linearization_covering(problem, sol, columns.iter().copied())?;
        let (n, k, m) = (lz.col.n, lz.col.k, lz.col.m());
        let q = columns.len();
        let size = m * n + k;
        let mut rhs = vec![0.0; size * q];
        let mut jn_cols = Vec::with_capacity(q);
        for (j, &c) in columns.iter().enumerate() {
            jn_cols.push(lz.model_column(c, &mut rhs[j * size..(j + 1) * size])?);
        }
        for v in rhs.iter_mut() {
            *v = -*v;
        }
        if refine {
            lz.solve_refined(&mut rhs, q, false)?;
        } else {
            lz.factorization.solve_in_place(&mut rhs, q)?;
        }
        if let Some(pos) = rhs.iter().position(|v| !v.is_finite()) {
            return Err(BvpError::SingularJacobian {
                detail: format!("sensitivity solve gave a non-finite value (entry {pos})"),
            });
        }
        let mut dy = vec![0.0; m * n * q];
        let mut d_unknowns = vec![0.0; k * q];
        for j in 0..q {
            for r in 0..m * n {
                dy[r * q + j] = rhs[j * size + r];
            }
            for l in 0..k {
                d_unknowns[l * q + j] = rhs[j * size + m * n + l];
            }
        }
        let mut dyp = vec![0.0; m * n * q];
        for i in 0..m {
            for c in 0..n {
                for (j, &jc) in jn_cols.iter().enumerate() {
                    let mut v = lz.jn(i, c, jc);
                    for l in 0..n {
                        v += lz.jn(i, c, l) * dy[(i * n + l) * q + j];
                    }
                    for l in 0..k {
                        v += lz.jn(i, c, n + l) * d_unknowns[l * q + j];
                    }
                    dyp[(i * n + c) * q + j] = v;
                }
            }
        }
        Ok(Sensitivities {
            n,
            q,
            x: sol.x.clone(),
            columns,
            dy,
            dyp,
            d_unknowns,
        })
    }

    /// Number of columns: the model parameters differentiated in (all of them unless computed
    /// by [`compute_for`](Self::compute_for)).
    pub fn num_params(&self) -> usize {
        self.q
    }

    /// The model parameter (index into the model parameters) of each column.
    pub fn columns(&self) -> &[usize] {
        &self.columns
    }

    /// `∂y_c(x)/∂p_j` of the interpolated solution at `x`, written into `dy` (`n × q`, row-major),
    /// and of its derivative into `dyp`. Like [`Solution::eval_into`]: outside the mesh the end
    /// interval's cubic is extrapolated, and a non-finite `x` gives NaN everywhere.
    pub fn at_into(&self, x: f64, dy: &mut [f64], dyp: &mut [f64]) {
        let (n, q) = (self.n, self.q);
        if !x.is_finite() {
            dy[..n * q].fill(f64::NAN);
            dyp[..n * q].fill(f64::NAN);
            return;
        }
        let i = interval_of(&self.x, x);
        let h = self.x[i + 1] - self.x[i];
        let (v, d) = hermite_weights((x - self.x[i]) / h, h);
        for c in 0..n {
            for j in 0..q {
                let a = (i * n + c) * q + j;
                let b = ((i + 1) * n + c) * q + j;
                dy[c * q + j] =
                    v[0] * self.dy[a] + v[1] * self.dyp[a] + v[2] * self.dy[b] + v[3] * self.dyp[b];
                dyp[c * q + j] =
                    d[0] * self.dy[a] + d[1] * self.dyp[a] + d[2] * self.dy[b] + d[3] * self.dyp[b];
            }
        }
    }

    /// `∂y(x)/∂p` at `x`, `n × q` row-major.
    pub fn at(&self, x: f64) -> Vec<f64> {
        let mut dy = vec![0.0; self.n * self.q];
        let mut dyp = vec![0.0; self.n * self.q];
        self.at_into(x, &mut dy, &mut dyp);
        dy
    }
}

/// Errors on the first non-finite evaluation point.
fn check_points(xs: &[f64]) -> Result<(), BvpError> {
    match xs.iter().position(|x| !x.is_finite()) {
        Some(j) => Err(BvpError::InvalidInput(format!(
            "evaluation point {j} is not finite (x = {})",
            xs[j]
        ))),
        None => Ok(()),
    }
}

/// Values and exact Jacobian `dr/dp` (`len × s`, row-major, `s = sens.num_params()`: column `j`
/// is model parameter `sens.columns()[j]`, all `q` of them for [`Sensitivities::compute`]) of a
/// residual vector `r_j = g(j, x_j, y(x_j), p)` at the points `xs`, from forward sensitivities
/// (one solve with `s` right-hand sides). This is what a Gauss–Newton fit calls.
pub fn residual_jacobian<P: Bvp, G: PointFunction>(
    problem: &P,
    sol: &Solution,
    sens: &Sensitivities,
    xs: &[f64],
    g: &G,
) -> Result<(Vec<f64>, Vec<f64>), BvpError> {
    let (n, k, q) = (sol.n, sol.unknowns.len(), sol.params.len());
    if problem.dim() != n || problem.num_unknowns() != k || problem.num_params() != q {
        return Err(BvpError::InvalidInput(
            "the solution does not belong to this problem (dimensions differ)".into(),
        ));
    }
    if sens.columns.last().is_some_and(|&j| j >= q) || sens.x != sol.x {
        return Err(BvpError::InvalidInput(
            "the sensitivities were computed for a different solution".into(),
        ));
    }
    check_points(xs)?;
    let p = sol.full_params();
    let mut engine = DualJacobian::default();
    let mut input = vec![0.0; n + k + q];
    let mut grad = vec![0.0; n + k + q];
    let mut y = vec![0.0; n];
    let mut yp = vec![0.0; n];
    let s = sens.q;
    let mut dy = vec![0.0; n * s];
    let mut dyp = vec![0.0; n * s];
    let mut values = Vec::with_capacity(xs.len());
    let mut jac = vec![0.0; xs.len() * s];
    for (idx, &x) in xs.iter().enumerate() {
        sol.eval_into(x, &mut y, &mut yp);
        sens.at_into(x, &mut dy, &mut dyp);
        input[..n].copy_from_slice(&y);
        input[n..].copy_from_slice(&p);
        let f = PointFn {
            g,
            index: idx,
            x,
            n,
        };
        let mut out = [0.0];
        engine.jacobian(&f, &input, n + k + q, &mut out, &mut grad);
        if !out[0].is_finite() || grad.iter().any(|v| !v.is_finite()) {
            return Err(BvpError::NonFinite {
                what: "point function",
                component: idx,
                x,
            });
        }
        values.push(out[0]);
        for (j, &pj) in sens.columns.iter().enumerate() {
            let mut v = grad[n + k + pj];
            for c in 0..n {
                v += grad[c] * dy[c * s + j];
            }
            for l in 0..k {
                v += grad[n + l] * sens.d_unknowns[l * s + j];
            }
            jac[idx * s + j] = v;
        }
    }
    Ok((values, jac))
}

/// Adds the weight `w` times the gradient `grad` (in the state and the parameters) of a point
/// inside interval `i`, whose state is the Hermite interpolant with weights `v` (`y = v0 y_i +
/// v1 f_i + v2 y_{i+1} + v3 f_{i+1}`, `f_j = f(x_j, y_j, p)`), to the adjoint right-hand side
/// `b` (the two nodes' states, through their slopes the unknowns) and to `dg_dp` (the model
/// parameters, through the slopes). Shared by point and integral objectives.
fn add_hermite_gradient(
    lz: &Linearization,
    i: usize,
    v: &[f64; 4],
    w: f64,
    grad: &[f64],
    b: &mut [f64],
    dg_dp: &mut [f64],
) {
    let (n, k, m) = (lz.col.n, lz.col.k, lz.col.m());
    let np = k + lz.col.q;
    for (node, (vy, vf)) in [(i, (v[0], v[1])), (i + 1, (v[2], v[3]))] {
        for l in 0..n {
            let mut s = vy * grad[l];
            for c in 0..n {
                s += vf * grad[c] * lz.jn(node, c, l);
            }
            b[node * n + l] += w * s;
        }
        for l in 0..np {
            let mut s = 0.0;
            for c in 0..n {
                s += vf * grad[c] * lz.jn(node, c, n + l);
            }
            if l < k {
                b[m * n + l] += w * s;
            } else {
                dg_dp[l - k] += w * s;
            }
        }
    }
}

/// Value and gradient `dG/dp` of `G = Σ_j w_j g(j, x_j, y(x_j), p)` by the adjoint method: one
/// transposed solve with the solution's factorisation, independent of the number of parameters.
pub fn adjoint_gradient<P: Bvp, G: PointFunction>(
    problem: &P,
    sol: &Solution,
    xs: &[f64],
    weights: &[f64],
    g: &G,
) -> Result<(f64, Vec<f64>), BvpError> {
    if xs.len() != weights.len() {
        return Err(BvpError::InvalidInput(format!(
            "{} points but {} weights",
            xs.len(),
            weights.len()
        )));
    }
    check_points(xs)?;
    if let Some(j) = weights.iter().position(|w| !w.is_finite()) {
        return Err(BvpError::InvalidInput(format!(
            "weight {j} is not finite ({})",
            weights[j]
        )));
    }
    let lz = linearization(problem, sol)?;
    let p = sol.full_params();
    let (n, k, q, m) = (lz.col.n, lz.col.k, lz.col.q, lz.col.m());
    let size = m * n + k;
    let np = k + q;
    let mut engine = DualJacobian::default();
    let mut input = vec![0.0; n + np];
    let mut grad = vec![0.0; n + np];
    let mut y = vec![0.0; n];
    let mut yp = vec![0.0; n];
    let mut b = vec![0.0; size];
    let mut dg_dp = vec![0.0; q];
    let mut value = 0.0;
    for (idx, (&x, &w)) in xs.iter().zip(weights).enumerate() {
        let i = interval_of(&sol.x, x);
        let h = sol.x[i + 1] - sol.x[i];
        let (v, _) = hermite_weights((x - sol.x[i]) / h, h);
        sol.eval_into(x, &mut y, &mut yp);
        input[..n].copy_from_slice(&y);
        input[n..].copy_from_slice(&p);
        let f = PointFn {
            g,
            index: idx,
            x,
            n,
        };
        let mut out = [0.0];
        engine.jacobian(&f, &input, n + np, &mut out, &mut grad);
        if !out[0].is_finite() || grad.iter().any(|v| !v.is_finite()) {
            return Err(BvpError::NonFinite {
                what: "point function",
                component: idx,
                x,
            });
        }
        value += w * out[0];
        add_hermite_gradient(lz, i, &v, w, &grad, &mut b, &mut dg_dp);
        for l in 0..k {
            b[m * n + l] += w * grad[n + l];
        }
        for j in 0..q {
            dg_dp[j] += w * grad[n + k + j];
        }
    }
    lz.solve_refined(&mut b, 1, true)?;
    let mut col = vec![0.0; size];
    for (j, d) in dg_dp.iter_mut().enumerate() {
        lz.col.param_column(k + j, &mut col);
        let dot: f64 = b.iter().zip(&col).map(|(a, c)| a * c).sum();
        *d -= dot;
    }
    if let Some(pos) = dg_dp.iter().position(|v| !v.is_finite()) {
        return Err(BvpError::SingularJacobian {
            detail: format!("adjoint solve gave a non-finite gradient (parameter {pos})"),
        });
    }
    Ok((value, dg_dp))
}

/// Tangent (first-order) predictor: the warm start for a solve at the model parameters
/// `params` from the solution `sol` at `sol.params`, `Y + D_p Y · (params − sol.params)` on the
/// mesh of `sol`, unknown parameters included. `D_p Y · Δp` costs one linear solve with the
/// factorisation of the solution's linearisation (cached in `sol`; computed once and cached if
/// it is not there yet). Newton started from it converges in fewer iterations than from `sol`
/// itself when the step is small, because it is first-order accurate in the step; far from
/// `sol` it is no better than `sol` and may be worse, so a caller
/// should keep `Guess::from(sol)` as the fallback.
///
/// Errors if `params` does not have `num_params()` finite values or `sol` does not belong to
/// `problem`.
pub fn tangent_guess<P: Bvp>(
    problem: &P,
    sol: &Solution,
    params: &[f64],
) -> Result<crate::solve::Guess, BvpError> {
    let q = problem.num_params();
    if params.len() != q {
        return Err(BvpError::InvalidInput(format!(
            "tangent_guess: the problem has {q} model parameters but {} values were given",
            params.len()
        )));
    }
    if let Some(j) = params.iter().position(|v| !v.is_finite()) {
        return Err(BvpError::InvalidInput(format!(
            "tangent_guess: model parameter {j} is not finite"
        )));
    }
    check_belongs(problem, sol)?;
    let changed: Vec<usize> = (0..q).filter(|&j| params[j] != sol.params[j]).collect();
    // the cached linearisation, whatever it is seeded in (its factorisation and state
    // Jacobians serve any parameter), or one seeded in the changed parameters
    let lz = match sol.linearization.get() {
        Some(l) => l,
        None => sol.linearization_covering(problem, changed.iter().copied())?,
    };
    let (n, k, m) = (lz.col.n, lz.col.k, lz.col.m());
    // the changed parameters it was not seeded in: their derivatives of f and g alone
    let missing: Vec<usize> = changed
        .iter()
        .copied()
        .filter(|&j| lz.col.param_slot(k + j).is_none())
        .collect();
    let extra = match missing.is_empty() {
        true => None,
        false => Some(Linearization::extra_columns(
            problem,
            (&sol.x, &sol.y, &sol.yp),
            &sol.full_params(),
            &missing,
        )?),
    };
    let size = m * n + k;
    let mut rhs = vec![0.0; size];
    let mut column = vec![0.0; size];
    for &j in &changed {
        let dp = params[j] - sol.params[j];
        match (lz.col.param_slot(k + j), &extra) {
            (Some(slot), _) => lz.col.param_column(slot, &mut column),
            (None, Some(e)) => {
                let s = missing.partition_point(|&i| i < j);
                lz.col.param_column_with(e, s, &mut column);
            }
            (None, None) => {
                lz.model_column(j, &mut column)?;
            }
        }
        for (r, c) in rhs.iter_mut().zip(&column) {
            *r -= dp * c;
        }
    }
    lz.factorization.solve_in_place(&mut rhs, 1)?;
    if rhs.iter().any(|v| !v.is_finite()) {
        return Err(BvpError::SingularJacobian {
            detail: "the tangent predictor's solve gave a non-finite value".into(),
        });
    }
    let y = sol
        .y
        .iter()
        .zip(&rhs[..m * n])
        .map(|(y, d)| y + d)
        .collect();
    let unknowns = sol
        .unknowns
        .iter()
        .zip(&rhs[m * n..])
        .map(|(u, d)| u + d)
        .collect();
    Ok(crate::solve::Guess {
        x: sol.x.clone(),
        y,
        unknowns,
    })
}

//! Integral functionals `G(p) = ∫_a^b g(x, y(x), p) dx + φ(y(a), y(b), p)` of a solution, their
//! value and their exact gradient `dG/dp` by the adjoint or from forward sensitivities.
//!
//! The quadrature is Simpson's rule on every mesh interval with the interpolant's midpoint
//! value: `∫_{x_i}^{x_{i+1}} g dx ≈ h/6 (g_i + 4 g_{i+1/2} + g_{i+1})`. The collocation
//! solution is a C1 piecewise cubic accurate to `O(h⁴)`; Simpson's rule is exact for cubics, so
//! a `g` linear in `y` is integrated exactly on the interpolant, and any smooth `g` to `O(h⁴)`:
//! the quadrature keeps the collocation's order and costs one `g` evaluation per node and one
//! per interval. The midpoint value is the Hermite interpolant's,
//! `y_{i+1/2} = (y_i + y_{i+1})/2 + h/8 (f_i − f_{i+1})`, the collocation's own midpoint state.
//!
//! Both gradients differentiate this discrete `G` (the quadrature of the interpolated discrete
//! solution), so they agree with each other to round-off and with the exact `dG/dp` to the
//! same `O(h⁴)` as the value.
//!
//! ```
//! use diffbvp::mesh::linspace;
//! use diffbvp::sensitivity::{integral_adjoint, integral_forward, IntegralFunction, Sensitivities};
//! use diffbvp::{solve, Bvp, DualNum, Guess, SolveOptions};
//!
//! /// y'' = k² y, y(0) = 1, y(1) = 0 (one model parameter k): y = sinh(k(1−x))/sinh(k).
//! struct Decay;
//! impl Bvp for Decay {
//!     fn dim(&self) -> usize { 2 }
//!     fn num_params(&self) -> usize { 1 }
//!     fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
//!         f[0] = y[1];
//!         f[1] = p[0] * p[0] * y[0];
//!     }
//!     fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
//!         r[0] = ya[0] - 1.0;
//!         r[1] = yb[0];
//!     }
//! }
//!
//! /// G = ∫₀¹ y dx = (cosh k − 1)/(k sinh k), written once for f64 and dual numbers.
//! struct Mean;
//! impl IntegralFunction for Mean {
//!     fn integrand<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D]) -> D {
//!         y[0]
//!     }
//! }
//!
//! let k = 2.0f64;
//! let sol = solve(&Decay, &[k], &Guess::constant(linspace(0.0, 1.0, 11), &[0.5, -1.0]),
//!                 &SolveOptions::with_tol(1e-9))?;
//! let (g, grad) = integral_adjoint(&Decay, &sol, &Mean)?; // one transposed solve
//! let sens = Sensitivities::compute(&Decay, &sol)?;
//! let (_, forward) = integral_forward(&Decay, &sol, &sens, &Mean)?;
//! let exact = (k.cosh() - 1.0) / (k * k.sinh());
//! // d/dk of the closed form
//! let d_exact = (k * k.sinh() * k.sinh() - (k.cosh() - 1.0) * (k.sinh() + k * k.cosh()))
//!     / (k * k.sinh()).powi(2);
//! assert!((g - exact).abs() < 1e-8);
//! assert!((grad[0] - d_exact).abs() < 1e-7);
//! assert!((grad[0] - forward[0]).abs() < 1e-12);
//! # Ok::<(), diffbvp::BvpError>(())
//! ```

use super::{add_hermite_gradient, check_belongs, linearization, Sensitivities};
use crate::dual_jacobian::{DualFn, DualJacobian};
use crate::error::BvpError;
use crate::problem::Bvp;
use crate::solution::{hermite_weights, Solution};
use num_dual::DualNum;

/// An integral functional `G = ∫_a^b g(x, y, p) dx + φ(y(a), y(b), p)` of a solution, with
/// `p = (unknowns, model parameters)` as in [`Bvp`]. Both parts are written once, generically
/// over dual numbers; `G`'s units are those of `g` times those of `x`, plus those of `φ`.
pub trait IntegralFunction {
    /// The integrand `g(x, y, p)` at `x`.
    fn integrand<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D]) -> D;

    /// The boundary term `φ(y(a), y(b), p)` (default: none, zero).
    fn endpoint<D: DualNum<Primitive = f64> + Copy>(&self, _ya: &[D], _yb: &[D], _p: &[D]) -> D {
        D::zero()
    }
}

/// `g` as a function of `(y, p)` at a fixed `x`, for the dual-number engine.
struct IntegrandFn<'a, G> {
    g: &'a G,
    x: f64,
    n: usize,
}

impl<G: IntegralFunction> DualFn for IntegrandFn<'_, G> {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, input: &[D], out: &mut [D]) {
        let (y, p) = input.split_at(self.n);
        out[0] = self.g.integrand(self.x, y, p);
    }
}

/// `φ` as a function of `(y(a), y(b), p)`.
struct EndpointFn<'a, G> {
    g: &'a G,
    n: usize,
}

impl<G: IntegralFunction> DualFn for EndpointFn<'_, G> {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, input: &[D], out: &mut [D]) {
        let (ya, rest) = input.split_at(self.n);
        let (yb, p) = rest.split_at(self.n);
        out[0] = self.g.endpoint(ya, yb, p);
    }
}

/// One quadrature point: where, its weight, and (for a midpoint) its interval.
#[derive(Clone, Copy)]
struct QuadPoint {
    x: f64,
    w: f64,
    /// `Some(i)` for the midpoint of interval `i`, `None` for node `node`.
    interval: Option<usize>,
    node: usize,
}

/// Simpson's points of the mesh `x`: every node with weight `(h_{i-1} + h_i)/6`, every interval
/// midpoint with `4 h_i / 6`.
fn simpson_points(x: &[f64]) -> impl Iterator<Item = QuadPoint> + '_ {
    let m = x.len();
    let nodes = (0..m).map(move |i| {
        let left = if i > 0 { x[i] - x[i - 1] } else { 0.0 };
        let right = if i + 1 < m { x[i + 1] - x[i] } else { 0.0 };
        QuadPoint {
            x: x[i],
            w: (left + right) / 6.0,
            interval: None,
            node: i,
        }
    });
    let mids = (0..m - 1).map(move |i| {
        let h = x[i + 1] - x[i];
        QuadPoint {
            x: x[i] + 0.5 * h,
            w: 4.0 * h / 6.0,
            interval: Some(i),
            node: i,
        }
    });
    nodes.chain(mids)
}

/// The state at a quadrature point: the node value, or the Hermite midpoint value.
fn state_at(sol: &Solution, pt: &QuadPoint, y: &mut [f64]) {
    let n = sol.n;
    match pt.interval {
        None => y.copy_from_slice(&sol.y[pt.node * n..(pt.node + 1) * n]),
        Some(i) => {
            let h = sol.x[i + 1] - sol.x[i];
            let (v, _) = hermite_weights(0.5, h);
            let (a, b) = (i * n, (i + 1) * n);
            for c in 0..n {
                y[c] = v[0] * sol.y[a + c]
                    + v[1] * sol.yp[a + c]
                    + v[2] * sol.y[b + c]
                    + v[3] * sol.yp[b + c];
            }
        }
    }
}

/// What a non-finite integrand reports (where: the point `x`; what to check: its domain).
const INTEGRAND: &str =
    "the integral functional's integrand g (value or derivative: is the state in its domain?)";

fn non_finite(what: &'static str, x: f64) -> BvpError {
    BvpError::NonFinite {
        what,
        component: 0,
        x,
    }
}

/// The value of `G` on `sol` (no derivatives): Simpson's rule on every mesh interval with the
/// interpolant's midpoint value, plus `φ`. `m + (m − 1)` evaluations of `g` in `f64`.
pub fn integral_value<P: Bvp, G: IntegralFunction>(
    problem: &P,
    sol: &Solution,
    g: &G,
) -> Result<f64, BvpError> {
    check_belongs(problem, sol)?;
    let n = sol.n;
    let m = sol.x.len();
    let p = sol.full_params();
    let mut y = vec![0.0; n];
    let mut value = 0.0;
    for pt in simpson_points(&sol.x) {
        state_at(sol, &pt, &mut y);
        let v = g.integrand(pt.x, &y, &p);
        if !v.is_finite() {
            return Err(non_finite(INTEGRAND, pt.x));
        }
        value += pt.w * v;
    }
    let phi = g.endpoint(&sol.y[..n], &sol.y[(m - 1) * n..], &p);
    if !phi.is_finite() {
        return Err(non_finite(
            "the integral functional's end-point term φ (value or derivative)",
            sol.x[m - 1],
        ));
    }
    Ok(value + phi)
}

/// Value and gradient `dG/dp` (one entry per model parameter) of the integral functional `g`
/// by the adjoint method: the gradient of the quadrature in the node states, unknowns and
/// parameters from dual numbers (through the Hermite midpoint and its node slopes
/// `f(x_i, y_i, p)`), then one transposed solve with the factorisation of the solution's
/// linearisation (cached in `sol`; computed once if absent). Its cost does not grow with the
/// number of parameters.
///
/// Errors if `sol` does not belong to `problem`, if `g` or `φ` or their derivatives are not
/// finite somewhere (the error names the point), or if the transposed solve fails.
pub fn integral_adjoint<P: Bvp, G: IntegralFunction>(
    problem: &P,
    sol: &Solution,
    g: &G,
) -> Result<(f64, Vec<f64>), BvpError> {
    let lz = linearization(problem, sol)?;
    let p = sol.full_params();
    let (n, k, q, m) = (lz.col.n, lz.col.k, lz.col.q, lz.col.m());
    let size = m * n + k;
    let np = k + q;
    let mut engine = DualJacobian::default();
    let mut input = vec![0.0; 2 * n + np];
    let mut grad = vec![0.0; 2 * n + np];
    // b = ∂G/∂(Y, unknowns) through the node slopes; dg_dp = the explicit ∂G/∂p_model
    let mut b = vec![0.0; size];
    let mut dg_dp = vec![0.0; q];
    let mut value = 0.0;
    let mut out = [0.0];
    for pt in simpson_points(&sol.x) {
        state_at(sol, &pt, &mut input[..n]);
        input[n..n + np].copy_from_slice(&p);
        let f = IntegrandFn { g, x: pt.x, n };
        engine.jacobian(&f, &input[..n + np], n + np, &mut out, &mut grad[..n + np]);
        if !out[0].is_finite() || grad[..n + np].iter().any(|v| !v.is_finite()) {
            return Err(non_finite(INTEGRAND, pt.x));
        }
        let w = pt.w;
        value += w * out[0];
        match pt.interval {
            None => {
                for l in 0..n {
                    b[pt.node * n + l] += w * grad[l];
                }
            }
            Some(i) => {
                let (v, _) = hermite_weights(0.5, sol.x[i + 1] - sol.x[i]);
                add_hermite_gradient(lz, i, &v, w, &grad[..n + np], &mut b, &mut dg_dp)
            }
        }
        for l in 0..k {
            b[m * n + l] += w * grad[n + l];
        }
        for j in 0..q {
            dg_dp[j] += w * grad[n + k + j];
        }
    }
    // φ(y(a), y(b), p): y(a) and y(b) are the first and the last node
    input[..n].copy_from_slice(&sol.y[..n]);
    input[n..2 * n].copy_from_slice(&sol.y[(m - 1) * n..]);
    input[2 * n..].copy_from_slice(&p);
    engine.jacobian(
        &EndpointFn { g, n },
        &input,
        2 * n + np,
        &mut out,
        &mut grad,
    );
    if !out[0].is_finite() || grad.iter().any(|v| !v.is_finite()) {
        return Err(non_finite(
            "the integral functional's end-point term φ (value or derivative)",
            sol.x[m - 1],
        ));
    }
    value += out[0];
    for l in 0..n {
        b[l] += grad[l];
        b[(m - 1) * n + l] += grad[n + l];
    }
    for l in 0..k {
        b[m * n + l] += grad[2 * n + l];
    }
    for j in 0..q {
        dg_dp[j] += grad[2 * n + k + j];
    }
    // dG/dp = ∂_p G − λᵀ ∂_p S with (∂_Y S)ᵀ λ = ∂_Y G
    lz.solve_refined(&mut b, 1, true)?;
    let mut col = vec![0.0; size];
    for (j, d) in dg_dp.iter_mut().enumerate() {
        lz.col.param_column(k + j, &mut col);
        let dot: f64 = b.iter().zip(&col).map(|(a, c)| a * c).sum();
        *d -= dot;
    }
    if let Some(pos) = dg_dp.iter().position(|v| !v.is_finite()) {
        return Err(BvpError::SingularJacobian {
            detail: format!(
                "the integral functional's adjoint solve gave a non-finite gradient \
                 (parameter {pos})"
            ),
        });
    }
    Ok((value, dg_dp))
}

/// Value and gradient `dG/dp` of the integral functional `g` from forward sensitivities
/// `sens` of `sol` (column `j` of the gradient is model parameter `sens.columns()[j]`): the
/// same quadrature, each point's `∂g/∂y · ∂y/∂p + ∂g/∂p` with `∂y/∂p` interpolated like `y`.
/// No linear solve beyond the one that made `sens`; what a caller with several functionals and
/// few parameters uses.
///
/// Errors if `sol` does not belong to `problem`, if `sens` was computed for another solution,
/// or if `g`, `φ` or their derivatives are not finite somewhere.
pub fn integral_forward<P: Bvp, G: IntegralFunction>(
    problem: &P,
    sol: &Solution,
    sens: &Sensitivities,
    g: &G,
) -> Result<(f64, Vec<f64>), BvpError> {
    check_belongs(problem, sol)?;
    let (n, k, q) = (sol.n, sol.unknowns.len(), sol.params.len());
    if sens.columns.last().is_some_and(|&j| j >= q) || sens.x != sol.x || sens.n != n {
        return Err(BvpError::InvalidInput(
            "integral_forward: the sensitivities were computed for a different solution; \
             compute them with Sensitivities::compute on this solution"
                .into(),
        ));
    }
    let m = sol.x.len();
    let p = sol.full_params();
    let np = k + q;
    let s = sens.q;
    let mut engine = DualJacobian::default();
    let mut input = vec![0.0; 2 * n + np];
    let mut grad = vec![0.0; 2 * n + np];
    let mut dy = vec![0.0; n * s];
    let mut dyp = vec![0.0; n * s];
    let mut dyb = vec![0.0; n * s];
    let mut gradient = vec![0.0; s];
    let mut value = 0.0;
    let mut out = [0.0];
    for pt in simpson_points(&sol.x) {
        state_at(sol, &pt, &mut input[..n]);
        input[n..n + np].copy_from_slice(&p);
        sens.at_into(pt.x, &mut dy, &mut dyp);
        let f = IntegrandFn { g, x: pt.x, n };
        engine.jacobian(&f, &input[..n + np], n + np, &mut out, &mut grad[..n + np]);
        if !out[0].is_finite() || grad[..n + np].iter().any(|v| !v.is_finite()) {
            return Err(non_finite(INTEGRAND, pt.x));
        }
        value += pt.w * out[0];
        for (j, &pj) in sens.columns.iter().enumerate() {
            let mut v = grad[n + k + pj];
            for c in 0..n {
                v += grad[c] * dy[c * s + j];
            }
            for l in 0..k {
                v += grad[n + l] * sens.d_unknowns[l * s + j];
            }
            gradient[j] += pt.w * v;
        }
    }
    input[..n].copy_from_slice(&sol.y[..n]);
    input[n..2 * n].copy_from_slice(&sol.y[(m - 1) * n..]);
    input[2 * n..].copy_from_slice(&p);
    engine.jacobian(
        &EndpointFn { g, n },
        &input,
        2 * n + np,
        &mut out,
        &mut grad,
    );
    if !out[0].is_finite() || grad.iter().any(|v| !v.is_finite()) {
        return Err(non_finite(
            "the integral functional's end-point term φ (value or derivative)",
            sol.x[m - 1],
        ));
    }
    value += out[0];
    sens.at_into(sol.x[0], &mut dy, &mut dyp);
    sens.at_into(sol.x[m - 1], &mut dyb, &mut dyp);
    for (j, &pj) in sens.columns.iter().enumerate() {
        let mut v = grad[2 * n + k + pj];
        for c in 0..n {
            v += grad[c] * dy[c * s + j] + grad[n + c] * dyb[c * s + j];
        }
        for l in 0..k {
            v += grad[2 * n + l] * sens.d_unknowns[l * s + j];
        }
        gradient[j] += v;
    }
    Ok((value, gradient))
}

//! The problem a user writes: right-hand side and boundary residuals, generic over dual numbers.

use num_dual::DualNum;

/// A two-point boundary value problem
///
/// ```text
/// y'(x) = f(x, y, p),   a <= x <= b,      g(y(a), y(b), p) = 0,
/// ```
///
/// with states `y ∈ R^n` and a parameter vector `p = (unknowns, model parameters)`:
///
/// * the first [`num_unknowns`](Bvp::num_unknowns) entries `p[..k]` are **unknown parameters**
///   (eigenvalues, free constants) that the solver determines together with `y`; the boundary
///   conditions then number `n + k`, as in scipy's `solve_bvp`;
/// * the remaining [`num_params`](Bvp::num_params) entries `p[k..]` are **fixed model parameters**
///   whose values the caller supplies to [`Solver::solve`](crate::Solver::solve). They are what
///   sensitivities, continuation and parameter fits differentiate with respect to.
///
/// Both methods are written once, generically over [`DualNum`]: the solver calls them with `f64`
/// for values and with dual numbers for exact Jacobians with respect to `y` and `p`. A user never
/// writes a derivative.
///
/// ```
/// use diffbvp::{Bvp, DualNum};
/// /// Bratu's problem y'' + k e^y = 0, y(0) = y(1) = 0.
/// struct Bratu { k: f64 }
/// impl Bvp for Bratu {
///     fn dim(&self) -> usize { 2 }
///     fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
///         f[0] = y[1];
///         f[1] = -y[0].exp() * self.k;
///     }
///     fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
///         r[0] = ya[0];
///         r[1] = yb[0];
///     }
/// }
/// ```
pub trait Bvp {
    /// Number of states `n`.
    fn dim(&self) -> usize;

    /// Number `k` of unknown parameters solved for together with `y` (default 0). They occupy
    /// `p[..k]`; the boundary conditions must then provide `n + k` residuals.
    fn num_unknowns(&self) -> usize {
        0
    }

    /// Number of fixed model parameters (default 0). They occupy `p[k..]` and their values are
    /// supplied by the caller of the solver.
    fn num_params(&self) -> usize {
        0
    }

    /// Right-hand side `f(x, y, p)`, written into `f` (length `n`).
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D], f: &mut [D]);

    /// Boundary residuals `g(y(a), y(b), p)`, written into `r` (length `n + k`).
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]);
}

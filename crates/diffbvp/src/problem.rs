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

    /// A constant singular term `S` (`n × n`, row-major; default `None`): the equations become
    ///
    /// ```text
    /// y'(x) = S y / x + f(x, y, p),   0 <= x <= b,
    /// ```
    ///
    /// on an interval that must start at `a = 0`, as bvp4c's and scipy's `solve_bvp(S=...)`. A
    /// solution is smooth at 0 only if `S y(0) = 0` (the regularity condition); the boundary
    /// conditions must impose it (for `y'' + (2/x) y' = …` written as `y = (u, u')`,
    /// `S = [[0, 0], [0, -2]]` and the condition is `u'(0) = 0`). The solver then takes
    /// `y'(0) = (I − S)⁻¹ f(0, y(0), p)` at `x = 0`, projects the guess's `y(0)` onto the null
    /// space of `S` and checks `S y(0) = 0` at the solution; `I − S` must be nonsingular. The term
    /// is linear in `y`: it enters every Jacobian exactly, and forward and adjoint sensitivities,
    /// continuation and the mesh control work unchanged.
    ///
    /// ```
    /// use diffbvp::mesh::linspace;
    /// use diffbvp::{solve, Bvp, DualNum, Guess, SolveOptions};
    ///
    /// /// Emden's equation y'' + (2/x) y' + y^5 = 0, y'(0) = 0, y(1) = sqrt(3/4).
    /// struct Emden;
    /// impl Bvp for Emden {
    ///     fn dim(&self) -> usize { 2 }
    ///     fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
    ///         f[0] = y[1];
    ///         f[1] = -y[0].powi(5);
    ///     }
    ///     fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
    ///         r[0] = ya[1];
    ///         r[1] = yb[0] - 0.75f64.sqrt();
    ///     }
    ///     // the (2/x) y' term: row 1 of S y / x is -2 y[1] / x
    ///     fn singular_term(&self) -> Option<Vec<f64>> {
    ///         Some(vec![0.0, 0.0, 0.0, -2.0])
    ///     }
    /// }
    ///
    /// let guess = Guess::constant(linspace(0.0, 1.0, 5), &[1.0, 0.0]);
    /// let sol = solve(&Emden, &[], &guess, &SolveOptions::with_tol(1e-6))?;
    /// let exact = |x: f64| (1.0 + x * x / 3.0).powf(-0.5);
    /// assert!((sol.eval(0.0)[0] - exact(0.0)).abs() < 1e-6);
    /// assert!((sol.eval(0.5)[0] - exact(0.5)).abs() < 1e-6);
    /// # Ok::<(), diffbvp::BvpError>(())
    /// ```
    fn singular_term(&self) -> Option<Vec<f64>> {
        None
    }

    /// The structural sparsity of the right-hand side (default `None`: every component may read
    /// every input): entry `i` lists the inputs `f_i` may depend on, as indices into `[y, p]`
    /// (the states `0..n`, then the `k` unknowns and the `q` model parameters at `n..n + k + q`),
    /// in every region of a multipoint problem. With it the solver seeds inputs that no
    /// component reads together in one dual direction (a greedy column colouring, computed once
    /// per Jacobian evaluation), so a large sparse system needs a few dual passes instead of
    /// `(n + k) / 8`; the derivatives are the same numbers. A listed input that `f_i` does not
    /// read costs only speed; an input `f_i` reads but that is not listed makes the Jacobian
    /// wrong, so list every one. An index out of range is an
    /// [`BvpError::InvalidInput`](crate::BvpError::InvalidInput). Ignored for a problem with a
    /// [`singular_term`](Bvp::singular_term) (whose value at the singular point mixes the
    /// components). `expr::ExprBvp` (feature `expr`) derives it from its expressions.
    fn rhs_sparsity(&self) -> Option<&[Vec<usize>]> {
        None
    }

    /// Interior interface points `x_1 < … < x_{R-1}` of a multipoint problem (default none):
    /// the interval `[a, b]` is split into `R` regions, the states may jump at every interface,
    /// and the mesh holds each interface twice (its left and its right limit, as bvp4c's
    /// multipoint meshes; [`mesh::multipoint_linspace`](crate::mesh::multipoint_linspace)
    /// builds one). Each region has its own right-hand side
    /// ([`rhs_in_region`](Bvp::rhs_in_region)) and its own mesh control; the limits at interface
    /// `j` are related by `n` conditions ([`interface_conditions`](Bvp::interface_conditions)),
    /// the ends by [`bc`](Bvp::bc). Such separated interface conditions keep the Newton matrix
    /// almost block diagonal: the structured elimination serves a chain of regions at the cost
    /// of one interval with as many nodes. [`Solution::eval`](crate::Solution::eval) at an
    /// interface gives the right limit.
    ///
    /// ```
    /// use diffbvp::mesh::multipoint_linspace;
    /// use diffbvp::{solve, Bvp, DualNum, Guess, SolveOptions};
    ///
    /// /// Steady conduction through two layers: T' = -q / k_r, q' = 0 in layer r, T(0) = 1,
    /// /// T(1) = 0; T and the flux q continuous at x = 0.4.
    /// struct TwoLayers { k: [f64; 2] }
    /// impl Bvp for TwoLayers {
    ///     fn dim(&self) -> usize { 2 }
    ///     fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D], f: &mut [D]) {
    ///         self.rhs_in_region(usize::from(x > 0.4), x, y, p, f);
    ///     }
    ///     fn rhs_in_region<D: DualNum<Primitive = f64> + Copy>(
    ///         &self, region: usize, _x: f64, y: &[D], _p: &[D], f: &mut [D],
    ///     ) {
    ///         f[0] = -y[1] / self.k[region];
    ///         f[1] = D::zero();
    ///     }
    ///     fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
    ///         r[0] = ya[0] - 1.0;
    ///         r[1] = yb[0];
    ///     }
    ///     fn interfaces(&self) -> &[f64] { &[0.4] }
    ///     // the default interface conditions: both states continuous
    /// }
    ///
    /// let guess = Guess::constant(multipoint_linspace(&[0.0, 0.4, 1.0], 4), &[0.5, 1.0]);
    /// let sol = solve(&TwoLayers { k: [1.0, 3.0] }, &[], &guess, &SolveOptions::with_tol(1e-6))?;
    /// // the flux through resistances 0.4 / 1 + 0.6 / 3 in series
    /// let q = 1.0 / (0.4 / 1.0 + 0.6 / 3.0);
    /// assert!((sol.eval(0.2)[1] - q).abs() < 1e-10);
    /// assert!((sol.eval(0.4)[0] - (1.0 - 0.4 * q)).abs() < 1e-10);
    /// # Ok::<(), diffbvp::BvpError>(())
    /// ```
    fn interfaces(&self) -> &[f64] {
        &[]
    }

    /// The right-hand side in region `region` (`0..R`, left to right, see
    /// [`interfaces`](Bvp::interfaces)); default [`rhs`](Bvp::rhs). At an interface the left
    /// limit's node is evaluated with the left region, the right limit's with the right one.
    fn rhs_in_region<D: DualNum<Primitive = f64> + Copy>(
        &self,
        region: usize,
        x: f64,
        y: &[D],
        p: &[D],
        f: &mut [D],
    ) {
        let _ = region;
        self.rhs(x, y, p, f);
    }

    /// The `n` conditions `r = h_j(y(x_j⁻), y(x_j⁺), p)` at interface `j` (`0..R-1`) between
    /// the left limit `left` and the right limit `right`; default continuity of every state,
    /// `r = right − left`. A jump `y(x_j⁺) = J y(x_j⁻)` or a flux balance is written here.
    fn interface_conditions<D: DualNum<Primitive = f64> + Copy>(
        &self,
        index: usize,
        left: &[D],
        right: &[D],
        p: &[D],
        r: &mut [D],
    ) {
        let _ = (index, p);
        for ((r, &l), &rt) in r.iter_mut().zip(left).zip(right) {
            *r = rt - l;
        }
    }
}

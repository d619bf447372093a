//! The solution object: mesh, values, derivatives, unknown parameters, the C1 piecewise-cubic
//! interpolant, per-interval residuals and statistics.

use crate::error::BvpError;
use crate::linear::Factorization;
use crate::linearization::Linearization;
use crate::problem::Bvp;
use std::sync::{Arc, OnceLock};

/// Counters of one solve.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SolveStats {
    /// Newton iterations (all meshes).
    pub newton_iterations: usize,
    /// Numeric factorisations of the Newton matrix.
    pub jacobian_factorizations: usize,
    /// Right-hand-side evaluations with `f64` (one per point).
    pub rhs_evaluations: usize,
    /// Right-hand-side evaluations with dual numbers (one per point and dual pass).
    pub rhs_dual_evaluations: usize,
    /// Mesh modifications (refinements and coarsenings).
    pub mesh_refinements: usize,
    /// Of those, coarsenings.
    pub mesh_coarsenings: usize,
    /// Largest scaled RMS collocation residual on the final mesh.
    pub max_residual: f64,
    /// Largest absolute boundary-condition residual.
    pub max_bc_residual: f64,
    /// The mesh iteration after which the refinement switched to scipy's rule because the
    /// equidistributed mesh did not settle (see
    /// [`MeshOptions::settle`](crate::mesh::MeshOptions::settle)); `None`: no switch.
    pub mesh_rule_switched_at: Option<usize>,
}

impl SolveStats {
    /// All right-hand-side evaluations, values and dual passes counted alike (the cost measure of
    /// the continuation step control).
    pub fn total_rhs_evaluations(&self) -> usize {
        self.rhs_evaluations + self.rhs_dual_evaluations
    }
}

/// A converged solution of a [`Bvp`].
#[derive(Debug, Clone)]
pub struct Solution {
    /// Number of states.
    pub n: usize,
    /// Mesh nodes.
    pub x: Vec<f64>,
    /// States at the nodes, `m × n` row-major: `y[i * n + c]`.
    pub y: Vec<f64>,
    /// Derivatives `f(x_i, y_i, p)` at the nodes, same layout.
    pub yp: Vec<f64>,
    /// The unknown parameters found (length `k`).
    pub unknowns: Vec<f64>,
    /// The fixed model parameters the solution was computed with.
    pub params: Vec<f64>,
    /// Scaled RMS collocation residual per interval (length `m - 1`).
    pub rms_residuals: Vec<f64>,
    /// Residual scale per component used by error control (`s_c` in `r_c / (s_c + |f_c|)`).
    pub residual_scale: Vec<f64>,
    /// Statistics.
    pub stats: SolveStats,
    /// The linearisation at this solution (Jacobians seeded in the parameters, factorised Newton
    /// matrix), computed at most once: by the solve (seeded in the model parameters of
    /// [`SolveOptions::linearization_params`](crate::SolveOptions::linearization_params)) or by
    /// the first derivative request.
    pub(crate) linearization: OnceLock<Arc<Linearization>>,
    /// The linearisation seeded in all parameters, when the solve's was seeded in fewer and a
    /// request needed all (computed at most once).
    pub(crate) full_linearization: OnceLock<Arc<Linearization>>,
    /// The factorised Newton matrix of the solve's last Newton step, with
    /// [`SolveOptions::keep_newton_matrix`](crate::SolveOptions::keep_newton_matrix): a
    /// start for simplified Newton nearby, not a linearisation at this solution.
    pub(crate) newton_matrix: Option<Arc<Factorization>>,
}

impl Solution {
    /// Number of mesh nodes.
    pub fn nodes(&self) -> usize {
        self.x.len()
    }

    /// All parameters `p = (unknowns, model parameters)` as the problem sees them.
    pub fn full_params(&self) -> Vec<f64> {
        let mut p = self.unknowns.clone();
        p.extend_from_slice(&self.params);
        p
    }

    /// State `c` at node `i`.
    ///
    /// # Panics
    ///
    /// Panics if `i >= self.nodes()` or `c >= self.n` (as slice indexing does); see
    /// [`get`](Self::get) for a non-panicking version.
    pub fn at_node(&self, i: usize, c: usize) -> f64 {
        assert!(
            c < self.n,
            "Solution::at_node: component {c} out of range ({} states)",
            self.n
        );
        self.y[i * self.n + c]
    }

    /// State `c` at node `i`, or `None` if `i >= self.nodes()` or `c >= self.n`.
    pub fn get(&self, i: usize, c: usize) -> Option<f64> {
        if c < self.n && i < self.nodes() {
            self.y.get(i * self.n + c).copied()
        } else {
            None
        }
    }

    /// Values of component `c` at all nodes.
    ///
    /// # Panics
    ///
    /// Panics if `c >= self.n`; see [`try_component`](Self::try_component) for a
    /// non-panicking version.
    pub fn component(&self, c: usize) -> Vec<f64> {
        assert!(
            c < self.n,
            "Solution::component: component {c} out of range ({} states)",
            self.n
        );
        (0..self.nodes()).map(|i| self.y[i * self.n + c]).collect()
    }

    /// Values of component `c` at all nodes, or `None` if `c >= self.n`.
    pub fn try_component(&self, c: usize) -> Option<Vec<f64>> {
        (c < self.n).then(|| self.component(c))
    }

    /// Index of the interval `[x_i, x_{i+1}]` containing `x`, clamped to the mesh: `0` for
    /// `x <= a` (including `-inf`), `nodes() - 2` for `x >= b` (including `+inf`). A NaN `x`
    /// gives `0` (any interval would do: every evaluation at NaN gives NaN).
    pub fn interval(&self, x: f64) -> usize {
        interval_of(&self.x, x)
    }

    /// The C1 interpolant and its derivative at `x`, written into `y` and `yp` (length `n`).
    ///
    /// Outside `[a, b]` the cubic of the end interval is extrapolated (as scipy's
    /// `solve_bvp` solution does); far outside (the cube of the distance in interval lengths
    /// beyond `f64::MAX`, about 1e100) its terms overflow and the result is `±inf` or NaN. A
    /// non-finite `x` (NaN or `±inf`) gives NaN in every component of `y` and `yp`.
    ///
    /// # Panics
    ///
    /// Panics if `y` or `yp` is shorter than `n`; [`try_eval_into`](Self::try_eval_into)
    /// returns an error instead.
    pub fn eval_into(&self, x: f64, y: &mut [f64], yp: &mut [f64]) {
        if !x.is_finite() {
            y[..self.n].fill(f64::NAN);
            yp[..self.n].fill(f64::NAN);
            return;
        }
        let i = self.interval(x);
        hermite(&self.x, &self.y, &self.yp, self.n, i, x, y, yp);
    }

    /// [`eval_into`](Self::eval_into) with the buffer lengths checked: a
    /// [`BvpError::InvalidInput`] naming the buffer and both
    /// lengths when `y` or `yp` is shorter than `n`.
    pub fn try_eval_into(&self, x: f64, y: &mut [f64], yp: &mut [f64]) -> Result<(), BvpError> {
        for (name, len) in [("y", y.len()), ("yp", yp.len())] {
            if len < self.n {
                return Err(BvpError::InvalidInput(format!(
                    "Solution::try_eval_into: the buffer {name} has {len} entries, the solution {} states",
                    self.n
                )));
            }
        }
        self.eval_into(x, y, yp);
        Ok(())
    }

    /// The interpolated state at `x` (see [`eval_into`](Self::eval_into) for `x` outside
    /// `[a, b]` and non-finite `x`).
    pub fn eval(&self, x: f64) -> Vec<f64> {
        let mut y = vec![0.0; self.n];
        let mut yp = vec![0.0; self.n];
        self.eval_into(x, &mut y, &mut yp);
        y
    }

    /// The derivative of the interpolant at `x` (see [`eval_into`](Self::eval_into) for `x`
    /// outside `[a, b]` and non-finite `x`).
    pub fn eval_derivative(&self, x: f64) -> Vec<f64> {
        let mut y = vec![0.0; self.n];
        let mut yp = vec![0.0; self.n];
        self.eval_into(x, &mut y, &mut yp);
        yp
    }

    /// The factorisation of the collocation Jacobian at this solution, if it has been computed:
    /// by the solve ([`SolveOptions::factor_at_solution`](crate::SolveOptions::factor_at_solution))
    /// or by an earlier sensitivity or adjoint computation on this solution (or the solution it
    /// was cloned from after that).
    pub fn factorization(&self) -> Option<&Factorization> {
        self.linearization.get().map(|l| &l.factorization)
    }

    /// Whether the solve kept its last Newton matrix
    /// ([`SolveOptions::keep_newton_matrix`](crate::SolveOptions::keep_newton_matrix)): a solve
    /// nearby on this mesh ([`Solver::solve_near`](crate::Solver::solve_near)) starts from it.
    pub fn has_newton_matrix(&self) -> bool {
        self.newton_matrix.is_some()
    }

    /// Bytes this solution holds on the heap: its vectors and, once computed, its cached
    /// linearisation (Jacobians seeded in all parameters and the factorised Newton matrix; a
    /// sparse LU's factors estimated) and a kept Newton matrix. What a fit keeps per run and solution, for planning the
    /// memory of a large fit.
    pub fn heap_bytes(&self) -> usize {
        let v = self.x.len()
            + self.y.len()
            + self.yp.len()
            + self.unknowns.len()
            + self.params.len()
            + self.rms_residuals.len()
            + self.residual_scale.len();
        8 * v
            + self.linearization.get().map_or(0, |l| l.heap_bytes())
            + self.full_linearization.get().map_or(0, |l| l.heap_bytes())
            + self.newton_matrix.as_ref().map_or(0, |f| f.heap_bytes())
    }

    /// A linearisation at this solution seeded (at least) in the model parameters `model`
    /// (strictly increasing): the cached one if it covers them, else the full one (cached in
    /// its own slot, computed now if need be, once); with nothing cached, one seeded in `model`
    /// is computed and cached. Assumes the public fields are those the solve returned.
    pub(crate) fn linearization_covering<P: Bvp>(
        &self,
        problem: &P,
        model: impl IntoIterator<Item = usize>,
    ) -> Result<&Linearization, BvpError> {
        let model: Vec<usize> = model.into_iter().collect();
        let (slot, seeds) = match self.linearization.get() {
            Some(l) if l.covers(model.iter().copied()) => return Ok(l),
            Some(_) => (&self.full_linearization, None),
            // nothing cached: the parameters asked for (all of them in the usual request)
            None if model.len() < self.params.len() => (&self.linearization, Some(&model[..])),
            None => (&self.linearization, None),
        };
        if let Some(l) = slot.get() {
            return Ok(l);
        }
        let l = Linearization::with_fresh_workspace(
            problem,
            &self.x,
            &self.y,
            &self.yp,
            &self.full_params(),
            seeds,
        )?;
        // another thread may have set it meanwhile: either value is the same linearisation
        let _ = slot.set(Arc::new(l));
        slot.get().map(|l| &**l).ok_or_else(|| {
            BvpError::InvalidInput("the solution's linearisation could not be cached".into())
        })
    }
}

/// Index of the interval of the mesh `x` (at least 2 nodes) containing `v`, clamped; NaN gives 0.
pub(crate) fn interval_of(x: &[f64], v: f64) -> usize {
    let m = x.len();
    // NaN must be caught: `partition_point` would return 0 for it and the
    // subtraction below would overflow
    if v.is_nan() || v <= x[0] {
        return 0;
    }
    if v >= x[m - 1] {
        return m - 2;
    }
    // first index with x[idx] > v, minus one
    let idx = x.partition_point(|&xi| xi <= v);
    (idx - 1).min(m - 2)
}

/// Hermite basis weights at `t ∈ [0, 1]` on an interval of length `h`:
/// `(w_yi, w_fi, w_yj, w_fj)` for the value and `(d_yi, d_fi, d_yj, d_fj)` for the derivative.
#[inline]
pub(crate) fn hermite_weights(t: f64, h: f64) -> ([f64; 4], [f64; 4]) {
    let t2 = t * t;
    let t3 = t2 * t;
    let v = [
        2.0 * t3 - 3.0 * t2 + 1.0,
        h * (t3 - 2.0 * t2 + t),
        -2.0 * t3 + 3.0 * t2,
        h * (t3 - t2),
    ];
    let d = [
        (6.0 * t2 - 6.0 * t) / h,
        3.0 * t2 - 4.0 * t + 1.0,
        (-6.0 * t2 + 6.0 * t) / h,
        3.0 * t2 - 2.0 * t,
    ];
    (v, d)
}

#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn hermite(
    xs: &[f64],
    ys: &[f64],
    fs: &[f64],
    n: usize,
    i: usize,
    x: f64,
    y: &mut [f64],
    yp: &mut [f64],
) {
    let h = xs[i + 1] - xs[i];
    let t = (x - xs[i]) / h;
    let (v, d) = hermite_weights(t, h);
    for c in 0..n {
        let (yi, yj) = (ys[i * n + c], ys[(i + 1) * n + c]);
        let (fi, fj) = (fs[i * n + c], fs[(i + 1) * n + c]);
        y[c] = v[0] * yi + v[1] * fi + v[2] * yj + v[3] * fj;
        yp[c] = d[0] * yi + d[1] * fi + d[2] * yj + d[3] * fj;
    }
}

/// Interpolates node values `ys` (with slopes `fs`) on mesh `xs` onto `new_x`.
pub(crate) fn resample(xs: &[f64], ys: &[f64], fs: &[f64], n: usize, new_x: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; new_x.len() * n];
    // sorted new nodes: the interval search continues from the previous one (what
    // `interval_of` finds, without a binary search per node)
    let last = xs.len().saturating_sub(2);
    let mut i = 0;
    for (j, &x) in new_x.iter().enumerate() {
        if xs.len() < 2 || x.is_nan() || x < xs[i] {
            i = interval_of(xs, x);
        } else {
            while i < last && x >= xs[i + 1] {
                i += 1;
            }
        }
        // the values of `hermite` (its slopes are not needed here)
        let h = xs[i + 1] - xs[i];
        let (v, _) = hermite_weights((x - xs[i]) / h, h);
        let (yi, yj) = (&ys[i * n..(i + 1) * n], &ys[(i + 1) * n..(i + 2) * n]);
        let (fi, fj) = (&fs[i * n..(i + 1) * n], &fs[(i + 1) * n..(i + 2) * n]);
        for (c, o) in out[j * n..(j + 1) * n].iter_mut().enumerate() {
            *o = v[0] * yi[c] + v[1] * fi[c] + v[2] * yj[c] + v[3] * fj[c];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_reproduces_cubics_and_derivatives() {
        let xs = [0.0, 0.3, 1.0];
        let p = |x: f64| 1.0 + 2.0 * x - x * x + 0.5 * x * x * x;
        let dp = |x: f64| 2.0 - 2.0 * x + 1.5 * x * x;
        let ys: Vec<f64> = xs.iter().map(|&x| p(x)).collect();
        let fs: Vec<f64> = xs.iter().map(|&x| dp(x)).collect();
        let mut y = [0.0];
        let mut yp = [0.0];
        for &x in &[0.0, 0.1, 0.3, 0.77, 1.0] {
            hermite(&xs, &ys, &fs, 1, interval_of(&xs, x), x, &mut y, &mut yp);
            assert!((y[0] - p(x)).abs() < 1e-14);
            assert!((yp[0] - dp(x)).abs() < 1e-13);
        }
    }

    #[test]
    fn interval_lookup_is_clamped() {
        let xs = [0.0, 1.0, 2.0, 3.0];
        assert_eq!(interval_of(&xs, -1.0), 0);
        assert_eq!(interval_of(&xs, 0.0), 0);
        assert_eq!(interval_of(&xs, 1.0), 1);
        assert_eq!(interval_of(&xs, 2.5), 2);
        assert_eq!(interval_of(&xs, 3.0), 2);
        assert_eq!(interval_of(&xs, 9.0), 2);
        assert_eq!(interval_of(&xs, f64::NAN), 0);
        assert_eq!(interval_of(&xs, f64::INFINITY), 2);
        assert_eq!(interval_of(&xs, f64::NEG_INFINITY), 0);
    }
}

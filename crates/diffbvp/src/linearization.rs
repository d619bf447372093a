//! The linearisation of the collocation system at a converged solution, computed once and shared.
//!
//! Forward sensitivities and adjoint gradients both need, at the solution, the Jacobians of the
//! right-hand side and the boundary conditions in the states, the unknown parameters *and* the
//! model parameters (one dual-number pass seeded in all of them), and the factorisation of the
//! Newton matrix `∂_Y S`. A [`Solution`](crate::Solution) caches this once (behind a
//! `OnceLock`): the solve computes it with its own workspace when
//! [`SolveOptions::factor_at_solution`](crate::SolveOptions::factor_at_solution) is set, or the
//! first derivative request computes it; every later request (and every clone of the solution)
//! reuses it. A caller that never asks for derivatives pays nothing.

use crate::collocation::Collocation;
use crate::error::BvpError;
use crate::linear::{Factorization, LinearSystem, Pattern};
use crate::problem::Bvp;
use std::sync::Arc;

/// Jacobians seeded in the parameters and the factorised Newton matrix at one solution.
pub(crate) struct Linearization {
    /// Mesh, interval lengths and the Jacobians `jn`, `jm`, `jbc` seeded in the `k` unknowns and
    /// the model parameters `col.model_seeds` (all `q` of them unless the solve was told which
    /// ones a caller will differentiate in: [`SolveOptions::linearization_params`](crate::SolveOptions::linearization_params));
    /// the value buffers are empty.
    pub col: Collocation,
    /// The factorisation of `∂_Y S` at the solution.
    pub factorization: Factorization,
}

impl std::fmt::Debug for Linearization {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Linearization {{ nodes: {}, seeded parameters: {} (model parameters {:?}), \
             factorization: {:?} }}",
            self.col.m(),
            self.col.seeded_params,
            self.col.model_seeds,
            self.factorization
        )
    }
}

impl Linearization {
    /// Bytes on the heap: the Jacobians and the factors (see [`Factorization::heap_bytes`]).
    pub(crate) fn heap_bytes(&self) -> usize {
        let c = &self.col;
        8 * (c.x.len() + c.h.len() + c.jn.len() + c.jm.len() + c.jbc.len())
            + self.factorization.heap_bytes()
    }

    /// Computes the linearisation at the node values `y` with all parameters
    /// `p = (unknowns, model parameters)` in `col` and `lin` (a solver's workspace or fresh ones),
    /// which must hold this mesh and the midpoint states of `y` (after a residual evaluation at
    /// `y`, or [`Collocation::set_midpoints_from_slopes`]): one dual pass seeded in the states,
    /// the `k` unknowns and the model parameters `model` (all `q` if `None`), one
    /// factorisation.
    pub(crate) fn compute<P: Bvp>(
        problem: &P,
        col: &mut Collocation,
        lin: &mut LinearSystem,
        y: &[f64],
        p: &[f64],
        model: Option<&[usize]>,
    ) -> Result<Self, BvpError> {
        match model {
            Some(list) => col.jacobians_in(problem, y, p, list)?,
            None => col.jacobians(problem, y, p, col.k + col.q)?,
        }
        lin.factor(col)?;
        Ok(Linearization {
            col: col.jacobian_copy(),
            factorization: lin.snapshot(),
        })
    }

    /// The linearisation at a solution (`x`, `y`, slopes `yp`, parameters `p`) with a fresh
    /// workspace, seeded in the model parameters `model` (all if `None`): what a derivative
    /// request computes when the solve did not. No right-hand-side
    /// evaluation in `f64`: the midpoint states follow from the stored slopes.
    pub(crate) fn with_fresh_workspace<P: Bvp>(
        problem: &P,
        x: &[f64],
        y: &[f64],
        yp: &[f64],
        p: &[f64],
        model: Option<&[usize]>,
    ) -> Result<Self, BvpError> {
        let (n, k, q) = (problem.dim(), problem.num_unknowns(), problem.num_params());
        let mut col = Collocation::new(n, k, q);
        col.set_mesh(x);
        let mut lin = LinearSystem::new(Arc::new(Pattern::new(n, k, x.len())?));
        col.set_midpoints_from_slopes(y, yp);
        Self::compute(problem, &mut col, &mut lin, y, p, model)
    }

    /// The derivatives of `f` and `g` in the model parameters `model` at a solution (`x`, `y`,
    /// slopes `yp`, parameters `p`), nothing in the states: a dual pass `n + k` inputs narrower
    /// than a linearisation's and no factorisation, for the columns of parameters a cached
    /// linearisation was not seeded in ([`Collocation::param_column_with`]).
    pub(crate) fn extra_columns<P: Bvp>(
        problem: &P,
        (x, y, yp): (&[f64], &[f64], &[f64]),
        p: &[f64],
        model: &[usize],
    ) -> Result<Collocation, BvpError> {
        let (n, k, q) = (problem.dim(), problem.num_unknowns(), problem.num_params());
        let mut col = Collocation::new(n, k, q);
        col.set_mesh(x);
        col.set_midpoints_from_slopes(y, yp);
        col.param_jacobians_only(problem, y, p, model)?;
        Ok(col)
    }

    /// Whether the Jacobians hold the columns of all model parameters `model` (indices into
    /// the `q` model parameters).
    pub(crate) fn covers(&self, model: impl IntoIterator<Item = usize>) -> bool {
        let c = &self.col;
        c.model_seeds.len() == c.q || model.into_iter().all(|j| c.param_slot(c.k + j).is_some())
    }

    /// The column of `∂r/∂p` for model parameter `j`, which must be covered
    /// ([`covers`](Self::covers)), into `out`; returns the column of the node Jacobian
    /// ([`jn`](Self::jn)) holding `∂f/∂p_j`.
    pub(crate) fn model_column(&self, j: usize, out: &mut [f64]) -> Result<usize, BvpError> {
        let c = &self.col;
        match c.param_slot(c.k + j) {
            Some(slot) => {
                c.param_column(slot, out);
                Ok(c.n + slot)
            }
            None => Err(BvpError::InvalidInput(format!(
                "the linearisation at this solution is not seeded in model parameter {j} \
                 (seeded in {:?})",
                c.model_seeds
            ))),
        }
    }

    /// Solves `∂_Y S · X = B` (or its transpose) for `ncols` right-hand sides stored column after
    /// column in `b`, followed by one step of iterative refinement in working precision: the
    /// residual `B − (∂_Y S) X` is formed from the Jacobian blocks (not from the factors) and the
    /// correction solved with the same factorisation (Skeel: one step makes Gaussian elimination
    /// with partial pivoting componentwise backward stable). The fiber system's rows and columns
    /// differ in scale by orders of magnitude; without the step the structured and the sparse
    /// elimination (each with its own pivoting) gave forward sensitivities differing by 3.5e-11,
    /// with it by 1e-15. Costs one block product and one more solve with the factors.
    pub(crate) fn solve_refined(
        &self,
        b: &mut [f64],
        ncols: usize,
        transpose: bool,
    ) -> Result<(), BvpError> {
        let mut scratch = Vec::new();
        let mut r = b.to_vec();
        let f = &self.factorization;
        f.solve_with_scratch(b, ncols, transpose, &mut scratch)?;
        self.subtract_product(b, ncols, transpose, &mut r);
        f.solve_with_scratch(&mut r, ncols, transpose, &mut scratch)?;
        for (x, d) in b.iter_mut().zip(&r) {
            *x += d;
        }
        Ok(())
    }

    /// `r −= (∂_Y S) x` (or `(∂_Y S)ᵀ x`) for `ncols` columns.
    fn subtract_product(&self, x: &[f64], ncols: usize, transpose: bool, r: &mut [f64]) {
        let col = &self.col;
        let (n, k, m) = (col.n, col.k, col.m());
        let size = m * n + k;
        let mut pcols = vec![0.0; k * size];
        for l in 0..k {
            col.param_column(l, &mut pcols[l * size..(l + 1) * size]);
        }
        let mut ab = vec![0.0; 2 * n * n];
        // Entry `v` at (row, column) of the Newton matrix, applied as A or Aᵀ to every column.
        let mut add = |row: usize, column: usize, v: f64| {
            let (out, from) = if transpose {
                (column, row)
            } else {
                (row, column)
            };
            for j in 0..ncols {
                let xv = x[j * size + from];
                r[j * size + out] -= v * xv;
            }
        };
        for i in 0..m - 1 {
            col.interval_rows(i, &mut ab, 2 * n);
            for rr in 0..n {
                let row = i * n + rr;
                for (c, v) in ab[rr * 2 * n..(rr + 1) * 2 * n].iter().enumerate() {
                    add(row, i * n + c, *v);
                }
                for l in 0..k {
                    add(row, m * n + l, pcols[l * size + row]);
                }
            }
        }
        for rr in 0..n + k {
            let row = (m - 1) * n + rr;
            for c in 0..n {
                add(row, c, col.bc_state(rr, 0, c));
                add(row, (m - 1) * n + c, col.bc_state(rr, 1, c));
            }
            for l in 0..k {
                add(row, m * n + l, pcols[l * size + row]);
            }
        }
    }

    /// Node Jacobian entry `∂f_c/∂(y, p)_l` at node `i`.
    #[inline]
    pub(crate) fn jn(&self, i: usize, c: usize, l: usize) -> f64 {
        let n = self.col.n;
        let w = n + self.col.seeded_params;
        self.col.jn[i * n * w + c * w + l]
    }
}

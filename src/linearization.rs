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

/// Jacobians seeded in all parameters and the factorised Newton matrix at one solution.
pub(crate) struct Linearization {
    /// Mesh, interval lengths and the Jacobians `jn`, `jm`, `jbc` seeded in `k + q` parameters
    /// (the value buffers are empty).
    pub col: Collocation,
    /// The factorisation of `∂_Y S` at the solution.
    pub factorization: Factorization,
}

impl std::fmt::Debug for Linearization {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Linearization {{ nodes: {}, seeded parameters: {}, factorization: {:?} }}",
            self.col.m(),
            self.col.seeded_params,
            self.factorization
        )
    }
}

impl Linearization {
    /// Computes the linearisation at the node values `y` with all parameters
    /// `p = (unknowns, model parameters)` in `col` and `lin` (a solver's workspace or fresh ones),
    /// which must hold this mesh and the midpoint states of `y` (after a residual evaluation at
    /// `y`, or [`Collocation::set_midpoints_from_slopes`]): one dual pass seeded in the states
    /// and all `k + q` parameters, one factorisation.
    pub(crate) fn compute<P: Bvp>(
        problem: &P,
        col: &mut Collocation,
        lin: &mut LinearSystem,
        y: &[f64],
        p: &[f64],
    ) -> Result<Self, BvpError> {
        col.jacobians(problem, y, p, col.k + col.q)?;
        lin.factor(col)?;
        Ok(Linearization {
            col: col.jacobian_copy(),
            factorization: lin.snapshot(),
        })
    }

    /// The linearisation at a solution (`x`, `y`, slopes `yp`, parameters `p`) with a fresh
    /// workspace: what a derivative request computes when the solve did not. No right-hand-side
    /// evaluation in `f64`: the midpoint states follow from the stored slopes.
    pub(crate) fn with_fresh_workspace<P: Bvp>(
        problem: &P,
        x: &[f64],
        y: &[f64],
        yp: &[f64],
        p: &[f64],
    ) -> Result<Self, BvpError> {
        let (n, k, q) = (problem.dim(), problem.num_unknowns(), problem.num_params());
        let mut col = Collocation::new(n, k, q);
        col.set_mesh(x);
        let mut lin = LinearSystem::new(Arc::new(Pattern::new(n, k, x.len())?));
        col.set_midpoints_from_slopes(y, yp);
        Self::compute(problem, &mut col, &mut lin, y, p)
    }

    /// Node Jacobian entry `∂f_c/∂(y, p)_l` at node `i`.
    #[inline]
    pub(crate) fn jn(&self, i: usize, c: usize, l: usize) -> f64 {
        let n = self.col.n;
        let w = n + self.col.seeded_params;
        self.col.jn[i * n * w + c * w + l]
    }
}

//! Sparse matrices a user can take away (feature `sprs`): the toolkit's exact dual-number
//! Jacobians as [`sprs::CsMat<f64>`](sprs::CsMat), for inspection, export or a solver of one's
//! own. The solver itself keeps factorising with faer; nothing here is on its path.
//!
//! * [`collocation_jacobian`]: `∂S/∂(Y, unknowns)` of the collocation system at a solution, the
//!   Newton matrix whose factorisation the solution caches (same values, same sparsity);
//! * [`param_jacobian`]: `∂S/∂p` in the model parameters at a solution;
//! * [`sensitivity_matrix`]: forward sensitivities `D_p Y` as a `(m n + k) × s` matrix;
//! * [`fit_jacobian`]: the residual Jacobian `∂r/∂θ` of a least-squares fit at its optimum,
//!   with the block-arrow structure kept when the fit had one.
//!
//! Rows of `S` and `Y` are ordered as in [`inspect::discrete_system`](crate::inspect::discrete_system):
//! the `(m − 1) n` collocation residuals interval by interval, then the `n + k` boundary
//! residuals; the states node by node, then the `k` unknowns.
//!
//! ```
//! use diffbvp::inspect::discrete_system;
//! use diffbvp::mesh::linspace;
//! use diffbvp::sparse::collocation_jacobian;
//! use diffbvp::{solve, Bvp, DualNum, Guess, SolveOptions};
//!
//! /// Bratu's problem y'' + e^y = 0, y(0) = y(1) = 0.
//! struct Bratu;
//! impl Bvp for Bratu {
//!     fn dim(&self) -> usize { 2 }
//!     fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
//!         f[0] = y[1];
//!         f[1] = -y[0].exp();
//!     }
//!     fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
//!         r[0] = ya[0];
//!         r[1] = yb[0];
//!     }
//! }
//!
//! let sol = solve(&Bratu, &[], &Guess::constant(linspace(0.0, 1.0, 6), &[0.0, 0.0]),
//!                 &SolveOptions::fixed_mesh())?;
//! let jac: sprs::CsMat<f64> = collocation_jacobian(&Bratu, &sol)?;
//! let size = sol.y.len();
//! assert_eq!(jac.shape(), (size, size));
//! assert!(jac.nnz() < size * size / 2); // block-banded: two n × n blocks per row
//!
//! // central differences of the residual S(Y) at the solution, column by column
//! let at = Guess::from(&sol);
//! let h = 1e-6;
//! for c in 0..size {
//!     let (mut plus, mut minus) = (at.clone(), at.clone());
//!     plus.y[c] += h;
//!     minus.y[c] -= h;
//!     let rp = discrete_system(&Bratu, &[], &plus)?.residual;
//!     let rm = discrete_system(&Bratu, &[], &minus)?.residual;
//!     for r in 0..size {
//!         let fd = (rp[r] - rm[r]) / (2.0 * h);
//!         let exact = jac.get(r, c).copied().unwrap_or(0.0);
//!         assert!((fd - exact).abs() < 1e-7 * (1.0 + exact.abs()), "({r}, {c}): {fd} vs {exact}");
//!     }
//! }
//! # Ok::<(), diffbvp::BvpError>(())
//! ```

use crate::error::BvpError;
use crate::least_squares::FitResult;
use crate::linear::Pattern;
use crate::problem::Bvp;
use crate::sensitivity::Sensitivities;
use crate::solution::Solution;
use sprs::{CsMat, TriMat};

/// Errors unless `sol` has the dimensions of `problem`'s solutions.
fn check_belongs<P: Bvp>(problem: &P, sol: &Solution) -> Result<(), BvpError> {
    let (n, k, q) = (problem.dim(), problem.num_unknowns(), problem.num_params());
    if sol.n != n || sol.unknowns.len() != k || sol.params.len() != q {
        return Err(BvpError::InvalidInput(format!(
            "sparse: the solution does not belong to this problem ({} states, {} unknowns, {} \
             model parameters; the problem has {n}, {k}, {q})",
            sol.n,
            sol.unknowns.len(),
            sol.params.len()
        )));
    }
    Ok(())
}

/// The collocation Jacobian `∂S/∂(Y, unknowns)` at the solution `sol`, `(m n + k)²`, in
/// compressed sparse columns: the values of the linearisation cached in `sol` (computed once
/// from dual numbers if the solve did not keep it), in the sparsity pattern faer factorises.
///
/// Errors if `sol` does not belong to `problem` or the linearisation cannot be computed (a
/// non-finite Jacobian entry).
pub fn collocation_jacobian<P: Bvp>(problem: &P, sol: &Solution) -> Result<CsMat<f64>, BvpError> {
    check_belongs(problem, sol)?;
    let lz = sol.linearization_covering(problem, std::iter::empty())?;
    let (n, k, m) = (lz.col.n, lz.col.k, lz.col.m());
    let pattern = Pattern::new(n, k, m)?;
    let mut values = Vec::new();
    let mut work = Vec::new();
    pattern.assemble(&lz.col, &mut values, &mut work);
    let symbolic = pattern.symbolic();
    let size = pattern.size();
    CsMat::try_new_csc(
        (size, size),
        symbolic.col_ptr().to_vec(),
        symbolic.row_idx().to_vec(),
        values,
    )
    .map_err(|(_, _, _, e)| {
        BvpError::InvalidInput(format!(
            "sparse: the collocation pattern is not valid CSC: {e}"
        ))
    })
}

/// `∂S/∂p` at the solution `sol` in all model parameters, `(m n + k) × q`, exact entries that
/// are zero left out (a parameter enters only the rows of the intervals and boundary
/// conditions it appears in).
pub fn param_jacobian<P: Bvp>(problem: &P, sol: &Solution) -> Result<CsMat<f64>, BvpError> {
    check_belongs(problem, sol)?;
    let q = sol.params.len();
    let lz = sol.linearization_covering(problem, 0..q)?;
    let (n, k, m) = (lz.col.n, lz.col.k, lz.col.m());
    let size = m * n + k;
    let mut column = vec![0.0; size];
    let mut tri = TriMat::new((size, q));
    for j in 0..q {
        lz.model_column(j, &mut column)?;
        for (r, &v) in column.iter().enumerate() {
            if v != 0.0 {
                tri.add_triplet(r, j, v);
            }
        }
    }
    Ok(tri.to_csc())
}

/// Forward sensitivities as a `(m n + k) × s` matrix (rows: the states node by node, then the
/// unknowns; column `j` is model parameter `sens.columns()[j]`). Dense in general (a parameter
/// moves the whole solution); stored in compressed columns without the exact zeros.
pub fn sensitivity_matrix(sens: &Sensitivities) -> CsMat<f64> {
    let s = sens.num_params();
    // rows per column: the layouts are `row * s + column` (no rows without columns)
    let states = sens.dy.len().checked_div(s).unwrap_or(0);
    let k = sens.d_unknowns.len().checked_div(s).unwrap_or(0);
    let mut tri = TriMat::new((states + k, s));
    for r in 0..states {
        for j in 0..s {
            let v = sens.dy[r * s + j];
            if v != 0.0 {
                tri.add_triplet(r, j, v);
            }
        }
    }
    for l in 0..k {
        for j in 0..s {
            let v = sens.d_unknowns[l * s + j];
            if v != 0.0 {
                tri.add_triplet(states + l, j, v);
            }
        }
    }
    tri.to_csc()
}

/// The residual Jacobian `∂r/∂θ` (`N × P`) of a fit at its optimum, from
/// [`FitResult::jacobian`] or, for a block-arrow fit, [`FitResult::block_jacobian`]: then only
/// the block-arrow entries (each block's rows in the shared and its own local parameters) are
/// stored, the structural zeros are not. Exact zeros of a dense Jacobian are left out.
pub fn fit_jacobian(result: &FitResult) -> CsMat<f64> {
    let np = result.p.len();
    let nr = result.residuals.len();
    let mut tri = TriMat::new((nr, np));
    match &result.block_jacobian {
        Some(b) => {
            let s = b.structure();
            for blk in 0..s.num_blocks() {
                for i in s.rows(blk) {
                    for j in (0..s.num_shared()).chain(s.locals(blk)) {
                        tri.add_triplet(i, j, b.get(i, j));
                    }
                }
            }
        }
        None => {
            for i in 0..nr {
                for j in 0..np {
                    let v = result.jacobian[i * np + j];
                    if v != 0.0 {
                        tri.add_triplet(i, j, v);
                    }
                }
            }
        }
    }
    tri.to_csc()
}

//! The discrete collocation system at a given point, for checking a problem's derivatives and
//! for debugging convergence: residual vector and the exact (dual-number) Jacobian, dense.

use crate::collocation::Collocation;
use crate::error::BvpError;
use crate::linear::Pattern;
use crate::mesh;
use crate::problem::Bvp;
use crate::solve::Guess;

/// Residual and Jacobian of the collocation system at `(Y, p)`.
#[derive(Debug, Clone)]
pub struct DiscreteSystem {
    /// Size `m n + k`.
    pub size: usize,
    /// Residuals: `(m-1) n` collocation residuals (interval by interval), then `n + k` boundary
    /// residuals.
    pub residual: Vec<f64>,
    /// Jacobian `∂S/∂(Y, unknowns)`, dense row-major `size × size`.
    pub jacobian: Vec<f64>,
    /// `∂S/∂(model parameters)`, dense row-major `size × q`.
    pub param_jacobian: Vec<f64>,
}

/// Largest dense Jacobian [`discrete_system`] builds, in entries (2^27, 1 GiB of `f64`).
pub const MAX_DENSE_ENTRIES: usize = 1 << 27;

/// Evaluates the discrete system of `problem` at the mesh, states and unknowns of `at`, with
/// model parameters `params`. The Jacobian is dense (`size²` values), so this is meant for
/// small meshes: a system with more than [`MAX_DENSE_ENTRIES`] Jacobian entries is an error,
/// not an allocation failure.
pub fn discrete_system<P: Bvp>(
    problem: &P,
    params: &[f64],
    at: &Guess,
) -> Result<DiscreteSystem, BvpError> {
    let (n, k, q) = (problem.dim(), problem.num_unknowns(), problem.num_params());
    mesh::validate(&at.x)?;
    if at.y.len() != at.x.len() * n || at.unknowns.len() != k || params.len() != q {
        return Err(BvpError::InvalidInput(
            "dimensions of the point do not match the problem".into(),
        ));
    }
    let m = at.x.len();
    let size = m * n + k;
    if size
        .checked_mul(size.max(q))
        .is_none_or(|e| e > MAX_DENSE_ENTRIES)
    {
        return Err(BvpError::InvalidInput(format!(
            "the dense Jacobian of {m} nodes x {n} states (+ {k} unknowns) would have {size}² \
             entries, more than MAX_DENSE_ENTRIES = {MAX_DENSE_ENTRIES}; inspect a coarser mesh"
        )));
    }
    let p: Vec<f64> = at.unknowns.iter().chain(params).copied().collect();
    let mut col = Collocation::new(n, k, q);
    col.set_mesh(&at.x);
    col.residual(problem, &at.y, &p)?;
    col.jacobians(problem, &at.y, &p, k + q)?;
    let pattern = Pattern::new(n, k, m)?;
    let mut values = Vec::new();
    let mut work = Vec::new();
    pattern.assemble(&col, &mut values, &mut work);
    let mut jacobian = vec![0.0; size * size];
    let cp = pattern.symbolic().col_ptr();
    let ri = pattern.symbolic().row_idx();
    for c in 0..size {
        for idx in cp[c]..cp[c + 1] {
            jacobian[ri[idx] * size + c] = values[idx];
        }
    }
    let mut param_jacobian = vec![0.0; size * q];
    let mut column = vec![0.0; size];
    for j in 0..q {
        col.param_column(k + j, &mut column);
        for r in 0..size {
            param_jacobian[r * q + j] = column[r];
        }
    }
    Ok(DiscreteSystem {
        size,
        residual: col.res.clone(),
        jacobian,
        param_jacobian,
    })
}

//! The least-squares response of a fit to a change of its residuals with the model fixed,
//! `Δp = −(JᵀJ)⁻¹ Jᵀ d`: how far the estimate would move (a finer discretisation, an error
//! budget's perturbed input). Dense fits factorise `JᵀJ` once; block-arrow fits go through the
//! Schur complement ([`BlockCovariance`]), linear in the number of blocks.

use super::{BlockCovariance, BlockJacobian, FitResult};
use nalgebra::{DMatrix, DVector};

impl FitResult {
    /// The parameters' least-squares response `Δp = −(JᵀJ)⁻¹ Jᵀ d` to a change `d` of the
    /// residuals with the model's parameters fixed (length `P`; `None` if `JᵀJ` is singular or
    /// `d` has the wrong length). A block-arrow fit computes it through the Schur complement:
    /// time and memory linear in the number of blocks, no `N × P` matrix. For many changes,
    /// prepare the map once with [`linear_response_map`](Self::linear_response_map).
    pub fn linear_response(&self, d: &[f64]) -> Option<Vec<f64>> {
        self.linear_response_map()?.apply(d)
    }

    /// The map `d ↦ −(JᵀJ)⁻¹ Jᵀ d` of [`linear_response`](Self::linear_response), factorised
    /// once (`None` if `JᵀJ` is singular).
    pub fn linear_response_map(&self) -> Option<LinearResponse<'_>> {
        let kind = match &self.block_jacobian {
            Some(j) => ResponseKind::Block {
                j,
                cov: BlockCovariance::linear(j, 1.0)?,
            },
            None => {
                let j = DMatrix::from_row_slice(self.residuals.len(), self.p.len(), &self.jacobian);
                let jt = j.transpose();
                let chol = (&jt * &j).cholesky()?;
                ResponseKind::Dense { jt, chol }
            }
        };
        Some(LinearResponse {
            residuals: self.residuals.len(),
            kind,
        })
    }
}

/// The least-squares response `d ↦ −(JᵀJ)⁻¹ Jᵀ d` of a fit to a change of its residuals,
/// factorised once ([`FitResult::linear_response_map`]): dense (one Cholesky factorisation of
/// `JᵀJ`) or, for a block-arrow fit, through the Schur complement (linear in the blocks).
pub struct LinearResponse<'a> {
    residuals: usize,
    kind: ResponseKind<'a>,
}

enum ResponseKind<'a> {
    Dense {
        jt: DMatrix<f64>,
        chol: nalgebra::Cholesky<f64, nalgebra::Dyn>,
    },
    Block {
        j: &'a BlockJacobian,
        cov: BlockCovariance,
    },
}

impl LinearResponse<'_> {
    /// `−(JᵀJ)⁻¹ Jᵀ d` (length `P`; `None` if `d` does not have one entry per residual).
    pub fn apply(&self, d: &[f64]) -> Option<Vec<f64>> {
        if d.len() != self.residuals {
            return None;
        }
        let x: Vec<f64> = match &self.kind {
            ResponseKind::Dense { jt, chol } => chol
                .solve(&(jt * DVector::from_column_slice(d)))
                .iter()
                .copied()
                .collect(),
            ResponseKind::Block { j, cov } => cov.mul_vec(&j.tr_mul_vec(d)),
        };
        Some(x.into_iter().map(|v| -v).collect())
    }

    /// The first `n_shared` entries of [`apply`](Self::apply) (the shared parameters of a
    /// block-arrow fit come first): for a block fit without the local rows, and a change
    /// confined to a few blocks costs work in those blocks only (besides `Jᵀ d`).
    pub fn apply_shared(&self, d: &[f64], n_shared: usize) -> Option<Vec<f64>> {
        if d.len() != self.residuals {
            return None;
        }
        match &self.kind {
            ResponseKind::Dense { .. } => Some(self.apply(d)?.into_iter().take(n_shared).collect()),
            ResponseKind::Block { j, cov } => Some(
                cov.mul_vec_shared(&j.tr_mul_vec(d))
                    .into_iter()
                    .take(n_shared)
                    .map(|v| -v)
                    .collect(),
            ),
        }
    }
}

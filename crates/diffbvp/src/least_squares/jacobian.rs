//! The Jacobian as a problem evaluates it (dense or block-arrow) and the driver's linear
//! algebra on it: gradient, trust-region step, `J s`.

use super::blocks::{BlockJacobian, BlockStructure};
use super::loss::{self, Loss};
use super::schur::block_trust_region_step;
use super::trust_region_step;
use nalgebra::{DMatrix, DVector};
use std::sync::Arc;

/// A Jacobian `∂r/∂p` as [`LeastSquaresProblem::evaluate_jacobian`](super::LeastSquaresProblem::evaluate_jacobian)
/// returns it.
#[derive(Debug, Clone, PartialEq)]
pub enum Jacobian {
    /// Dense, row-major `N × P`.
    Dense(Vec<f64>),
    /// Block-arrow (shared and per-block local parameters, see [`BlockJacobian`]): the driver
    /// then solves its steps through the Schur complement, in time and memory linear in the
    /// number of blocks.
    Blocks(BlockJacobian),
}

impl Jacobian {
    /// Whether it is an `nr × np` Jacobian.
    pub fn has_shape(&self, nr: usize, np: usize) -> bool {
        match self {
            Jacobian::Dense(j) => j.len() == nr * np,
            Jacobian::Blocks(b) => {
                let s = b.structure();
                s.num_residuals() == nr && s.num_params() == np
            }
        }
    }

    /// Whether every entry is finite.
    pub fn is_finite(&self) -> bool {
        match self {
            Jacobian::Dense(j) => j.iter().all(|v| v.is_finite()),
            Jacobian::Blocks(b) => b.is_finite(),
        }
    }

    /// The block structure, if it is a block-arrow Jacobian.
    pub fn structure(&self) -> Option<&Arc<BlockStructure>> {
        match self {
            Jacobian::Dense(_) => None,
            Jacobian::Blocks(b) => Some(b.structure()),
        }
    }

    /// The dense row-major `N × P` matrix (`np` columns; copies a block-arrow Jacobian into
    /// `N · P` numbers).
    pub fn to_dense(&self) -> Vec<f64> {
        match self {
            Jacobian::Dense(j) => j.clone(),
            Jacobian::Blocks(b) => b.to_dense(),
        }
    }

    /// `‖J s‖` for a step `s` of `np` parameters (`nr` residuals).
    pub(super) fn effect(&self, s: &DVector<f64>, nr: usize, np: usize) -> f64 {
        match self {
            Jacobian::Dense(j) => (&DMatrix::from_row_slice(nr, np, j) * s).norm(),
            Jacobian::Blocks(b) => b
                .mul_vec(s.as_slice())
                .iter()
                .map(|v| v * v)
                .sum::<f64>()
                .sqrt(),
        }
    }

    /// The residuals and Jacobian the Gauss–Newton iteration works on under a robust loss
    /// ([`loss::rescale`]); `None` for the linear loss.
    pub(super) fn rescaled(
        &self,
        loss: Loss,
        f_scale: f64,
        r: &[f64],
        np: usize,
    ) -> Option<(Vec<f64>, Jacobian)> {
        match self {
            Jacobian::Dense(j) => {
                loss::rescale(loss, f_scale, r, j, np).map(|(rs, js)| (rs, Jacobian::Dense(js)))
            }
            Jacobian::Blocks(b) => {
                if loss.is_linear() {
                    return None;
                }
                let w = loss::weights(loss, f_scale, r);
                let rs = w
                    .iter()
                    .zip(r)
                    .map(|((d1, wi), ri)| d1 * ri / wi.sqrt())
                    .collect();
                let f: Vec<f64> = w.iter().map(|(_, wi)| wi.sqrt()).collect();
                let mut js = b.clone();
                js.scale_rows(&f);
                Some((rs, Jacobian::Blocks(js)))
            }
        }
    }
}

/// The linearisation `J s + r` at the iterate, in the form the step computation needs.
pub(super) enum Linearized<'a> {
    Dense { jm: DMatrix<f64>, rv: DVector<f64> },
    Blocks { j: &'a BlockJacobian, r: &'a [f64] },
}

impl<'a> Linearized<'a> {
    /// The linearisation of `jac` (`nr × np`) and `r`.
    pub(super) fn new(jac: &'a Jacobian, r: &'a [f64], nr: usize, np: usize) -> Self {
        match jac {
            Jacobian::Dense(j) => Linearized::Dense {
                jm: DMatrix::from_row_slice(nr, np, j),
                rv: DVector::from_column_slice(r),
            },
            Jacobian::Blocks(j) => Linearized::Blocks { j, r },
        }
    }

    /// The gradient `Jᵀ r`.
    pub(super) fn gradient(&self) -> DVector<f64> {
        match self {
            Linearized::Dense { jm, rv } => jm.transpose() * rv,
            Linearized::Blocks { j, r } => DVector::from_vec(j.tr_mul_vec(r)),
        }
    }

    /// The trust-region step `min ‖J s + r‖²`, `‖D s‖ ≤ Δ`.
    pub(super) fn step(&self, d: &[f64], radius: f64) -> DVector<f64> {
        match self {
            Linearized::Dense { jm, rv } => trust_region_step(jm, rv, d, radius),
            Linearized::Blocks { j, r } => {
                DVector::from_vec(block_trust_region_step(j, r, d, radius))
            }
        }
    }

    /// The relative offset of Bates and Watts at this linearisation:
    /// `(‖J s‖/√P) / (‖r + J s‖/√(N − P))` for the Gauss–Newton step `s` (`step(d, ∞)`; the
    /// scaling `d` does not change it where `JᵀJ` is regular). `0` where the residuals vanish
    /// with the step; `N ≤ P` counts as one degree of freedom.
    pub(super) fn relative_offset(&self, s: &DVector<f64>, nr: usize, np: usize) -> f64 {
        let (js, r): (Vec<f64>, &[f64]) = match self {
            Linearized::Dense { jm, rv } => ((jm * s).iter().copied().collect(), rv.as_slice()),
            Linearized::Blocks { j, r } => (j.mul_vec(s.as_slice()), *r),
        };
        let along: f64 = js.iter().map(|v| v * v).sum::<f64>().sqrt();
        let across: f64 = js
            .iter()
            .zip(r)
            .map(|(a, b)| (a + b) * (a + b))
            .sum::<f64>()
            .sqrt();
        let dof = nr.saturating_sub(np).max(1) as f64;
        let scatter = across / dof.sqrt();
        if scatter > 0.0 {
            along / (np.max(1) as f64).sqrt() / scatter
        } else if along > 0.0 {
            f64::INFINITY
        } else {
            0.0
        }
    }

    /// The predicted reduction `−(rᵀ J s + ½‖J s‖²)` of `½‖J s + r‖²`.
    pub(super) fn predicted_reduction(&self, s: &DVector<f64>) -> f64 {
        match self {
            Linearized::Dense { jm, rv } => {
                let jr = jm * s;
                -(jr.dot(rv) + 0.5 * jr.norm_squared())
            }
            Linearized::Blocks { j, r } => {
                let jr = j.mul_vec(s.as_slice());
                let dot: f64 = jr.iter().zip(r.iter()).map(|(a, b)| a * b).sum();
                let sq: f64 = jr.iter().map(|v| v * v).sum();
                -(dot + 0.5 * sq)
            }
        }
    }
}

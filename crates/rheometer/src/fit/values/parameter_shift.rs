//! How the fitted parameters move when the model changes with the data fixed: the linear map
//! `dθ/dq = −(JᵀJ)⁻¹ Jᵀ ∂r/∂q` at a fit from its dense Jacobian, for the detection limits of
//! `diagnose` (the bias an undetected effect causes). A fit's own map, linear in the number of
//! experiments for a block-arrow fit, is
//! [`FitResult::linear_response_map`](diffbvp::least_squares::FitResult::linear_response_map)
//! (the [error budget](crate::fit::error_budget()) and the discretisation check use it).

use crate::fit::options::RheometerError;
use nalgebra::{DMatrix, DVector};

/// The linear map from a residual column `∂r/∂q` to the fitted parameters' derivative
/// `dθ/dq = −(JᵀJ)⁻¹ Jᵀ ∂r/∂q` (one Cholesky factorisation of `JᵀJ`, reused for every column):
/// how the estimate moves when the model's `q` changes by one unit with the data fixed. A fit
/// that leaves out an effect present in the data with strength `s` is therefore biased by
/// `−s dθ/dq` (first order).
#[derive(Debug, Clone)]
pub struct ParameterShift {
    xt: DMatrix<f64>,
    chol: nalgebra::Cholesky<f64, nalgebra::Dyn>,
}

impl ParameterShift {
    /// From the residual Jacobian `x` (`n_res × q`, row-major) at the fit. Errors if `JᵀJ` is
    /// singular (the fit's parameters are not determined) or the sizes do not match.
    pub fn new(x: &[f64], n_res: usize, q: usize) -> Result<Self, RheometerError> {
        if x.len() != n_res * q {
            return Err(RheometerError::Data(format!(
                "parameter shift: a Jacobian of {} entries is not {n_res} × {q}",
                x.len()
            )));
        }
        let xm = DMatrix::from_row_slice(n_res, q, x);
        let xt = xm.transpose();
        let chol = (&xt * &xm).cholesky().ok_or_else(|| {
            RheometerError::Data(
                "JᵀJ of the fit is singular (the fit's parameters are not determined)".into(),
            )
        })?;
        Ok(ParameterShift { xt, chol })
    }

    /// `dθ/dq` (length `q`) for the residual column `c = ∂r/∂q` (length `n_res`).
    pub fn derivative(&self, c: &DVector<f64>) -> DVector<f64> {
        -self.chol.solve(&(&self.xt * c))
    }
}

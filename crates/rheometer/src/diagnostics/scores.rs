//! Linearised scores of candidate effects at a fitted model.
//!
//! With the residual vector `r` at the fit (length `N`), the Jacobian `X` of the fitted
//! parameters and a candidate's sensitivity direction `c = ∂r/∂(strength)` (exact, from forward
//! sensitivities), the candidate's **orthogonalised signature** is `c⊥ = (I − Q Qᵀ) c`
//! (`X = Q R`): what the effect does to the residuals that no refit of the present parameters can
//! mimic. Its Gauss–Newton predicted cost reduction is the **score**
//! `(r·c⊥)²/‖c⊥‖²` and its linearised strength `−(r·c⊥)/‖c⊥‖²`. Two candidates whose signatures
//! have a cosine near ±1 cannot be told apart by the data.

use nalgebra::DMatrix;

/// A candidate's linearised numbers.
#[derive(Debug, Clone)]
pub struct LinearScore {
    /// Predicted reduction of `J = ‖r‖²`.
    pub score: f64,
    /// Linearised strength.
    pub strength: f64,
    /// `‖c⊥‖` (0: the effect is invisible once the fitted parameters adapt).
    pub norm: f64,
    /// The orthogonalised signature `c⊥` (length `N`).
    pub signature: Vec<f64>,
}

/// Scores of the candidate columns `cands` (each length `N`) against residuals `r` with the
/// fitted parameters' Jacobian `x` (`N × q`, row-major).
pub fn linear_scores(r: &[f64], x: &[f64], q: usize, cands: &[Vec<f64>]) -> Vec<LinearScore> {
    let n = r.len();
    let q_mat = if q > 0 {
        let xm = DMatrix::from_row_slice(n, q, x);
        Some(xm.qr().q())
    } else {
        None
    };
    cands
        .iter()
        .map(|c| {
            let mut cp = nalgebra::DVector::from_column_slice(c);
            if let Some(qm) = &q_mat {
                let proj = qm.transpose() * &cp;
                cp -= qm * proj;
            }
            let norm2 = cp.norm_squared();
            let rc: f64 = cp.iter().zip(r).map(|(a, b)| a * b).sum();
            let (score, strength) = if norm2 > 0.0 && norm2.is_finite() {
                (rc * rc / norm2, -rc / norm2)
            } else {
                (0.0, 0.0)
            };
            LinearScore {
                score,
                strength,
                norm: norm2.sqrt(),
                signature: cp.iter().copied().collect(),
            }
        })
        .collect()
}

/// Cosine between two signatures (0 if one vanishes).
pub fn cosine(a: &[f64], b: &[f64]) -> f64 {
    let ab: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let na: f64 = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    let nb: f64 = b.iter().map(|x| x * x).sum::<f64>().sqrt();
    if na > 0.0 && nb > 0.0 {
        ab / (na * nb)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn score_is_the_least_squares_reduction() {
        // r = 2 c + x-direction: the x part is already fitted, the c part is explained
        let x = vec![1.0, 1.0, 1.0, 1.0];
        let c = vec![1.0, -1.0, 2.0, 0.0];
        let cbar = 0.5;
        let r: Vec<f64> = c.iter().map(|v| -2.0 * (v - cbar)).collect();
        let s = &linear_scores(&r, &x, 1, &[c])[0];
        let rr: f64 = r.iter().map(|v| v * v).sum();
        assert!((s.score - rr).abs() < 1e-12 * rr);
        assert!((s.strength - 2.0).abs() < 1e-12);
    }
}

//! From an information matrix to what a rheologist reads: the predicted covariance, standard
//! errors and correlation of the fitted parameters, and the three classical design criteria,
//! made unit-free by the current standard errors.
//!
//! With `C` the predicted covariance and `S = diag(current standard errors)`, the scaled
//! covariance `C̃ = S⁻¹ C S⁻¹` is the identity-diagonal for the current data:
//!
//! * **D**: `ln det I` gain over the current data (`ln det C_now − ln det C`): the confidence
//!   region's volume shrinks by `exp(−D/2)`;
//! * **A**: `tr C̃ / p`, the mean ratio of new to current variance (1 now, smaller is better);
//! * **E**: the largest eigenvalue of `C̃`, the worst direction's variance ratio.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Which criterion ranks the candidates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Criterion {
    /// D-optimal: the largest gain in `ln det` of the information (default).
    #[default]
    D,
    /// A-optimal: the smallest mean variance ratio.
    A,
    /// E-optimal: the smallest worst-direction variance ratio.
    E,
}

impl Criterion {
    /// `"D"`, `"A"` or `"E"`.
    pub fn name(&self) -> &'static str {
        match self {
            Criterion::D => "D",
            Criterion::A => "A",
            Criterion::E => "E",
        }
    }

    /// Parses `d`, `a` or `e` (any case).
    pub fn parse(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "d" => Ok(Criterion::D),
            "a" => Ok(Criterion::A),
            "e" => Ok(Criterion::E),
            other => Err(format!(
                "unknown design criterion '{other}': use d (volume of the confidence region), \
                 a (mean variance) or e (worst direction)"
            )),
        }
    }
}

/// The predicted uncertainty of the fitted shared parameters for one set of experiments (JSON:
/// `NaN` written as `null`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Prediction {
    /// Predicted standard errors, in the order of the design's parameter names (model units).
    pub stderr: Vec<f64>,
    /// Predicted correlation of `n` and `κ` (`NaN` when either is not fitted).
    pub correlation_n_kappa: f64,
    /// `ln det` gain of the information over the current data \[-\] (0 for the current data).
    pub d_gain: f64,
    /// Mean ratio of new to current variance \[-\] (1 for the current data).
    pub a_ratio: f64,
    /// Largest eigenvalue of the scaled covariance \[-\] (1 or more for the current data).
    pub e_ratio: f64,
}

impl Prediction {
    /// The score of `criterion` (larger is better).
    pub fn score(&self, criterion: Criterion) -> f64 {
        match criterion {
            Criterion::D => self.d_gain,
            Criterion::A => -self.a_ratio,
            Criterion::E => -self.e_ratio,
        }
    }

    /// The predicted gain under `criterion` in words' numbers: the relative shrink \[-\] of the
    /// confidence-region volume (D), of the mean variance (A), of the worst variance (E).
    pub fn gain(&self, criterion: Criterion, current: &Prediction) -> f64 {
        match criterion {
            Criterion::D => 1.0 - (-0.5 * self.d_gain).exp(),
            Criterion::A => 1.0 - self.a_ratio / current.a_ratio,
            Criterion::E => 1.0 - self.e_ratio / current.e_ratio,
        }
    }
}

/// The inverse of a symmetric positive definite matrix and its `ln det`, `None` when it is
/// not positive definite.
fn spd_inverse(m: &DMatrix<f64>) -> Option<(DMatrix<f64>, f64)> {
    let ch = m.clone().cholesky()?;
    let logdet = 2.0 * ch.l().diagonal().iter().map(|v| v.ln()).sum::<f64>();
    Some((ch.inverse(), logdet))
}

/// The reference of the scaled criteria: the information of the current data.
#[derive(Debug, Clone)]
pub struct Reference {
    logdet: f64,
    se: Vec<f64>,
    n_kappa: Option<(usize, usize)>,
}

/// The covariance `A⁻¹ B A⁻¹` \[unit²\] of a fit whose information is `a` and whose score's
/// covariance under the real noise is `b` (both `p × p` row-major; see
/// `information`); `None` when `a` is not positive definite.
pub(crate) fn sandwich(a: &[f64], b: &[f64], p: usize) -> Option<Vec<f64>> {
    let (ai, _) = spd_inverse(&DMatrix::from_row_slice(p, p, a))?;
    let c = &ai * DMatrix::from_row_slice(p, p, b) * &ai;
    // symmetric by construction; rounding made exact so that Cholesky sees a symmetric matrix
    let c = (&c + c.transpose()) * 0.5;
    Some(c.transpose().as_slice().to_vec())
}

impl Reference {
    /// The reference for the current information `info` (`p × p` row-major) with the parameter
    /// `names`; `None` when the current data do not determine every parameter (singular).
    pub fn new(info: &[f64], names: &[String]) -> Option<Self> {
        let p = names.len();
        let (cov, _) = spd_inverse(&DMatrix::from_row_slice(p, p, info))?;
        Self::from_covariance(cov.transpose().as_slice(), names)
    }

    /// The reference for the current covariance `cov` \[unit²\] (`p × p` row-major) with the
    /// parameter `names`; `None` when it is not positive definite.
    pub fn from_covariance(cov: &[f64], names: &[String]) -> Option<Self> {
        let p = names.len();
        let (_, logdet_cov) = spd_inverse(&DMatrix::from_row_slice(p, p, cov))?;
        let se = (0..p).map(|i| cov[i * p + i].sqrt()).collect();
        let n = names.iter().position(|s| s == "n");
        let k = names.iter().position(|s| s == "kappa");
        Some(Reference {
            logdet: -logdet_cov,
            se,
            n_kappa: n.zip(k),
        })
    }

    /// The prediction for information `info` (`p × p` row-major), `None` when singular.
    pub fn predict(&self, info: &[f64]) -> Option<Prediction> {
        let p = self.se.len();
        let (cov, _) = spd_inverse(&DMatrix::from_row_slice(p, p, info))?;
        self.predict_covariance(cov.transpose().as_slice())
    }

    /// The prediction for the covariance `cov` \[unit²\] (`p × p` row-major), `None` when it is
    /// not positive definite. The D-criterion reads `ln det C⁻¹` as the information's
    /// `ln det`.
    pub fn predict_covariance(&self, cov: &[f64]) -> Option<Prediction> {
        let p = self.se.len();
        let cov = DMatrix::from_row_slice(p, p, cov);
        let (_, logdet_cov) = spd_inverse(&cov)?;
        let logdet = -logdet_cov;
        let stderr: Vec<f64> = (0..p).map(|i| cov[(i, i)].sqrt()).collect();
        let scaled = DMatrix::from_fn(p, p, |i, j| cov[(i, j)] / (self.se[i] * self.se[j]));
        let a_ratio = scaled.trace() / p as f64;
        let e_ratio = scaled
            .symmetric_eigen()
            .eigenvalues
            .iter()
            .fold(f64::NAN, |a, &b| a.max(b));
        let correlation_n_kappa = self
            .n_kappa
            .map_or(f64::NAN, |(i, j)| cov[(i, j)] / (stderr[i] * stderr[j]));
        Some(Prediction {
            stderr,
            correlation_n_kappa,
            d_gain: logdet - self.logdet,
            a_ratio,
            e_ratio,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_predicts_itself_and_a_doubled_information_halves_variances() {
        let names = vec!["n".to_string(), "kappa".to_string()];
        let info = [400.0, -150.0, -150.0, 100.0];
        let r = Reference::new(&info, &names).unwrap();
        let now = r.predict(&info).unwrap();
        assert!(now.d_gain.abs() < 1e-12);
        assert!((now.a_ratio - 1.0).abs() < 1e-12);
        // the scaled covariance has unit diagonal and off-diagonal ρ: eigenvalues 1 ± |ρ|
        assert!((now.e_ratio - (1.0 + now.correlation_n_kappa.abs())).abs() < 1e-12);
        let det: f64 = 400.0 * 100.0 - 150.0 * 150.0;
        assert!((now.stderr[0] - (100.0 / det).sqrt()).abs() < 1e-12);
        let twice: Vec<f64> = info.iter().map(|v| 2.0 * v).collect();
        let p = r.predict(&twice).unwrap();
        assert!((p.d_gain - 2.0 * 2f64.ln()).abs() < 1e-12);
        assert!((p.a_ratio - 0.5).abs() < 1e-12);
        assert!((p.gain(Criterion::D, &now) - 0.5).abs() < 1e-12);
        assert!(Reference::new(&[1.0, 1.0, 1.0, 1.0], &names).is_none());
        // the sandwich with B = A is A⁻¹, and a noise twice the fit's level quadruples it
        let same = sandwich(&info, &info, 2).unwrap();
        let q = r.predict_covariance(&same).unwrap();
        assert!((q.stderr[0] - now.stderr[0]).abs() < 1e-12 * now.stderr[0]);
        let four: Vec<f64> = info.iter().map(|v| 4.0 * v).collect();
        let q = r
            .predict_covariance(&sandwich(&info, &four, 2).unwrap())
            .unwrap();
        assert!((q.stderr[1] / now.stderr[1] - 2.0).abs() < 1e-12);
        assert_eq!(Criterion::parse(" E ").unwrap(), Criterion::E);
        assert!(Criterion::parse("x")
            .unwrap_err()
            .contains("unknown design criterion"));
    }
}

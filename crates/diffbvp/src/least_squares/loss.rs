//! Robust losses for [`fit`](super::fit), as scipy's `least_squares` defines them: the cost is
//! `F(p) = ½ C² Σ ρ(zᵢ)`, `zᵢ = (rᵢ/C)²`, with the soft margin `C` ([`Loss`]'s `f_scale`) and
//!
//! | loss | `ρ(z)` |
//! |---|---|
//! | [`Loss::Linear`] | `z` (ordinary least squares, `F = ½‖r‖²`) |
//! | [`Loss::SoftL1`] | `2(√(1+z) − 1)` |
//! | [`Loss::Huber`] | `z` for `z ≤ 1`, else `2√z − 1` |
//! | [`Loss::Cauchy`] | `ln(1 + z)` |
//!
//! The trust-region driver stays Gauss–Newton on rescaled residuals and Jacobian (the approach
//! of scipy's `least_squares`, Triggs et al., *Bundle adjustment — a modern synthesis*, 1999):
//! with `ρ'`, `ρ''` at `zᵢ` and `wᵢ = max(ρ' + 2ρ'' zᵢ, ε)`,
//! `r̃ᵢ = ρ' rᵢ/√wᵢ` and `J̃ᵢ = √wᵢ Jᵢ`, so that `J̃ᵀr̃ = Σ ρ' rᵢ Jᵢ = ∇F` exactly and `J̃ᵀJ̃` is
//! the Gauss–Newton Hessian of `F` (its negative curvature, possible for Cauchy beyond
//! `z = 1`, clipped at `ε`).
//!
//! `Loss::Linear` leaves residuals and Jacobian untouched (bit for bit the plain driver).

use std::fmt;

/// Floor of the Gauss–Newton weight `ρ' + 2ρ''z` (scipy's `EPS`).
const WEIGHT_FLOOR: f64 = f64::EPSILON;

/// The loss `ρ(z)` of the residuals (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case")
)]
pub enum Loss {
    /// `ρ(z) = z`: ordinary least squares.
    #[default]
    Linear,
    /// `ρ(z) = 2(√(1+z) − 1)`: smooth L1.
    SoftL1,
    /// `ρ(z) = z` (z ≤ 1), `2√z − 1` (z > 1).
    Huber,
    /// `ρ(z) = ln(1 + z)`: strongly suppresses outliers; the cost is not convex.
    Cauchy,
}

impl Loss {
    /// The name as on the command line and in JSON (`linear`, `soft_l1`, `huber`, `cauchy`).
    pub fn name(&self) -> &'static str {
        match self {
            Loss::Linear => "linear",
            Loss::SoftL1 => "soft_l1",
            Loss::Huber => "huber",
            Loss::Cauchy => "cauchy",
        }
    }

    /// Parses [`name`](Self::name) (also `soft-l1`).
    pub fn parse(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().replace('-', "_").as_str() {
            "linear" => Ok(Loss::Linear),
            "soft_l1" => Ok(Loss::SoftL1),
            "huber" => Ok(Loss::Huber),
            "cauchy" => Ok(Loss::Cauchy),
            _ => Err(format!(
                "unknown loss {s:?}: use linear, soft_l1, huber or cauchy"
            )),
        }
    }

    /// `(ρ(z), ρ'(z), ρ''(z))`.
    pub fn rho(&self, z: f64) -> (f64, f64, f64) {
        match self {
            Loss::Linear => (z, 1.0, 0.0),
            Loss::SoftL1 => {
                let t = 1.0 + z;
                (2.0 * (t.sqrt() - 1.0), t.powf(-0.5), -0.5 * t.powf(-1.5))
            }
            Loss::Huber => {
                if z <= 1.0 {
                    (z, 1.0, 0.0)
                } else {
                    let q = z.sqrt();
                    (2.0 * q - 1.0, 1.0 / q, -0.5 / (z * q))
                }
            }
            Loss::Cauchy => {
                let t = 1.0 + z;
                (t.ln(), 1.0 / t, -1.0 / (t * t))
            }
        }
    }

    /// Whether this is [`Loss::Linear`].
    pub fn is_linear(&self) -> bool {
        *self == Loss::Linear
    }
}

impl fmt::Display for Loss {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The cost `½ C² Σ ρ((rᵢ/C)²)` (`½‖r‖²` for the linear loss).
pub fn robust_cost(loss: Loss, f_scale: f64, r: &[f64]) -> f64 {
    if loss.is_linear() {
        return 0.5 * r.iter().map(|v| v * v).sum::<f64>();
    }
    let c2 = f_scale * f_scale;
    0.5 * c2 * r.iter().map(|v| loss.rho(v * v / c2).0).sum::<f64>()
}

/// Per residual: `(ρ'(zᵢ), wᵢ = max(ρ' + 2ρ''zᵢ, ε))`.
pub fn weights(loss: Loss, f_scale: f64, r: &[f64]) -> Vec<(f64, f64)> {
    let c2 = f_scale * f_scale;
    r.iter()
        .map(|v| {
            let z = v * v / c2;
            let (_, d1, d2) = loss.rho(z);
            (d1, (d1 + 2.0 * d2 * z).max(WEIGHT_FLOOR))
        })
        .collect()
}

/// The rescaled residuals and Jacobian (row-major, `np` columns) the Gauss–Newton iteration
/// works on (see the module docs); `None` for the linear loss (use `r`, `jac` as they are).
pub fn rescale(
    loss: Loss,
    f_scale: f64,
    r: &[f64],
    jac: &[f64],
    np: usize,
) -> Option<(Vec<f64>, Vec<f64>)> {
    if loss.is_linear() {
        return None;
    }
    let w = weights(loss, f_scale, r);
    let mut rs = Vec::with_capacity(r.len());
    let mut js = jac.to_vec();
    for (i, ((d1, wi), ri)) in w.iter().zip(r).enumerate() {
        let sw = wi.sqrt();
        rs.push(d1 * ri / sw);
        for v in &mut js[i * np..(i + 1) * np] {
            *v *= sw;
        }
    }
    Some((rs, js))
}

/// Number of residuals with `|rᵢ| > C` (`z > 1`: where a robust loss down-weights; 0 for the
/// linear loss).
pub fn down_weighted(loss: Loss, f_scale: f64, r: &[f64]) -> usize {
    if loss.is_linear() {
        return 0;
    }
    r.iter().filter(|v| v.abs() > f_scale).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_match_finite_differences() {
        for loss in [Loss::SoftL1, Loss::Huber, Loss::Cauchy] {
            for z in [0.3, 0.9, 2.0, 7.5] {
                let h = 1e-6;
                let (r0, d1, d2) = loss.rho(z);
                let (rp, d1p, _) = loss.rho(z + h);
                let (rm, d1m, _) = loss.rho(z - h);
                assert!(((rp - rm) / (2.0 * h) - d1).abs() < 1e-6, "{loss} {z}");
                assert!(((d1p - d1m) / (2.0 * h) - d2).abs() < 1e-5, "{loss} {z}");
                assert!(r0 <= z + 1e-15);
            }
        }
    }

    #[test]
    fn rescaled_gradient_is_the_robust_gradient() {
        let r = [0.1, -3.0, 0.5];
        let jac = [1.0, 2.0, -1.0];
        let (rs, js) = rescale(Loss::SoftL1, 0.5, &r, &jac, 1).unwrap();
        let g: f64 = rs.iter().zip(&js).map(|(a, b)| a * b).sum();
        let h = 1e-7;
        let f = |t: f64| {
            let rr: Vec<f64> = r.iter().zip(&jac).map(|(a, b)| a + t * b).collect();
            robust_cost(Loss::SoftL1, 0.5, &rr)
        };
        assert!((g - (f(h) - f(-h)) / (2.0 * h)).abs() < 1e-6);
        assert!(rescale(Loss::Linear, 1.0, &r, &jac, 1).is_none());
        assert_eq!(Loss::parse("soft-l1").unwrap(), Loss::SoftL1);
        assert!(Loss::parse("arctan").is_err());
    }
}

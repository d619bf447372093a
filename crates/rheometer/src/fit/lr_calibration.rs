//! The calibrated reference distribution of the likelihood-ratio test against the Newtonian
//! law. Under the Newtonian law (`n = 1`) `κ` does not enter, so the statistic
//! `LR = (J_N − J)/σ̂²` is the largest over `κ` of one-sided tests for strain thinning (Davies
//! 1987), and the boundary mixture `½χ²₀ + ½χ²₁` of one `κ` makes its p-value too small.
//!
//! To first order about the Newtonian fit, thinning that sets in at `K = e^κ` changes the
//! residuals along `d(κ) = −∂r/∂n` at `n = 1` (the Carreau-type law's derivative at `n = 1`,
//! `−½ μ_e0 ln(1 + (μ_e0 ε̇/K)²)`, depends on `κ`; `K` beyond the data's stresses gives the
//! shape `ε̇²` of the other Newtonian corner, `n → 0`). With the nuisance parameters (take-up
//! factors, effect strengths and shapes) projected out, `u(κ) = d⊥/‖d⊥‖`, the statistic under
//! the Newtonian law is `LR ≈ max_κ max(0, u(κ)·z)²`, `z` standard normal. Its distribution is
//! simulated over a grid of `κ` (spacing [`KAPPA_STEP`], up to a few units beyond the data's
//! stresses, where the shape no longer changes) with [`REPLICATES`] draws: one residual and
//! Jacobian evaluation at the Newtonian fit per grid point, the draws themselves a few
//! milliseconds.

use super::data::Rheometer;
use super::identify::identification::Identification;
use super::layout::FitStart;
use super::objective::Objective;
use super::options::{IdentifyOptions, RheometerError};
use crate::data::synthetic::SplitMix64;
use diffbvp::least_squares::LeastSquaresProblem;
use nalgebra::{DMatrix, DVector};

/// Draws of the simulated reference distribution.
pub(crate) const REPLICATES: usize = 4000;
/// Spacing of the grid of `κ` \[-\] (a factor 1.65 in `K`).
const KAPPA_STEP: f64 = 0.5;
/// Seed of the draws (the calibration is reproducible).
const SEED: u64 = 0x0065_0002;

/// The calibrated p-value \[-\] of the statistic `lr` against the Newtonian fit `newtonian`
/// (`strengths` its effects' strengths and shapes by name), over `κ` in `kappa_range`;
/// `None` where no column of the grid could be evaluated.
pub(crate) fn calibrated_p(
    rh: &Rheometer,
    newtonian: &Identification,
    strengths: &[(String, f64)],
    options: &IdentifyOptions,
    kappa_range: [f64; 2],
    lr: f64,
) -> Result<Option<f64>, RheometerError> {
    let start = FitStart {
        law: [1.0, kappa_range[1]],
        free_candidates: Vec::new(),
        strengths: strengths.to_vec(),
        warm: Some(newtonian.solutions.clone()),
    };
    let take_up = newtonian.take_up_factors().to_vec();
    let mut obj = rh.objective_at_take_up(&start, options, &take_up, true)?;
    let Some(directions) = directions(&mut obj, &take_up, kappa_range) else {
        return Ok(None);
    };
    Ok(Some(p_of(&directions, lr)))
}

/// The unit directions `u(κ)` (each of length `N`) over the grid, nuisance projected out;
/// `None` without any.
fn directions(
    obj: &mut Objective<'_>,
    take_up: &[f64],
    kappa_range: [f64; 2],
) -> Option<Vec<DVector<f64>>> {
    let names = obj.layout().names.clone();
    let col_n = names.iter().position(|n| n == "n")?;
    let col_k = names.iter().position(|n| n == "kappa");
    let ns = obj.layout().num_shared();
    let mut p = obj.initial_parameters();
    if p.len() == ns + take_up.len() {
        p[ns..].copy_from_slice(take_up);
    }
    p[col_n] = 1.0;
    let np = p.len();
    let [lo, hi] = kappa_range;
    let count = ((hi - lo) / KAPPA_STEP).floor().max(0.0) as usize + 1;
    let mut columns: Vec<DVector<f64>> = Vec::new();
    let mut basis: Option<DMatrix<f64>> = None;
    for k in 0..count {
        if let Some(c) = col_k {
            p[c] = lo + KAPPA_STEP * k as f64;
        }
        let Ok((r, jac)) = obj.evaluate(&p) else {
            continue;
        };
        let m = r.len();
        if jac.len() != m * np {
            continue;
        }
        let q = basis.get_or_insert_with(|| {
            let keep: Vec<usize> = (0..np)
                .filter(|&j| j != col_n && Some(j) != col_k)
                .collect();
            orthonormal(&DMatrix::from_fn(m, keep.len(), |i, j| {
                jac[i * np + keep[j]]
            }))
        });
        let d = DVector::from_fn(m, |i, _| -jac[i * np + col_n]);
        let d = &d - &*q * (q.transpose() * &d);
        let norm = d.norm();
        if norm.is_finite() && norm > 0.0 {
            columns.push(d / norm);
        }
    }
    (!columns.is_empty()).then_some(columns)
}

/// The orthonormal basis of the columns of `x` (singular values above `1e-12` of the largest).
fn orthonormal(x: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, q) = x.shape();
    if m == 0 || q == 0 {
        return DMatrix::zeros(m, 0);
    }
    let svd = x.clone().svd(true, false);
    let Some(u) = svd.u else {
        return DMatrix::zeros(m, 0);
    };
    let smax = svd.singular_values.iter().copied().fold(0.0, f64::max);
    let keep: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&i| svd.singular_values[i] > 1e-12 * smax)
        .collect();
    DMatrix::from_fn(m, keep.len(), |r, c| u[(r, keep[c])])
}

/// `(1 + #{LR* ≥ lr})/(B + 1)` over [`REPLICATES`] draws `LR* = max_κ max(0, u(κ)·z)²`.
fn p_of(directions: &[DVector<f64>], lr: f64) -> f64 {
    let m = directions[0].len();
    let mut rng = SplitMix64::new(SEED);
    let mut z = DVector::zeros(m);
    let mut exceed = 0usize;
    for _ in 0..REPLICATES {
        for v in z.iter_mut() {
            *v = rng.normal();
        }
        let best = directions
            .iter()
            .map(|u| u.dot(&z).max(0.0).powi(2))
            .fold(0.0, f64::max);
        if best >= lr {
            exceed += 1;
        }
    }
    (1 + exceed) as f64 / (REPLICATES + 1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One direction: the statistic is `max(0, z₁)²`, whose tail is `½ P(χ²₁ > lr)`.
    #[test]
    fn one_direction_gives_the_boundary_mixture() {
        let u = DVector::from_fn(5, |i, _| if i == 0 { 1.0 } else { 0.0 });
        for lr in [0.5, 2.71, 3.84] {
            let p = p_of(std::slice::from_ref(&u), lr);
            let exact = 0.5 * crate::data::statistics::chi2_1_survival(lr);
            assert!((p - exact).abs() < 0.015, "{lr}: {p} vs {exact}");
        }
    }

    /// Two orthogonal directions: the largest of two independent one-sided tests,
    /// `1 − (1 − ½P(χ²₁ > lr))²`, larger than one alone.
    #[test]
    fn orthogonal_directions_raise_the_p_value() {
        let e = |k: usize| DVector::from_fn(4, |i, _| if i == k { 1.0 } else { 0.0 });
        let lr = 2.71;
        let one = 0.5 * crate::data::statistics::chi2_1_survival(lr);
        let p = p_of(&[e(0), e(1)], lr);
        let exact = 1.0 - (1.0 - one) * (1.0 - one);
        assert!(
            (p - exact).abs() < 0.015 && p > one + 0.02,
            "{p} vs {exact}"
        );
    }
}

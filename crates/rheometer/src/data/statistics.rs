//! Statistics of relative residuals: noise estimates, the Wald–Wolfowitz runs test, lag-1
//! autocorrelation and Spearman rank correlation. One home for the statistics the rheometer
//! (its fit report and data checks), the comparison (`diagnostics::compare`) and the diagnosis
//! (`diagnostics::diagnose`) compute; tail probabilities of the F distribution in
//! `distributions`.
//!
//! The noise model of record is [`NoiseModel`](crate::data::noise_model::NoiseModel) (robust
//! scale, scale along the line, outliers, one lag-1 autocorrelation, the judgement numbers);
//! this module holds the building blocks it and the tests share.

pub(crate) mod distributions;

use serde::{Deserialize, Serialize};

/// `1/Φ⁻¹(3/4)`: turns a median absolute deviation into a normal standard deviation.
const MAD_TO_SD: f64 = 1.482_602_218_505_602;

/// Complementary error function `erfc(x)` (Chebyshev fit of Press et al., relative error below
/// 1.2e-7 everywhere).
pub(crate) fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// `P(χ²₁ > x)` \[-\] for the χ² distribution with one degree of freedom (`1` for `x ≤ 0`).
pub(crate) fn chi2_1_survival(x: f64) -> f64 {
    if x <= 0.0 {
        1.0
    } else {
        erfc((0.5 * x).sqrt())
    }
}

/// Median of `v` (`NaN` if empty); `v` is reordered.
pub fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// Robust standard deviation `1.4826 · median |v − median v|` (`NaN` if empty).
pub(crate) fn robust_sd(v: &[f64]) -> f64 {
    let mut w = v.to_vec();
    let med = median(&mut w);
    let mut dev: Vec<f64> = v.iter().map(|x| (x - med).abs()).collect();
    MAD_TO_SD * median(&mut dev)
}

/// Normalised second differences of one experiment's residuals `r` at positions `s`.
///
/// For consecutive points `i−1, i, i+1` with spacings `h₁ = s_i − s_{i−1}`, `h₂ = s_{i+1} − s_i`
/// the combination `e = (h₂ r_{i−1} − (h₁ + h₂) r_i + h₁ r_{i+1}) / ‖(h₂, h₁ + h₂, h₁)‖` vanishes
/// for any residual linear in `s` and has the variance `σ²` of independent noise of standard
/// deviation `σ`. A smooth systematic residual therefore drops out (to second order).
pub(crate) fn second_differences(s: &[f64], r: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    for i in 1..r.len().saturating_sub(1) {
        let h1 = s[i] - s[i - 1];
        let h2 = s[i + 1] - s[i];
        let w = [h2, -(h1 + h2), h1];
        let norm = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
        if norm > 0.0 {
            out.push((w[0] * r[i - 1] + w[1] * r[i] + w[2] * r[i + 1]) / norm);
        }
    }
    out
}

/// The Wald–Wolfowitz runs test on the signs of residuals.
///
/// With `n₊` positive and `n₋` negative residuals (exact zeros are left out) and `R` runs of
/// equal sign, `μ = 2 n₊ n₋ / n + 1`, `var = (μ − 1)(μ − 2)/(n − 1)` and `z = (R − μ)/√var`.
/// White noise gives `z ≈ N(0, 1)`; a smooth systematic residual gives too few runs, `z ≪ 0`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct RunsTest {
    /// Number of runs `R`.
    pub runs: usize,
    /// Positive residuals `n₊`.
    pub positive: usize,
    /// Negative residuals `n₋`.
    pub negative: usize,
    /// Expected number of runs `μ` for random signs.
    pub expected: f64,
    /// Variance of the number of runs for random signs.
    pub variance: f64,
    /// `z = (R − μ)/√var` (`NaN` if the variance is 0, e.g. all residuals of one sign).
    pub z: f64,
}

impl RunsTest {
    /// The test on one sequence of residuals (in order along the spin line).
    pub fn of(r: &[f64]) -> Self {
        let signs: Vec<bool> = r.iter().filter(|v| **v != 0.0).map(|v| *v > 0.0).collect();
        let positive = signs.iter().filter(|b| **b).count();
        let negative = signs.len() - positive;
        let runs = if signs.is_empty() {
            0
        } else {
            1 + signs.windows(2).filter(|w| w[0] != w[1]).count()
        };
        let n = signs.len() as f64;
        let (expected, variance) = if signs.len() >= 2 {
            let mu = 2.0 * positive as f64 * negative as f64 / n + 1.0;
            (mu, (mu - 1.0) * (mu - 2.0) / (n - 1.0))
        } else {
            (f64::NAN, 0.0)
        };
        RunsTest {
            runs,
            positive,
            negative,
            expected,
            variance,
            z: z_of(runs as f64, expected, variance),
        }
    }

    /// Pools independent sequences: runs, expectations and variances add.
    pub fn pooled(tests: &[RunsTest]) -> Self {
        let mut t = RunsTest::default();
        for x in tests.iter().filter(|x| x.expected.is_finite()) {
            t.runs += x.runs;
            t.positive += x.positive;
            t.negative += x.negative;
            t.expected += x.expected;
            t.variance += x.variance;
        }
        t.z = z_of(t.runs as f64, t.expected, t.variance);
        t
    }
}

fn z_of(value: f64, expected: f64, variance: f64) -> f64 {
    if variance > 0.0 {
        (value - expected) / variance.sqrt()
    } else {
        f64::NAN
    }
}

fn ranks(v: &[f64]) -> Vec<f64> {
    let mut idx: Vec<usize> = (0..v.len()).collect();
    idx.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
    let mut r = vec![0.0; v.len()];
    let mut i = 0;
    while i < idx.len() {
        let mut j = i;
        while j + 1 < idx.len() && v[idx[j + 1]] == v[idx[i]] {
            j += 1;
        }
        let avg = 0.5 * (i + j) as f64 + 1.0;
        for &k in &idx[i..=j] {
            r[k] = avg;
        }
        i = j + 1;
    }
    r
}

/// Spearman rank correlation of `x` and `y` (`NaN` with fewer than 3 finite pairs or no
/// spread).
pub(crate) fn spearman(x: &[f64], y: &[f64]) -> f64 {
    let (xs, ys): (Vec<f64>, Vec<f64>) = x
        .iter()
        .zip(y)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(a, b)| (*a, *b))
        .unzip();
    if xs.len() < 3 {
        return f64::NAN;
    }
    let (rx, ry) = (ranks(&xs), ranks(&ys));
    let n = rx.len() as f64;
    let (mx, my) = (rx.iter().sum::<f64>() / n, ry.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in rx.iter().zip(&ry) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
        syy += (b - my) * (b - my);
    }
    if sxx > 0.0 && syy > 0.0 {
        sxy / (sxx * syy).sqrt()
    } else {
        f64::NAN
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi2_survival_at_known_quantiles() {
        // the 95 % and 90 % points of χ²₁, and P(χ²₁ > 1) = 0.3173
        assert!((chi2_1_survival(3.841_458_820_694_124) - 0.05).abs() < 1e-7);
        assert!((chi2_1_survival(2.705_543_454_095_404) - 0.10).abs() < 1e-7);
        assert!((chi2_1_survival(1.0) - 0.317_310_507_862_914).abs() < 1e-7);
        assert_eq!(chi2_1_survival(0.0), 1.0);
        assert!((erfc(-1.0) - 1.842_700_792_949_715).abs() < 1e-6);
    }

    #[test]
    fn runs_of_known_sequence() {
        let t = RunsTest::of(&[1.0, 2.0, -1.0, -1.0, 3.0, 0.0, -2.0]);
        assert_eq!((t.runs, t.positive, t.negative), (4, 3, 3));
        assert!((t.expected - 4.0).abs() < 1e-12);
        assert!((t.variance - 6.0 / 5.0).abs() < 1e-12);
        assert!(t.z.abs() < 1e-12);
    }

    #[test]
    fn second_differences_remove_lines_and_keep_variance() {
        let s = [0.0, 0.1, 0.3, 0.4, 0.7];
        let r: Vec<f64> = s.iter().map(|x| 0.03 - 0.2 * x).collect();
        assert!(second_differences(&s, &r).iter().all(|e| e.abs() < 1e-15));
    }

    #[test]
    fn spearman_of_monotone_and_reversed() {
        let x = [1.0, 2.0, 3.0, 4.0];
        assert!((spearman(&x, &[1.0, 4.0, 9.0, 16.0]) - 1.0).abs() < 1e-12);
        assert!((spearman(&x, &[4.0, 3.0, 2.0, 1.0]) + 1.0).abs() < 1e-12);
    }
}

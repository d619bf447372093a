//! The one noise model of the relative residuals `r = (d_model − d_meas)/d_meas` \[-\] along the
//! spin line, used by the comparison and ready for the diagnosis: a robust noise scale, a noise
//! scale that may vary along the line, gross outliers, one lag-1 autocorrelation and the
//! judgement numbers "is the misfit noise?" computed like with like.
//!
//! ```
//! use rheometer::data::noise_model::{NoiseModel, NoiseOptions};
//! let s: Vec<f64> = (0..26).map(|i| 0.02 * i as f64).collect();
//! let r: Vec<f64> = (0..26).map(|i| 0.01 * ((i * 7919 % 13) as f64 / 6.0 - 1.0)).collect();
//! let nm = NoiseModel::from_profiles(&[(s, r)], &NoiseOptions::default())?;
//! assert!(nm.sigma > 0.0 && nm.outliers.is_empty());
//! # Ok::<(), String>(())
//! ```
//!
//! **Estimators** (positions `s` in m, `L` the line length of each experiment):
//! 1. *Robust noise scale* `σ`: `1.4826 · MAD` of the spacing-normalised second differences
//!    (`second_differences`), pooled over
//!    experiments, leaving out every difference that touches an outlier. A normalised second
//!    difference has variance `σ²` for independent noise of SD `σ` on any spacing and cancels a
//!    residual linear in `s`, so a smooth systematic misfit hardly enters; the MAD ignores kinks.
//! 2. *Noise along the line* `σ(s/L)`: in [`NoiseOptions::bins`] equal bins of `s/L` pooled over
//!    experiments (a bin with fewer than [`NoiseOptions::min_count`] differences is merged into
//!    its neighbour), the RMS of the normalised second differences that touch no outlier,
//!    interpolated linearly between bin centres and constant beyond the outer centres
//!    ([`NoiseModel::local_sigma`]). The RMS (not the MAD) because (a) the outliers are already
//!    out, (b) it is what the RMS of the residuals is judged against (like with like: a bin
//!    whose noise grows toward the take-up contributes its mean square, not its median), and
//!    (c) it is 2.7 times as efficient, which matters for bins of a few dozen correlated
//!    differences.
//! 3. *Outliers*: each point's residual is compared with a local robust line through its
//!    [`NoiseOptions::neighbours`] nearest neighbours (Theil–Sen slope, median intercept; the
//!    point itself left out). The deviations are scaled by their own robust SD in the point's
//!    bin, and a point deviating by more than [`NoiseOptions::outlier_threshold`] (4.5) of them
//!    is an outlier. (For Gaussian noise a false flag has probability ≈ 7·10⁻⁶ per point.)
//! 4. *Lag-1 autocorrelation* of the residuals normalised by the local noise, about zero
//!    (an offset is a misfit too), pooled over experiments, over consecutive pairs without an
//!    outlier: `ρ₁ = Σ zᵢ zᵢ₊₁ / Σ zᵢ²`, `zᵢ = rᵢ / σ(sᵢ/L)`; for white noise
//!    `ρ₁ √pairs ≈ N(0, 1)`.
//! 5. *Judgement* (outliers left out): `rms_over_noise = RMS(r) / √(mean σ(sᵢ/L)²)` compares the
//!    RMS of the residuals with the RMS of the local noise at the same points, so a noise that
//!    grows toward the take-up does not look like a misfit; `robust_rms_over_noise =
//!    √(median(zᵢ²)/0.4549)` (the median of `χ²₁` is 0.4549) is the same ratio immune to
//!    outliers. Both are ≈ 1 for noise and exceed 1 for a misfit.
//! 6. *Correlated noise*: noise correlated along the line (a vibrating fiber, a slow gauge)
//!    is modelled as AR(1) with lag-1 autocorrelation `ρ`. For AR(1) noise the first
//!    differences `dᵢ = zᵢ₊₁ − zᵢ` have lag-1 autocorrelation `−(1 − ρ)/2`, so
//!    `ρ̂ = 1 + 2 r₁(d)` ([`NoiseModel::correlation`]), pooled over experiments, pairs touching
//!    an outlier left out, corrected for its small-sample bias (`+1.2 (1 − ρ)/n` on lines of
//!    `n` points). Like second differences, first differences hardly see a smooth
//!    misfit. For white noise `ρ̂` has standard error `√(2/pairs)` (Bartlett's formula for
//!    the MA(1) process of the differences). A misfit can look like correlated noise too
//!    (a sharp one near the die raises `ρ̂` as much as noise of `ρ = 0.5`), but it leaves
//!    residuals of one shape in related experiments, while noise is independent between
//!    experiments. So the noise is treated as correlated ([`NoiseModel::correlation_used`])
//!    only where (a) `ρ̂` exceeds 2 standard errors, (b) `ρ̂ ≤ 0.9` (beyond, on lines of a
//!    few dozen points, AR(1) noise and a misfit cannot be told apart; a broken fit shows
//!    `ρ̂` near or above 1, which no noise gives), (c) no experiment's residuals are twice the median experiment's in RMS (one
//!    experiment's misfit is no noise), and (d) the
//!    experiments' residual shapes, in 5 bins of `s/L` (a missing effect's shape is smooth) and centred (a fit leaves each experiment's residuals summing to about zero), are no more alike (mean squared
//!    cosine over pairs) than independent AR(1) noise at `ρ̂` plus one standard error makes
//!    them in 200 simulated sets (p above 0.05, at least 3 experiments;
//!    [`NoiseModel::coherence_p`]). White noise is judged as before in about 98 % of data
//!    sets (one-sided 2.3 %; at `ρ = 0.3` on 9 lines of 26 points, standard error 0.096, the
//!    gate passes about 85 %). Then the normalised second
//!    differences, whose variance is `σ²(1 − 4ρ/3 + ρ²/3)` for AR(1) noise of SD `σ`, are
//!    divided by that factor's root (the noise level is the noise's own SD, not the white
//!    part of it), the lag-1 test compares `ρ₁` with `ρ̂` instead of 0, the misfit limits
//!    widen by the sampling spread of a mean square of AR(1) noise
//!    ([`NoiseModel::misfit_ratio_limit`]) and parameter variances grow by the long-run factor
//!    `(1 + ρ)/(1 − ρ)` ([`NoiseModel::variance_inflation`]).

use crate::data::statistics::median;
use serde::{Deserialize, Serialize};

mod estimate;

/// Standard errors of white noise's [`NoiseModel::correlation`] beyond which the noise is
/// treated as correlated: one-sided 2.3 % of white-noise data sets; at `ρ = 0.3` on 9 lines
/// of 26 points (standard error 0.096) it passes about 85 % of them.
pub(crate) const CORRELATION_GATE_Z: f64 = 2.0;

/// The p-value at or below which the experiments' residuals are more alike than independent
/// noise makes them: the along-line correlation is then a misfit the experiments share.
pub(crate) const COHERENCE_LEVEL: f64 = 0.05;

/// The largest along-line correlation the noise model takes for noise \[-\]: beyond it an
/// AR(1) model of 26 points per line cannot tell noise from a misfit (the noise level would
/// grow more than 3.8-fold over the second differences'; a broken fit shows `ρ̂` near 1), and
/// the noise is judged as white. At 0.8 instead, 8 of the 20 sets of `ρ = 0.7` in
/// `noise_rates` were judged white and called SYSTEMATIC.
pub(crate) const MAX_CORRELATION: f64 = 0.9;

/// `√pairs` times the standard deviation of `ρ₁ − ρ̂` under AR(1) noise: the spread of the
/// residuals' lag-1 autocorrelation about the noise's own (both estimated from the same
/// points), measured by simulating AR(1) noise with `ρ` 0.3 to 0.7 on 9 lines of 26 points
/// (1.5 to 1.7; white noise's `ρ₁` alone has 1).
const LAG1_DIFFERENCE_SPREAD: f64 = 1.65;

/// Median of the `χ²` distribution with one degree of freedom.
const CHI2_1_MEDIAN: f64 = 0.454_936_423_119_572_8;

/// Settings of the [`NoiseModel`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NoiseOptions {
    /// Number of equal bins of `s/L` for the noise along the line (default 5).
    pub bins: usize,
    /// Minimum number of second differences (and of deviations) per bin (default 15).
    pub min_count: usize,
    /// Neighbours of a point in its local robust line (default 8).
    pub neighbours: usize,
    /// Outlier threshold in local robust SDs of the deviations (default 4.5).
    pub outlier_threshold: f64,
}

impl Default for NoiseOptions {
    fn default() -> Self {
        NoiseOptions {
            bins: 5,
            min_count: 15,
            neighbours: 8,
            outlier_threshold: 4.5,
        }
    }
}

/// One experiment's residual profile, the input of [`NoiseModel::estimate`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ResidualSeries {
    /// Experiment name.
    pub name: String,
    /// Measurement positions `s` \[m\], increasing.
    pub positions_m: Vec<f64>,
    /// Relative residuals `(d_model − d_meas)/d_meas` \[-\].
    pub residuals: Vec<f64>,
    /// Measured diameters \[m\] (for the outlier report; may be empty).
    pub measured_m: Vec<f64>,
    /// Spin-line length `L` \[m\]; `None`: the last position.
    pub length_m: Option<f64>,
}

/// A gross outlier.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outlier {
    /// Experiment name.
    pub experiment: String,
    /// Index of the experiment.
    pub experiment_index: usize,
    /// Index of the point in its experiment.
    pub point_index: usize,
    /// Position `s` \[m\].
    pub position_m: f64,
    /// Measured diameter \[m\] (`NaN` if not given).
    pub d_meas_m: f64,
    /// Predicted (model) diameter `d_meas (1 + r)` \[m\] (`NaN` if not given).
    pub d_model_m: f64,
    /// Relative residual `r` \[-\].
    pub residual: f64,
    /// Deviation from the local robust line in local robust SDs \[-\].
    pub deviation_sigmas: f64,
}

/// The noise scale in one bin of `s/L`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NoiseBin {
    /// Lower edge of `s/L` \[-\].
    pub from: f64,
    /// Upper edge of `s/L` \[-\].
    pub to: f64,
    /// Centre of the points' `s/L` in the bin \[-\].
    pub centre: f64,
    /// Robust noise SD in the bin \[-\] (relative).
    pub sigma: f64,
    /// Number of second differences used.
    pub count: usize,
}

/// The noise model of a set of residual profiles (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoiseModel {
    /// Robust noise scale `σ` over the whole line \[-\] (relative).
    pub sigma: f64,
    /// The noise scale along the line, in bins of `s/L`.
    pub bins: Vec<NoiseBin>,
    /// Largest over smallest bin `σ` \[-\].
    pub variation_ratio: f64,
    /// `|ln(σ_max/σ_min)|` in standard errors (`se(ln σ̂) ≈ 1/√count` per bin: the RMS of
    /// second differences, whose neighbours correlate with −2/3 and 1/6).
    pub variation_z: f64,
    /// Whether the noise varies along the line (`variation_z > 3` and ratio > 1.3).
    pub varies_along_line: bool,
    /// The outliers, by experiment and position.
    pub outliers: Vec<Outlier>,
    /// Points used (outliers excluded).
    pub points: usize,
    /// RMS of the residuals, outliers excluded \[-\].
    pub rms: f64,
    /// RMS of the local noise `σ(sᵢ/L)` over the same points \[-\].
    pub noise_rms: f64,
    /// `rms / noise_rms` \[-\] (≈ 1 for noise).
    pub rms_over_noise: f64,
    /// `√(median(zᵢ²)/0.4549)`, `zᵢ = rᵢ/σ(sᵢ/L)` over all points \[-\] (≈ 1 for noise).
    pub robust_rms_over_noise: f64,
    /// Pooled lag-1 autocorrelation of `zᵢ` about zero, outliers excluded \[-\].
    pub lag1: f64,
    /// Number of lag pairs.
    pub lag1_pairs: usize,
    /// The lag-1 structure in standard errors \[-\]: `ρ₁ √pairs` for white noise; for
    /// correlated noise `(ρ₁ − ρ̂) √pairs / 1.65`, the residuals' correlation beyond the
    /// noise's own (module docs, item 6).
    pub lag1_z: f64,
    /// Per experiment: the lag-1 autocorrelation of its `zᵢ` about zero \[-\].
    pub lag1_per_experiment: Vec<f64>,
    /// The noise's own lag-1 autocorrelation along the line, from first differences (item 6
    /// of the module docs) \[-\]; ≈ 0 for white noise.
    #[serde(default, deserialize_with = "crate::report::serde_nan::f64")]
    pub correlation: f64,
    /// Its standard error for white noise, `√(2/pairs)` \[-\].
    #[serde(default, deserialize_with = "crate::report::serde_nan::f64")]
    pub correlation_se: f64,
    /// The correlation the noise level, the tests and the intervals use: `correlation`
    /// where it passes the gate of item 6 of the module docs,
    /// else 0 (white noise) \[-\].
    #[serde(default)]
    pub correlation_used: f64,
    /// How alike the experiments' residual shapes are, as a p-value against independent
    /// noise with the correlation found (item 6 of the module docs); `None` where the
    /// correlation was not significant or there are fewer than 3 experiments. At or below
    /// 0.05 the correlation is a shared misfit and
    /// the noise is treated as white.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coherence_p: Option<f64>,
    /// Settings used.
    pub options: NoiseOptions,
    /// Per experiment, the spin-line length used for `s/L` \[m\].
    pub lengths_m: Vec<f64>,
}

fn theil_sen_at(s0: f64, pts: &[(f64, f64)]) -> f64 {
    let mut slopes = Vec::new();
    for a in 0..pts.len() {
        for b in a + 1..pts.len() {
            let ds = pts[b].0 - pts[a].0;
            if ds != 0.0 {
                slopes.push((pts[b].1 - pts[a].1) / ds);
            }
        }
    }
    let slope = if slopes.is_empty() {
        0.0
    } else {
        median(&mut slopes)
    };
    let mut icpt: Vec<f64> = pts.iter().map(|(s, r)| r - slope * (s - s0)).collect();
    median(&mut icpt)
}

/// Deviation of each residual from the robust line through its neighbours (`NaN` for
/// experiments with fewer than 4 points).
fn local_deviations(s: &[f64], r: &[f64], neighbours: usize) -> Vec<f64> {
    let n = r.len();
    if n < 4 {
        return vec![f64::NAN; n];
    }
    let k = neighbours.clamp(3, n - 1);
    (0..n)
        .map(|i| {
            // k nearest neighbours by index, window shifted at the ends
            let lo = i.saturating_sub(k / 2).min(n - 1 - k);
            let pts: Vec<(f64, f64)> = (lo..=lo + k)
                .filter(|&j| j != i)
                .take(k)
                .map(|j| (s[j], r[j]))
                .collect();
            r[i] - theil_sen_at(s[i], &pts)
        })
        .collect()
}

fn bin_of(x: f64, bins: usize) -> usize {
    ((x * bins as f64).floor().max(0.0) as usize).min(bins - 1)
}

/// Groups `bins` equal bins so that each group has at least `min_count` entries (merging a
/// short bin into the next, the last short group into the previous). Returns, per bin, its group.
fn merge_bins(counts: &[usize], min_count: usize) -> Vec<usize> {
    let mut group = vec![0; counts.len()];
    let (mut g, mut acc) = (0, 0);
    let mut closed = Vec::new();
    for (b, &c) in counts.iter().enumerate() {
        group[b] = g;
        acc += c;
        if acc >= min_count {
            closed.push(acc);
            g += 1;
            acc = 0;
        }
    }
    if acc < min_count && g > 0 && (acc > 0 || group.contains(&g)) {
        for x in group.iter_mut() {
            if *x == g {
                *x = g - 1;
            }
        }
    }
    group
}

impl NoiseModel {
    /// The model of `(positions [m], residuals [-])` per experiment (names `#1`, `#2`, …; no
    /// diameters; `L` = last position). The call the diagnosis uses with
    /// [`Identification::residual_profiles`](crate::fit::Identification::residual_profiles).
    pub fn from_profiles(
        profiles: &[(Vec<f64>, Vec<f64>)],
        options: &NoiseOptions,
    ) -> Result<Self, String> {
        let series: Vec<ResidualSeries> = profiles
            .iter()
            .enumerate()
            .map(|(k, (s, r))| ResidualSeries {
                name: format!("#{}", k + 1),
                positions_m: s.clone(),
                residuals: r.clone(),
                ..ResidualSeries::default()
            })
            .collect();
        Self::estimate(&series, options)
    }

    /// The local noise SD `σ(s/L)` \[-\] at `x = s/L`: linear between bin centres, constant
    /// beyond the outer ones, `σ` without bins.
    pub fn local_sigma(&self, x: f64) -> f64 {
        let b = &self.bins;
        match b.len() {
            0 => self.sigma,
            1 => b[0].sigma,
            _ => {
                if x <= b[0].centre {
                    return b[0].sigma;
                }
                for w in b.windows(2) {
                    if x <= w[1].centre {
                        let t = (x - w[0].centre) / (w[1].centre - w[0].centre);
                        return w[0].sigma + t * (w[1].sigma - w[0].sigma);
                    }
                }
                b[b.len() - 1].sigma
            }
        }
    }

    /// The local noise SD at position `s` \[m\] of experiment `k` (its length `L`).
    pub fn local_sigma_at(&self, k: usize, s: f64) -> f64 {
        let l = self.lengths_m.get(k).copied().unwrap_or(1.0);
        self.local_sigma(s / l)
    }

    /// The factor by which the noise's long-run variance exceeds its point variance,
    /// `(1 + ρ)/(1 − ρ)` with `ρ` the [`correlation_used`](Self::correlation_used) \[-\]: 1
    /// for white noise. A fit's parameter variances from the point variance are too small
    /// by this factor where the noise is correlated along the line.
    pub fn variance_inflation(&self) -> f64 {
        let r = self.correlation_used;
        (1.0 + r) / (1.0 - r)
    }

    /// [`lag1_z`](Self::lag1_z) as it would be for noise of along-line correlation `rho`
    /// (0: white), e.g. the data's, decided on another fit of the same data \[-\].
    pub fn lag1_z_against(&self, rho: f64) -> f64 {
        let root = (self.lag1_pairs as f64).sqrt();
        if rho > 0.0 {
            (self.lag1 - rho) * root / LAG1_DIFFERENCE_SPREAD
        } else {
            self.lag1 * root
        }
    }

    /// The factor by which a noise level from second differences grows for AR(1) noise of
    /// correlation `rho` (the noise's own SD over the white part's), `1/√(1 − 4ρ/3 + ρ²/3)`.
    pub fn level_factor(rho: f64) -> f64 {
        1.0 / (1.0 - 4.0 * rho / 3.0 + rho * rho / 3.0).sqrt()
    }

    /// The limit of [`rms_over_noise`](Self::rms_over_noise) that `limit` (for white noise)
    /// becomes for this noise: its excess over 1 widened by the sampling spread of a mean
    /// square of AR(1) noise relative to white, `√((1 + ρ²)/(1 − ρ²))` \[-\].
    pub fn misfit_ratio_limit(&self, limit: f64) -> f64 {
        let r2 = self.correlation_used.powi(2);
        1.0 + (limit - 1.0) * ((1.0 + r2) / (1.0 - r2)).sqrt()
    }

    /// The correlation effect-free noise is drawn with where false alarms are calibrated by
    /// simulation \[-\]: 0 for white noise; for correlated noise [`correlation_used`](Self::correlation_used)
    /// plus one standard error (at most 0.9). A smooth signature picks up
    /// more of a more correlated noise, so a calibration at an underestimated `ρ` would be
    /// too lenient; one standard error keeps it at the stated rate for about 84 % of the
    /// estimates instead of half.
    pub fn calibration_correlation(&self) -> f64 {
        if self.correlation_used > 0.0 {
            self.calibration_correlation_of(self.correlation_used)
        } else {
            0.0
        }
    }

    /// Whether point `i` of experiment `k` is an outlier.
    pub fn is_outlier(&self, k: usize, i: usize) -> bool {
        self.outliers
            .iter()
            .any(|o| o.experiment_index == k && o.point_index == i)
    }

    fn judge(&mut self, series: &[ResidualSeries], is_out: &[Vec<bool>]) {
        let (mut sum_r2, mut sum_s2, mut count) = (0.0, 0.0, 0usize);
        let mut z2 = Vec::new();
        let (mut num, mut den, mut pairs) = (0.0, 0.0, 0usize);
        let mut per = Vec::new();
        for (k, e) in series.iter().enumerate() {
            let z: Vec<f64> = e
                .positions_m
                .iter()
                .zip(&e.residuals)
                .map(|(s, r)| r / self.local_sigma_at(k, *s))
                .collect();
            z2.extend(z.iter().map(|v| v * v));
            let (mut n_k, mut d_k) = (0.0, 0.0);
            for i in 0..z.len() {
                if is_out[k][i] {
                    continue;
                }
                let sl = self.local_sigma_at(k, e.positions_m[i]);
                sum_r2 += e.residuals[i].powi(2);
                sum_s2 += sl * sl;
                count += 1;
                d_k += z[i] * z[i];
                if i + 1 < z.len() && !is_out[k][i + 1] {
                    n_k += z[i] * z[i + 1];
                    pairs += 1;
                }
            }
            num += n_k;
            den += d_k;
            per.push(if d_k > 0.0 { n_k / d_k } else { f64::NAN });
        }
        self.points = count;
        let c = count.max(1) as f64;
        self.rms = (sum_r2 / c).sqrt();
        self.noise_rms = (sum_s2 / c).sqrt();
        self.rms_over_noise = self.rms / self.noise_rms;
        self.robust_rms_over_noise = (median(&mut z2) / CHI2_1_MEDIAN).sqrt();
        self.lag1 = if den > 0.0 { num / den } else { f64::NAN };
        self.lag1_pairs = pairs;
        self.lag1_z = self.lag1_z_against(self.correlation_used);
        self.lag1_per_experiment = per;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::synthetic::SplitMix64;

    fn white(seed: u64, sd: f64, m: usize, n: usize) -> Vec<(Vec<f64>, Vec<f64>)> {
        let mut rng = SplitMix64::new(seed);
        (0..m)
            .map(|_| {
                let s: Vec<f64> = (0..n).map(|i| 0.02 * i as f64).collect();
                let r: Vec<f64> = s.iter().map(|_| sd * rng.normal()).collect();
                (s, r)
            })
            .collect()
    }

    #[test]
    fn white_noise_is_noise() {
        let nm =
            NoiseModel::from_profiles(&white(3, 0.02, 9, 26), &NoiseOptions::default()).unwrap();
        assert!((nm.sigma / 0.02 - 1.0).abs() < 0.15, "{}", nm.sigma);
        assert!(nm.outliers.len() <= 1, "{:?}", nm.outliers);
        assert!(
            (nm.rms_over_noise - 1.0).abs() < 0.2,
            "{}",
            nm.rms_over_noise
        );
        assert!(nm.lag1_z.abs() < 3.0);
        assert!(!nm.varies_along_line, "{:?}", nm.bins);
    }

    #[test]
    fn a_spike_is_an_outlier_and_an_offset_is_correlated() {
        let mut p = white(5, 0.01, 3, 26);
        p[1].1[7] += 0.2;
        for (_, r) in &mut p {
            for v in r.iter_mut() {
                *v += 0.03;
            }
        }
        let nm = NoiseModel::from_profiles(&p, &NoiseOptions::default()).unwrap();
        assert_eq!(nm.outliers.len(), 1, "{:?}", nm.outliers);
        assert_eq!(
            (nm.outliers[0].experiment_index, nm.outliers[0].point_index),
            (1, 7)
        );
        assert!(nm.rms_over_noise > 2.0 && nm.lag1_z > 3.0);
    }

    /// AR(1) noise of lag-1 autocorrelation 0.6 and SD 0.02 on 9 lines of 26 points: the
    /// correlation is found, the level is the noise's own SD (second differences alone give
    /// 0.02 √(1 − 0.8 + 0.12) = 0.011), the residuals are at that noise and keep no structure
    /// beyond it, and parameter variances grow (by (1 + ρ)/(1 − ρ) = 4 at the true ρ); white noise is
    /// white (the seeds are fixed: these are the draws' values, which could fail).
    #[test]
    fn correlated_noise_is_noise_with_its_correlation() {
        let mut rng = SplitMix64::new(11);
        let (rho, sd) = (0.6_f64, 0.02);
        let p: Vec<(Vec<f64>, Vec<f64>)> = (0..9)
            .map(|_| {
                let s: Vec<f64> = (0..26).map(|i| 0.02 * i as f64).collect();
                let mut z = rng.normal();
                let r = s
                    .iter()
                    .map(|_| {
                        let v = sd * z;
                        z = rho * z + (1.0 - rho * rho).sqrt() * rng.normal();
                        v
                    })
                    .collect();
                (s, r)
            })
            .collect();
        let nm = NoiseModel::from_profiles(&p, &NoiseOptions::default()).unwrap();
        assert!((nm.correlation - rho).abs() < 0.2, "{}", nm.correlation);
        assert_eq!(nm.correlation_used, nm.correlation);
        assert!((nm.noise_rms / sd - 1.0).abs() < 0.25, "{}", nm.noise_rms);
        assert!(
            nm.rms_over_noise < nm.misfit_ratio_limit(1.2),
            "{} {}",
            nm.rms_over_noise,
            nm.misfit_ratio_limit(1.2)
        );
        assert!(nm.lag1_z < 3.0, "{}", nm.lag1_z);
        assert!(nm.variance_inflation() > 1.5, "{}", nm.variance_inflation());
        let w =
            NoiseModel::from_profiles(&white(3, 0.02, 9, 26), &NoiseOptions::default()).unwrap();
        assert_eq!(w.correlation_used, 0.0, "{}", w.correlation);
        assert_eq!(w.variance_inflation(), 1.0);
        assert_eq!(w.misfit_ratio_limit(1.2), 1.2);
    }

    /// A misfit the experiments share that wiggles like correlated noise (one AR(1) draw of
    /// `ρ = 0.6` and SD 0.02, the same in every experiment) on white noise of SD 0.01: the
    /// first differences' correlation is significant, but the experiments' residuals are
    /// alike, so the noise stays white (its level is not raised, its intervals not widened).
    #[test]
    fn a_shared_wiggle_is_not_correlated_noise() {
        let mut p = white(21, 0.01, 9, 26);
        let mut rng = SplitMix64::new(5);
        let mut v = rng.normal();
        let wiggle: Vec<f64> = (0..26)
            .map(|_| {
                let w = 0.02 * v;
                v = 0.6 * v + 0.8 * rng.normal();
                w
            })
            .collect();
        for (_, r) in p.iter_mut() {
            for (ri, w) in r.iter_mut().zip(&wiggle) {
                *ri += w;
            }
        }
        let nm = NoiseModel::from_profiles(&p, &NoiseOptions::default()).unwrap();
        assert!(
            nm.correlation > CORRELATION_GATE_Z * nm.correlation_se,
            "{} ± {}",
            nm.correlation,
            nm.correlation_se
        );
        assert!(
            nm.coherence_p.is_some_and(|p| p <= COHERENCE_LEVEL),
            "{:?}",
            nm.coherence_p
        );
        assert_eq!(nm.correlation_used, 0.0);
        assert_eq!(nm.variance_inflation(), 1.0);
    }

    #[test]
    fn short_bins_are_merged() {
        assert_eq!(merge_bins(&[20, 5, 5, 20, 3], 10), vec![0, 1, 1, 2, 2]);
        assert_eq!(merge_bins(&[3, 3], 10), vec![0, 0]);
    }
}

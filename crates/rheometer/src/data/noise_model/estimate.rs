//! [`NoiseModel::estimate`], step by step: the outliers from local robust lines, the second
//! differences without them (globally and in bins of `s/L`), the noise along the line, and
//! the judgement numbers.

use super::{
    bin_of, local_deviations, merge_bins, NoiseBin, NoiseModel, NoiseOptions, Outlier,
    ResidualSeries, COHERENCE_LEVEL, CORRELATION_GATE_Z, MAX_CORRELATION,
};
use crate::data::statistics::{robust_sd, second_differences};
use crate::data::synthetic::SplitMix64;

impl NoiseModel {
    /// The model of the residual profiles `series`. Errors: mismatched lengths, non-finite
    /// values, fewer than 3 second differences in all, bad options.
    pub fn estimate(series: &[ResidualSeries], options: &NoiseOptions) -> Result<Self, String> {
        if options.bins == 0 || options.neighbours < 3 || options.outlier_threshold <= 0.0 {
            return Err(format!(
                "noise model options need bins ≥ 1, neighbours ≥ 3 and a positive outlier \
                 threshold, got {options:?}"
            ));
        }
        let lengths = line_lengths(series)?;
        // 1. deviations from local robust lines, binned by s/L; 2. outliers
        let (outliers, is_out) = find_outliers(series, &lengths, options);
        // 3. second differences without outliers, global and binned
        let clean = CleanDifferences::new(series, &lengths, &is_out, options.bins);
        if clean.all.len() < 3 {
            return Err(format!(
                "only {} second differences of the residuals: too few points to estimate the noise",
                clean.all.len()
            ));
        }
        let sigma = robust_sd(&clean.all);
        let bins = clean.noise_bins(options, sigma);
        let (variation_ratio, variation_z) = variation(&bins);
        let mut model = NoiseModel {
            sigma,
            bins,
            variation_ratio,
            variation_z,
            varies_along_line: variation_z > 3.0 && variation_ratio > 1.3,
            outliers,
            points: 0,
            rms: f64::NAN,
            noise_rms: f64::NAN,
            rms_over_noise: f64::NAN,
            robust_rms_over_noise: f64::NAN,
            lag1: f64::NAN,
            lag1_pairs: 0,
            lag1_z: f64::NAN,
            lag1_per_experiment: Vec::new(),
            correlation: f64::NAN,
            correlation_se: f64::NAN,
            correlation_used: 0.0,
            coherence_p: None,
            options: *options,
            lengths_m: lengths,
        };
        model.correlate(series, &is_out);
        model.judge(series, &is_out);
        Ok(model)
    }
}

/// The line length `L` of each experiment (its own, else its last position, else 1 m), after
/// checking its lengths and values.
fn line_lengths(series: &[ResidualSeries]) -> Result<Vec<f64>, String> {
    let mut lengths = Vec::new();
    for e in series {
        let n = e.positions_m.len();
        if e.residuals.len() != n || (!e.measured_m.is_empty() && e.measured_m.len() != n) {
            return Err(format!(
                "experiment {}: {} positions, {} residuals, {} measured diameters",
                e.name,
                n,
                e.residuals.len(),
                e.measured_m.len()
            ));
        }
        if e.positions_m
            .iter()
            .chain(&e.residuals)
            .any(|v| !v.is_finite())
            || e.positions_m.windows(2).any(|w| w[1] <= w[0])
        {
            return Err(format!(
                "experiment {}: positions must be finite and increasing, residuals finite",
                e.name
            ));
        }
        let l = e
            .length_m
            .or(e.positions_m.last().copied())
            .filter(|l| *l > 0.0)
            .unwrap_or(1.0);
        lengths.push(l);
    }
    Ok(lengths)
}

/// The outliers: points deviating from their local robust line by more than the threshold in
/// robust SDs of the deviations in their bin. Returns them and, per experiment, a flag per
/// point.
fn find_outliers(
    series: &[ResidualSeries],
    lengths: &[f64],
    options: &NoiseOptions,
) -> (Vec<Outlier>, Vec<Vec<bool>>) {
    let nb = options.bins;
    let devs: Vec<Vec<f64>> = series
        .iter()
        .map(|e| local_deviations(&e.positions_m, &e.residuals, options.neighbours))
        .collect();
    let (dev_groups, dev_sd) = deviation_scales(series, &devs, lengths, options);
    let mut outliers = Vec::new();
    let mut is_out: Vec<Vec<bool>> = Vec::new();
    for (k, e) in series.iter().enumerate() {
        let mut flags = vec![false; e.residuals.len()];
        for (i, d) in devs[k].iter().enumerate() {
            let sd = dev_sd[dev_groups[bin_of(e.positions_m[i] / lengths[k], nb)]];
            let z = d / sd;
            if sd > 0.0 && z.abs() > options.outlier_threshold {
                flags[i] = true;
                let (dm, dd) = match e.measured_m.get(i) {
                    Some(m) => (*m, m * (1.0 + e.residuals[i])),
                    None => (f64::NAN, f64::NAN),
                };
                outliers.push(Outlier {
                    experiment: e.name.clone(),
                    experiment_index: k,
                    point_index: i,
                    position_m: e.positions_m[i],
                    d_meas_m: dm,
                    d_model_m: dd,
                    residual: e.residuals[i],
                    deviation_sigmas: z,
                });
            }
        }
        is_out.push(flags);
    }
    (outliers, is_out)
}

/// The robust SD of the deviations `devs` from the local lines in each group of bins of `s/L`
/// (short bins merged): per bin its group, per group the SD.
fn deviation_scales(
    series: &[ResidualSeries],
    devs: &[Vec<f64>],
    lengths: &[f64],
    options: &NoiseOptions,
) -> (Vec<usize>, Vec<f64>) {
    let nb = options.bins;
    let mut dev_bins: Vec<Vec<f64>> = vec![Vec::new(); nb];
    for (k, e) in series.iter().enumerate() {
        for (i, d) in devs[k].iter().enumerate() {
            if d.is_finite() {
                dev_bins[bin_of(e.positions_m[i] / lengths[k], nb)].push(*d);
            }
        }
    }
    let dev_groups = merge_bins(
        &dev_bins.iter().map(Vec::len).collect::<Vec<_>>(),
        options.min_count,
    );
    let ng = dev_groups.iter().max().map_or(1, |m| m + 1);
    let dev_sd: Vec<f64> = (0..ng)
        .map(|g| {
            let v: Vec<f64> = (0..nb)
                .filter(|b| dev_groups[*b] == g)
                .flat_map(|b| dev_bins[b].iter().copied())
                .collect();
            robust_sd(&v)
        })
        .collect();
    (dev_groups, dev_sd)
}

/// The normalised second differences that touch no outlier, pooled and in bins of `s/L`.
struct CleanDifferences {
    /// All of them.
    all: Vec<f64>,
    /// Those in each bin.
    sd_bins: Vec<Vec<f64>>,
    /// The positions `s/L` of those in each bin.
    x_bins: Vec<Vec<f64>>,
}

impl CleanDifferences {
    fn new(series: &[ResidualSeries], lengths: &[f64], is_out: &[Vec<bool>], nb: usize) -> Self {
        let mut all = Vec::new();
        let mut sd_bins: Vec<Vec<f64>> = vec![Vec::new(); nb];
        let mut x_bins: Vec<Vec<f64>> = vec![Vec::new(); nb];
        for (k, e) in series.iter().enumerate() {
            let sd2 = second_differences(&e.positions_m, &e.residuals);
            // second_differences skips zero-norm triples, which increasing positions exclude
            for (j, v) in sd2.iter().enumerate() {
                let i = j + 1;
                if is_out[k][i - 1] || is_out[k][i] || is_out[k][i + 1] {
                    continue;
                }
                all.push(*v);
                let x = e.positions_m[i] / lengths[k];
                sd_bins[bin_of(x, nb)].push(*v);
                x_bins[bin_of(x, nb)].push(x);
            }
        }
        CleanDifferences {
            all,
            sd_bins,
            x_bins,
        }
    }

    /// The noise along the line: per group of bins (short bins merged) the RMS of its
    /// differences at their mean position (`sigma` for a bin whose RMS is 0).
    fn noise_bins(&self, options: &NoiseOptions, sigma: f64) -> Vec<NoiseBin> {
        let nb = options.bins;
        let groups = merge_bins(
            &self.sd_bins.iter().map(Vec::len).collect::<Vec<_>>(),
            options.min_count,
        );
        let ng = groups.iter().max().map_or(1, |m| m + 1);
        let mut bins = Vec::new();
        for g in 0..ng {
            let members: Vec<usize> = (0..nb).filter(|b| groups[*b] == g).collect();
            let v: Vec<f64> = members
                .iter()
                .flat_map(|b| self.sd_bins[*b].iter().copied())
                .collect();
            let x: Vec<f64> = members
                .iter()
                .flat_map(|b| self.x_bins[*b].iter().copied())
                .collect();
            if v.is_empty() {
                continue;
            }
            let (from, to) = match (members.first(), members.last()) {
                (Some(a), Some(b)) => (*a as f64 / nb as f64, (*b + 1) as f64 / nb as f64),
                _ => continue,
            };
            let bs = (v.iter().map(|e| e * e).sum::<f64>() / v.len() as f64).sqrt();
            bins.push(NoiseBin {
                from,
                to,
                centre: x.iter().sum::<f64>() / x.len() as f64,
                sigma: if bs > 0.0 { bs } else { sigma },
                count: v.len(),
            });
        }
        bins
    }
}

/// How much the noise varies along the line: the ratio of the largest to the smallest bin's
/// SD and its `z` value (`(1, 0)` with fewer than two bins).
fn variation(bins: &[NoiseBin]) -> (f64, f64) {
    let (mut lo, mut hi) = (0, 0);
    for (i, b) in bins.iter().enumerate() {
        if b.sigma < bins[lo].sigma {
            lo = i;
        }
        if b.sigma > bins[hi].sigma {
            hi = i;
        }
    }
    if bins.len() >= 2 {
        let se2 = 1.0 / bins[lo].count as f64 + 1.0 / bins[hi].count as f64;
        let ratio = bins[hi].sigma / bins[lo].sigma;
        (ratio, ratio.ln() / se2.sqrt())
    } else {
        (1.0, 0.0)
    }
}

impl NoiseModel {
    /// Item 6 of the module docs: the noise's lag-1 autocorrelation from first differences of
    /// the noise-normalised residuals, and, where it is significant and the experiments'
    /// residuals are no more alike than independent noise makes them, the noise level as the
    /// correlated noise's own SD.
    fn correlate(&mut self, series: &[ResidualSeries], is_out: &[Vec<bool>]) {
        let z: Vec<Vec<f64>> = series
            .iter()
            .enumerate()
            .map(|(k, e)| {
                e.positions_m
                    .iter()
                    .zip(&e.residuals)
                    .map(|(s, r)| r / self.local_sigma_at(k, *s))
                    .collect()
            })
            .collect();
        let Some((rho, pairs)) = difference_correlation(&z, is_out) else {
            return;
        };
        self.correlation = rho;
        self.correlation_se = (2.0 / pairs as f64).sqrt();
        // significantly above 0, and not beyond what AR(1) noise on these lines can be told
        // from a misfit by
        let margin = CORRELATION_GATE_Z * self.correlation_se;
        if !(rho > margin && rho <= MAX_CORRELATION && homogeneous(&z, is_out)) {
            return;
        }
        let x: Vec<Vec<f64>> = series
            .iter()
            .zip(&self.lengths_m)
            .map(|(e, l)| e.positions_m.iter().map(|s| s / l).collect())
            .collect();
        let Some(p) = coherence_p(&z, &x, is_out, self.calibration_correlation_of(rho)) else {
            return;
        };
        self.coherence_p = Some(p);
        if p <= COHERENCE_LEVEL {
            return;
        }
        let r = rho.min(MAX_CORRELATION);
        self.correlation_used = r;
        // normalised second differences of AR(1) noise: variance σ²(1 − 4ρ/3 + ρ²/3)
        let scale = NoiseModel::level_factor(r);
        self.sigma *= scale;
        for b in &mut self.bins {
            b.sigma *= scale;
        }
    }

    /// [`NoiseModel::calibration_correlation`] for a correlation `rho` about to be used.
    pub(super) fn calibration_correlation_of(&self, rho: f64) -> f64 {
        (rho.min(MAX_CORRELATION) + self.correlation_se).min(MAX_CORRELATION)
    }
}

/// The small-sample bias of `1 + 2 r₁` is `DIFFERENCE_BIAS (1 − ρ)/n` on lines of `n` points
/// (measured by simulating 9 lines of 12, 26 and 51 points of AR(1) noise with `ρ` 0 to 0.7:
/// 0.041 at `ρ = 0`, 26 points; after the correction every mean is within 0.006 of `ρ`).
const DIFFERENCE_BIAS: f64 = 1.2;

/// `ρ̂ = 1 + 2 r₁` of the first differences of `z` (differences touching an outlier left
/// out), corrected for its small-sample bias, and the number of difference pairs; `None`
/// with fewer than 3 pairs.
fn difference_correlation(z: &[Vec<f64>], is_out: &[Vec<bool>]) -> Option<(f64, usize)> {
    let (mut num, mut den, mut pairs) = (0.0, 0.0, 0usize);
    for (zk, out) in z.iter().zip(is_out) {
        // the difference i → i + 1, where neither point is an outlier
        let d: Vec<Option<f64>> = (0..zk.len().saturating_sub(1))
            .map(|i| (!out[i] && !out[i + 1]).then(|| zk[i + 1] - zk[i]))
            .collect();
        for (i, di) in d.iter().enumerate() {
            let Some(di) = di else { continue };
            den += di * di;
            if let Some(Some(dn)) = d.get(i + 1) {
                num += di * dn;
                pairs += 1;
            }
        }
    }
    if !(pairs >= 3 && den > 0.0 && num.is_finite()) {
        return None;
    }
    let points: usize = z.iter().map(Vec::len).sum();
    let c = DIFFERENCE_BIAS * z.len() as f64 / points as f64;
    Some(((1.0 + 2.0 * num / den - c) / (1.0 - c), pairs))
}

/// The largest experiment's RMS of `z` over the median experiment's above which the
/// experiments do not share one noise: one experiment's misfit (a wrong file, a broken run)
/// raises the pooled correlation but is no noise. For AR(1) noise of `ρ ≤ 0.7` on 26 points
/// an experiment's RMS scatters by about 25 %, so 2 is never reached by noise alone.
const HOMOGENEITY_RATIO: f64 = 2.0;

/// Whether the experiments' residuals (outliers left out) are alike in size
/// ([`HOMOGENEITY_RATIO`]); true with fewer than 2 experiments.
fn homogeneous(z: &[Vec<f64>], is_out: &[Vec<bool>]) -> bool {
    let mut rms: Vec<f64> = z
        .iter()
        .zip(is_out)
        .filter_map(|(zk, out)| {
            let v: Vec<f64> = zk
                .iter()
                .zip(out)
                .filter(|(_, o)| !**o)
                .map(|(v, _)| v * v)
                .collect();
            (!v.is_empty()).then(|| (v.iter().sum::<f64>() / v.len() as f64).sqrt())
        })
        .collect();
    if rms.len() < 2 {
        return true;
    }
    let max = rms.iter().copied().fold(0.0, f64::max);
    let mid = crate::data::statistics::median(&mut rms);
    mid > 0.0 && max <= HOMOGENEITY_RATIO * mid
}

/// Bins of `s/L` in which the experiments' residual shapes are compared.
const COHERENCE_BINS: usize = 5;

/// Simulated effect-free data sets behind the coherence p-value.
const COHERENCE_REPLICATES: usize = 200;

/// The experiments' binned residual profiles (the sum of `z` per bin of `s/L`, outliers left
/// out, centred over the bins) and their mean squared cosine over pairs of experiments.
fn coherence(
    z: &[Vec<f64>],
    x: &[Vec<f64>],
    is_out: &[Vec<bool>],
    rows: &mut [[f64; COHERENCE_BINS]],
) -> f64 {
    for (k, row) in rows.iter_mut().enumerate() {
        let mut count = [0usize; COHERENCE_BINS];
        *row = [0.0; COHERENCE_BINS];
        for i in 0..z[k].len() {
            if !is_out[k][i] {
                let b = bin_of(x[k][i], COHERENCE_BINS);
                row[b] += z[k][i];
                count[b] += 1;
            }
        }
        // centred: a fit leaves each experiment's residuals summing to about zero (its
        // take-up factor), which makes every row lie in the same subspace; independent noise
        // centred alike does too, so the comparison stays like with like
        let used = count.iter().filter(|c| **c > 0).count().max(1);
        let mean = row.iter().sum::<f64>() / used as f64;
        for (v, c) in row.iter_mut().zip(count) {
            *v = if c > 0 { *v - mean } else { 0.0 };
        }
        let norm = row.iter().map(|v| v * v).sum::<f64>().sqrt();
        for v in row.iter_mut() {
            *v = if norm > 0.0 { *v / norm } else { 0.0 };
        }
    }
    let (mut sum, mut pairs) = (0.0, 0usize);
    for a in 0..rows.len() {
        for b in a + 1..rows.len() {
            let c: f64 = rows[a].iter().zip(&rows[b]).map(|(u, v)| u * v).sum();
            sum += c * c;
            pairs += 1;
        }
    }
    sum / pairs.max(1) as f64
}

/// How alike the experiments' residual shapes are, as a p-value against independent AR(1)
/// noise of correlation `rho` in each experiment (same points, same outliers left out; a
/// fixed seed, so a report is reproducible). A missing effect leaves residuals of one shape
/// (up to sign and scale) in related experiments; noise leaves independent ones. `None` with
/// fewer than 3 experiments.
fn coherence_p(z: &[Vec<f64>], x: &[Vec<f64>], is_out: &[Vec<bool>], rho: f64) -> Option<f64> {
    if z.len() < 3 {
        return None;
    }
    let mut rows = vec![[0.0; COHERENCE_BINS]; z.len()];
    let observed = coherence(z, x, is_out, &mut rows);
    let mut rng = SplitMix64::new(0xC0_4E_2E_9C);
    let innovation = (1.0 - rho * rho).sqrt();
    let mut sim: Vec<Vec<f64>> = z.iter().map(|zk| vec![0.0; zk.len()]).collect();
    let mut beyond = 0usize;
    for _ in 0..COHERENCE_REPLICATES {
        for zk in sim.iter_mut() {
            let mut v = 0.0;
            for (i, zi) in zk.iter_mut().enumerate() {
                let w = rng.normal();
                v = if i == 0 { w } else { rho * v + innovation * w };
                *zi = v;
            }
        }
        if coherence(&sim, x, is_out, &mut rows) >= observed {
            beyond += 1;
        }
    }
    Some((1 + beyond) as f64 / (1 + COHERENCE_REPLICATES) as f64)
}

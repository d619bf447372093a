//! [`NoiseModel::estimate`], step by step: the outliers from local robust lines, the second
//! differences without them (globally and in bins of `s/L`), the noise along the line, and
//! the judgement numbers.

use super::{
    bin_of, local_deviations, merge_bins, NoiseBin, NoiseModel, NoiseOptions, Outlier,
    ResidualSeries,
};
use crate::data::statistics::{robust_sd, second_differences};

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
            options: *options,
            lengths_m: lengths,
        };
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

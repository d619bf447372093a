//! The comparison in words: noise level, χ²/dof, whiteness, where the misfit is systematic.

use super::{Comparison, NoiseModel, Segment};
use std::fmt::Write;

fn pct(v: f64) -> f64 {
    100.0 * v
}

/// "model too thin by 5.0 ± 1.1 % on s = 0.02–0.12 m in 9 of 9 experiments".
fn segment_line(seg: &Segment, total: usize, names: &[String], pooled: bool) -> String {
    let range = if seg.stations == 1 {
        format!("at s = {:.3} m", seg.start_m)
    } else {
        format!("on s = {:.3}–{:.3} m", seg.start_m, seg.end_m)
    };
    let mut s = format!(
        "model too {} by {:.1}",
        seg.direction(),
        pct(seg.mean.abs())
    );
    if pooled {
        let _ = write!(
            s,
            " ± {:.1} % {range} in {} of {total} experiments \
             ({} significant alone; ± is the spread across experiments; {} points, z = {:.1})",
            pct(seg.spread),
            seg.same_sign,
            seg.significant,
            seg.points,
            seg.z
        );
        let other: Vec<&str> = seg
            .per_experiment
            .iter()
            .filter(|(_, v)| (*v > 0.0) != (seg.mean > 0.0))
            .filter_map(|(k, _)| names.get(*k).map(String::as_str))
            .collect();
        if !other.is_empty() && other.len() <= 4 {
            let _ = write!(s, "; opposite sign in {}", other.join(", "));
        }
    } else {
        let pts = if seg.points == 1 { "point" } else { "points" };
        let _ = write!(s, " % {range} ({} {pts}, z = {:.1})", seg.points, seg.z);
    }
    s
}

/// Most outliers listed in the text (all are in the JSON).
const MAX_LISTED_OUTLIERS: usize = 30;

impl Comparison {
    /// The noise model in words: scale along the line, RMS/noise, outliers.
    fn noise_lines(nm: &NoiseModel, s: &mut String) {
        let bins: Vec<String> = nm
            .bins
            .iter()
            .map(|b| format!("{:.2} % on s/L {:.1}-{:.1}", pct(b.sigma), b.from, b.to))
            .collect();
        let along = if nm.varies_along_line {
            format!(
                "the noise VARIES along the line ({:.1}x between bins, z = {:.1})",
                nm.variation_ratio, nm.variation_z
            )
        } else {
            format!(
                "no significant variation along the line ({:.1}x, z = {:.1})",
                nm.variation_ratio, nm.variation_z
            )
        };
        let _ = writeln!(s, "noise along the line {}: {along}", bins.join(", "));
        let _ = writeln!(
            s,
            "RMS/noise = {:.2} (RMS {:.2} % vs local noise RMS {:.2} % over the same {} points, outliers left out); robust RMS/noise = {:.2}",
            nm.rms_over_noise,
            pct(nm.rms),
            pct(nm.noise_rms),
            nm.points,
            nm.robust_rms_over_noise
        );
        if nm.outliers.is_empty() {
            let _ = writeln!(
                s,
                "outliers: none (no point deviates from its neighbours' robust line by more than                  {} local sigma)",
                nm.options.outlier_threshold
            );
            return;
        }
        let _ = writeln!(
            s,
            "OUTLIERS: {} points deviate from their neighbours' robust line by more than {} local sigma (left out of chi2, RMS/noise and lag-1):",
            nm.outliers.len(),
            nm.options.outlier_threshold
        );
        for o in nm.outliers.iter().take(MAX_LISTED_OUTLIERS) {
            let _ = writeln!(
                s,
                "  - {} at s = {:.3} m: measured {:.2} um, model {:.2} um, residual {:+.1} % ({:+.1} sigma)",
                o.experiment,
                o.position_m,
                1e6 * o.d_meas_m,
                1e6 * o.d_model_m,
                pct(o.residual),
                o.deviation_sigmas
            );
        }
        if nm.outliers.len() > MAX_LISTED_OUTLIERS {
            let _ = writeln!(
                s,
                "  ... and {} more (see compare.json, noise.outliers)",
                nm.outliers.len() - MAX_LISTED_OUTLIERS
            );
        }
    }

    /// The summary in words.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let m = self.experiments.len();
        let _ = writeln!(
            s,
            "[[Model vs measurement: {m} experiments, {} points]]",
            self.points
        );
        let _ = writeln!(
            s,
            "RMS relative residual (d_model - d_meas)/d_meas = {:.2} %",
            pct(self.rms)
        );
        let _ = writeln!(s, "noise level sigma = {}", self.noise.describe());
        if let Some(nm) = &self.noise.model {
            Self::noise_lines(nm, &mut s);
        }
        self.misfit_lines(&mut s);
        self.segment_lines(&mut s);
        crate::report::format::wrap_long_lines(&s)
    }

    /// The summary's lines on the misfit against the noise: `chi2/dof` and the whiteness tests.
    fn misfit_lines(&self, s: &mut String) {
        let dof = self.dof as f64;
        let excess = (self.chi2 - dof) / (2.0 * dof).sqrt();
        let verdict = if self.dof == 0 {
            "no degrees of freedom left".to_string()
        } else if excess < 3.0 {
            "consistent with the noise".to_string()
        } else {
            format!(
                "the misfit is {:.1} times the noise variance (RMS {:.1} sigma)",
                self.chi2_per_dof,
                self.chi2_per_dof.sqrt()
            )
        };
        let _ = writeln!(
            s,
            "chi2/dof = {:.1}/{} = {:.2} ({} fitted parameters{}): {verdict}",
            self.chi2,
            self.dof,
            self.chi2_per_dof,
            self.fitted_parameters,
            match self.noise.model.as_ref().map_or(0, |m| m.outliers.len()) {
                0 => String::new(),
                k => format!(", {k} outliers left out"),
            }
        );
        let correlated = self.noise.correlation();
        if correlated > 0.0 {
            // the runs test assumes independent signs; the lag-1 z is against the noise's own
            let verdict = if self.lag1_z.is_nan() || self.lag1_z < 2.0 {
                "no structure beyond the noise's own correlation"
            } else if self.lag1_z < 3.0 {
                "marginal evidence of structure beyond the noise's correlation (2-3 sigma)"
            } else {
                "structure along s beyond the noise's correlation"
            };
            let _ = writeln!(
                s,
                "whiteness: not expected (the noise is correlated along the line, lag-1 {:.2}; \
                 the runs test, z = {:.1}, assumes white noise); lag-1 autocorrelation {:.2} of \
                 the noise-normalised residuals (z = {:.1} against the noise's): {verdict}",
                correlated, self.runs.z, self.lag1, self.lag1_z,
            );
            return;
        }
        // evidence against whiteness: the larger of −z(runs) and z(lag-1)
        let evidence = (-self.runs.z).max(self.lag1_z);
        let verdict = if evidence.is_nan() || evidence < 2.0 {
            "residuals look white"
        } else if evidence < 3.0 {
            "marginal evidence of structure along s (2-3 sigma)"
        } else {
            "residuals are NOT white (structure along s that noise does not explain)"
        };
        let _ = writeln!(
            s,
            "whiteness: runs test z = {:.1} ({} runs of residual signs, {:.1} expected for \
             random signs), lag-1 autocorrelation {:.2} of the noise-normalised residuals \
             (z = {:.1}): {verdict}",
            self.runs.z, self.runs.runs, self.runs.expected, self.lag1, self.lag1_z,
        );
    }

    /// The summary's lines on the structure of the residual: the systematic segments, the
    /// trends and each experiment's figures.
    fn segment_lines(&self, s: &mut String) {
        let m = self.experiments.len();
        let names: Vec<String> = self.experiments.iter().map(|e| e.name.clone()).collect();
        if self.segments.is_empty() {
            let _ = writeln!(
                s,
                "no systematic segment: the pooled residual stays within the noise along the \
                 spin line (|z| < {} or below {:.1} %)",
                self.segment_options.z_segment,
                pct(self.segment_options.min_effect)
            );
        } else {
            let _ = writeln!(s, "systematic misfit (pooled over experiments):");
            for seg in &self.segments {
                let _ = writeln!(s, "  - {}", segment_line(seg, m, &names, true));
            }
        }
        let trends: Vec<String> = self
            .trends
            .iter()
            .map(|t| format!("{} {:+.2}", t.quantity.replace('_', " "), t.spearman))
            .collect();
        let _ = writeln!(
            s,
            "rank correlation of the residual with: {}",
            trends.join(", ")
        );
        let _ = writeln!(s, "per experiment:");
        for e in &self.experiments {
            let _ = writeln!(
                s,
                "  {}: RMS {:.2} %, mean {:+.2} %, chi2/n {:.2}, runs z {:.1}, lag-1 {:.2}",
                e.name,
                pct(e.rms),
                pct(e.mean),
                e.chi2 / e.points.len().max(1) as f64,
                e.runs.z,
                e.lag1
            );
            for seg in &e.segments {
                let _ = writeln!(s, "      {}", segment_line(seg, 1, &names, false));
            }
        }
    }
}

//! The diagnosis in words, and the before/after residual figure.

use super::diagnose::{CandidateResult, Diagnosis, DiagnosisRun, ResidualProfiles};
use crate::plot::{save_panels, Panel, PlotError, Series};
use std::path::Path;

fn fmt_range(r: [f64; 2]) -> String {
    format!("{:.2}–{:.2} m", r[0], r[1])
}

impl Diagnosis {
    /// The report in words.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let b = &self.base_fit;
        s.push_str(&format!(
            "[[Diagnosis: which effect is missing from the {} model?]]\n",
            match self.model {
                crate::fiber::effects::LawChoice::Newtonian => "Newtonian",
                crate::fiber::effects::LawChoice::Carreau => "Carreau-type",
            }
        ));
        s.push_str(&format!(
            "Your model fitted with the principled estimator: J = {:.4e}, RMS relative residual {:.3} % \
             over {} measurements; noise level {:.3} % ({}).\n",
            b.cost,
            100.0 * b.rms_relative_residual,
            b.residuals,
            100.0 * self.noise_level,
            self.noise_source
        ));
        for w in &b.warnings {
            s.push_str(&format!("WARNING about your model's fit: {w}\n"));
        }
        s.push_str(&format!(
            "The residuals are {} (RMS/noise = {:.2}, lag-1 autocorrelation {:+.2}).\n",
            if self.systematic {
                "SYSTEMATIC: the model misses something"
            } else {
                "consistent with noise"
            },
            self.rms_over_noise,
            self.lag1_autocorrelation
        ));
        match (&self.most_likely_missing, self.candidates.first()) {
            (Some(name), Some(c)) => {
                s.push_str(&format!(
                    "Most likely missing: {name}. Its signature lies along s = {} (strongest at {:.2} m). \
                     Adding it removes {:.1} % of the misfit (J {:.4e} -> {:.4e}), RMS {:.3} % -> {:.3} %, \
                     delta BIC = {:.1}, delta AIC = {:.1}; fitted strength {:.4} +/- {:.4} {}.\n",
                    fmt_range(c.signature_range_m),
                    c.signature_peak_m,
                    100.0 * (1.0 - c.cost_after / c.cost_before),
                    c.cost_before,
                    c.cost_after,
                    100.0 * b.rms_relative_residual,
                    100.0 * c.rms_relative_residual_after,
                    c.delta_bic,
                    c.delta_aic,
                    c.strength,
                    c.stderr_strength,
                    c.unit
                ));
                if let Some(b) = c.at_bound.iter().find(|b| b.parameter == c.effect) {
                    s.push_str(&format!(
                        "WARNING: its strength ends AT ITS {} BOUND {} {}: the data push it beyond its \
                         search range, so this is not a credible estimate of the effect (a different \
                         effect, or a process or instrument error, may be behind the misfit).\n",
                        b.side.name().to_uppercase(),
                        b.bound,
                        c.unit
                    ));
                }
                if c.n.is_finite() {
                    s.push_str(&format!(
                        "With it: n = {}, kappa = {}.\n",
                        estimate_with_ci(c, "n", c.n, c.ci95_n),
                        estimate_with_ci(c, "kappa", c.kappa, c.ci95_kappa)
                    ));
                }
            }
            _ => s.push_str(
                "No candidate earns its place: no effect lowers BIC by more than the threshold; \
                 the model is adequate for these data (or the missing effect is not among the candidates).\n",
            ),
        }
        s.push_str("[[Candidates, best first]]\n");
        s.push_str("    effect                   refit  strength +/- stderr        J after      RMS after  dBIC     signature\n");
        for c in &self.candidates {
            let bound = match c.at_bound.iter().find(|b| b.parameter == c.effect) {
                Some(b) => format!("  AT {} BOUND", b.side.name().to_uppercase()),
                None => String::new(),
            };
            s.push_str(&format!(
                "    {:<24} {:<5}  {:>10.4} +/- {:<10.4} {:<4} {:.4e}  {:>8}  {:>7.1}  {} (peak {:.2} m){bound}\n",
                c.effect,
                if c.refitted { "yes" } else { "lin" },
                c.strength,
                c.stderr_strength,
                c.unit,
                c.cost_after,
                if c.rms_relative_residual_after.is_finite() {
                    format!("{:.3} %", 100.0 * c.rms_relative_residual_after)
                } else {
                    "-".into()
                },
                c.delta_bic,
                fmt_range(c.signature_range_m),
                c.signature_peak_m
            ));
        }
        if self.indistinguishable.is_empty() {
            s.push_str("No two candidates have strongly correlated signatures.\n");
        } else {
            for p in &self.indistinguishable {
                s.push_str(&format!(
                    "The data cannot tell {} and {} apart (signature cosine {:+.3}).\n",
                    p.effects[0], p.effects[1], p.cosine
                ));
            }
        }
        s.push_str(&format!("wall time {:.2} s\n", self.wall_time_s));
        s
    }
}

/// `"0.8040 (95% CI [0.79, 0.82])"`, or the estimate marked at its bound without an interval.
fn estimate_with_ci(c: &CandidateResult, name: &str, value: f64, ci: [f64; 2]) -> String {
    match c.at_bound.iter().find(|b| b.parameter == name) {
        Some(b) => format!(
            "{value:.4} (AT ITS {} BOUND: no valid 95% CI)",
            b.side.name().to_uppercase()
        ),
        None if ci.iter().all(|v| v.is_finite()) => {
            format!("{value:.4} (95% CI [{:.4}, {:.4}])", ci[0], ci[1])
        }
        None => format!("{value:.4} (no valid 95% CI)"),
    }
}

/// Residuals before (and after) adding an effect, one panel per experiment.
pub fn save_residual_figure(
    path: &Path,
    before: &ResidualProfiles,
    after: Option<(&str, &ResidualProfiles)>,
) -> Result<(), PlotError> {
    let panels: Vec<Panel> = before
        .iter()
        .enumerate()
        .map(|(k, (name, b))| {
            let mut p =
                Panel::new(name.clone(), "s / m", "(d_model - d_meas)/d_meas / %").with_series(
                    Series::markers("without", b.iter().map(|&(s, r)| (s, 100.0 * r)).collect()),
                );
            if let Some((label, a)) = after {
                if let Some((_, a)) = a.get(k) {
                    p = p.with_series(Series::line(
                        format!("with {label}"),
                        a.iter().map(|&(s, r)| (s, 100.0 * r)).collect(),
                    ));
                }
            }
            p
        })
        .collect();
    let cols = 3.min(panels.len().max(1));
    let rows = panels.len().div_ceil(cols) as u32;
    save_panels(path, &panels, cols, (420 * cols as u32, 320 * rows.max(1)))
}

impl DiagnosisRun {
    /// Writes the before/after residual figure.
    pub fn save_figure(&self, path: &Path) -> Result<(), PlotError> {
        let name = self
            .diagnosis
            .most_likely_missing
            .clone()
            .unwrap_or_default();
        save_residual_figure(
            path,
            &self.residuals_before,
            self.residuals_after.as_ref().map(|a| (name.as_str(), a)),
        )
    }
}

//! The diagnosis in words, and the before/after residual figure.

use super::candidate::{Candidate, ShapeAlternative};
use super::diagnose::verdict::{Help, Unexplained, Verdict};
use super::diagnosis::{Diagnosis, DiagnosisRun, ResidualProfiles};
use super::refits::consistency::Consistency;
use super::refits::scan::Profile;
use crate::fit::summary::Estimate;
use crate::report::format::{fmt_at, fmt_g, fmt_pm, unit_suffix};
use crate::report::output_files::OutputFile;
use crate::report::plot::{render_panels, Panel, PlotError, Series};
use std::path::Path;

mod text;

fn fmt_range(r: [f64; 2]) -> String {
    format!("{:.2}–{:.2} m", r[0], r[1])
}

/// `value ± se unit` rounded to the uncertainty.
fn pm_unit(value: f64, se: f64, unit: &str) -> String {
    format!("{}{}", fmt_pm(value, se), unit_suffix(unit))
}

/// `ΔBIC` gap below which two causes are an exact tie: no first, no second.
const EXACT_TIE: f64 = 1.0;

/// A probability in words: `"0.3 %"`, `"< 0.05 %"` (below the bootstrap's resolution), `"-"`.
fn probability(p: f64) -> String {
    if !p.is_finite() {
        "-".into()
    } else if p < 5e-4 {
        "< 0.05 %".into()
    } else {
        format!("{:.1} %", 100.0 * p)
    }
}

/// " What decides: ..." — the independent checks of `effects`, each once with the effects it
/// decides (one measurement, e.g. the fiber temperature, can decide two); effects without one
/// (strain thinning, a user effect) are left to data at other conditions. Empty for no effects.
fn what_decides<'a>(effects: impl Iterator<Item = &'a String>) -> String {
    let mut checks: Vec<(&str, Vec<&str>)> = Vec::new();
    for e in effects {
        let c = super::ties::independent_check(e).unwrap_or(super::ties::OTHER_CONDITIONS);
        match checks.iter_mut().find(|(k, _)| *k == c) {
            Some((_, for_)) if !for_.contains(&e.as_str()) => for_.push(e),
            Some(_) => {}
            None => checks.push((c, vec![e])),
        }
    }
    if checks.is_empty() {
        return String::new();
    }
    let lines: Vec<String> = checks
        .iter()
        .map(|(c, for_)| format!("{c} (for {})", for_.join(", ")))
        .collect();
    format!(" What decides: {}.", lines.join("; "))
}

impl Diagnosis {
    /// The verdict in words (see [`Verdict`]).
    /// "; noise level re-estimated with them: x %" where the verdict's noise level is below the
    /// user's fit's (whose misfit inflated its estimate).
    fn reestimated(&self, level: f64) -> String {
        let base = self.base_fit.noise.level;
        if level.is_finite() && level > 0.0 && level < 0.95 * base {
            format!(
                "; noise level {:.3} % re-estimated from these residuals (the {:.3} % of your \
                 model's fit is inflated by its misfit)",
                100.0 * level,
                100.0 * base
            )
        } else {
            String::new()
        }
    }

    fn verdict_text(&self) -> String {
        match &self.verdict {
            Verdict::Adequate => "VERDICT: the model is adequate for these data: the residuals \
                 are consistent with the noise and no candidate earns its place.\n"
                .into(),
            Verdict::Explained {
                effects,
                rms_over_noise,
                noise_level,
            } => format!(
                "VERDICT: explained by {}: with {} the residuals are at the noise (RMS/noise \
                 {rms_over_noise:.2}, no structure left along the line){}{}.\n",
                effects.join(" + "),
                if effects.len() > 1 { "them" } else { "it" },
                self.reestimated(*noise_level),
                match self.pair.as_ref().filter(|p| !p.replaces) {
                    Some(p) => format!(
                        "; or by {} about as well, with the same law",
                        p.effects.join(" + ")
                    ),
                    None => String::new(),
                }
            ),
            Verdict::Ambiguous {
                effects,
                alternatives,
                rms_over_noise,
                noise_level,
                n_range,
                kappa_range,
            } => format!(
                "VERDICT: AMBIGUOUS: explained by {} (RMS/noise {rms_over_noise:.2}, no structure \
                 left along the line){}, OR by {} about as well, with another law: the data \
                 cannot tell these explanations apart, and the material law is NOT A RESULT \
                 (over all, n lies in [{:.3}, {:.3}] and kappa in [{:.2}, {:.2}], 95 % \
                 intervals).{}\n",
                effects.join(" + "),
                self.reestimated(*noise_level),
                alternatives
                    .iter()
                    .map(|a| match a.as_slice() {
                        [one] => format!(
                            "{one}{}",
                            self.candidate(one).map_or("", |c| c.status.qualifier())
                        ),
                        _ => a.join(" + "),
                    })
                    .collect::<Vec<_>>()
                    .join(", OR by "),
                n_range[0],
                n_range[1],
                kappa_range[0],
                kappa_range[1],
                what_decides(effects.iter().chain(alternatives.iter().flatten()))
            ),
            Verdict::NoneOfTheCandidates {
                helps,
                unexplained,
                rms_over_noise,
                noise_level,
                stand_ins,
            } => self.none_explains_text(
                helps,
                unexplained,
                *rms_over_noise,
                *noise_level,
                stand_ins,
            ),
        }
    }

    /// The verdict where none of the candidates explains the misfit: what helps (or the
    /// stand-ins), that the law is not a result, the segments left `unexplained`, the next step.
    fn none_explains_text(
        &self,
        helps: &[Help],
        unexplained: &[Unexplained],
        rms_over_noise: f64,
        noise_level: f64,
        stand_ins: &[Consistency],
    ) -> String {
        let mut t = String::from(
            "VERDICT: NONE OF THE CANDIDATES explains the misfit: something else is missing",
        );
        if !stand_ins.is_empty() {
            t = stand_in_text(stand_ins, rms_over_noise, &self.reestimated(noise_level));
        } else if helps.is_empty() {
            t.push_str("; no candidate helps");
        } else {
            let h: Vec<String> = helps
                .iter()
                .take(4)
                .map(|h| format!("{} removes {:.0} %", h.effect, 100.0 * h.share_of_excess))
                .collect();
            t.push_str(&format!(
                " ({} of the excess misfit over the noise)",
                h.join(", ")
            ));
        }
        if stand_ins.is_empty() {
            t.push_str(&format!(
                "; with the best of them RMS/noise is {rms_over_noise:.2}{}.\n",
                self.reestimated(noise_level)
            ));
        }
        t.push_str(
            "    The material law (n, kappa) of these fits is NOT A RESULT: a model that \
             does not describe the data biases it by what it misses.\n",
        );
        for u in unexplained.iter().take(4) {
            t.push_str(&format!(
                "    unexplained: s = {:.3}-{:.3} m, the model too {} by {:.1} % ({:.1} \
                 standard errors) in {}\n",
                u.start_m,
                u.end_m,
                if u.mean > 0.0 { "thick" } else { "thin" },
                100.0 * u.mean.abs(),
                u.z.abs(),
                if u.experiments.is_empty() {
                    "the pooled residual".to_string()
                } else {
                    u.experiments.join(", ")
                }
            ));
        }
        t.push_str(
            "    Next step: describe the missing effect as an effect of your own (a term \
             and a descriptor; see the book's chapter \"When the model fails\") and \
             diagnose again with it as a candidate.\n",
        );
        t
    }
}

/// The verdict's first line where the named effects bring the residuals to the noise only
/// with strengths that differ between the experiments.
fn stand_in_text(stand_ins: &[Consistency], rms_over_noise: f64, reestimated: &str) -> String {
    let each: Vec<String> = stand_ins
        .iter()
        .map(|c| {
            format!(
                "{} (one strength {} for all) varies with {}: to first order {} ({})",
                c.effect,
                c.strength_words(c.strength),
                c.conditions.join(", "),
                c.spread_words(),
                c.test_words()
            )
        })
        .collect();
    format!(
        "VERDICT: NONE OF THE CANDIDATES explains the data: with {} the residuals are at the \
         noise (RMS/noise {rms_over_noise:.2}{reestimated}), but only with a strength that is \
         not the same in every experiment, which a physical constant or one instrument's error \
         is not: {}. It stands in for an effect none of the candidates describes (a process \
         error that differs between the runs would do the same: check them).\n",
        stand_ins
            .iter()
            .map(|c| c.effect.as_str())
            .collect::<Vec<_>>()
            .join(" + "),
        each.join("; ")
    )
}

/// One profile in a line: up to 9 points (the lowest always among them) as `strength: J/J_base`.
fn profile_line(p: &Profile) -> String {
    let n = p.points.len();
    let imin = p
        .points
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.cost.total_cmp(&b.1.cost))
        .map(|x| x.0);
    let step = n.div_ceil(9).max(1);
    let mut idx: Vec<usize> = (0..n).step_by(step).collect();
    if n > 0 && !idx.contains(&(n - 1)) {
        idx.push(n - 1);
    }
    if let Some(i) = imin {
        if !idx.contains(&i) {
            idx.push(i);
            idx.sort_unstable();
        }
    }
    let unit = if p.unit == "-" { "" } else { p.unit.as_str() };
    let cells: Vec<String> = idx
        .iter()
        .map(|&i| {
            let q = &p.points[i];
            let mark = if Some(i) == imin { "*" } else { "" };
            let phys = if q.strength < p.physical_range[0] || q.strength > p.physical_range[1] {
                "!"
            } else {
                ""
            };
            format!(
                "{:.3}{phys}: {:.3}{mark}",
                q.strength,
                q.cost / p.cost_base.max(1e-300)
            )
        })
        .collect();
    let mut line = format!(
        "{} ({unit}{}physical {}..{}): {}",
        p.label(),
        if unit.is_empty() { "" } else { "; " },
        p.physical_range[0],
        p.physical_range[1],
        cells.join(", ")
    );
    for st in &p.stopped {
        line.push_str(&format!(" [{st}]"));
    }
    line
}

/// Profiles of `J/J_base` against strength, one panel per candidate (one curve per scanned
/// shape; dashed vertical lines: the physical range of the strength).
pub(crate) fn profile_figure(path: &Path, diagnosis: &Diagnosis) -> Result<OutputFile, PlotError> {
    let panels: Vec<Panel> = diagnosis
        .candidates
        .iter()
        .filter(|c| !c.profiles.is_empty())
        .map(|c| {
            let unit = if c.unit == "-" { "-" } else { c.unit.as_str() };
            let mut p = Panel::new(
                format!("{} ({})", c.effect, c.status.name()),
                format!("strength / {unit}"),
                "J / J_base",
            )
            .with_log_y(true);
            let (mut ylo, mut yhi) = (f64::INFINITY, f64::NEG_INFINITY);
            for (k, pr) in c.profiles.iter().enumerate() {
                let pts: Vec<(f64, f64)> = pr
                    .points
                    .iter()
                    .map(|q| (q.strength, q.cost / pr.cost_base))
                    .filter(|q| q.1.is_finite() && q.1 > 0.0)
                    .collect();
                for q in &pts {
                    ylo = ylo.min(q.1);
                    yhi = yhi.max(q.1);
                }
                let label = if pr.shape.is_empty() {
                    "J/J_base".to_string()
                } else {
                    pr.shape
                        .iter()
                        .map(|s| format!("{} {:.3} {}", s.name, s.value, s.unit))
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                p = p
                    .with_series(Series::markers("", pts.clone()).with_color(k))
                    .with_series(Series::line(label, pts).with_color(k));
            }
            if ylo.is_finite() && yhi.is_finite() {
                for (j, x) in c.physical_range.iter().enumerate() {
                    if x.is_finite() {
                        let label = if j == 0 { "physical range" } else { "" };
                        p = p.with_series(
                            Series::dashed(label, vec![(*x, ylo), (*x, yhi)]).with_color(7),
                        );
                    }
                }
            }
            if c.refitted() && c.strength().is_finite() && c.cost_before > 0.0 {
                p = p.with_series(
                    Series::markers("refit", vec![(c.strength(), c.cost_after / c.cost_before)])
                        .with_color(3),
                );
            }
            p
        })
        .collect();
    let cols = 3.min(panels.len().max(1));
    let rows = panels.len().div_ceil(cols).max(1) as u32;
    let bytes = render_panels(path, &panels, cols, (440 * cols as u32, 340 * rows))?;
    Ok(OutputFile::new(path, bytes))
}

/// `"0.804 ± 0.007 (95% CI [0.790, 0.818])"` (rounded to the standard error behind the
/// interval), or the estimate marked at its bound without an interval.
fn estimate_with_ci(c: &Candidate, name: &str, e: Option<&Estimate>) -> String {
    estimate_with_ci_bounds(c.at_bound(), name, e.unwrap_or(&Estimate::unknown()))
}

/// [`estimate_with_ci`] of a fit's estimate `name` (its bounds from `at_bound`).
fn estimate_with_ci_bounds(at_bound: &[crate::fit::AtBound], name: &str, e: &Estimate) -> String {
    let (value, ci) = (e.value, e.ci95);
    match at_bound.iter().find(|b| b.parameter == name) {
        Some(b) => format!(
            "{} (AT ITS {} BOUND: no valid 95% CI)",
            fmt_g(value),
            b.side.name().to_uppercase()
        ),
        None if ci.iter().all(|v| v.is_finite()) => {
            let se = e.stderr;
            format!(
                "{} (95% CI [{}, {}])",
                fmt_pm(value, se),
                fmt_at(ci[0], se),
                fmt_at(ci[1], se)
            )
        }
        None => format!("{} (no valid 95% CI)", fmt_g(value)),
    }
}

/// Residuals before (and after) adding an effect, one panel per experiment, rendered as the
/// file `path` (write it with [`OutputFile::save`] or through a command's checked outputs).
pub fn residual_figure(
    path: &Path,
    before: &ResidualProfiles,
    after: Option<(&str, &ResidualProfiles)>,
) -> Result<OutputFile, PlotError> {
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
    let bytes = render_panels(path, &panels, cols, (420 * cols as u32, 320 * rows.max(1)))?;
    Ok(OutputFile::new(path, bytes))
}

impl DiagnosisRun {
    /// The figure of the `J` profiles (one panel per candidate, `J` against its strength),
    /// rendered as the file `path`.
    pub fn profile_figure(&self, path: &Path) -> Result<OutputFile, PlotError> {
        profile_figure(path, &self.diagnosis)
    }

    /// The before/after residual figure, rendered as the file `path`.
    pub fn residual_figure(&self, path: &Path) -> Result<OutputFile, PlotError> {
        // the "after" residuals are the final fit's, with every effect found
        let name = self.diagnosis.found.join(" + ");
        residual_figure(
            path,
            &self.residuals_before,
            self.residuals_after.as_ref().map(|a| (name.as_str(), a)),
        )
    }
}

/// The sentence on a shape the data cannot choose (see [`ShapeAlternative`]): the other
/// shape's strength and material estimate, and how far the latter lies from the reported one
/// in its standard errors.
fn shape_alternative_line(c: &Candidate, a: &ShapeAlternative) -> String {
    let r = &a.refit;
    let Some(e) = r.effect(&c.effect) else {
        return String::new();
    };
    let shape = e
        .shapes
        .iter()
        .map(|p| match p.unit.as_str() {
            "-" | "" => format!("{} {}", p.name, fmt_g(p.value)),
            u => format!("{} {} {u}", p.name, fmt_g(p.value)),
        })
        .collect::<Vec<_>>()
        .join(", ");
    let shift = |x: f64, x0: f64, se: f64| (x - x0) / se;
    let se_of = |e: Option<&Estimate>| e.map_or(f64::NAN, Estimate::valid_stderr);
    format!(
        "SHAPE: these data cannot choose the shape of {}: with {shape} (delta BIC {:+.1}) its \
         strength is {}, n = {} (95% CI [{}, {}]), kappa = {} (95% CI [{}, {}]): n {:+.1}, \
         kappa {:+.1} standard errors from the estimate above, a systematic uncertainty of the \
         shape.\n",
        c.effect,
        a.delta_bic_gap,
        pm_unit(e.strength.value, e.strength.stderr, &c.unit),
        fmt_at(r.n.value, r.n.stderr),
        fmt_at(r.n.ci95[0], r.n.stderr),
        fmt_at(r.n.ci95[1], r.n.stderr),
        fmt_at(r.kappa.value, r.kappa.stderr),
        fmt_at(r.kappa.ci95[0], r.kappa.stderr),
        fmt_at(r.kappa.ci95[1], r.kappa.stderr),
        shift(r.n.value, c.n(), se_of(c.n_estimate())),
        shift(r.kappa.value, c.kappa(), se_of(c.kappa_estimate()))
    )
}

#[cfg(test)]
mod tests {
    use super::what_decides;

    #[test]
    fn the_checks_that_decide_are_named_once_each() {
        let effects: Vec<String> = ["air_temperature_profile", "gauge_offset", "mass_flow_scale"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let t = what_decides(effects.iter().chain(effects.iter()));
        assert!(t.starts_with(" What decides: "), "{t}");
        assert!(t.contains("reference wire (for gauge_offset)"), "{t}");
        assert!(t.contains("(for mass_flow_scale)"), "{t}");
        assert_eq!(t.matches("gauge_offset").count(), 1, "{t}");
        // missing physics is decided by a measurement along the line too
        assert!(
            t.contains("a thermocouple moved along the line) (for air_temperature_profile)"),
            "{t}"
        );
        // one measurement that decides two effects is named once, for both
        let heat = ["radiation".to_string(), "nusselt_scale".to_string()];
        let t = what_decides(heat.iter());
        assert_eq!(t.matches("pyrometer").count(), 1, "{t}");
        assert!(t.ends_with("cools (for radiation, nusselt_scale)."), "{t}");
        let same = ["air_coflow_line".to_string(), "user_pull".to_string()];
        let t = what_decides(same.iter());
        assert!(
            t.contains("hot-wire anemometer) (for air_coflow_line)"),
            "{t}"
        );
        // an effect without a check: data at other conditions
        assert!(t.contains("another take-up speed"), "{t}");
        assert!(t.ends_with("differently (for user_pull)."), "{t}");
        assert_eq!(what_decides(std::iter::empty()), "");
    }
}

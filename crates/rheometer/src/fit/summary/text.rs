//! The text report of a [`FitSummary`]: the result on one screen first (the law with its
//! intervals, what the data support about strain thinning, the fit against the noise, the
//! warnings), the details below (how the fit ran, the other fitted parameters, the profile
//! intervals, the flow curve, correlations, the error budget). Numbers carry the digits their
//! uncertainty supports ([`fmt_pm`]); lines are at most
//! [`LINE_WIDTH`](crate::report::format::LINE_WIDTH) characters
//! ([`wrap_long_lines`]).

use crate::fit::estimator::Estimator;
use crate::fit::summary::{Estimate, FitSummary};
use crate::model::effects::LawChoice;
use crate::report::format::{fmt_at, fmt_e, fmt_g, fmt_pm, fmt_sig, wrap_long_lines};

/// `" unit"`, or nothing for a dimensionless quantity.
pub(crate) fn unit_suffix(unit: &str) -> String {
    match unit.trim() {
        "" | "-" => String::new(),
        u => format!(" {u}"),
    }
}

/// `[lo, hi]` at the precision of `u`.
pub(crate) fn fmt_interval(ci: [f64; 2], u: f64) -> String {
    format!("[{}, {}]", fmt_at(ci[0], u), fmt_at(ci[1], u))
}

impl FitSummary {
    /// Whether the linearised 95 % interval of a fitted estimate says nothing: a standard
    /// error of 1e5 or more, or an interval wider than the estimate's whole search range (a
    /// nearly singular covariance, e.g. two effects of the same physics fitted together).
    fn not_determined(&self, e: &Estimate) -> bool {
        let wider_than_range = self.interval(&e.name).is_some_and(|i| {
            let [lo, hi] = i.search_range;
            (e.ci95[1] - e.ci95[0]).abs() > (hi - lo).abs()
        });
        e.stderr >= 1e5 || wider_than_range
    }

    /// The line of a fitted or fixed estimate: `label value ± se  95% CI [lo, hi]`, or its
    /// bound, or why it has no interval.
    fn estimate_line(&self, label: &str, e: &Estimate) -> String {
        let unit = unit_suffix(&e.unit);
        let (value, se) = (e.value, e.stderr);
        if !e.fitted {
            return format!("    {label} {}{unit} (fixed)\n", fmt_g(value));
        }
        let mut s = if let Some(b) = self.bound_of(&e.name) {
            format!(
                "    {label} {}{unit} AT {} BOUND {} (no valid 95% CI: the optimum lies at or \
                 beyond the search range)",
                fmt_sig(value, 4),
                b.side.name().to_uppercase(),
                fmt_g(b.bound)
            )
        } else if let Some(side) = e.at_bound {
            format!(
                "    {label} {}{unit} AT {} BOUND (no valid 95% CI)",
                fmt_sig(value, 4),
                side.name().to_uppercase()
            )
        } else if !(se.is_finite() && se > 0.0) {
            format!(
                "    {label} {}{unit} (no standard error: singular covariance)",
                fmt_sig(value, 5)
            )
        } else {
            let undetermined = if self.not_determined(e) {
                " (not determined)"
            } else {
                ""
            };
            format!(
                "    {label} {}{unit}  95% CI {}{unit}{undetermined}",
                fmt_pm(value, se),
                fmt_interval(e.ci95, se)
            )
        };
        if let Some(i) = self.interval(&e.name) {
            if !i.linearised_trusted() {
                s.push_str(&format!("; profile likelihood: {}", i.words()));
            }
        }
        s.push('\n');
        s
    }

    /// The text report (see the module doc), a `[[Warnings]]` section when a check found
    /// something.
    pub fn to_text(&self) -> String {
        let mut s = self.result_text();
        if !self.warnings.is_empty() {
            s.push_str(&format!(
                "[[Warnings: {} — check these before using the estimates]]\n",
                self.warnings.len()
            ));
            for w in &self.warnings {
                s.push_str(&format!("    WARNING {w}\n"));
            }
        }
        s.push_str(&self.header_text());
        let details = self.take_up_text() + &self.effects_text();
        if !details.is_empty() {
            s.push_str("[[Variables]]\n");
            s.push_str(&details);
        }
        s.push_str(&self.intervals_text());
        s.push_str(&self.flow_curve_text());
        if self.correlation_n_kappa.is_finite() && !self.newtonian_on_data() {
            s.push_str("[[Correlations]]\n");
            s.push_str(&format!(
                "    C(n, kappa) = {:+.4}\n",
                self.correlation_n_kappa
            ));
        }
        if let Some(b) = &self.error_budget {
            s.push_str(&b.to_text());
        }
        wrap_long_lines(&s)
    }

    /// The result on one screen: the law, the finding, the fit against the noise, warnings.
    fn result_text(&self) -> String {
        let law = match self.law {
            LawChoice::Carreau => "Carreau-type law",
            LawChoice::Newtonian => "Newtonian law",
        };
        let mut s = format!(
            "[[Result: {law}, {} estimator, {} experiments]]\n",
            self.estimator.name(),
            self.experiments.len().max(self.take_up_factors.len())
        );
        s.push_str(&self.law_text());
        if let Some(why) = self.law_not_a_result() {
            s.push_str(&format!(
                "    NOT A RESULT: {why}; this law is no material property (warnings below)\n"
            ));
        }
        let finding = self.law_finding();
        if !finding.is_empty() {
            s.push_str(&format!("    {finding}\n"));
        }
        let rms = 100.0 * self.rms_relative_residual;
        if self.noise.level.is_finite() && self.noise.level > 0.0 {
            s.push_str(&format!(
                "    fit: RMS relative residual {rms:.3} %, {:.2} times the noise level {} %\n",
                self.rms_relative_residual / self.noise.level,
                crate::data::noise_summary::percent(self.noise.level)
            ));
        } else {
            s.push_str(&format!(
                "    fit: RMS relative residual {rms:.3} % (no noise level)\n"
            ));
        }
        s.push_str(&match self.warnings.len() {
            0 => "    warnings: none\n".to_string(),
            n => format!("    warnings: {n}, listed below\n"),
        });
        s
    }

    /// How the fit ran.
    fn header_text(&self) -> String {
        let mut s = String::new();
        s.push_str(&format!("[[Fit: {} estimator]]\n", self.estimator.name()));
        s.push_str(&format!(
            "    model law         = {}{}\n",
            match self.law {
                LawChoice::Carreau => "Carreau-type",
                LawChoice::Newtonian => "Newtonian",
            },
            if self.fitted.is_empty() {
                String::new()
            } else {
                format!(" (fitted: {})", self.fitted.join(", "))
            }
        ));
        s.push_str(&format!(
            "    start             = (n, kappa) = ({}, {})\n",
            fmt_g(self.start[0]),
            fmt_g(self.start[1])
        ));
        let sv = &self.solver;
        s.push_str(&format!(
            "    termination       = {}\n",
            sv.termination_text()
        ));
        s.push_str(&format!(
            "    iterations        = {} ({} failed BVP trial points)\n",
            sv.iterations, sv.failed_evaluations
        ));
        s.push_str(&format!(
            "    wall time         = {:.3} s\n",
            sv.wall_time_s
        ));
        if let Some(line) = self.discretisation_line() {
            s.push_str(&line);
        }
        s.push_str(&format!("    residuals         = {}\n", self.residuals));
        s.push_str(&format!("    cost J            = {:.6e}\n", self.cost));
        if !self.loss.is_linear() {
            s.push_str(&format!(
                "    loss              = {} (f_scale {:.3} % relative residual, {}; {} of {} \
                 residuals beyond it, down-weighted; CIs from the sandwich covariance)\n",
                self.loss,
                100.0 * self.f_scale,
                self.f_scale_source,
                self.down_weighted,
                self.residuals
            ));
        }
        s.push_str(&format!(
            "    RMS (d_model - d_meas)/d_meas = {:.4} %\n",
            100.0 * self.rms_relative_residual
        ));
        if self.noise.level.is_finite() {
            s.push_str(&format!(
                "    noise level       = {}\n",
                self.noise.describe()
            ));
        }
        s
    }

    /// `BVP accuracy = tol 1e-4, 121-294 nodes per experiment; at 1e-6 the estimates move
    /// by at most 0.0004 standard errors`.
    fn discretisation_line(&self) -> Option<String> {
        let sv = &self.solver;
        if !sv.bvp_tolerance.is_finite() {
            return None;
        }
        let (lo, hi) = sv
            .nodes
            .iter()
            .fold((usize::MAX, 0), |(a, b), &n| (a.min(n), b.max(n)));
        let nodes = match sv.nodes.len() {
            0 => String::new(),
            _ if lo == hi => format!(", {lo} nodes per experiment"),
            _ => format!(", {lo}-{hi} nodes per experiment"),
        };
        let check = if sv.discretisation_shift_se.is_finite() {
            format!(
                "; on meshes with every interval halved the estimates move by at most {:.1e} \
                 standard errors",
                sv.discretisation_shift_se
            )
        } else {
            String::new()
        };
        Some(format!(
            "    BVP accuracy      = tol {:.0e}{nodes}{check}\n",
            sv.bvp_tolerance
        ))
    }

    /// The significant digits `K` is printed with: those its relative error `se(κ)` supports
    /// (2 to 8).
    pub(crate) fn k_digits(&self) -> usize {
        (1 - self.kappa.stderr.max(1e-15).log10().floor() as i64).clamp(2, 8) as usize
    }

    /// `n`, `κ` and `K` (or the Newtonian law).
    fn law_text(&self) -> String {
        let mut s = String::new();
        if !self.n.fitted && !self.kappa.fitted && self.law == LawChoice::Newtonian {
            s.push_str("    law:   Newtonian (n = 1 fixed; kappa and K do not enter)\n");
            return s;
        }
        if self.newtonian_on_data() {
            s.push_str(&format!(
                "    law:   Newtonian within the data's strain rates; n and kappa are not \
                 estimated (the fit's n = {}, kappa = {} is one of many laws Newtonian over \
                 them)\n",
                fmt_sig(self.n.value, 2),
                fmt_sig(self.kappa.value, 3)
            ));
            return s;
        }
        s.push_str(&self.estimate_line("n:    ", &self.n));
        s.push_str(&self.estimate_line("kappa:", &self.kappa));
        let k = &self.k_pa;
        if k.has_interval() {
            let e = |v: f64| fmt_e(v, self.k_digits());
            s.push_str(&format!(
                "    K:     {} Pa  95% CI [{}, {}] Pa\n",
                e(k.value),
                e(k.ci95[0]),
                e(k.ci95[1])
            ));
        } else {
            s.push_str(&format!(
                "    K:     {} Pa  (no valid 95% CI)\n",
                fmt_sig(k.value, 4)
            ));
        }
        if let Some(b) = &self.error_budget {
            let sys = |label: &str, v: Option<f64>, e: &Estimate| {
                v.filter(|v| v.is_finite() && *v > 0.0 && e.fitted)
                    .map(|v| format!("{label} ± {}", fmt_sig(v, 2)))
            };
            let parts: Vec<String> = [
                sys("n", b.systematic_n, &self.n),
                sys("kappa", b.systematic_kappa, &self.kappa),
            ]
            .into_iter()
            .flatten()
            .collect();
            if !parts.is_empty() {
                s.push_str(&format!(
                    "    systematic (error budget, one standard uncertainty): {}\n",
                    parts.join(", ")
                ));
            }
        }
        s
    }

    fn take_up_text(&self) -> String {
        let mut s = String::new();
        if self.estimator != Estimator::Principled {
            return s;
        }
        let f: Vec<String> = self
            .take_up_factors
            .iter()
            .map(|v| format!("{v:.4}"))
            .collect();
        s.push_str(&format!(
            "    take-up factors d_out/d_fit(L): [{}]\n",
            f.join(", ")
        ));
        for b in self
            .at_bound
            .iter()
            .filter(|b| b.parameter.starts_with("take_up_factor["))
        {
            s.push_str(&format!(
                "    {}: {:.4} AT {} BOUND {}\n",
                b.parameter,
                b.value,
                b.side.name().to_uppercase(),
                fmt_g(b.bound)
            ));
        }
        s
    }

    fn effects_text(&self) -> String {
        let mut s = String::new();
        for e in &self.effects {
            let label = format!("{}:", e.effect);
            s.push_str(&self.estimate_line(&label, &e.strength));
            for sh in &e.shapes {
                let label = format!("  {}.{}:", e.effect, sh.name);
                s.push_str(&self.estimate_line(&label, sh));
            }
        }
        s
    }

    /// The profile intervals and the likelihood-ratio test.
    fn intervals_text(&self) -> String {
        let mut s = String::new();
        if let Some(why) = self.likelihood_skipped() {
            s.push_str("[[Profile-likelihood intervals and likelihood-ratio test]]\n");
            s.push_str(&format!("    not computed: {why}\n"));
            return s;
        }
        if !self.intervals.is_empty() {
            s.push_str("[[Profile-likelihood intervals (95 %: deviance 3.84; one-sided 2.71)]]\n");
        }
        for i in &self.intervals {
            let lin = self
                .parameters()
                .into_iter()
                .find(|e| e.name == i.parameter)
                .filter(|e| e.has_interval());
            let compare = match lin {
                Some(e) if i.ci95.iter().all(|v| v.is_finite()) => {
                    let wl = e.ci95[1] - e.ci95[0];
                    let wp = i.ci95[1] - i.ci95[0];
                    format!(
                        "; linearised {} ({:+.1} % in width)",
                        fmt_interval(e.ci95, e.stderr),
                        100.0 * (wp / wl - 1.0)
                    )
                }
                Some(e) => format!("; linearised {}", fmt_interval(e.ci95, e.stderr)),
                None => String::new(),
            };
            let trust = if i.linearised_trusted() {
                String::new()
            } else {
                format!(
                    " — linearised interval not trusted: {}",
                    i.reasons.join(", ")
                )
            };
            s.push_str(&format!(
                "    {}: profile {}{compare}{trust} ({} refits)\n",
                i.parameter,
                i.words(),
                i.points.len().saturating_sub(1)
            ));
        }
        if let Some(t) = &self.newtonian_test {
            s.push_str("[[Newtonian law (n = 1) against this fit: likelihood-ratio test]]\n");
            match t.p_mixture {
                Some(pm) => s.push_str(&format!(
                    "    LR = {}, {} calibrated ({} draws of the largest one-sided score over \
                     kappa under the Newtonian fit; ½χ²₀ + ½χ²₁ would give {}, too small as \
                     kappa is not identified under n = 1)\n",
                    fmt_sig(t.statistic, 3),
                    fmt_p(t.p_value),
                    t.calibration_replicates,
                    fmt_p(pm)
                )),
                None => s.push_str(&format!(
                    "    LR = {}, {} (null distribution ½χ²₀ + ½χ²₁; kappa is not identified \
                     under n = 1, so p is approximate)\n",
                    fmt_sig(t.statistic, 3),
                    fmt_p(t.p_value)
                )),
            }
            s.push_str(&format!(
                "    RMS relative residual {:.3} % with the Newtonian law, {:.3} % with this fit: \
                 {}\n",
                100.0 * t.rms_newtonian,
                100.0 * self.rms_relative_residual,
                match t.preferred {
                    LawChoice::Newtonian => "the Newtonian law fits as well (preferred, simpler)",
                    LawChoice::Carreau => "the strain thinning is significant",
                }
            ));
        }
        s
    }

    /// The flow curve in three lines.
    fn flow_curve_text(&self) -> String {
        let Some(c) = &self.flow_curve else {
            return String::new();
        };
        let mut s = format!(
            "[[Flow curve at {} K (flow_curve.csv, .json and figure with --out)]]\n",
            fmt_g(c.temperature_k)
        );
        s.push_str(&format!(
            "    Newtonian plateau {} eta0 = {} Pa s (Trouton ratio times the VFT shear \
             viscosity)\n",
            fmt_g(c.trouton),
            fmt_sig(c.plateau_pa_s, 3)
        ));
        s.push_str(&format!(
            "    the data cover strain rates {} to {} 1/s at this temperature (median {} 1/s); \
             beyond, the law is extrapolated\n",
            fmt_sig(c.covered_per_s[0], 2),
            fmt_sig(c.covered_per_s[1], 2),
            fmt_sig(c.median_per_s, 2)
        ));
        if let Some(p) = c.nearest(c.median_per_s) {
            let band = |b: [f64; 2]| format!("[{}, {}]", fmt_sig(b[0], 3), fmt_sig(b[1], 3));
            let how = |m: &str| format!(", 95 % band {} Pa s ({m})", band(p.stat95_pa_s));
            s.push_str(&format!(
                "    at {} 1/s: eta_E = {} Pa s{}{}\n",
                fmt_sig(p.strain_rate_per_s, 2),
                fmt_sig(p.eta_pa_s, 3),
                match c.band {
                    crate::fit::uncertainty::flow_curve::BandMethod::Delta => how("delta method"),
                    crate::fit::uncertainty::flow_curve::BandMethod::Profile =>
                        how("along the profile"),
                    crate::fit::uncertainty::flow_curve::BandMethod::None =>
                        format!(" ({NO_BAND})"),
                },
                if c.systematic {
                    format!(", with systematic {} Pa s", band(p.total95_pa_s))
                } else {
                    String::new()
                }
            ));
        }
        s
    }
}

/// Why a flow curve has no statistical band
/// ([`BandMethod::None`](crate::fit::uncertainty::flow_curve::BandMethod::None)).
pub(crate) const NO_BAND: &str =
    "no statistical band: no fitted law parameter, or no covariance of the fitted ones";

/// A p-value in words: `p = 0.41`, `p = 2.3e-5`, `p < 1e-15`.
pub(crate) fn fmt_p(p: f64) -> String {
    if !p.is_finite() {
        "p unknown".into()
    } else if p < 1e-15 {
        "p < 1e-15".into()
    } else if p < 1e-3 {
        format!("p = {p:.1e}")
    } else {
        format!("p = {}", fmt_sig(p, 2))
    }
}

//! The text report of a [`FitSummary`] (lmfit-style sections).

use super::estimator::Estimator;
use super::summary::{Estimate, FitSummary};
use crate::fiber::effects::LawChoice;
use crate::fiber::format::fmt_g;

impl FitSummary {
    /// One `label value +/- se ... 95% CI` line of a fitted law parameter.
    fn variable_line(&self, label: &str, e: &Estimate) -> String {
        let (value, se, ci) = (e.value, e.stderr, e.ci95);
        if let Some(b) = self.bound_of(&e.name) {
            format!(
                "    {label} {value:.5} AT {} BOUND {} ({}no valid 95% CI: the optimum lies at or \
                 beyond the search range)\n",
                b.side.name().to_uppercase(),
                fmt_g(b.bound),
                if se.is_finite() {
                    format!("+/- {} not valid; ", fmt_g(se))
                } else {
                    String::new()
                }
            )
        } else if !se.is_finite() {
            format!("    {label} {value:.5} +/- (no standard error: singular covariance)\n")
        } else if se >= 1e5 {
            format!(
                "    {label} {value:.5} +/- {se:.3e}  95% CI [{:.3e}, {:.3e}] (not determined)\n",
                ci[0], ci[1]
            )
        } else {
            format!(
                "    {label} {value:.5} +/- {se:.5} ({:.2}%)  95% CI [{:.5}, {:.5}]\n",
                100.0 * se / value.abs(),
                ci[0],
                ci[1]
            )
        }
    }

    /// An lmfit-style text report, with a `[[Warnings]]` section when a check found something.
    pub fn to_text(&self) -> String {
        let mut s = self.header_text();
        if !self.warnings.is_empty() {
            s.push_str(&format!(
                "[[Warnings: {} — do not use these estimates without checking]]\n",
                self.warnings.len()
            ));
            for w in &self.warnings {
                s.push_str(&format!("    WARNING {w}\n"));
            }
        }
        s.push_str("[[Variables]]\n");
        s.push_str(&self.law_text());
        s.push_str(&self.take_up_text());
        s.push_str(&self.effects_text());
        if self.correlation_n_kappa.is_finite() {
            s.push_str("[[Correlations]]\n");
            s.push_str(&format!(
                "    C(n, kappa) = {:+.4}\n",
                self.correlation_n_kappa
            ));
        }
        if let Some(b) = &self.error_budget {
            s.push_str(&b.to_text());
        }
        s
    }

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
            self.start[0], self.start[1]
        ));
        let sv = &self.solver;
        s.push_str(&format!("    termination       = {}\n", sv.termination));
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

    /// `BVP accuracy = tol 1e-4, 121–294 nodes per experiment; at 1e-6 the estimates move
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
                "; at {:.0e} the estimates move by at most {:.1e} standard errors",
                sv.check_tolerance, sv.discretisation_shift_se
            )
        } else {
            String::new()
        };
        Some(format!(
            "    BVP accuracy      = tol {:.0e}{nodes}{check}\n",
            sv.bvp_tolerance
        ))
    }

    fn law_text(&self) -> String {
        let mut s = String::new();
        if !self.n.fitted && !self.kappa.fitted && self.law == LawChoice::Newtonian {
            s.push_str("    law:   Newtonian (n = 1 fixed; kappa and K do not enter)\n");
            return s;
        }
        if self.n.fitted {
            s.push_str(&self.variable_line("n:    ", &self.n));
        } else {
            s.push_str(&format!("    n:     {:.5} (fixed)\n", self.n.value));
        }
        s.push_str(&self.variable_line("kappa:", &self.kappa));
        if self.k_pa.has_interval() {
            s.push_str(&format!(
                "    K:     {:.5e} Pa  95% CI [{:.5e}, {:.5e}] Pa\n",
                self.k_pa.value, self.k_pa.ci95[0], self.k_pa.ci95[1]
            ));
        } else {
            s.push_str(&format!(
                "    K:     {:.5e} Pa  (no valid 95% CI)\n",
                self.k_pa.value
            ));
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
            let st = &e.strength;
            if !st.fitted {
                s.push_str(&format!(
                    "    {}: {:.5} {} (fixed)\n",
                    e.effect, st.value, st.unit
                ));
            } else if let Some(side) = st.at_bound {
                let bound = self
                    .bound_of(&e.effect)
                    .map_or(String::new(), |b| format!(" {}", fmt_g(b.bound)));
                s.push_str(&format!(
                    "    {}: {:.5} {} AT {} BOUND{bound} (no valid 95% CI)\n",
                    e.effect,
                    st.value,
                    st.unit,
                    side.name().to_uppercase(),
                ));
            } else {
                s.push_str(&format!(
                    "    {}: {:.5} +/- {:.5} {}  95% CI [{:.5}, {:.5}]\n",
                    e.effect, st.value, st.stderr, st.unit, st.ci95[0], st.ci95[1]
                ));
            }
            for sh in &e.shapes {
                if sh.fitted {
                    s.push_str(&format!(
                        "      {}.{}: {:.5} +/- {:.5} {}\n",
                        e.effect, sh.name, sh.value, sh.stderr, sh.unit
                    ));
                } else {
                    s.push_str(&format!(
                        "      {}.{}: {:.5} {} (fixed)\n",
                        e.effect, sh.name, sh.value, sh.unit
                    ));
                }
            }
        }
        s
    }
}

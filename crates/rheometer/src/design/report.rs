//! The design as text: the current uncertainty, the best candidates with their predicted
//! standard errors and gains, the worst, and the infeasible ones.

use super::estimation::{CandidateOutcome, Design};
use std::fmt::Write as _;

/// How many ranked candidates the text lists.
pub const TEXT_TOP: usize = 10;

impl Design {
    /// The design as a text report (top `TEXT_TOP` candidates, the worst feasible one, and
    /// the number of infeasible ones with the first reason).
    pub fn to_text(&self) -> String {
        let mut t = String::new();
        let _ = writeln!(
            t,
            "Which experiment next: {} candidates ({} mass flows x {} {} values), template {}, \
             ranked by the {}-criterion",
            self.candidates.len(),
            self.grid.mass_flows.len(),
            self.grid.take_up.values().len(),
            self.grid.take_up.label(),
            self.template,
            self.criterion.name()
        );
        let _ = writeln!(t, "Noise of the predictions: {}", self.noise_model);
        let _ = writeln!(
            t,
            "\nNow (predicted from the fit's sensitivities; the fit's own in brackets):"
        );
        for (i, p) in self.parameters.iter().enumerate() {
            let _ = writeln!(
                t,
                "  {p:<24} {:>12.5}  se {:>10.3e}  [{:.3e}]",
                self.values[i], self.current.stderr[i], self.fit_stderr[i]
            );
        }
        if self.current.correlation_n_kappa.is_finite() {
            let _ = writeln!(
                t,
                "  correlation(n, kappa) {:+.3}",
                self.current.correlation_n_kappa
            );
        }
        let header = self.header();
        let _ = writeln!(t, "\nBest candidates:\n{header}");
        for &i in self.ranking.iter().take(TEXT_TOP) {
            let _ = writeln!(t, "{}", self.line(&self.candidates[i]));
        }
        if self.ranking.len() > TEXT_TOP {
            if let Some(w) = self.worst() {
                let _ = writeln!(t, "  ...\nWorst feasible candidate:\n{}", self.line(w));
            }
        }
        infeasible_paragraph(
            &mut t,
            "the model",
            self.candidates
                .iter()
                .filter_map(|c| Some((c.name.as_str(), c.infeasible.as_deref()?))),
        );
        if let Some(b) = self.best() {
            let _ = writeln!(
                t,
                "\nRecommended: {} (mass flow {:.4e} kg/s, {} {:.4e} {}): gain({}) {:.1} %",
                b.name,
                b.candidate.mass_flow,
                self.grid.take_up.label(),
                b.candidate.take_up,
                self.grid.take_up.unit(),
                self.criterion.name(),
                100.0 * b.gain
            );
        }
        for n in &self.notes {
            let _ = writeln!(t, "\nNote: {n}");
        }
        let _ = writeln!(t, "\n{:.1} s", self.wall_time_s);
        t
    }

    fn se_columns(&self) -> Vec<usize> {
        ["n", "kappa"]
            .iter()
            .filter_map(|p| self.index_of(p))
            .collect()
    }

    fn header(&self) -> String {
        let mut h = format!(
            "  rank  mass flow [kg/s]  {} [{}]",
            self.grid.take_up.label(),
            self.grid.take_up.unit()
        );
        for c in self.se_columns() {
            let _ = write!(h, "  se({})", self.parameters[c]);
        }
        let _ = write!(h, "  corr(n,kappa)  gain({})", self.criterion.name());
        h
    }

    fn line(&self, c: &CandidateOutcome) -> String {
        let mut l = format!(
            "  {:>4}  {:>16.4e}  {:>18.4e}",
            c.rank.unwrap_or(0),
            c.candidate.mass_flow,
            c.candidate.take_up
        );
        if let Some(p) = &c.prediction {
            for i in self.se_columns() {
                let _ = write!(l, "  {:.3e}", p.stderr[i]);
            }
            let _ = write!(
                l,
                "  {:+.3}  {:.1} %",
                p.correlation_n_kappa,
                100.0 * c.gain
            );
        }
        l
    }
}

/// The count of infeasible candidates with the first one's name and reason (`(name, reason)`
/// of each; `model`: what could not be solved, e.g. "the model"); nothing when there are none.
pub(super) fn infeasible_paragraph<'a>(
    t: &mut String,
    model: &str,
    infeasible: impl Iterator<Item = (&'a str, &'a str)>,
) {
    let bad: Vec<(&str, &str)> = infeasible.collect();
    if let Some((name, reason)) = bad.first() {
        let _ = writeln!(
            t,
            "\n{} candidates infeasible (no solution of {model}), e.g. {name}: {reason}",
            bad.len()
        );
    }
}

impl Design {
    /// Every candidate as CSV: grid indices, conditions, predicted standard errors, correlation,
    /// criteria, rank, and why it is infeasible.
    pub fn to_csv(&self) -> String {
        let d = self;
        let mut s = String::from("i,j,mass_flow_kg_s,take_up,");
        for p in &d.parameters {
            s.push_str(&format!("se_{p},"));
        }
        s.push_str("corr_n_kappa,d_gain,a_ratio,e_ratio,gain,rank,infeasible\n");
        for c in &d.candidates {
            s.push_str(&format!(
                "{},{},{:e},{:e},",
                c.candidate.i, c.candidate.j, c.candidate.mass_flow, c.candidate.take_up
            ));
            match &c.prediction {
                Some(p) => {
                    for v in &p.stderr {
                        s.push_str(&format!("{v:e},"));
                    }
                    s.push_str(&format!(
                        "{},{},{},{},{},{},\n",
                        p.correlation_n_kappa,
                        p.d_gain,
                        p.a_ratio,
                        p.e_ratio,
                        c.gain,
                        c.rank.map_or(String::new(), |r| r.to_string())
                    ));
                }
                None => {
                    s.push_str(&",".repeat(d.parameters.len() + 6));
                    let why = c.infeasible.as_deref().unwrap_or("singular information");
                    s.push_str(&format!("\"{}\"\n", why.replace('"', "'")));
                }
            }
        }
        s
    }
}

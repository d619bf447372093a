//! The design for discrimination as text: the rivals' fits, the separation the current data
//! reach, the best candidates with their predicted separations, and the infeasible ones.

use super::discrimination::{Discrimination, DiscriminationOutcome, Separation};
use super::report::{infeasible_paragraph, TEXT_TOP};
use std::fmt::Write as _;

impl Discrimination {
    /// The design as a text report (top `TEXT_TOP` candidates, the worst feasible one, and
    /// the number of infeasible ones with the first reason).
    pub fn to_text(&self) -> String {
        let mut t = String::new();
        let names: Vec<&str> = self.rivals.iter().map(|r| r.name.as_str()).collect();
        let _ = writeln!(
            t,
            "Telling rivals apart: {}; {} candidates ({} mass flows x {} {} values), template {}",
            names.join(" vs "),
            self.candidates.len(),
            self.grid.mass_flows.len(),
            self.grid.take_up.values().len(),
            self.grid.take_up.label(),
            self.template
        );
        let _ = writeln!(t, "\nRivals fitted to the current data:");
        for r in &self.rivals {
            let strengths: Vec<String> = r
                .strengths
                .iter()
                .map(|(e, v, se, u)| format!("{e} {v:.4} ± {se:.4} {u}"))
                .collect();
            let _ = writeln!(
                t,
                "  {:<24} n {:.4}  kappa {:.4}  {}  BIC {:+.1}",
                r.name,
                r.n,
                r.kappa,
                strengths.join(", "),
                r.delta_bic
            );
        }
        let _ = writeln!(t, "\nNow: {}", pairs_words(&self.current));
        let _ = writeln!(
            t,
            "\nBest candidates (lambda: the refitted rival's excess cost / noise variance; \
             expected dBIC of the truth against it):\n{}",
            self.header()
        );
        for &i in self.ranking.iter().take(TEXT_TOP) {
            let _ = writeln!(t, "{}", line(&self.candidates[i]));
        }
        if self.ranking.len() > TEXT_TOP {
            if let Some(&w) = self.ranking.last() {
                let _ = writeln!(
                    t,
                    "  ...\nWorst feasible candidate:\n{}",
                    line(&self.candidates[w])
                );
            }
        }
        infeasible_paragraph(
            &mut t,
            "a rival's model",
            self.candidates
                .iter()
                .filter_map(|c| Some((c.name.as_str(), c.infeasible.as_deref()?))),
        );
        if let Some(b) = self.best() {
            let _ = writeln!(
                t,
                "\nRecommended: {} (mass flow {:.4e} kg/s, {} {:.4e} {}): {}",
                b.name,
                b.candidate.mass_flow,
                self.grid.take_up.label(),
                b.candidate.take_up,
                self.grid.take_up.unit(),
                pairs_words(&b.separations)
            );
        }
        for n in &self.notes {
            let _ = writeln!(t, "\nNote: {n}");
        }
        let _ = writeln!(t, "\n{:.1} s", self.wall_time_s);
        t
    }

    fn header(&self) -> String {
        let mut h = format!(
            "  rank  mass flow [kg/s]  {} [{}]",
            self.grid.take_up.label(),
            self.grid.take_up.unit()
        );
        for s in &self.current {
            let _ = write!(h, "  lambda({}|{})    dBIC", s.truth, s.refitted);
        }
        h
    }
}

/// `"if A is true, B misses by lambda 3.2 (expected dBIC -3.2); ..."`.
fn pairs_words(s: &[Separation]) -> String {
    s.iter()
        .map(|p| {
            format!(
                "if {} is true, {} refitted misses by lambda {} (expected dBIC {})",
                p.truth,
                p.refitted,
                num(p.lambda),
                num(p.expected_delta_bic)
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

fn line(c: &DiscriminationOutcome) -> String {
    let mut l = format!(
        "  {:>4}  {:>16.4e}  {:>18.4e}",
        c.rank.unwrap_or(0),
        c.candidate.mass_flow,
        c.candidate.take_up
    );
    for s in &c.separations {
        let w = s.truth.len() + s.refitted.len() + 9;
        let _ = write!(
            l,
            "  {:>w$}  {:>6}",
            num(s.lambda),
            num(s.expected_delta_bic)
        );
    }
    l
}

/// One decimal from 10 on, three below (a separation of 0.004 is not "0.0").
fn num(v: f64) -> String {
    if v.abs() >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.3}")
    }
}

impl Discrimination {
    /// Every candidate of a design for discrimination as CSV: grid indices, conditions, `λ` and
    /// expected `ΔBIC` of every ordered pair of rivals, rank, and why it is infeasible.
    pub fn to_csv(&self) -> String {
        let d = self;
        let mut s = String::from("i,j,mass_flow_kg_s,take_up,");
        for p in &d.current {
            s.push_str(&format!(
                "lambda_{t}_vs_{r},dbic_{t}_vs_{r},",
                t = p.truth,
                r = p.refitted
            ));
        }
        s.push_str("min_lambda,rank,infeasible\n");
        for c in &d.candidates {
            s.push_str(&format!(
                "{},{},{:e},{:e},",
                c.candidate.i, c.candidate.j, c.candidate.mass_flow, c.candidate.take_up
            ));
            if c.separations.is_empty() {
                s.push_str(&",".repeat(2 * d.current.len() + 2));
            } else {
                for p in &c.separations {
                    s.push_str(&format!("{},{},", p.lambda, p.expected_delta_bic));
                }
                s.push_str(&format!(
                    "{},{},",
                    c.min_lambda,
                    c.rank.map_or(String::new(), |r| r.to_string())
                ));
            }
            let why = c.infeasible.as_deref().unwrap_or("");
            if why.is_empty() {
                s.push('\n');
            } else {
                s.push_str(&format!("\"{}\"\n", why.replace('"', "'")));
            }
        }
        s
    }
}

//! What the data support about the law, in words: the one-sentence finding of a fit (strain
//! thinning detected or not over the strain rates the data cover, the one-sided bound on `n`,
//! the likelihood-ratio test) and a profile interval in words.

use crate::fit::summary::text::{fmt_interval, fmt_p};
use crate::fit::summary::{BoundSide, FitSummary};
use crate::fit::uncertainty::profile::ProfileInterval;
use crate::model::effects::LawChoice;
use crate::report::format::{fmt_at, fmt_e, fmt_g, fmt_pm, fmt_sig};

impl ProfileInterval {
    /// The interval in words: `[0.79, 0.82] (95 %)`, an end left open by the search range,
    /// and the one-sided bound (`n > 0.96 (one-sided 95 %)`).
    pub fn words(&self) -> String {
        let [lo, hi] = self.ci95;
        let width = if lo.is_finite() && hi.is_finite() {
            hi - lo
        } else {
            self.search_range[1] - self.search_range[0]
        };
        // two significant digits of a quarter of the width (about one standard error)
        let u = (width / 4.0).abs().max(1e-12);
        let mut s = match (lo.is_finite(), hi.is_finite()) {
            (true, true) => format!("{} (95 %)", fmt_interval([lo, hi], u)),
            (true, false) => format!(
                "[{}, up to the end {} of the search range] (95 %)",
                fmt_at(lo, u),
                fmt_g(self.search_range[1])
            ),
            (false, true) => format!(
                "[down to the end {} of the search range, {}] (95 %)",
                fmt_g(self.search_range[0]),
                fmt_at(hi, u)
            ),
            (false, false) => format!(
                "not bounded by the data within the search range [{}, {}]",
                fmt_g(self.search_range[0]),
                fmt_g(self.search_range[1])
            ),
        };
        if let Some(b) = &self.one_sided95 {
            s.push_str(&format!(
                "; {} {} {} (one-sided 95 %)",
                self.parameter,
                match b.side {
                    BoundSide::Lower => ">",
                    BoundSide::Upper => "<",
                },
                fmt_sig(b.bound, 3)
            ));
        }
        s
    }
}

impl FitSummary {
    /// What the data support about strain thinning, in one sentence (empty where the fit ran
    /// no likelihood-ratio test): e.g. "no strain thinning detected for strain rates 0.01 to
    /// 3e4 1/s at 513.15 K; n > 0.96 (one-sided 95 %); the Newtonian law fits as well
    /// (likelihood-ratio p = 0.41)".
    pub fn law_finding(&self) -> String {
        let range = self.strain_rates.as_ref().map_or(String::new(), |c| {
            format!(
                " for strain rates {} to {} 1/s at {} K",
                fmt_sig(c.reduced_per_s[0], 2),
                fmt_sig(c.reduced_per_s[2], 2),
                fmt_g(c.reference_temperature_k)
            )
        });
        if !self.law_fitted() {
            return if self.law == LawChoice::Newtonian {
                "the model's law is Newtonian (n = 1 fixed): eta_E = Trouton ratio x eta0(T)".into()
            } else {
                String::new()
            };
        }
        let Some(t) = &self.newtonian_test else {
            return String::new();
        };
        match t.preferred {
            LawChoice::Newtonian => {
                let mut s = format!("no strain thinning detected{range}");
                match t
                    .thinning_bound
                    .as_ref()
                    .filter(|b| b.n_lower95.is_finite())
                {
                    Some(b) => s.push_str(&format!(
                        "; thinning setting in within them (K < {} Pa) needs n > {} \
                         (one-sided 95 %)",
                        fmt_e(b.k_max_pa, 2),
                        fmt_sig(b.n_lower95, 3)
                    )),
                    None if t.thinning_bound.is_some() => {
                        s.push_str("; n is not bounded by these data")
                    }
                    None => {}
                }
                s.push_str(&format!(
                    "; the Newtonian law fits as well (likelihood-ratio {})",
                    fmt_p(t.p_value)
                ));
                s
            }
            LawChoice::Carreau => {
                let n = match self.interval("n") {
                    Some(i) if !i.linearised_trusted() => format!("n in {}", i.words()),
                    _ if self.n.stderr.is_finite() => {
                        format!("n = {}", fmt_pm(self.n.value, self.n.stderr))
                    }
                    _ => format!("n = {}", fmt_sig(self.n.value, 4)),
                };
                format!(
                    "strain thinning detected{range}: {n}; the Newtonian law is rejected \
                     (likelihood-ratio {})",
                    fmt_p(t.p_value)
                )
            }
        }
    }
}

//! What the data support about the law, in words: the one-sentence finding of a fit (strain
//! thinning detected or not over the strain rates the data cover, the one-sided bound on `n`,
//! the likelihood-ratio test) and a profile interval in words.

use crate::fit::summary::text::{fmt_interval, fmt_p};
use crate::fit::summary::{BoundSide, FitSummary};
use crate::fit::uncertainty::profile::ProfileInterval;
use crate::fit::values::thresholds::NEWTONIAN_THINNING;
use crate::fit::WarningCode;
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
    /// Whether the likelihood-ratio test prefers the Newtonian law
    /// (`NewtonianTest::law_not_estimated`):
    /// the law is Newtonian within the data's strain rates, `n` and `κ` are not estimates
    /// (the report gives the finding and the bounds on thinning instead).
    pub fn newtonian_on_data(&self) -> bool {
        self.law_fitted()
            && (self.newtonian_test.as_ref()).is_some_and(|t| t.law_not_estimated.is_some())
    }

    /// Whether the fitted law thins by less than 5 % (`NEWTONIAN_THINNING`) at the largest strain
    /// rate the data cover (at the coverage's temperature): Newtonian over the data's strain
    /// rates whatever its `n` (at `n → 0`, `K` beyond the data's stresses). In memory only
    /// (false for a fit read from JSON).
    pub fn law_newtonian_over_data(&self) -> bool {
        self.law_fitted()
            && (self.strain_rates.as_ref()).is_some_and(|c| c.thinning_at_max < NEWTONIAN_THINNING)
    }

    /// Where the Newtonian law is preferred ([`newtonian_on_data`](Self::newtonian_on_data)):
    /// the warnings about `n` and `κ` as estimates (at a bound, their uncertainty, an
    /// implausible `n`, a covariance ill-conditioned by `κ` not entering, a systematic
    /// uncertainty of `κ` "leaving the law undetermined") dropped, they are not estimates.
    pub(crate) fn drop_law_estimate_warnings(&mut self) {
        if !self.newtonian_on_data() {
            return;
        }
        let no_effects = self.effects.iter().all(|e| !e.strength.fitted);
        self.warnings.retain(|w| {
            !(super::checks::about_the_law_estimate(w)
                || w.code == WarningCode::Systematic
                || (no_effects && w.code == WarningCode::IllConditioned))
        });
    }

    /// What the data support about strain thinning, in one sentence (empty where the fit ran
    /// no likelihood-ratio test): e.g. "no strain thinning detected between 1.4 and 830 1/s at
    /// 513.15 K; thinning, if any, sets in above 2200 1/s (one-sided 95 %, for the strongest a
    /// melt shows, n = 0.2), or setting in within them (K < 3.7e6 Pa) needs n > 0.869
    /// (one-sided 95 %); the Newtonian law fits as well (likelihood-ratio p = 0.5)".
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
                let mut s = match &self.strain_rates {
                    Some(c) => format!(
                        "no strain thinning detected between {} and {} 1/s at {} K",
                        fmt_sig(c.reduced_per_s[0], 2),
                        fmt_sig(c.reduced_per_s[2], 2),
                        fmt_g(c.reference_temperature_k)
                    ),
                    None => "no strain thinning detected".to_string(),
                };
                let bound = t.thinning_bound.as_ref();
                match bound.and_then(|b| b.onset_lower95_per_s) {
                    Some(r) => s.push_str(&format!(
                        "; thinning, if any, sets in above {} 1/s (one-sided 95 %, for the \
                         strongest a melt shows, n = 0.2)",
                        fmt_sig(r, 2)
                    )),
                    None if bound.is_some() => {
                        s.push_str("; the data do not bound where thinning sets in")
                    }
                    None => {}
                }
                match bound.filter(|b| b.n_lower95.is_finite()) {
                    Some(b) => s.push_str(&format!(
                        ", or setting in within them (K < {} Pa) needs n > {} (one-sided 95 %)",
                        fmt_e(b.k_max_pa, 2),
                        fmt_sig(b.n_lower95, 3)
                    )),
                    None if bound.is_some() => s.push_str("; n is not bounded by these data"),
                    None => {}
                }
                s.push_str(&format!(
                    "; the Newtonian law fits as well (likelihood-ratio {}{})",
                    fmt_p(t.p_value),
                    if t.p_mixture.is_some() {
                        ", calibrated"
                    } else {
                        ""
                    }
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

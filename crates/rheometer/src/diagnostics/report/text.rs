//! The diagnosis in words ([`Diagnosis::to_text`]), paragraph by paragraph.

use super::super::candidate::{Candidate, StrengthStatus};
use super::super::diagnose::verdict::Verdict;
use super::super::diagnosis::Diagnosis;
use super::{
    estimate_with_ci, estimate_with_ci_bounds, fmt_range, pm_unit, probability, profile_line,
    shape_alternative_line, unit_suffix, EXACT_TIE,
};
use crate::fit::FitSummary;
use crate::report::format::{fmt_g, wrap_long_lines};

impl Diagnosis {
    /// The report in words.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        self.fit_paragraph(&mut s);
        self.outliers_paragraph(&mut s);
        s.push_str(&self.verdict_text());
        match (&self.most_likely_missing, self.named()) {
            (Some(name), Some(c)) => self.named_paragraph(&mut s, name, c),
            _ => {
                s.push_str(&self.nothing_named_text());
                if let Some(w) = self.detection.words() {
                    s.push_str(&format!("{w}\n"));
                }
            }
        }
        self.further_steps_paragraph(&mut s);
        self.consistency_paragraph(&mut s);
        self.pair_paragraph(&mut s);
        self.not_named_paragraph(&mut s);
        self.candidates_table(&mut s);
        self.profiles_paragraph(&mut s);
        self.indistinguishable_paragraph(&mut s);
        s.push_str(&self.detection.to_text());
        s.push_str(&self.wall_time_text());
        wrap_long_lines(&s)
    }

    /// The wall time and where it went (see [`StageTimes`](super::super::diagnosis::StageTimes);
    /// a report read from a JSON file written before the stages were timed: the total alone).
    fn wall_time_text(&self) -> String {
        let t = &self.stage_times;
        if t.steps_s() + t.pairs_s + t.rest_s <= 0.0 {
            return format!("wall time {:.2} s\n", self.wall_time_s);
        }
        format!(
            "wall time {:.2} s (fits {:.2} s, linearisation and calibration {:.2} s, scans {:.2} \
             s, refits {:.2} s, pairs {:.2} s, the rest {:.2} s)\n",
            self.wall_time_s, t.fits_s, t.linearised_s, t.scans_s, t.refits_s, t.pairs_s, t.rest_s
        )
    }

    /// The heading, the base fit (its warnings) and whether its residuals are noise.
    fn fit_paragraph(&self, s: &mut String) {
        let b = &self.base_fit;
        s.push_str(&format!(
            "[[Diagnosis: which effect is missing from the {} model?]]\n",
            match self.model {
                crate::model::effects::LawChoice::Newtonian => "Newtonian",
                crate::model::effects::LawChoice::Carreau => "Carreau-type",
            }
        ));
        s.push_str(&format!(
            "Your model fitted with the principled estimator: J = {:.4e}, RMS relative residual {:.3} % \
             over {} measurements; noise level {}.\n",
            b.cost,
            100.0 * b.rms_relative_residual,
            b.residuals,
            b.noise.describe()
        ));
        // effects the user put in the model (--with, --from): what the search starts from
        let fixed: Vec<String> = b
            .effects
            .iter()
            .filter(|e| !e.strength.fitted)
            .map(|e| {
                format!(
                    "{} {} (fixed)",
                    e.effect,
                    pm_unit(e.strength.value, 0.0, &e.strength.unit)
                )
            })
            .collect();
        let in_model: Vec<String> = fitted_effects(b).into_iter().chain(fixed).collect();
        if !in_model.is_empty() {
            s.push_str(&format!(
                "Effects in your model: {}.\n",
                in_model.join(", ")
            ));
        }
        if let Some(r) = &self.robust {
            s.push_str(&format!("{}\n", r.words()));
        }
        if b.newtonian_on_data() {
            s.push_str(&format!(
                "Its law is Newtonian within the data's strain rates; n and kappa are not \
                 estimated: {}.\n",
                b.law_finding()
            ));
        }
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
            self.rms_over_noise(),
            self.lag1_autocorrelation()
        ));
    }

    /// The outliers, one per line (nothing without any).
    fn outliers_paragraph(&self, s: &mut String) {
        if self.outliers().is_empty() {
            return;
        }
        let fits = match &self.robust {
            Some(r) => format!("the {} loss down-weighted them in the fits", r.loss),
            None => "and out of the fits; `--loss huber` lets a robust loss weight them".into(),
        };
        s.push_str(&format!(
            "OUTLIERS ({}; left out of the noise level, the RMS and the autocorrelation, {fits}):\n",
            self.outliers().len()
        ));
        for o in self.outliers() {
            s.push_str(&format!(
                "    {} at s = {:.3} m: measured {:.2} um, model {:.2} um, residual {:+.1} % ({:.1} robust sd)\n",
                o.experiment,
                o.position_m,
                1e6 * o.d_meas_m,
                1e6 * o.d_model_m,
                100.0 * o.residual,
                o.deviation_sigmas
            ));
        }
    }

    /// The named cause `c` (`name`): what adding it does, its strength and warnings, the
    /// material parameters with it, a shape the data cannot choose, and its ties.
    fn named_paragraph(&self, s: &mut String, name: &str, c: &Candidate) {
        let b = &self.base_fit;
        let exact: Vec<&str> = self
            .alternatives
            .iter()
            .filter(|a| a.delta_bic_gap < EXACT_TIE)
            .map(|a| a.effect.as_str())
            .collect();
        let replaced = self.pair.as_ref().is_some_and(|p| p.replaces);
        let ambiguous = matches!(self.verdict, Verdict::Ambiguous { .. });
        let lead = if replaced {
            "Best single candidate (a pair explains the data better, below):".to_string()
        } else if ambiguous && exact.is_empty() {
            "One of the explanations the verdict cannot tell apart (the forward search's):"
                .to_string()
        } else if let (true, Verdict::NoneOfTheCandidates { stand_ins, .. }) =
            (exact.is_empty(), &self.verdict)
        {
            // the verdict says that something else is missing: the named candidate is no cause
            if stand_ins.iter().any(|c| c.effect == name) {
                "Best candidate, a stand-in (not the cause: its strength differs between the \
                 experiments, see the verdict):"
                    .to_string()
            } else {
                "Helps most, but does not explain the data (something none of the candidates \
                 describes is missing, see the verdict):"
                    .to_string()
            }
        } else if exact.is_empty() {
            "Most likely missing:".to_string()
        } else {
            format!(
                "TIE: {name} and {} explain these data equally well (delta BIC gap below \
                 {EXACT_TIE}); the data cannot choose, and the one listed first is not \
                 preferred. Taking",
                exact.join(", ")
            )
        };
        s.push_str(&format!(
            "{lead} {name}{}. Its signature lies along s = {} (strongest at {:.2} m). \
             Adding it removes {:.1} % of the misfit ({:.0} % of the excess over the noise; \
             false-alarm probability of the search {}) (J {:.4e} -> {:.4e}), RMS {:.3} % -> {:.3} %, \
             delta BIC = {:.1}, delta AIC = {:.1}; fitted strength {}{}.\n",
            super::super::ties::or_alternatives(&self.alternatives),
            fmt_range(c.signature_range_m),
            c.signature_peak_m,
            100.0 * (1.0 - c.cost_after / c.cost_before),
            100.0 * c.share_of_excess,
            probability(c.false_alarm),
            c.cost_before,
            c.cost_after,
            100.0 * b.rms_relative_residual,
            100.0 * c.rms_relative_residual_after(),
            c.delta_bic,
            c.delta_aic,
            pm_unit(c.strength(), c.stderr_strength(), &c.unit),
            starts_reached(c.refit_starts)
        ));
        if let Some(b) = c.at_bound().iter().find(|b| b.parameter == c.effect) {
            s.push_str(&format!(
                "WARNING: its strength ends AT ITS {} BOUND {}{}: the data push it beyond its \
                 search range, so this is not a credible estimate of the effect (a different \
                 effect, or a process or instrument error, may be behind the misfit).\n",
                b.side.name().to_uppercase(),
                fmt_g(b.bound),
                unit_suffix(&c.unit)
            ));
        }
        if let (StrengthStatus::Physical, Some(note)) = (c.status, &c.status_note) {
            s.push_str(&format!("NOTE: {note}.\n"));
        }
        if c.n().is_finite() {
            // under "none of the candidates" the law with the best candidate is biased too
            let lead = match self.law_not_a_result() {
                Some(why) if !replaced => format!("With it (NOT A RESULT: {why})"),
                _ if replaced => {
                    "With it alone (NOT A RESULT: the pair below explains the data)".to_string()
                }
                _ => "With it".to_string(),
            };
            s.push_str(&format!(
                "{lead}: n = {}, kappa = {}.\n",
                estimate_with_ci(c, "n", c.n_estimate()),
                estimate_with_ci(c, "kappa", c.kappa_estimate())
            ));
        }
        if let Some(a) = &c.shape_alternative {
            s.push_str(&shape_alternative_line(c, a));
        }
        s.push_str(&super::super::ties::ties_paragraph(
            c,
            &self.alternatives,
            &self.candidates,
        ));
    }

    /// The pair named by the joint search of pairs, with its strengths.
    fn pair_paragraph(&self, s: &mut String) {
        let Some(p) = &self.pair else { return };
        let strengths: Vec<String> = p
            .effects
            .iter()
            .filter_map(|e| {
                let est = p.fit.as_ref().or(self.final_fit.as_ref())?.effect(e)?;
                let unit = self.candidate(e).map_or("", |c| c.unit.as_str());
                Some(format!(
                    "{e} {}",
                    pm_unit(est.strength.value, est.strength.stderr, unit)
                ))
            })
            .collect();
        let lead = if p.replaces {
            format!(
                "Fitted in pairs, the best explanation (better than the forward search's result by \
                 more than {:.1} in delta BIC: the tie margin and 2 ln of the pairs tried)",
                p.replace_margin
            )
        } else {
            format!(
                "Fitted in pairs, an explanation the data do not clearly separate from the one \
                 above (delta BIC within the tie margin above it, or less than {:.1} below it: \
                 the tie margin and 2 ln of the pairs tried)",
                p.replace_margin
            )
        };
        s.push_str(&format!(
            "{lead}: {} jointly bring the residuals to the noise: delta BIC {:.1} against your \
             model (the forward search's result: {:.1}), {:.1} against {} alone and {:.1} against \
             {} alone; strengths {}; {} of {} starts reached this optimum ({} pairs of refitted \
             candidates tried).\n",
            p.effects.join(" + "),
            p.delta_bic,
            p.delta_bic_of_steps,
            p.delta_bic_against_single[0],
            p.effects[0],
            p.delta_bic_against_single[1],
            p.effects[1],
            strengths.join(", "),
            p.starts_at_optimum,
            p.starts,
            p.pairs_tried
        ));
        if let Some(pf) = p.fit.as_ref() {
            s.push_str(&law_line(&p.effects.join(" + "), "", pf));
            if let (Some(_), Some(f)) = (p.laws_disagree, self.final_fit.as_ref()) {
                s.push_str(&format!(
                    "WARNING: {}. A measurement that separates the effects (the air temperature \
                     along the line, the fiber temperature, the throughput) decides.\n",
                    crate::diagnostics::refits::pair::disagreement(
                        f,
                        &[(p.effects.join(" + "), pf)]
                    )
                ));
            }
        }
    }

    /// The further steps (each with the causes found before in the model) and the final fit
    /// with every cause found.
    fn further_steps_paragraph(&self, s: &mut String) {
        if let Some(why) = &self.stopped {
            s.push_str(&format!(
                "NOTE: the forward search stopped early: {why}; what the steps before found \
                 stands.\n"
            ));
        }
        for (k, st) in self.further_steps.iter().enumerate() {
            s.push_str(&format!(
                "Step {} (with {} in the model, fitted jointly): {}.\n",
                k + 2,
                st.model_effects.join(" + "),
                match st
                    .named
                    .as_deref()
                    .and_then(|n| st.candidates.iter().find(|c| c.effect == n))
                {
                    Some(c) => format!(
                        "{} named too (delta BIC {:.1}, {:.0} % of the remaining excess, \
                         false-alarm probability {})",
                        c.effect,
                        c.delta_bic,
                        100.0 * c.share_of_excess,
                        probability(c.false_alarm)
                    ),
                    None => "no further candidate earns its place".into(),
                }
            ));
        }
        if let Some(f) = &self.final_fit {
            if self.found.len() > 1 {
                let note = self
                    .law_not_a_result()
                    .map_or(String::new(), |why| format!(" (NOT A RESULT: {why})"));
                s.push_str(&law_line(&self.found.join(" + "), &note, f));
            }
        }
    }

    /// Whether each found effect's strength is the same in every experiment.
    fn consistency_paragraph(&self, s: &mut String) {
        for c in &self.consistency {
            s.push_str(&format!(
                "One strength in every experiment? {}: {} (score test against a strength varying \
                 with {}: {}; it would remove {:.1} % of J){}.\n",
                c.effect,
                if c.consistent() { "yes" } else { "NO" },
                c.conditions.join(", "),
                c.test_words(),
                100.0 * c.share_of_cost,
                if c.consistent() {
                    ""
                } else {
                    ": an effect whose strength must change with the experiment's conditions \
                     stands in for something else"
                }
            ));
        }
    }

    /// The refits that lower BIC but are not named (outside the physical range, at a bound).
    /// Why nothing is named: no effect lowers BIC, or those that do are not credible
    /// estimates (listed under NOT NAMED) or not by enough (the threshold, the look-elsewhere
    /// test, the share of the excess misfit: the candidates table); the model is called
    /// adequate only where its residuals are noise.
    fn nothing_named_text(&self) -> String {
        let lowering = |physical: bool| {
            self.candidates
                .iter()
                .filter(|c| {
                    c.refitted()
                        && (c.status == StrengthStatus::Physical) == physical
                        && c.delta_bic < 0.0
                })
                .count()
        };
        let (credible, not_credible) = (lowering(true), lowering(false));
        let mut why = Vec::new();
        if not_credible > 0 {
            why.push(format!(
                "{not_credible} lower{} BIC without a credible estimate (see NOT NAMED below)",
                if not_credible == 1 { "s" } else { "" }
            ));
        }
        if credible > 0 {
            why.push(format!(
                "{credible} credible refit{} lower{} BIC, but not by enough to be named (the \
                 threshold, the false-alarm probability, the share of the excess misfit: see the \
                 candidates table)",
                if credible == 1 { "" } else { "s" },
                if credible == 1 { "s" } else { "" }
            ));
        }
        if why.is_empty() {
            why.push("no effect lowers BIC".to_string());
        }
        let adequate = if self.systematic {
            "the residuals are systematic: the missing effect is not among the candidates"
        } else {
            "the model is adequate for these data (or the missing effect is not among the \
             candidates)"
        };
        format!(
            "No candidate earns its place: {}; {adequate}.\n",
            why.join("; ")
        )
    }

    fn not_named_paragraph(&self, s: &mut String) {
        for c in self
            .candidates
            .iter()
            .filter(|c| c.refitted() && c.status != StrengthStatus::Physical && c.delta_bic < 0.0)
        {
            if let Some(note) = &c.status_note {
                s.push_str(&format!(
                    "NOT NAMED: {} lowers BIC by {:.1} but {note}; not a credible estimate of \
                     the effect (a different effect, or a process or instrument error, may be \
                     behind the misfit).\n",
                    c.effect, -c.delta_bic
                ));
            }
        }
    }

    /// The table of candidates, two lines each, and its footnote.
    fn candidates_table(&self, s: &mut String) {
        s.push_str("[[Candidates, best first (credible refits by delta BIC, then refits at a bound or not physical)]]\n");
        s.push_str("    effect                   refit  strength ± stderr      RMS after     dBIC  false-al.  excess\n");
        s.push_str("        status, J after, lin.dJ/J, signature (peak), shape\n");
        for c in &self.candidates {
            let shape: String = c
                .shape()
                .iter()
                .map(|p| format!(", {} {}{}", p.name, fmt_g(p.value), unit_suffix(&p.unit)))
                .collect();
            s.push_str(&format!(
                "    {:<24} {:<5}  {:<22} {:>9}  {:>7.1}  {:>9}  {:>6}\n",
                c.effect,
                if c.refitted() { "yes" } else { "lin" },
                pm_unit(c.strength(), c.stderr_strength(), &c.unit),
                if c.rms_relative_residual_after().is_finite() {
                    format!("{:.3} %", 100.0 * c.rms_relative_residual_after())
                } else {
                    "-".into()
                },
                c.delta_bic,
                probability(c.false_alarm),
                if c.share_of_excess.is_finite() {
                    format!("{:.0} %", 100.0 * c.share_of_excess)
                } else {
                    "-".into()
                },
            ));
            s.push_str(&format!(
                "        {}, J after {:.4e}, lin.dJ/J {:.4}, signature {} (peak {:.2} m){shape}\n",
                c.status.name(),
                c.cost_after,
                if c.cost_before > 0.0 {
                    c.linear_score / c.cost_before
                } else {
                    f64::NAN
                },
                fmt_range(c.signature_range_m),
                c.signature_peak_m
            ));
        }
        s.push_str(
            "(lin.dJ/J: the first-order (linearised) share of J the effect would remove at strength 0; \
             a refit far better than it means the finite effect differs from its first-order signature.)\n",
        );
    }

    /// The candidates' profiles of `J/J_base`, one line each (nothing without any).
    fn profiles_paragraph(&self, s: &mut String) {
        let with_profiles: Vec<&Candidate> = self
            .candidates
            .iter()
            .filter(|c| !c.profiles.is_empty())
            .collect();
        if !with_profiles.is_empty() {
            s.push_str("[[Profiles: J/J_base against strength, material parameters refitted at each fixed strength; * = lowest, ! = outside the physical range]]\n");
            for c in with_profiles {
                for p in &c.profiles {
                    s.push_str(&format!("    {}\n", profile_line(p)));
                }
            }
        }
    }

    /// The pairs of candidates whose signatures the data cannot tell apart.
    fn indistinguishable_paragraph(&self, s: &mut String) {
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
    }
}

/// The fitted effects of `f`, each as `"air_coflow 27.2 ± 2.8 m/s (decay_length 0.192 ±
/// 0.012 m)"` (its fitted shapes in brackets).
fn fitted_effects(f: &FitSummary) -> Vec<String> {
    f.effects
        .iter()
        .filter(|e| e.strength.fitted)
        .map(|e| {
            let shapes: Vec<String> = e
                .shapes
                .iter()
                .filter(|sh| sh.fitted)
                .map(|sh| format!("{} {}", sh.name, pm_unit(sh.value, sh.stderr, &sh.unit)))
                .collect();
            let strength = pm_unit(e.strength.value, e.strength.stderr, &e.strength.unit);
            if shapes.is_empty() {
                format!("{} {strength}", e.effect)
            } else {
                format!("{} {strength} ({})", e.effect, shapes.join(", "))
            }
        })
        .collect()
}

/// `With <effects><note>: n = …, kappa = …, RMS … %; strengths: …`: a fit's law with its
/// intervals, and the fitted strengths and shapes of its effects (a model with several effects
/// is one fit: its strengths are not those of each effect's own refit).
fn law_line(effects: &str, note: &str, f: &FitSummary) -> String {
    let fitted = fitted_effects(f);
    let strengths = if fitted.is_empty() {
        String::new()
    } else {
        format!("; strengths: {}", fitted.join(", "))
    };
    format!(
        "With {effects}{note}: n = {}, kappa = {}, RMS {:.3} %{strengths}.\n",
        estimate_with_ci_bounds(&f.at_bound, "n", &f.n),
        estimate_with_ci_bounds(&f.at_bound, "kappa", &f.kappa),
        100.0 * f.rms_relative_residual
    )
}

/// How many of a candidate's refit starts reached its best cost, in words (`refit_starts` =
/// `[ran, reached]`; empty without refit): a best reached from one start of many is a sign of a
/// rugged landscape.
fn starts_reached(refit_starts: [usize; 2]) -> String {
    let [ran, reached] = refit_starts;
    if ran == 0 {
        String::new()
    } else {
        format!(" ({reached} of {ran} refit starts reached this optimum)")
    }
}

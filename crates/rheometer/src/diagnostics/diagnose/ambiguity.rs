//! Stage 11a (part of the verdict): explanations the data cannot tell apart from the result,
//! and whether they agree on the material law.
//!
//! The diagnosis' result (the effects it names, fitted jointly with the law) has rivals it
//! cannot exclude:
//!
//! * a candidate whose `ΔBIC` lies within the tie margin of the result's (see
//!   [`ties`](crate::diagnostics::ties)), credible or refused only because its best
//!   strength lies outside its physical range or at a search bound — a fit as good, which only
//!   the range's prior excludes — or only because its law jumped from the user's (its own law
//!   a result: the jump is a suspicion that the effect buys a law, and as good a fit with
//!   another law is what "ambiguous" means);
//! * a pair of candidates fitted jointly within the look-elsewhere margin (see
//!   [`pair`](crate::diagnostics::refits::pair)).
//!
//! Where every rival's law agrees with the result's (each estimate inside the other's 95 %
//! interval, [`laws_disagree`]), the choice does not matter for the law. Where one disagrees,
//! the data leave the law undetermined between them: the verdict is [`Verdict::Ambiguous`],
//! the final fit carries an `implausible` warning, and the range all of them span is given.
//! (The ties paragraph of the report grades a shift of one standard error as a caution; this
//! stage acts only where the laws disagree at 95 %.)
//!
//! Before this stage, the power study of `tests/diagnose/global.rs` printed 12 wrong laws with
//! confidence in 100 sets (more than 3 standard errors from the truth, verdict "explained"): a
//! mass-flow error named as its near-twin, the Nusselt factor (2 sets, 3.4 and 3.6 standard
//! errors), and a gauge offset of 27 µm, beyond the ±20 µm the catalogue calls physical,
//! refused and "explained" by other effects (10 sets, 3.2 to 9.6 standard errors). With it:
//! none.

use super::verdict::Verdict;
use super::DiagnoseOptions;
use crate::diagnostics::candidate::{Candidate, StrengthStatus};
use crate::diagnostics::refits::pair::{disagreement, law_envelope_of, laws_disagree, PairFound};
use crate::fit::{FitSummary, FitWarning, WarningCode};

/// A rival explanation: its effects, whether its strengths are credible, and its fit.
pub(crate) struct Rival<'a> {
    /// The effects of the rival explanation.
    pub effects: Vec<String>,
    /// Its strength's status (a pair's are credible).
    pub status: StrengthStatus,
    /// Its fit (law with intervals).
    pub fit: &'a FitSummary,
}

/// The rivals of the result `found` (final fit `result`, `ΔBIC` `result_dbic` against the
/// user's model) whose law disagrees with it: the pair reported beside it, and every refitted
/// candidate of the first step (`candidates`) not in the result whose `ΔBIC` is below the
/// earn threshold and within the tie margin of the result's — a credible one (a tie), or one
/// whose best strength lies outside its physical range or at a search bound: such a fit
/// explains the data as well, and only the range's prior excludes it (without it, a strength
/// just beyond its range is refused and its data "explained" by another candidate with a law
/// many standard errors off). A refit whose law is itself implausible is no rival.
pub(crate) fn disagreeing_rivals<'a>(
    candidates: &'a [Candidate],
    found: &[String],
    result: &FitSummary,
    result_dbic: f64,
    pair: Option<&'a PairFound>,
    options: &DiagnoseOptions,
) -> Vec<Rival<'a>> {
    let mut rivals: Vec<Rival<'a>> = candidates
        .iter()
        .filter(|c| !found.contains(&c.effect))
        .filter(|c| {
            c.delta_bic < options.earn_threshold && c.delta_bic < result_dbic + options.tie_margin
        })
        .filter_map(|c| {
            let fit = c.refit.as_ref()?;
            let may_rival = c.status.fit_is_evidence()
                || (c.status == StrengthStatus::ImplausibleLaw && only_jumped(fit));
            (may_rival && laws_disagree(fit, result)).then(|| Rival {
                effects: vec![c.effect.clone()],
                status: c.status,
                fit,
            })
        })
        .collect();
    if let Some(p) = pair.filter(|p| !p.replaces && p.laws_disagree.is_some()) {
        if let Some(fit) = p.fit.as_ref() {
            rivals.push(Rival {
                effects: p.effects.to_vec(),
                status: StrengthStatus::Physical,
                fit,
            });
        }
    }
    rivals
}

/// Whether a refit refused for an implausible law was refused only for its jump from the
/// user's law (a move the gain in fit does not pay for), its own law being a result (`n`
/// plausible, nothing at a bound, no implausible warning of its own). The jump says that the
/// effect may buy a different law rather than explain the data; where such a refit explains
/// the data as well as the result, the data cannot say which law is right, and it is a rival.
/// With few experiments a missing effect biases the user's law by many of its standard
/// errors, and the true effect's refit is refused for that very jump (three runs with an
/// aspirator: the right effect's law within its interval of the truth, refused, and a line
/// co-flow with radiation named with `n` 0.47 against the true 0.8).
fn only_jumped(fit: &FitSummary) -> bool {
    fit.law_not_a_result().is_none()
}

/// The warning on the result's fit where rivals disagree on the law: each law, the range all
/// span, and that none is a result ([`disagreement`]).
pub(crate) fn warning(result: &FitSummary, rivals: &[Rival<'_>]) -> FitWarning {
    let labelled: Vec<(String, &FitSummary)> = rivals
        .iter()
        .map(|r| {
            (
                format!("{}{}", r.effects.join(" + "), r.status.qualifier()),
                r.fit,
            )
        })
        .collect();
    FitWarning::new(WarningCode::Implausible, disagreement(result, &labelled))
}

/// The verdict `explained` made ambiguous by `rivals` (unchanged where there is none or the
/// verdict is of another kind).
pub(crate) fn verdict(verdict: Verdict, result: &FitSummary, rivals: &[Rival<'_>]) -> Verdict {
    match verdict {
        Verdict::Explained {
            effects,
            rms_over_noise,
            noise_level,
        } if !rivals.is_empty() => {
            let [n_range, kappa_range] =
                law_envelope_of(rivals.iter().map(|r| r.fit).chain([result]));
            Verdict::Ambiguous {
                effects,
                alternatives: rivals.iter().map(|r| r.effects.clone()).collect(),
                rms_over_noise,
                noise_level,
                n_range,
                kappa_range,
            }
        }
        v => v,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnostics::ties::tests::cand;
    use StrengthStatus::*;

    /// `c` with its refit's own law implausible (the warning the fit's checks write).
    fn own_law_implausible(mut c: Candidate) -> Candidate {
        if let Some(f) = c.refit.as_mut() {
            f.warnings.push(FitWarning::new(
                WarningCode::Implausible,
                "n = 0.1 is implausible for a polymer melt: this is not a material result"
                    .to_string(),
            ));
        }
        c
    }

    #[test]
    fn rivals_as_good_with_another_law_make_the_verdict_ambiguous() {
        // the named effect: n = 0.844 ± 0.01 (cand's standard errors: 0.01 and 0.1)
        let named = cand("air_temperature_profile", Physical, -55.1, 0.844, 10.70);
        let result = named.refit.clone().unwrap();
        let list = vec![
            named,
            // better, but outside its physical range, with another law: a rival
            cand("gauge_offset", Unphysical, -63.2, 0.80, 11.70),
            // within the tie margin, credible, another law: a rival
            cand("mass_flow_scale", Physical, -50.0, 0.87, 10.70),
            // within the margin with the same law: no rival
            cand("radiation", Physical, -52.0, 0.846, 10.72),
            // another law but worse by more than the margin: no rival
            cand("nusselt_scale", Physical, -43.1, 0.70, 10.70),
            // as good, another law, but its own law implausible: no rival
            own_law_implausible(cand(
                "die_temperature_offset",
                ImplausibleLaw,
                -60.0,
                0.1,
                10.7,
            )),
            // as good, another law, refused only for its jump from the user's law: a rival
            cand("inlet_diameter", ImplausibleLaw, -58.0, 0.78, 11.0),
            // not refitted: no rival
            cand("air_coflow", NotRefitted, -70.0, 0.7, 10.7),
        ];
        let options = DiagnoseOptions::default();
        let found = vec!["air_temperature_profile".to_string()];
        let rivals = disagreeing_rivals(&list, &found, &result, -55.1, None, &options);
        let names: Vec<&str> = rivals.iter().map(|r| r.effects[0].as_str()).collect();
        assert_eq!(names, ["gauge_offset", "mass_flow_scale", "inlet_diameter"]);
        let w = warning(&result, &rivals);
        assert_eq!(w.code, WarningCode::Implausible);
        assert!(
            w.message
                .contains("0.800 with gauge_offset at a strength outside its physical range"),
            "{}",
            w.message
        );
        assert!(w.message.contains("no law is a result"), "{}", w.message);
        let v = verdict(
            Verdict::Explained {
                effects: found.clone(),
                rms_over_noise: 1.0,
                noise_level: 0.015,
            },
            &result,
            &rivals,
        );
        let Verdict::Ambiguous {
            alternatives,
            n_range,
            kappa_range,
            ..
        } = &v
        else {
            panic!("{v:?}")
        };
        assert_eq!(alternatives.len(), 3);
        // the range spans every law's 95 % interval: 0.78 - 1.96 se to 0.87 + 1.96 se
        assert!((n_range[0] - (0.78 - 0.0196)).abs() < 1e-3, "{n_range:?}");
        assert!((n_range[1] - (0.87 + 0.0196)).abs() < 1e-3, "{n_range:?}");
        assert!(kappa_range[1] > 11.70, "{kappa_range:?}");
        assert!(!v.law_is_a_result());
        // without rivals, or under another verdict, nothing changes
        let explained = Verdict::Explained {
            effects: found,
            rms_over_noise: 1.0,
            noise_level: 0.015,
        };
        assert_eq!(verdict(explained.clone(), &result, &[]), explained);
        assert_eq!(
            verdict(Verdict::Adequate, &result, &rivals),
            Verdict::Adequate
        );
    }
}

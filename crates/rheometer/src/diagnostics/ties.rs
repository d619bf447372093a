//! Ties: candidates the data cannot tell apart from the named one.
//!
//! The named cause ([`Diagnosis::most_likely_missing`](super::diagnosis::Diagnosis)) is the
//! credible candidate with the lowest `ΔBIC`. Another candidate that also earns its place
//! (refitted, its strength physical and away from the search bounds, `ΔBIC` below the earn
//! threshold) and whose `ΔBIC` is within
//! [`DiagnoseOptions::tie_margin`](super::diagnose::DiagnoseOptions::tie_margin) of the best is
//! an **alternative**: the data do not prefer the named one strongly. `ΔBIC ≈ −2 ln B` (B the
//! Bayes factor), so a gap below 6 is less than "strong" evidence on the Kass–Raftery scale
//! (gap 0–2: not worth more than a bare mention, 2–6: positive, 6–10: strong, > 10: very
//! strong). For each alternative the diagnosis lists its gap, the cosine of its orthogonalised
//! signature with the named one's, its refit's `(n, κ)` with 95% CIs, and how far `n` and `κ`
//! move from the named refit's, in units of the named refit's standard errors: whether the
//! material result is robust to the choice. Every effect in a tie but strain thinning can be
//! checked independently of these data (a process condition, the instrument, the air's speed
//! or temperature, the fiber's temperature): the check is its descriptor's
//! [`independent_check`](crate::model::EffectDescriptor::independent_check), a
//! user-written candidate's included.

use super::candidate::{earns_its_place, Candidate};
use crate::model::effects::{Category, Effect, EffectDescriptor};
use serde::{Deserialize, Serialize};

/// Default [`DiagnoseOptions::tie_margin`](super::diagnose::DiagnoseOptions::tie_margin): a
/// `ΔBIC` gap below 6 is less than "strong" evidence (Kass–Raftery) for the named cause.
pub(crate) const DEFAULT_TIE_MARGIN: f64 = 6.0;

use crate::fit::summary::Estimate;

/// Shifts of `n` and `κ` (in the named refit's standard errors) below which the material
/// result is robust to the choice between tied causes.
pub(crate) const ROBUST_SHIFT_SE: f64 = 1.0;

/// A candidate about as consistent with the data as the named one (JSON: an entry of
/// `alternatives`). Its refit (strength, `(n, κ)` with intervals) is the candidate's own
/// ([`Diagnosis::candidate`](super::diagnosis::Diagnosis::candidate)); the record says how it
/// compares with the named one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Alternative {
    /// Canonical name of the alternative.
    pub effect: String,
    /// Its category (physics, process, instrument).
    pub category: Category,
    /// Category of the named cause it ties with.
    pub named_category: Category,
    /// `ΔBIC(alternative) − ΔBIC(named)` (≥ 0, below the tie margin).
    pub delta_bic_gap: f64,
    /// Cosine of its orthogonalised (linearised) signature with the named one's (`NaN` when
    /// not available).
    pub signature_cosine: f64,
    /// `(n_alt − n_named) / se(n_named)` (`NaN` where the named refit has no valid CI).
    pub n_shift_se: f64,
    /// `(κ_alt − κ_named) / se(κ_named)`.
    pub kappa_shift_se: f64,
    /// Whether `|n_shift_se|` and `|kappa_shift_se|` are both below `ROBUST_SHIFT_SE`: the
    /// material result does not depend on which of the two causes is chosen.
    pub material_robust: bool,
    /// The measurement outside these data that decides whether the alternative is the cause
    /// (its descriptor's independent check; absent for strain thinning and user effects
    /// without one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub independent_check: Option<String>,
    /// The same for the named cause.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub named_independent_check: Option<String>,
}

/// Whether `c` ties with the `named` cause: a different candidate that earns its place
/// ([`earns_its_place`] with `earn_threshold`) with a `ΔBIC` less than `tie_margin` above the
/// named one's. At-bound, unphysical and unrefitted candidates never tie.
pub(crate) fn ties_with(
    named: &Candidate,
    c: &Candidate,
    earn_threshold: f64,
    tie_margin: f64,
) -> bool {
    c.effect != named.effect
        && earns_its_place(c, earn_threshold)
        && c.delta_bic - named.delta_bic < tie_margin
}

/// Standard error of a refit's law parameter where its interval is valid (`NaN` else).
fn stderr_of(e: Option<&Estimate>) -> f64 {
    e.map_or(f64::NAN, Estimate::valid_stderr)
}

/// `(alt − named) / se`, `NaN` unless `se` is positive and finite.
fn shift(alt: f64, named: f64, se: f64) -> f64 {
    if se.is_finite() && se > 0.0 {
        (alt - named) / se
    } else {
        f64::NAN
    }
}

impl Alternative {
    /// The record of `alt` tying with `named`, with the categories and the signature cosine
    /// supplied by the caller (the candidate results do not carry them); the independent checks
    /// are the built-in effects' of those names ([`with_checks`](Self::with_checks) sets
    /// others).
    pub fn new(
        named: &Candidate,
        alt: &Candidate,
        named_category: Category,
        category: Category,
        signature_cosine: f64,
    ) -> Self {
        let n_shift_se = shift(alt.n(), named.n(), stderr_of(named.n_estimate()));
        let kappa_shift_se = shift(
            alt.kappa(),
            named.kappa(),
            stderr_of(named.kappa_estimate()),
        );
        Alternative {
            effect: alt.effect.clone(),
            category,
            named_category,
            delta_bic_gap: alt.delta_bic - named.delta_bic,
            signature_cosine,
            n_shift_se,
            kappa_shift_se,
            // NaN shifts (no valid interval) compare false: not robust
            material_robust: n_shift_se.abs() < ROBUST_SHIFT_SE
                && kappa_shift_se.abs() < ROBUST_SHIFT_SE,
            independent_check: independent_check(&alt.effect).map(String::from),
            named_independent_check: independent_check(&named.effect).map(String::from),
        }
    }

    /// With the independent checks of the named cause and of the alternative (e.g. from
    /// user-written descriptors).
    pub fn with_checks(mut self, named: Option<&str>, alternative: Option<&str>) -> Self {
        self.named_independent_check = named.map(String::from);
        self.independent_check = alternative.map(String::from);
        self
    }

    /// Whether the tie mixes missing physics with a process condition or an instrument error.
    pub fn mixes_physics_and_conditions(&self) -> bool {
        (self.category == Category::Physics) != (self.named_category == Category::Physics)
    }
}

/// The alternatives to `named` among `candidates` (in their order, best first), each built by
/// [`Alternative::new`] with `info(effect) = (category, signature cosine with the named one)`.
pub fn alternatives(
    named: &Candidate,
    candidates: &[Candidate],
    earn_threshold: f64,
    tie_margin: f64,
    named_category: Category,
    info: impl Fn(&str) -> (Category, f64),
) -> Vec<Alternative> {
    candidates
        .iter()
        .filter(|c| ties_with(named, c, earn_threshold, tie_margin))
        .map(|c| {
            let (cat, cos) = info(&c.effect);
            Alternative::new(named, c, named_category, cat, cos)
        })
        .collect()
}

/// The alternatives to `named` among `candidates` (in their order, best first), with each
/// effect's category and independent check read from its descriptor among `effects` (a name
/// not among them: physics, no check) and `cosine(effect)` its signature cosine with the named
/// one.
pub(crate) fn alternatives_among(
    named: &Candidate,
    candidates: &[Candidate],
    earn_threshold: f64,
    tie_margin: f64,
    effects: &[Effect],
    cosine: impl Fn(&str) -> f64,
) -> Vec<Alternative> {
    let of = |name: &str| Effect::find(effects, name).map(Effect::descriptor);
    let category = |d: Option<&EffectDescriptor>| d.map_or(Category::Physics, |d| d.category);
    let check = |d: Option<&EffectDescriptor>| d.and_then(|d| d.independent_check);
    let named_d = of(&named.effect);
    candidates
        .iter()
        .filter(|c| ties_with(named, c, earn_threshold, tie_margin))
        .map(|c| {
            let d = of(&c.effect);
            Alternative::new(named, c, category(named_d), category(d), cosine(&c.effect))
                .with_checks(check(named_d), check(d))
        })
        .collect()
}

/// An independent check (outside these diameter data) that decides whether the effect is
/// there: a process condition or the instrument off, the air's speed or temperature, the
/// fiber's cooling, for the built-in effects (their descriptors'
/// [`independent_check`](EffectDescriptor::independent_check); `None` for strain thinning and
/// unknown names).
pub fn independent_check(effect: &str) -> Option<&'static str> {
    crate::model::catalog::builtin(effect).and_then(|d| d.independent_check)
}

/// What else tells explanations apart that no measurement along the line decides: data at
/// other conditions.
pub(crate) const OTHER_CONDITIONS: &str = "data at other conditions (another take-up speed, air \
                                    condition or mass flow), which change their signatures \
                                    differently";

/// The category in words (`"missing physics"`, `"a process condition"`, `"an instrument
/// error"`, `"material data"`).
fn category_words(c: Category) -> &'static str {
    match c {
        Category::Physics => "missing physics",
        Category::Process => "a process condition",
        Category::Instrument => "an instrument error",
        Category::Material => "material data",
    }
}

/// `"0.8020 (95% CI [0.7865, 0.8175])"`, or the value without an interval.
fn value_with_ci(v: f64, ci: [f64; 2]) -> String {
    if ci.iter().all(|x| x.is_finite()) {
        format!("{v:.4} (95% CI [{:.4}, {:.4}])", ci[0], ci[1])
    } else {
        format!("{v:.4} (no valid 95% CI)")
    }
}

/// The words after the named cause in the report: `" — or, about as consistent with these
/// data, gauge_scale (delta BIC gap 2.1, signatures cos +0.986)"` (empty without
/// alternatives).
pub(super) fn or_alternatives(alts: &[Alternative]) -> String {
    if alts.is_empty() {
        return String::new();
    }
    let each: Vec<String> = alts
        .iter()
        .map(|a| {
            format!(
                "{} (delta BIC gap {:.1}, signatures cos {:+.3})",
                a.effect, a.delta_bic_gap, a.signature_cosine
            )
        })
        .collect();
    format!(
        " — or, about as consistent with these data, {}",
        each.join("; or ")
    )
}

/// The report's paragraph on a tie (empty without alternatives): each alternative's strength
/// and `(n, κ)`, whether the material result is robust to the choice, and what decides.
pub(super) fn ties_paragraph(
    named: &Candidate,
    alts: &[Alternative],
    candidates: &[Candidate],
) -> String {
    let c = named;
    let named = c.effect.as_str();
    let Some(first) = alts.first() else {
        return String::new();
    };
    let mut s = format!(
        "TIE: the data cannot choose between {named} and {} (a delta BIC gap below the tie \
         margin is less than strong evidence). The material estimate with either:\n",
        alts.iter()
            .map(|a| a.effect.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    s.push_str(&format!(
        "    with {named} ({:.4} +/- {:.4} {}): n = {}, kappa = {}\n",
        c.strength(),
        c.stderr_strength(),
        c.unit,
        value_with_ci(c.n(), c.ci95_n()),
        value_with_ci(c.kappa(), c.ci95_kappa())
    ));
    for a in alts {
        let Some(r) = candidates.iter().find(|x| x.effect == a.effect) else {
            continue;
        };
        s.push_str(&format!(
            "    with {} ({:.4} +/- {:.4} {}): n = {}, kappa = {}; shifts from {named}'s: \
             n {:+.1}, kappa {:+.1} standard errors\n",
            a.effect,
            r.strength(),
            r.stderr_strength(),
            r.unit,
            value_with_ci(r.n(), r.ci95_n()),
            value_with_ci(r.kappa(), r.ci95_kappa()),
            a.n_shift_se,
            a.kappa_shift_se
        ));
    }
    push_robustness(&mut s, alts);
    push_what_decides(&mut s, named, first, alts);
    s
}

/// The tie paragraph's sentence on whether the material result is robust to the choice among
/// `alts`.
fn push_robustness(s: &mut String, alts: &[Alternative]) {
    let fragile: Vec<&Alternative> = alts.iter().filter(|a| !a.material_robust).collect();
    if fragile.is_empty() {
        s.push_str(&format!(
            "The material result is ROBUST to the choice: n and kappa move by less than \
             {ROBUST_SHIFT_SE} standard error between them.\n"
        ));
    } else {
        s.push_str(&format!(
            "The material result DEPENDS ON THE CHOICE: with {} n or kappa moves by \
             {ROBUST_SHIFT_SE} standard error or more (or has no valid interval); decide the \
             cause before trusting (n, kappa).\n",
            fragile
                .iter()
                .map(|a| a.effect.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
}

/// The tie paragraph's last sentence: what decides between `named` and `alts` (`first`, the
/// first alternative, records the named effect's category and check), by the kinds of the
/// effects in the tie.
fn push_what_decides(s: &mut String, named: &str, first: &Alternative, alts: &[Alternative]) {
    // what decides: an independent check of each effect in the tie (the records' checks; a
    // record without them, e.g. read from older JSON, the built-in's)
    let members: Vec<(&str, Category)> = std::iter::once((named, first.named_category))
        .chain(alts.iter().map(|a| (a.effect.as_str(), a.category)))
        .collect();
    let recorded = std::iter::once(first.named_independent_check.as_deref())
        .chain(alts.iter().map(|a| a.independent_check.as_deref()));
    let checks: Vec<String> = members
        .iter()
        .zip(recorded)
        .filter_map(|((e, _), c)| {
            c.or_else(|| independent_check(e))
                .map(|c| format!("{e}: {c}"))
        })
        .collect();
    let words = |(e, c): &(&str, Category)| format!("{e} is {}", category_words(*c));
    if alts.iter().any(Alternative::mixes_physics_and_conditions) {
        s.push_str(&format!(
            "The tie mixes missing physics with process conditions or the instrument ({}): an \
             independent check decides",
            members.iter().map(words).collect::<Vec<_>>().join(", ")
        ));
    } else if members.iter().all(|m| m.1 == Category::Physics) {
        s.push_str(&format!(
            "All are missing physics: a measurement along the line, or {OTHER_CONDITIONS}, can \
             tell them apart"
        ));
    } else {
        s.push_str(&format!(
            "{}: an independent check decides",
            members.iter().map(words).collect::<Vec<_>>().join(", ")
        ));
    }
    if !checks.is_empty() {
        s.push_str(&format!(" ({}).\n", checks.join("; ")));
    } else if !s.ends_with('\n') {
        s.push_str(".\n");
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::diagnostics::candidate::StrengthStatus;
    use crate::fit::summary::tests::refit_summary;

    /// A candidate with a refit (unless not refitted): `ΔBIC` `dbic`, law `(n, kappa)` with
    /// standard errors 0.01 and 0.1.
    pub(crate) fn cand(
        effect: &str,
        status: StrengthStatus,
        dbic: f64,
        n: f64,
        kappa: f64,
    ) -> Candidate {
        Candidate {
            effect: effect.into(),
            unit: "-".into(),
            linear_score: 1.0,
            linear_strength: 0.0,
            linear_stderr: 0.005,
            cost_before: 1.0,
            cost_after: 0.8,
            extra_parameters: 1,
            delta_bic: dbic,
            delta_aic: dbic,
            signature_peak_m: 0.0,
            signature_range_m: [0.0, 0.04],
            status,
            status_note: None,
            physical_range: [-0.1, 0.1],
            search_range: [-0.2, 0.2],
            // se(n) = 0.01, se(κ) = 0.1
            refit: (status != StrengthStatus::NotRefitted)
                .then(|| refit_summary(effect, (0.03, 0.005), (n, 0.01), (kappa, 0.1))),
            shape_alternative: None,
            profiles: Vec::new(),
            scan_errors: Vec::new(),
            refit_starts: [0, 0],
            false_alarm: f64::NAN,
            share_of_excess: f64::NAN,
        }
    }

    #[test]
    fn only_credible_earning_candidates_within_the_margin_tie() {
        use StrengthStatus::*;
        let named = cand("a", Physical, -41.0, 0.80, 11.8);
        let (earn, margin) = (-10.0, DEFAULT_TIE_MARGIN);
        // just inside and just outside the margin
        assert!(ties_with(
            &named,
            &cand("b", Physical, -35.01, 0.8, 11.8),
            earn,
            margin
        ));
        assert!(!ties_with(
            &named,
            &cand("b", Physical, -34.99, 0.8, 11.8),
            earn,
            margin
        ));
        assert!(!ties_with(
            &named,
            &cand("b", Physical, -35.0, 0.8, 11.8),
            earn,
            margin
        ));
        // the named one never ties with itself
        assert!(!ties_with(&named, &named, earn, margin));
        // better ΔBIC but at a bound, unphysical, or not refitted: never an alternative
        for s in [AtBound, Unphysical, NotRefitted] {
            assert!(
                !ties_with(&named, &cand("c", s, -42.0, 0.8, 11.8), earn, margin),
                "{s:?}"
            );
        }
        // within the margin of a weak named cause but not earning its place
        let weak = cand("a", Physical, -12.0, 0.8, 11.8);
        assert!(!ties_with(
            &weak,
            &cand("d", Physical, -9.0, 0.8, 11.8),
            earn,
            margin
        ));
        assert!(ties_with(
            &weak,
            &cand("d", Physical, -10.5, 0.8, 11.8),
            earn,
            margin
        ));
    }

    #[test]
    fn shifts_are_in_the_named_refits_standard_errors() {
        use StrengthStatus::*;
        let named = cand("inlet_diameter", Physical, -41.2, 0.797, 11.79);
        let list = [
            named.clone(),
            cand("gauge_scale", Physical, -39.1, 0.802, 11.74),
            cand("radiation", Unphysical, -45.0, 0.7, 12.0),
            cand("die_temperature_offset", Physical, -36.0, 0.83, 11.5),
            cand("nusselt_scale", Physical, -20.0, 0.8, 11.8),
        ];
        let alts = alternatives(
            &named,
            &list,
            -10.0,
            DEFAULT_TIE_MARGIN,
            Category::Process,
            |e| match e {
                "gauge_scale" => (Category::Instrument, 0.986),
                _ => (Category::Process, 0.5),
            },
        );
        let names: Vec<&str> = alts.iter().map(|a| a.effect.as_str()).collect();
        assert_eq!(names, ["gauge_scale", "die_temperature_offset"]);
        let g = &alts[0];
        assert!((g.delta_bic_gap - 2.1).abs() < 1e-12);
        assert!((g.n_shift_se - 0.5).abs() < 1e-9, "{}", g.n_shift_se);
        assert!(
            (g.kappa_shift_se + 0.5).abs() < 1e-9,
            "{}",
            g.kappa_shift_se
        );
        assert!(g.material_robust);
        assert_eq!(g.signature_cosine, 0.986);
        assert!(!g.mixes_physics_and_conditions());
        let d = &alts[1];
        assert!((d.n_shift_se - 3.3).abs() < 1e-9);
        assert!(!d.material_robust);
        // without a valid CI of the named refit the shift is unknown: not robust
        let mut no_ci = named.clone();
        if let Some(r) = no_ci.refit.as_mut() {
            r.n.ci95 = [f64::NAN; 2];
        }
        let a = Alternative::new(&no_ci, &list[1], Category::Process, Category::Physics, 0.9);
        assert!(a.n_shift_se.is_nan() && !a.material_robust);
        assert!(a.mixes_physics_and_conditions());
    }

    #[test]
    fn the_report_says_what_decides_and_whether_the_material_result_is_robust() {
        use StrengthStatus::*;
        let named = cand("inlet_diameter", Physical, -41.2, 0.797, 11.79);
        let g = cand("gauge_scale", Physical, -39.1, 0.802, 11.74);
        let a = Alternative::new(&named, &g, Category::Process, Category::Instrument, 0.986);
        assert_eq!(
            or_alternatives(std::slice::from_ref(&a)),
            " — or, about as consistent with these data, gauge_scale (delta BIC gap 2.1, \
             signatures cos +0.986)"
        );
        let all = [named.clone(), g.clone()];
        let t = ties_paragraph(&named, std::slice::from_ref(&a), &all);
        assert!(t.contains("between inlet_diameter and gauge_scale"), "{t}");
        assert!(t.contains("ROBUST to the choice"), "{t}");
        assert!(t.contains("n +0.5, kappa -0.5 standard errors"), "{t}");
        assert!(
            t.contains("gauge_scale: calibrate the diameter gauge"),
            "{t}"
        );
        assert!(t.contains("inlet_diameter: measure the die swell"), "{t}");
        assert!(!t.contains("mixes missing physics"), "{t}");
        // physics tied with an instrument error, material result moved by 3 se
        let rad = cand("radiation", Physical, -38.0, 0.83, 11.79);
        let b = Alternative::new(&named, &rad, Category::Process, Category::Physics, -0.9);
        let t = ties_paragraph(&named, &[b], &[named.clone(), rad.clone()]);
        assert!(t.contains("DEPENDS ON THE CHOICE: with radiation"), "{t}");
        assert!(
            t.contains("mixes missing physics with process conditions"),
            "{t}"
        );
        assert!(t.contains("(inlet_diameter: measure the die swell"), "{t}");
        assert!(
            t.contains("radiation: measure the fiber temperature"),
            "{t}"
        );
        // missing physics only: a measurement along the line for each, or other conditions
        let warm = cand("air_temperature_profile", Physical, -37.0, 0.81, 11.7);
        let c = Alternative::new(&rad, &warm, Category::Physics, Category::Physics, 0.95);
        let t = ties_paragraph(&rad, &[c], &[rad.clone(), warm.clone()]);
        assert!(
            t.contains(
                "All are missing physics: a measurement along the line, or data at other \
                 conditions"
            ),
            "{t}"
        );
        assert!(
            t.contains("(radiation: measure the fiber temperature"),
            "{t}"
        );
        assert!(
            t.contains("air_temperature_profile: measure the air temperature"),
            "{t}"
        );
        assert!(t.trim_end().ends_with(")."), "{t}");
        assert!(ties_paragraph(&named, &[], &[]).is_empty());
        assert!(or_alternatives(&[]).is_empty());
    }

    #[test]
    fn every_effect_but_the_law_has_an_independent_check() {
        for e in crate::model::effects::Effect::all() {
            assert_eq!(
                independent_check(e.name()).is_some(),
                e.name() != "strain_thinning",
                "{}",
                e.name()
            );
        }
    }
}

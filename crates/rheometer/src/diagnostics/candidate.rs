//! The record of one candidate effect in a diagnosis, and how candidates are judged and
//! ranked.
//!
//! A [`Candidate`] holds the linearised numbers of its effect at the user's fit, the profile of
//! its global search, and — when refitted — the refit's own [`FitSummary`] (its strength, shapes,
//! `(n, κ)` with intervals, RMS, at-bound flags): nothing of the refit is copied into the record.

use super::refits::scan::{physical, search_range, Profile, ShapeParameter};
use crate::fit::options::BoundSide;
use crate::fit::summary::checks::bound_side;
use crate::fit::{AtBound, Estimate, FitSummary};
use crate::model::effects::Effect;
use serde::{Deserialize, Serialize};

/// How many standard errors a strength may lie beyond its physical range and still count as
/// consistent with it (the two-sided 95 % normal quantile): an emissivity estimated as
/// 1.02 ± 0.09 is consistent with ε ≤ 1, one of 2.0 ± 0.1 is not.
pub(crate) const PHYSICAL_RANGE_SE: f64 = 1.96;

/// Whether a candidate's refitted strength may be named as found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StrengthStatus {
    /// Not refitted (linearised numbers only).
    #[default]
    NotRefitted,
    /// Inside the physical range and away from the search bounds.
    Physical,
    /// At a bound of its search range: the data push it beyond the range.
    AtBound,
    /// Outside the physical range.
    Unphysical,
    /// The strength is credible but the refit's material law is not (`n` near 0, an interval
    /// beyond the law's range, a jump from the plain fit the gain does not pay for).
    ImplausibleLaw,
    /// The refit does not determine the strength (no standard error: a singular covariance).
    Undetermined,
}

impl StrengthStatus {
    /// The status as written in JSON (`"physical"`, `"at_bound"`, ...).
    pub fn name(&self) -> &'static str {
        match self {
            StrengthStatus::NotRefitted => "not_refitted",
            StrengthStatus::Physical => "physical",
            StrengthStatus::AtBound => "at_bound",
            StrengthStatus::Unphysical => "unphysical",
            StrengthStatus::ImplausibleLaw => "implausible_law",
            StrengthStatus::Undetermined => "undetermined",
        }
    }

    /// Whether a refit with this status is evidence about the data: its fit is as it stands
    /// (credible, or refused only for its strength's or shape's range, which a prior excludes,
    /// not the data), unlike a refit whose law is implausible, whose strength is undetermined,
    /// or a candidate not refitted. Such a refit shows a misfit the user's model leaves
    /// ([`diagnose`](super::diagnose)'s systematic test) and rivals the result's law (its
    /// ambiguity stage).
    pub fn fit_is_evidence(&self) -> bool {
        matches!(
            self,
            StrengthStatus::Physical | StrengthStatus::Unphysical | StrengthStatus::AtBound
        )
    }

    /// How a refit's strength stands, as a phrase to follow the effect's name in a sentence
    /// (empty where it is credible or not refitted).
    pub fn qualifier(&self) -> &'static str {
        match self {
            StrengthStatus::AtBound => " at a bound of its search range",
            StrengthStatus::Unphysical => " at a strength outside its physical range",
            StrengthStatus::ImplausibleLaw => " with an implausible law",
            StrengthStatus::Undetermined => " with an undetermined strength",
            StrengthStatus::NotRefitted | StrengthStatus::Physical => "",
        }
    }
}

/// A candidate's refit with another value of a discrete shape (the co-flow's tail `r`: 0 the
/// exponential, 0.5 the inverse-square decay) that the data cannot tell from the one reported:
/// `ΔBIC` within the tie margin. The reported refit keeps the default shape unless the other
/// is better by more than the margin.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShapeAlternative {
    /// Its `ΔBIC` minus the reported refit's (positive: worse).
    pub delta_bic_gap: f64,
    /// Its refit.
    pub refit: FitSummary,
}

/// One candidate's result (JSON: an entry of `candidates`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Candidate {
    /// Canonical name.
    pub effect: String,
    /// Unit of the strength.
    pub unit: String,
    /// Linearised predicted reduction of `J`.
    pub linear_score: f64,
    /// Linearised strength (the effect's unit).
    pub linear_strength: f64,
    /// Standard error of the linearised strength (the effect's unit).
    pub linear_stderr: f64,
    /// `J` of the user's model.
    pub cost_before: f64,
    /// `J` with the effect (refit, or linear prediction).
    pub cost_after: f64,
    /// Extra parameters of the refit (strength, fitted shapes; strain thinning: `n` and `κ`).
    pub extra_parameters: usize,
    /// `ΔBIC` (negative: the effect earns its place).
    pub delta_bic: f64,
    /// `ΔAIC`.
    pub delta_aic: f64,
    /// Position \[m\] where the effect changes the residuals most.
    pub signature_peak_m: f64,
    /// Positions \[m\] between which 80% of its effect on the residuals lies (10%–90%).
    pub signature_range_m: [f64; 2],
    /// Whether the refitted strength is credible: physical and inside its search range (only a
    /// [`StrengthStatus::Physical`] candidate can be named as the missing effect).
    #[serde(default)]
    pub status: StrengthStatus,
    /// Why the strength is not credible, in words (`"radiation would need 2.0000 > 1: not
    /// physical"`), or a note on a credible one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub status_note: Option<String>,
    /// Physical range of the strength (the effect's unit).
    pub physical_range: [f64; 2],
    /// Search range of the strength (the effect's unit).
    pub search_range: [f64; 2],
    /// The best refit with the effect (its strength and shapes freed), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refit: Option<FitSummary>,
    /// The best refit with another discrete shape (the co-flow's tail) where the data cannot
    /// choose between them (`ΔBIC` gap below the tie margin).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape_alternative: Option<ShapeAlternative>,
    /// Profiles of `J` against the strength, one per scanned shape.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub profiles: Vec<Profile>,
    /// Scans that could not start (one per variant, in words).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub scan_errors: Vec<String>,
    /// Refinements of this candidate that ran (from grid points and from other material
    /// laws) and how many of them reached its best cost (global search; `[0, 0]` without
    /// refit).
    #[serde(default)]
    pub refit_starts: [usize; 2],
    /// The probability that the search over all candidates and shapes finds an effect at
    /// least this convincing (`ΔBIC` at or below this one's) on effect-free data like these
    /// (see `calibrate`; `NaN` where not computed).
    #[serde(
        default = "crate::report::serde_nan::nan",
        deserialize_with = "crate::report::serde_nan::f64"
    )]
    pub false_alarm: f64,
    /// Share of the excess misfit (the cost above what the noise alone leaves) the effect
    /// removes \[-\] (`NaN` where not computed).
    #[serde(
        default = "crate::report::serde_nan::nan",
        deserialize_with = "crate::report::serde_nan::f64"
    )]
    pub share_of_excess: f64,
}

impl Candidate {
    /// Whether the numbers come from a refit (else from the linearisation).
    pub fn refitted(&self) -> bool {
        self.refit.is_some()
    }

    /// The refit's estimate of the strength.
    pub fn strength_estimate(&self) -> Option<&Estimate> {
        self.refit
            .as_ref()?
            .effect(&self.effect)
            .map(|e| &e.strength)
    }

    /// Fitted (or, without refit, linearised) strength (the effect's unit).
    pub fn strength(&self) -> f64 {
        self.strength_estimate()
            .map_or(self.linear_strength, |e| e.value)
    }

    /// Standard error of [`strength`](Self::strength).
    pub fn stderr_strength(&self) -> f64 {
        match (self.refit.as_ref(), self.strength_estimate()) {
            (Some(_), Some(e)) => e.stderr,
            (Some(_), None) => f64::NAN,
            (None, _) => self.linear_stderr,
        }
    }

    /// The refit's `n` when fitted there (`NaN` without refit or for a Newtonian refit).
    pub fn n(&self) -> f64 {
        self.fitted_law(|s| &s.n).map_or(f64::NAN, |e| e.value)
    }

    /// The refit's `κ` when fitted there.
    pub fn kappa(&self) -> f64 {
        self.fitted_law(|s| &s.kappa).map_or(f64::NAN, |e| e.value)
    }

    /// 95% CI of `n` in the refit (`NaN` without one).
    pub fn ci95_n(&self) -> [f64; 2] {
        self.fitted_law(|s| &s.n).map_or([f64::NAN; 2], |e| e.ci95)
    }

    /// 95% CI of `κ` in the refit.
    pub fn ci95_kappa(&self) -> [f64; 2] {
        self.fitted_law(|s| &s.kappa)
            .map_or([f64::NAN; 2], |e| e.ci95)
    }

    /// The refit's estimate of `n` when fitted there.
    pub fn n_estimate(&self) -> Option<&Estimate> {
        self.fitted_law(|s| &s.n)
    }

    /// The refit's estimate of `κ` when fitted there.
    pub fn kappa_estimate(&self) -> Option<&Estimate> {
        self.fitted_law(|s| &s.kappa)
    }

    fn fitted_law(&self, pick: impl Fn(&FitSummary) -> &Estimate) -> Option<&Estimate> {
        self.refit.as_ref().map(pick).filter(|e| e.fitted)
    }

    /// Estimates of the refit that ended at a bound of their search range (empty without refit).
    pub fn at_bound(&self) -> &[AtBound] {
        self.refit.as_ref().map_or(&[], |s| &s.at_bound)
    }

    /// The shape of the refit (empty for effects without a shape or without refit).
    pub fn shape(&self) -> Vec<ShapeParameter> {
        self.refit
            .as_ref()
            .and_then(|s| s.effect(&self.effect))
            .map(|e| {
                e.shapes
                    .iter()
                    .map(|sh| ShapeParameter {
                        name: sh.name.clone(),
                        value: sh.value,
                        unit: sh.unit.clone(),
                    })
                    .collect()
            })
            .unwrap_or_default()
    }

    /// RMS relative residual with the effect (`NaN` without refit) \[-\].
    pub fn rms_relative_residual_after(&self) -> f64 {
        self.refit
            .as_ref()
            .map_or(f64::NAN, |s| s.rms_relative_residual)
    }
}

/// The status of a refitted `strength` (standard error `stderr`) of `effect` with the fit's
/// estimates at a bound: at a search bound (listed in `at_bound`, or within the report's
/// tolerance of the range) comes first, then outside the physical range by more than
/// [`PHYSICAL_RANGE_SE`] standard errors. A strength beyond the physical range by less is
/// [`StrengthStatus::Physical`] with a note saying so (noise alone puts a true value at the
/// limit that far beyond it).
///
/// `unbounded` is the strength's optimum with its bounds lifted, to first order (the refit's
/// Gauss–Newton step from where it ended, [`unbounded_optimum`]); where given and the strength
/// ends at a search bound beyond its physical range, a strength whose unbounded optimum lies
/// within [`PHYSICAL_RANGE_SE`] standard errors of the physical limit is credible, with a note
/// (the data do not bound it on that side).
pub(crate) fn strength_status(
    effect: &Effect,
    strength: f64,
    stderr: f64,
    at_bound: &[AtBound],
    unbounded: Option<f64>,
) -> (StrengthStatus, Option<String>) {
    let (lo, hi) = search_range(effect);
    let unit = effect.unit();
    let side = at_bound
        .iter()
        .find(|b| b.parameter == effect.name())
        .map(|b| (b.side, b.bound))
        .or_else(|| {
            bound_side(strength, lo, hi).map(|s| {
                let b = if s == BoundSide::Lower { lo } else { hi };
                (s, b)
            })
        });
    if let Some((s, b)) = side {
        if let Some(note) = unbounded.and_then(|u| flat_beyond_physics(effect, b, u, stderr)) {
            return (StrengthStatus::Physical, Some(note));
        }
        return (
            StrengthStatus::AtBound,
            Some(format!(
                "{} best at its {} bound {b} {unit}: the data push it beyond its search range",
                effect.name(),
                s.name()
            )),
        );
    }
    match physical(effect, strength) {
        Ok(()) => (StrengthStatus::Physical, None),
        Err(why) => beyond_physical(effect, strength, stderr, why),
    }
}

/// A strength at the search bound `bound` that lies beyond the physical range, with its
/// unbounded optimum `unbounded` (first order): where that optimum lies within
/// [`PHYSICAL_RANGE_SE`] standard errors (`stderr`) of the physical limit, the data do not push
/// the strength beyond physics, they do not bound it on that side (a short co-flow's speed
/// trades off against its decay length: with unit trust-region scales its refit crawled 1 m/s
/// per iteration and stopped inside the range by chance, with scaled ones it runs along the
/// flat valley to the bound). Returns the note that says so, or `None` (a bound inside the
/// physical range, or an optimum further beyond: the status stays "at a bound").
fn flat_beyond_physics(effect: &Effect, bound: f64, unbounded: f64, stderr: f64) -> Option<String> {
    let (plo, phi) = effect.physical_range();
    let (limit, beyond) = if bound > phi {
        (phi, unbounded.max(bound) - phi)
    } else if bound < plo {
        (plo, plo - unbounded.min(bound))
    } else {
        return None;
    };
    let ok = stderr.is_finite() && stderr > 0.0 && beyond.is_finite();
    if !(ok && beyond <= PHYSICAL_RANGE_SE * stderr) {
        return None;
    }
    let u = match effect.unit() {
        "-" => String::new(),
        unit => format!(" {unit}"),
    };
    Some(format!(
        "{} = {bound} +/- {stderr:.4}{u} is best at its search bound; without the bound its \
         optimum would lie {:.2} standard errors beyond its physical limit {limit}{u}: the data \
         do not bound it on that side (it trades off against the effect's shape), consistent \
         with a value inside the physical range",
        effect.name(),
        beyond / stderr
    ))
}

/// The optimum of the fit parameter `name` of `id` with the bounds lifted, to first order: its
/// value plus its component of the fit's Gauss–Newton step
/// ([`FitResult::gauss_newton_step`](diffbvp::least_squares::FitResult::gauss_newton_step);
/// `None` without that parameter or that step).
pub(crate) fn unbounded_optimum(id: &crate::fit::Identification, name: &str) -> Option<f64> {
    let i = id.names.iter().position(|n| n == name)?;
    let step = id.fit.gauss_newton_step()?;
    Some(id.fit.p[i] + step[i])
}

/// A strength outside the physical range: credible with a note if within
/// [`PHYSICAL_RANGE_SE`] standard errors of the limit, else not physical (`why`).
fn beyond_physical(
    effect: &Effect,
    strength: f64,
    stderr: f64,
    why: String,
) -> (StrengthStatus, Option<String>) {
    let (plo, phi) = effect.physical_range();
    let (limit, beyond) = if strength > phi {
        (phi, strength - phi)
    } else {
        (plo, plo - strength)
    };
    let se_ok = stderr.is_finite() && stderr > 0.0;
    let u = match effect.unit() {
        "-" => String::new(),
        unit => format!(" {unit}"),
    };
    if se_ok && strength.is_finite() && beyond <= PHYSICAL_RANGE_SE * stderr {
        (
            StrengthStatus::Physical,
            Some(format!(
                "{} = {strength:.4} +/- {stderr:.4}{u} lies beyond its physical limit \
                 {limit}{u} by {:.2} standard errors: consistent with it (the data do not \
                 tell it from a value at the limit)",
                effect.name(),
                beyond / stderr
            )),
        )
    } else {
        (StrengthStatus::Unphysical, Some(why))
    }
}

/// Whether a candidate may be named as the missing effect: refitted, `ΔBIC` below `threshold`,
/// and its strength credible (never one at a search bound or outside the physical range).
pub fn earns_its_place(c: &Candidate, threshold: f64) -> bool {
    c.refitted() && c.status == StrengthStatus::Physical && c.delta_bic < threshold
}

/// Ranking: credible refits by `ΔBIC`, then refits that are not credible by `ΔBIC`, then
/// candidates without a refit by linear score.
pub(crate) fn rank_order(a: &Candidate, b: &Candidate) -> std::cmp::Ordering {
    let class = |c: &Candidate| match (c.refitted(), c.status) {
        (true, StrengthStatus::Physical) => 0,
        (true, _) => 1,
        (false, _) => 2,
    };
    class(a)
        .cmp(&class(b))
        .then_with(|| match (a.refitted(), b.refitted()) {
            (true, true) => a.delta_bic.total_cmp(&b.delta_bic),
            _ => b.linear_score.total_cmp(&a.linear_score),
        })
}

/// A pair of candidates the data cannot tell apart.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Indistinguishable {
    /// The two effects.
    pub effects: [String; 2],
    /// Cosine of their orthogonalised signatures.
    pub cosine: f64,
}
#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::BoundSide;

    fn result(
        effect: &str,
        refitted: bool,
        status: StrengthStatus,
        dbic: f64,
        lin: f64,
    ) -> Candidate {
        Candidate {
            effect: effect.into(),
            unit: "-".into(),
            linear_score: lin,
            linear_strength: 0.0,
            linear_stderr: 0.1,
            cost_before: 1.0,
            cost_after: 0.5,
            extra_parameters: 1,
            delta_bic: dbic,
            delta_aic: dbic,
            signature_peak_m: 0.0,
            signature_range_m: [0.0, 0.0],
            status,
            status_note: None,
            physical_range: [0.0, 1.0],
            search_range: [0.0, 1.0],
            refit: refitted.then(crate::fit::summary::tests::example),
            shape_alternative: None,
            profiles: Vec::new(),
            scan_errors: Vec::new(),
            refit_starts: [0, 0],
            false_alarm: f64::NAN,
            share_of_excess: f64::NAN,
        }
    }

    #[test]
    fn ranking_uses_the_refits_not_the_linearised_scores() {
        use StrengthStatus::*;
        // b has the larger linear score but the worse refit; c is not credible; d not refitted
        let mut v = [
            result("a", true, Physical, -40.0, 1.0),
            result("b", true, Physical, -5.0, 100.0),
            result("c", true, Unphysical, -90.0, 50.0),
            result("d", false, NotRefitted, 0.0, 500.0),
        ];
        v.sort_by(rank_order);
        let names: Vec<&str> = v.iter().map(|c| c.effect.as_str()).collect();
        assert_eq!(names, ["a", "b", "c", "d"]);
        assert!(earns_its_place(&v[0], -10.0));
        assert!(!earns_its_place(&v[1], -10.0)); // ΔBIC above the threshold
        assert!(!earns_its_place(&v[2], -10.0)); // best ΔBIC, but not physical
        assert!(!earns_its_place(&v[3], -10.0));
    }

    #[test]
    fn a_strength_at_a_bound_or_beyond_the_physical_range_is_not_credible() {
        let rad = Effect::Radiation;
        let (s, note) = strength_status(&rad, 0.9, 0.1, &[], None);
        assert_eq!((s, note), (StrengthStatus::Physical, None));
        let (s, note) = strength_status(&rad, 1.6, 0.1, &[], None);
        assert_eq!(s, StrengthStatus::Unphysical);
        assert!(note.unwrap().contains("> 1: not physical"));
        // beyond the limit by less than 1.96 standard errors: consistent with it, said so
        let (s, note) = strength_status(&rad, 1.02, 0.09, &[], None);
        assert_eq!(s, StrengthStatus::Physical);
        let note = note.unwrap();
        assert!(
            note.contains("radiation = 1.0200 +/- 0.0900 lies beyond its physical limit 1 by 0.22 standard errors"),
            "{note}"
        );
        let (s, _) = strength_status(&rad, -0.19, 0.1, &[], None);
        assert_eq!(s, StrengthStatus::Physical);
        // by more, or without a valid standard error: not physical
        assert_eq!(
            strength_status(&rad, 1.2, 0.1, &[], None).0,
            StrengthStatus::Unphysical
        );
        assert_eq!(
            strength_status(&rad, 1.02, f64::NAN, &[], None).0,
            StrengthStatus::Unphysical
        );
        // at the search bound 2 (found by value, without an at_bound entry)
        let (s, note) = strength_status(&rad, 2.0, 0.5, &[], None);
        assert_eq!(s, StrengthStatus::AtBound);
        assert!(note.unwrap().contains("upper bound 2"));
        // at a search bound beyond the physical range, its unbounded optimum within 1.96
        // standard errors of the limit: the data do not bound it on that side, said so
        let (s, note) = strength_status(&rad, 2.0, 0.6, &[], Some(2.0));
        assert_eq!(s, StrengthStatus::Physical);
        let note = note.unwrap();
        assert!(
            note.contains("radiation = 2 +/- 0.6000 is best at its search bound; without the bound its optimum would lie 1.67 standard errors beyond its physical limit 1"),
            "{note}"
        );
        // the data pushing it further (its unbounded optimum 2.5), without the optimum, or
        // without a standard error: at a bound
        for (se, unbounded) in [(0.6, Some(2.5)), (0.6, None), (f64::NAN, Some(2.0))] {
            assert_eq!(
                strength_status(&rad, 2.0, se, &[], unbounded).0,
                StrengthStatus::AtBound,
                "{se} {unbounded:?}"
            );
        }
        // listed by the fit report
        let c = Effect::AirCoflow {
            decay_length: Some(0.25),
            tail: None,
        };
        let ab = AtBound {
            parameter: "air_coflow".into(),
            side: BoundSide::Lower,
            bound: -5.0,
            value: -5.0,
        };
        let (s, note) = strength_status(&c, -5.0, 1.0, &[ab], Some(-5.0));
        assert_eq!(s, StrengthStatus::AtBound);
        let note = note.unwrap();
        assert!(
            note.contains("air_coflow best at its lower bound -5 m/s"),
            "{note}"
        );
        // an estimate at a bound of another parameter does not matter
        let other = AtBound {
            parameter: "kappa".into(),
            side: BoundSide::Upper,
            bound: 20.0,
            value: 20.0,
        };
        assert_eq!(
            strength_status(&c, 3.0, 1.0, &[other], None).0,
            StrengthStatus::Physical
        );
    }
}

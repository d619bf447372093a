//! Stage 6: judging each candidate's refit — its cost and information criteria, whether its
//! strength (and shape) is credible, where along the line it changes the residuals, and the
//! other shape the data cannot rule out.

use super::linear::linearise::Linearisation;
use super::linear::signature::{named_residuals, signature_location};
use super::shapes::Choice;
use crate::diagnostics::candidate::{
    strength_status, unbounded_optimum, Candidate, ShapeAlternative, StrengthStatus,
};
use crate::diagnostics::diagnosis::ResidualProfiles;
use crate::fit::summary::checks::{about_the_law_estimate, law_jump, PLAUSIBLE_N};
use crate::fit::{FitSummary, Identification, WarningCode};
use crate::model::effects::Effect;

/// Fills `record` from its chosen refit (`variant` the shape variant it belongs to) and the
/// other shape's refit; returns the refit's identification.
pub(crate) fn judge(
    lin: &Linearisation,
    base: &FitSummary,
    before: &ResidualProfiles,
    record: &mut Candidate,
    (variant, refit): Choice,
    other: Option<Choice>,
) -> Identification {
    let id = refit.identification;
    let summary = &id.summary;
    record.cost_after = refit.cost;
    (record.delta_bic, record.delta_aic) = lin.ic(refit.cost, record.extra_parameters);
    let strength = summary
        .effect(&record.effect)
        .map(|e| (e.strength.value, e.strength.stderr));
    let (s, se) = strength.unwrap_or((f64::NAN, f64::NAN));
    let unbounded = unbounded_optimum(&id, &record.effect);
    let (status, note) = match credibility(&variant, &record.effect, (s, se, unbounded), summary) {
        (StrengthStatus::Physical, note) => {
            plausibility(base, summary).unwrap_or((StrengthStatus::Physical, note))
        }
        other => other,
    };
    record.status = status;
    record.status_note = note;
    let after = named_residuals(&id);
    let change: Vec<f64> = after
        .iter()
        .zip(before)
        .flat_map(|(pa, pb)| pa.1.iter().zip(&pb.1).map(|(x, y)| x.1 - y.1))
        .collect();
    (record.signature_peak_m, record.signature_range_m) =
        signature_location(&lin.positions, &change);
    record.shape_alternative = other.and_then(|(_, o)| {
        let gap = lin.ic(o.cost, record.extra_parameters).0 - record.delta_bic;
        credible_shape(&record.effect, &o.identification.summary).then_some(ShapeAlternative {
            delta_bic_gap: gap,
            refit: o.identification.summary,
        })
    });
    record.refit = Some(summary.clone());
    id
}

/// The status of the refitted strength; a shape parameter at a bound of its range is no
/// credible estimate either.
fn credibility(
    variant: &Effect,
    effect: &str,
    (strength, stderr, unbounded): (f64, f64, Option<f64>),
    summary: &FitSummary,
) -> (StrengthStatus, Option<String>) {
    let (status, note) = strength_status(variant, strength, stderr, &summary.at_bound, unbounded);
    if status != StrengthStatus::Physical {
        return (status, note);
    }
    if !(stderr.is_finite() && stderr > 0.0) {
        return (
            StrengthStatus::Undetermined,
            Some(format!(
                "the refit does not determine {effect} (no standard error: its covariance is \
                 singular)"
            )),
        );
    }
    let prefix = format!("{effect}.");
    match summary
        .at_bound
        .iter()
        .find(|b| b.parameter.starts_with(&prefix))
    {
        Some(b) => (
            StrengthStatus::AtBound,
            Some(format!(
                "its shape parameter {} is best at its {} bound {}: the data push the effect's \
                 shape beyond its range",
                b.parameter,
                b.side.name(),
                b.bound
            )),
        ),
        None => (status, note),
    }
}

/// A refit whose material law is implausible (its own checks, or a jump from the plain fit
/// `base` that the gain in fit does not pay for) is not credible, whatever its strength. A
/// refit that ends in the law's other Newtonian corner (`n` below the plausible range with
/// `K` beyond the data's stresses: the law Newtonian over the data's strain rates,
/// [`FitSummary::law_newtonian_over_data`]) is a Newtonian melt with the effect: its `n` is no
/// reason, nor its move from a plain fit that is Newtonian over the data too.
fn plausibility(base: &FitSummary, refit: &FitSummary) -> Option<(StrengthStatus, Option<String>)> {
    let corner = refit.n.value < PLAUSIBLE_N[0] && refit.law_newtonian_over_data();
    let own = refit
        .warnings
        .iter()
        .filter(|w| !(corner && about_the_law_estimate(w)))
        .find(|w| w.code == WarningCode::Implausible)
        .map(|w| w.message.clone());
    let jump = law_jump(base, refit)
        .filter(|_| !(corner && base.law_newtonian_over_data()))
        .map(|(_, w)| w.message);
    own.or(jump).map(|m| {
        (
            StrengthStatus::ImplausibleLaw,
            Some(format!("its refit's law is implausible: {m}")),
        )
    })
}

/// Whether another shape's refit is credible: its strength and shape inside their ranges.
fn credible_shape(effect: &str, summary: &FitSummary) -> bool {
    let prefix = format!("{effect}.");
    summary.effect(effect).is_some()
        && !summary
            .at_bound
            .iter()
            .any(|b| b.parameter == effect || b.parameter.starts_with(&prefix))
}

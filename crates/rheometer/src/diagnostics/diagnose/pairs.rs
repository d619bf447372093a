//! Stage 9b: pairs of candidates fitted jointly, as a challenge to what the forward search
//! found (or to "none of the candidates").
//!
//! Two effects can hide each other: warm air heats the fiber where radiation cools it, and a
//! co-flow and warm air each shift the profile in ways the other half-undoes. Each alone then
//! explains little (radiation may even make a single refit worse), and the forward search,
//! which adds the best single effect first, can settle on a third effect that mimics their sum
//! with a biased material law. So wherever the user's residuals are systematic or an effect was
//! named, every pair of refitted candidates is fitted jointly with the law, started from the
//! members' own refits (strengths and shapes) and the user's fit's law and solutions. A pair is
//! kept only if
//!
//! * its joint fit brings the residuals to the noise ([`super::verdict::explained`]),
//! * both strengths are credible (not at a search bound, not outside the physical range) and
//!   the law is not at a bound,
//! * each member earns its place beside the other (`ΔBIC` of the pair against the other
//!   member alone below [`DiagnoseOptions::earn_threshold`]).
//!
//! Every pair is first fitted with its BVPs solved at the scans' tolerance and judged with
//! margins (`Margins::SCREEN`); only the pairs that pass are fitted again at full accuracy from
//! that optimum and judged as above (most pairs fail the screen, so few pay for full accuracy).
//!
//! The kept pair with the lowest `ΔBIC` (against the user's model) is judged against the
//! forward search's result by [`against_steps`](crate::diagnostics::refits::pair): it replaces
//! it only beyond a margin corrected for the pairs tried, and within it a disagreeing law is
//! no result.

use super::step::Step;
use super::DiagnoseOptions;
use crate::diagnostics::candidate::{
    strength_status, Candidate, Indistinguishable, StrengthStatus,
};
use crate::diagnostics::refits::pair::delta_bic;
use crate::diagnostics::refits::pair::PairFound;
use crate::fit::{
    FitStart, FitSummary, Identification, IdentifyOptions, Rheometer, RheometerError,
};
use crate::model::effects::{Effect, EffectSetting, ModelSpec};
use crate::model::setup::ExperimentSet;
use diffbvp::least_squares::Loss;
use diffbvp::solve::GrowthLimit;
use rayon::prelude::*;

/// Relative `J` within which two starts reached the same optimum \[-\].
const SAME_OPTIMUM: f64 = 1e-4;

/// How strictly a pair is judged ([`judge`]): the limits of "explained" `explained` times as
/// wide, and each member's place beside the other `bic` looser in `ΔBIC`.
#[derive(Clone, Copy)]
struct Margins {
    explained: f64,
    bic: f64,
}

impl Margins {
    /// As the module documentation says.
    const NONE: Margins = Margins {
        explained: 1.0,
        bic: 0.0,
    };
    /// For the screening fit at the scans' BVP tolerance (which moves a refit's `ΔBIC` by under
    /// 2 on 234 points): "explained" 10 % wider, a member's place 5 looser.
    const SCREEN: Margins = Margins {
        explained: 1.1,
        bic: 5.0,
    };
}

/// How a pair's joint fits solve their BVPs: at the fit's tolerance (`tol` `None`) or at
/// `tol`, with the refinements' mesh limits.
#[derive(Clone, Copy)]
struct Solves {
    tol: Option<f64>,
    growth_limit: Option<GrowthLimit>,
    max_nodes: usize,
}

/// One member of a pair: the effect with its discrete shapes fixed at its refit's, and its
/// start strength (with start values of its fitted shapes).
struct Member<'a> {
    candidate: &'a Candidate,
    effect: Effect,
    start: Vec<(String, f64)>,
}

impl Member<'_> {
    /// The start of the pair `self + b`: both members' refits.
    fn start(&self, b: &Member<'_>) -> Vec<(String, f64)> {
        self.start.iter().chain(&b.start).cloned().collect()
    }

    /// Start values `scale` times as far from neutral as the strength fitted in `fit` (its
    /// fitted shapes as fitted), kept inside the strength's search range (a start outside it
    /// would fail and count as a start that missed the optimum).
    fn scaled(&self, fit: &FitSummary, scale: f64) -> Vec<(String, f64)> {
        let Some(e) = fit.effect(self.effect.name()) else {
            return self.start.clone();
        };
        let neutral = self.effect.neutral();
        let (lo, hi) = self.effect.bounds();
        let inset = 1e-3 * (hi - lo);
        let mut v = vec![(
            self.candidate.effect.clone(),
            (neutral + scale * (e.strength.value - neutral)).clamp(lo + inset, hi - inset),
        )];
        for (name, _) in self.start.iter().skip(1) {
            let short = name.rsplit('.').next().unwrap_or(name);
            if let Some(sh) = e.shapes.iter().find(|sh| sh.name == short) {
                v.push((name.clone(), sh.value));
            }
        }
        v
    }
}

/// Whether the pair `kept + twin` is a result of two settled effects (`settled`) with one of
/// them replaced by its near-twin: `kept` is settled, `twin` is not, and `twin` cannot be told
/// apart from the other settled effect at the user's fit (their orthogonalised signatures'
/// `|cos|` above [`DiagnoseOptions::indistinguishable_cosine`], the threshold at which the
/// report says the data cannot tell two effects apart). The forward search adds the better
/// twin first and never tries the other beside the first effect, so without this pair a
/// twin's law would be printed as the result unchallenged (a die colder than declared with a
/// co-flow: the co-flow with the Nusselt factor named, `n` 2.5 standard errors off).
fn substitutes(twins: &[Indistinguishable], settled: &[String], kept: &str, twin: &str) -> bool {
    settled.iter().any(|e| e == kept)
        && !settled.iter().any(|e| e == twin)
        && twins.iter().any(|p| {
            let pair = [p.effects[0].as_str(), p.effects[1].as_str()];
            pair.contains(&twin)
                && settled
                    .iter()
                    .any(|e| e != kept && e != twin && pair.contains(&e.as_str()))
        })
}

/// The pair search on the first step's candidates; `None` when no pair qualifies. `settled`:
/// the effects the forward search found where they bring the residuals to the noise, each
/// with one strength in every experiment (pairs containing one of them are not fitted, but for
/// one of them beside the other's near-twin, see [`substitutes`]).
pub(crate) fn search(
    set: &ExperimentSet,
    base_spec: &ModelSpec,
    options: &DiagnoseOptions,
    first: &Step,
    settled: &[String],
) -> Option<(PairFound, Identification)> {
    // every refitted candidate, whatever it does alone: one that makes a single refit worse
    // (radiation beside unknown warm air) or ends at a bound may be compensating for the
    // missing partner; the pair's own strengths are judged below
    let members: Vec<Member<'_>> = first
        .candidates
        .iter()
        .filter(|c| c.refitted())
        .filter_map(|c| member(c, options))
        .collect();
    // a pair that adds an effect to a result already at the noise is the forward search's
    // next step, which parsimony refused: only other explanations compete with it, among
    // them the result with one of its effects replaced by a near-twin
    let settled_in = |m: &Member<'_>| settled.contains(&m.candidate.effect);
    let twins = &first.indistinguishable;
    let mut pairs = Vec::new();
    for i in 0..members.len() {
        for j in i + 1..members.len() {
            let (a, b) = (&members[i], &members[j]);
            let other = (!settled_in(a) && !settled_in(b))
                || substitutes(twins, settled, &a.candidate.effect, &b.candidate.effect)
                || substitutes(twins, settled, &b.candidate.effect, &a.candidate.effect);
            if other {
                pairs.push((i, j));
            }
        }
    }
    let tried = pairs.len();
    // the joint fits are refits like the single ones: the same mesh limits
    let full = Solves {
        tol: None,
        growth_limit: options.scan.refine_growth_limit,
        max_nodes: options.scan.refine_max_nodes,
    };
    // screening: every pair fitted with its BVPs solved at the scans' tolerance (1e-3 for the
    // fit's 1e-4) and judged with margins; a pair that passes is fitted again at full accuracy
    // from the screening's optimum and judged as it stands
    let screen = Solves {
        tol: Some(options.scan.grid_tol),
        ..full
    };
    let best = pairs
        .into_par_iter()
        .filter_map(|(i, j)| {
            let (a, b) = (&members[i], &members[j]);
            let fit = |from: &Identification, start: Vec<(String, f64)>, solves: Solves| {
                fit_pair(set, base_spec, first, (a, b), from, &[start], solves)
                    .ok()
                    .and_then(best_of)
            };
            let (loose, _) = fit(&first.base, a.start(b), screen)?;
            judge(
                first,
                options,
                (a, b),
                &loose,
                (1, 1, tried),
                Margins::SCREEN,
            )?;
            let (id, at) = fit(&loose, pair_start(a, b, &loose.summary, 1.0), full)?;
            let p = judge(first, options, (a, b), &id, (1, at, tried), Margins::NONE)?;
            Some((i, j, p, id))
        })
        .min_by(|x, y| x.2.delta_bic.total_cmp(&y.2.delta_bic))?;
    // the kept pair's globality: its fit again from strengths twice and half as far from
    // neutral as its optimum's (the user's law, warm solutions); the best of all starts is kept
    let (i, j, p, id) = best;
    let (a, b) = (&members[i], &members[j]);
    let more: Vec<Vec<(String, f64)>> = [2.0, 0.5]
        .iter()
        .map(|&scale| pair_start(a, b, &id.summary, scale))
        .collect();
    let mut fits =
        fit_pair(set, base_spec, first, (a, b), &first.base, &more, full).unwrap_or_default();
    fits.push(id);
    let starts = p.starts + more.len();
    let (id, at) = best_of(fits)?;
    let p = judge(
        first,
        options,
        (a, b),
        &id,
        (starts, at, tried),
        Margins::NONE,
    )?;
    Some((p, id))
}

/// The start of the pair `a + b` at `scale` times the distance from neutral of the strengths
/// fitted in `fit` (its fitted shapes as fitted; see [`Member::scaled`]).
fn pair_start(a: &Member<'_>, b: &Member<'_>, fit: &FitSummary, scale: f64) -> Vec<(String, f64)> {
    a.scaled(fit, scale)
        .into_iter()
        .chain(b.scaled(fit, scale))
        .collect()
}

/// The pair `a + b` fitted as `id` (from `starts` starts, `at` of them at its optimum, `tried`
/// pairs in all), if it qualifies (module documentation) with `margins`.
fn judge(
    first: &Step,
    options: &DiagnoseOptions,
    (a, b): (&Member<'_>, &Member<'_>),
    id: &Identification,
    (starts, at, tried): (usize, usize, usize),
    margins: Margins,
) -> Option<PairFound> {
    let n = first.base.fit.num_residuals() as f64;
    let j0 = first.base.summary.cost;
    let noise = &first.base.summary.noise;
    let s = &id.summary;
    let k = a.candidate.extra_parameters + b.candidate.extra_parameters;
    let dbic = delta_bic(n, j0, s.cost, k);
    // against each member alone: the other one's place beside it
    let against = |m: &Member<'_>, other: &Member<'_>| {
        delta_bic(
            n,
            m.candidate.cost_after,
            s.cost,
            other.candidate.extra_parameters,
        )
    };
    let vs = [against(a, b), against(b, a)];
    let credible = [a, b].iter().all(|m| {
        s.effect(m.effect.name()).is_some_and(|e| {
            strength_status(
                &m.effect,
                e.strength.value,
                e.strength.stderr,
                &s.at_bound,
                None,
            )
            .0 == StrengthStatus::Physical
        })
    });
    let law_free = s.bound_of("n").is_none() && s.bound_of("kappa").is_none();
    let earns = vs.iter().all(|v| *v < options.earn_threshold + margins.bic);
    let explained = super::verdict::explained_within(s, noise, margins.explained);
    (credible && law_free && earns && explained).then(|| PairFound {
        effects: [a.candidate.effect.clone(), b.candidate.effect.clone()],
        delta_bic: dbic,
        delta_bic_against_single: vs,
        starts,
        starts_at_optimum: at,
        pairs_tried: tried,
        delta_bic_of_steps: 0.0,
        replace_margin: 0.0,
        replaces: false,
        laws_disagree: None,
        fit: None,
    })
}

/// The member of candidate `c`: its variant (discrete shapes of its refit fixed) and its start
/// (the refit's strength and fitted shapes).
fn member<'a>(c: &'a Candidate, options: &DiagnoseOptions) -> Option<Member<'a>> {
    let mut effect = Effect::find(&options.candidates, &c.effect)?.clone();
    let fitted: Vec<&'static str> = effect
        .descriptor()
        .shapes
        .iter()
        .filter(|s| s.fitted_with_strength)
        .map(|s| s.name)
        .collect();
    let mut shape_starts = Vec::new();
    for sh in c.shape() {
        if fitted.contains(&sh.name.as_str()) {
            shape_starts.push((format!("{}.{}", c.effect, sh.name), sh.value));
        } else if let Ok(e) = effect.clone().with_shape(&sh.name, sh.value) {
            effect = e;
        }
    }
    if !c.strength().is_finite() {
        return None;
    }
    let mut start = vec![(c.effect.clone(), c.strength())];
    start.extend(shape_starts);
    Some(Member {
        candidate: c,
        effect,
        start,
    })
}

/// The joint fit of `a` and `b` from each of `starts` (start strengths and shapes by name; the
/// law of the fit `from` and its solutions as warm starts, one model for all starts, BVP
/// solves as `solves` says): the fits that converged.
fn fit_pair(
    set: &ExperimentSet,
    base_spec: &ModelSpec,
    first: &Step,
    (a, b): (&Member<'_>, &Member<'_>),
    from: &Identification,
    starts: &[Vec<(String, f64)>],
    solves: Solves,
) -> Result<Vec<Identification>, RheometerError> {
    let mut spec = base_spec.clone();
    spec.candidates.clear();
    let spec = spec
        .with(EffectSetting::fitted(a.effect.clone()))
        .with(EffectSetting::fitted(b.effect.clone()));
    let rh = Rheometer::with_spec(set, spec)?;
    // least squares, as the single refits the pair is judged against (whatever the loss of
    // the user's fit)
    let mut opts = IdentifyOptions {
        loss: Loss::Linear,
        ..first.opts.clone()
    };
    opts.simulate.growth_limit = solves.growth_limit;
    opts.simulate.max_nodes = opts.simulate.max_nodes.min(solves.max_nodes);
    if let Some(t) = solves.tol {
        opts.simulate.tol = opts.simulate.tol.max(t);
        opts.loose_tolerance = None;
    }
    let mut fits = Vec::new();
    for st in starts {
        let start = FitStart {
            strengths: st.clone(),
            warm: Some(from.solutions.clone()),
            ..FitStart::at(from.law())
        };
        if let Ok(id) = rh.identify_from(&start, &opts) {
            fits.push(id);
        }
    }
    Ok(fits)
}

/// The fit of lowest `J` among `fits` and how many of them reached it (relative `J` within
/// [`SAME_OPTIMUM`]); `None` without any fit.
fn best_of(fits: Vec<Identification>) -> Option<(Identification, usize)> {
    let lowest = fits
        .iter()
        .map(|f| f.summary.cost)
        .fold(f64::INFINITY, f64::min);
    let at = fits
        .iter()
        .filter(|f| f.summary.cost <= lowest * (1.0 + SAME_OPTIMUM))
        .count();
    let best = fits
        .into_iter()
        .min_by(|x, y| x.summary.cost.total_cmp(&y.summary.cost))?;
    Some((best, at))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn twin(a: &str, b: &str, cosine: f64) -> Indistinguishable {
        Indistinguishable {
            effects: [a.into(), b.into()],
            cosine,
        }
    }

    #[test]
    fn a_settled_result_is_challenged_only_by_its_members_twins() {
        let twins = vec![
            twin("nusselt_scale", "die_temperature_offset", -0.995),
            twin("air_coflow", "radiation", -0.96),
        ];
        let settled: Vec<String> = vec!["air_coflow".into(), "nusselt_scale".into()];
        // the co-flow beside the Nusselt factor's twin: the result with the twin swapped
        assert!(substitutes(
            &twins,
            &settled,
            "air_coflow",
            "die_temperature_offset"
        ));
        // the Nusselt factor beside the co-flow's twin
        assert!(substitutes(&twins, &settled, "nusselt_scale", "radiation"));
        // a member beside its own twin adds an effect to the result (parsimony refused it)
        assert!(!substitutes(
            &twins,
            &settled,
            "nusselt_scale",
            "die_temperature_offset"
        ));
        // no twin of the other member: a further effect, not a substitute
        assert!(!substitutes(&twins, &settled, "air_coflow", "gauge_offset"));
        // the twin must be outside the result, the kept effect in it
        assert!(!substitutes(&twins, &settled, "radiation", "nusselt_scale"));
        // a single settled effect has no partner to swap
        let one: Vec<String> = vec!["air_coflow".into()];
        assert!(!substitutes(&twins, &one, "air_coflow", "radiation"));
    }
}

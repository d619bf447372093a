//! `diagnose`: which physical effects are missing from a user's model — a chain of stages,
//! each in its own file, passing one record per candidate ([`Candidate`]) along.
//!
//! 1. **Fit the user's model** (`base`) with the principled estimator (raw relative residuals,
//!    take-up diameters fitted): the paper's smoothed-data estimator leaves residuals ~1.4× the
//!    noise even for a correct model, which would mask missing physics. The candidates are
//!    carried in the model at neutral strength (which reproduces the user's model exactly).
//! 2. **Linearise** (`linear::linearise`): each candidate's exact sensitivity direction at the
//!    fit (one sensitivity solve per experiment, reusing the factorisation of the last Newton step,
//!    gives all of them), orthogonalised against the fitted parameters' directions; its
//!    projection of the residual is the cost it would remove to first order
//!    (`scores`).
//! 3. **Test the noise**: are the residuals systematic? The RMS relative residual against the
//!    fit's one noise level (declared, else the noise model's estimate, outliers excluded) and
//!    the lag-1 autocorrelation of the residuals along each spin line (white noise:
//!    `ρ₁ √N ≈ N(0, 1)`); a candidate that earns its place (stage 6) also marks them
//!    systematic (the RMS test is weak when the noise is estimated). The detection limits of
//!    every candidate ([`detection`](super::detection)) come from the same linearisation.
//! 4. **Search** (`search`) every candidate globally, in parallel: its strength scanned over
//!    its search range (and, for effects with a shape, a few shapes), each grid point a
//!    warm-started refit of the material parameters with the strength fixed; the best grid
//!    points refined with the strength freed.
//! 5. **Choose shapes** (`shapes`): the default discrete shape unless another is better by
//!    more than the tie margin; the other one kept as a shape alternative where the data cannot
//!    choose.
//! 6. **Judge** (`judge`) each refit: achieved cost `J`, information criteria
//!    `ΔBIC = N ln(J_after/J_before) + Δk ln N`, `ΔAIC = N ln(J_after/J_before) + 2 Δk`
//!    (Gaussian errors with unknown variance; `Δk` extra parameters, 2 for strain thinning),
//!    whether the strength is credible ([`StrengthStatus::Physical`]: a best strength at a
//!    search bound or outside the physical range is reported as such and never named).
//! 7. **Rank** (`rank_order`): credible refits by `ΔBIC`, then the others. A candidate earns
//!    its place when `ΔBIC` is below [`DiagnoseOptions::earn_threshold`] (−10: "very strong"
//!    evidence on the Kass–Raftery scale) and its strength is credible.
//!    The false-alarm probability of each refit (`linear::calibrate`: how often the search over all
//!    candidates and shapes finds an effect at least that convincing on effect-free data like
//!    the user's) must be at most [`DiagnoseOptions::max_false_alarm`] (5 %), and the effect
//!    must remove at least half the excess misfit ([`verdict`]).
//! 8. **Ties** ([`ties`](super::ties)): other candidates that earn their place with a `ΔBIC`
//!    less than [`DiagnoseOptions::tie_margin`] (6) above the named one's, and pairs whose
//!    orthogonalised signatures have `|cos|` above
//!    [`DiagnoseOptions::indistinguishable_cosine`] (0.9).
//! 9. **Several effects** (`step`): while a named effect does not bring the residuals to the
//!    noise, it is added to the model (strength and shapes fitted jointly with the law) and the
//!    search runs again over the remaining candidates, at most
//!    [`DiagnoseOptions::max_effects`] effects in all. Then, wherever there is something to
//!    explain, every pair of refitted candidates is fitted jointly (`pairs`,
//!    [`PairFound`](super::refits::pair::PairFound)): two effects that hide each other (warm air
//!    heating where radiation cools) each explain little alone, and a third effect can mimic their
//!    sum with a biased law. A pair clearly better by `ΔBIC` (beyond a margin corrected for the
//!    pairs tried) replaces the forward search's result; one within it is reported beside it, and
//!    where the two laws disagree neither is a result.
//! 10. **One strength in every experiment** (`consistency`): a score test of the final fit
//!     against each found effect's strength varying with the conditions that differ between
//!     the experiments (no new fit); an effect that fails is a stand-in for something else.
//!     Where the residuals would otherwise be explained, the verdict is then "none of the
//!     candidates" (with its stand-ins). A further step whose fit fails ends the forward
//!     search there ([`Diagnosis::stopped`]), not the diagnosis.
//! 11. **Verdict** ([`verdict`]): explained by the named effects, adequate, ambiguous (a
//!     candidate within the tie margin, credible or refused only for its strength's range, or
//!     a pair beside the result, with another law: `ambiguity`), or none of the candidates
//!     (which help and how much, where the unexplained residual lies).

mod ambiguity;
mod base;
mod judge;
mod linear;
mod newtonian;
mod pairs;
mod search;
mod shapes;
mod step;
pub(crate) mod verdict;

use super::refits::consistency;
use super::refits::scan::ScanOptions;
use super::ties::DEFAULT_TIE_MARGIN;
use crate::data::noise_summary::NoiseSummary;
use crate::diagnostics::refits::scan::refitted_effect;
use crate::fit::{
    Estimator, FitSummary, FitWarning, Identification, IdentifyOptions, RheometerError, WarningCode,
};
use crate::model::effects::{Effect, EffectSetting, ModelSpec};
use crate::model::setup::ExperimentSet;
use std::time::Instant;
use verdict::{Help, Verdict};

pub use super::diagnosis::{
    Diagnosis, DiagnosisRun, ForwardStep, ResidualProfiles, RobustWeights, StageTimes,
};
pub(crate) use step::MAX_FALSE_ALARM;

/// Options of [`diagnose`].
#[derive(Debug, Clone)]
pub struct DiagnoseOptions {
    /// Fit settings (the estimator is always the principled one).
    pub identify: IdentifyOptions,
    /// The candidates (default: the built-in effects).
    pub candidates: Vec<Effect>,
    /// How many candidates, best linearised score first, get the global search and refits
    /// (default: all of them).
    pub refit_top: usize,
    /// Settings of the global search of each candidate's strength (and shape).
    pub scan: ScanOptions,
    /// `|cos|` of orthogonalised signatures above which two candidates are indistinguishable
    /// (default 0.9).
    pub indistinguishable_cosine: f64,
    /// `ΔBIC` a candidate must beat to earn its place (default −10).
    pub earn_threshold: f64,
    /// `ΔBIC` gap to the named cause below which another candidate that earns its place is
    /// listed as an alternative (default 6: `ΔBIC ≈ −2 ln B`, and a Bayes factor below
    /// `e³ ≈ 20` is less than "strong" evidence on the Kass–Raftery scale, so the data do not
    /// clearly prefer the named cause; see `ties`).
    pub tie_margin: f64,
    /// Start `(n, κ)` of the user's Carreau fit (default: the paper's start heuristic).
    pub start: Option<[f64; 2]>,
    /// Start values of the user's fitted effects: strengths by effect name, shapes by
    /// model-parameter name, e.g. a previous fit's (`diagnose --from`). The user's fit from
    /// them is kept where it ends lower than the nested fit, which starts them at neutral
    /// strength (default: none).
    pub start_strengths: Vec<(String, f64)>,
    /// Largest false-alarm probability of the search at which an effect is named (default
    /// 0.05; see `calibrate`).
    pub max_false_alarm: f64,
    /// Replicates of the look-elsewhere calibration (default 2000).
    pub calibration_replicates: usize,
    /// Most effects the forward search adds (default 2).
    pub max_effects: usize,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        DiagnoseOptions {
            identify: IdentifyOptions::with_estimator(Estimator::Principled),
            candidates: Effect::builtin(),
            refit_top: usize::MAX,
            scan: ScanOptions::default(),
            indistinguishable_cosine: 0.9,
            earn_threshold: -10.0,
            tie_margin: DEFAULT_TIE_MARGIN,
            start: None,
            start_strengths: Vec::new(),
            max_false_alarm: MAX_FALSE_ALARM,
            calibration_replicates: linear::calibrate::DEFAULT_REPLICATES,
            max_effects: 2,
        }
    }
}

/// Diagnoses which candidate effects are missing from the model `base_spec` on the data `set`:
/// the stages of the module documentation on the user's model, then — while an effect is
/// named but does not bring the residuals to the noise — the same with the effects found so
/// far added to the model and refitted jointly (at most [`DiagnoseOptions::max_effects`]), and
/// the verdict.
pub fn diagnose(
    set: &ExperimentSet,
    base_spec: &ModelSpec,
    options: &DiagnoseOptions,
) -> Result<DiagnosisRun, RheometerError> {
    let t0 = Instant::now();
    let first = step::run(set, base_spec, options, None)?;
    let mut steps = vec![first];
    let mut stopped = None;
    while steps.len() < options.max_effects.max(1) {
        let Some(last) = steps.last() else { break };
        let Some((variant, refit)) = &last.named_refit else {
            break;
        };
        if verdict::explained(&refit.summary, &steps[0].base.summary.noise) {
            break;
        }
        let mut spec = last.spec.clone();
        spec.candidates.clear();
        // the effect its refit fitted: the fitted shapes free again (the variant fixes them at
        // the grid's values), the discrete ones at the variant's
        let effect = match options.candidates.iter().find(|c| c.id() == variant.id()) {
            Some(c) => refitted_effect(c, variant).map_err(RheometerError::Data)?,
            None => variant.clone(),
        };
        let spec = spec.with(EffectSetting::fitted(effect));
        let mut opts = options.clone();
        opts.candidates
            .retain(|c| !spec.effects.iter().any(|e| e.effect.id() == c.id()));
        if opts.candidates.is_empty() {
            break;
        }
        opts.start = Some(refit.law());
        // the refit it starts from was weighted by the previous step's noise weights: the same
        // weights keep its optimum (unweighted, the outliers and the noisier take-up points
        // would pull the law away before this step's own noise model could weight them)
        opts.identify.noise_factors = last.opts.noise_factors.clone();
        // a further step that fails (its fit of the model with the effects found so far cannot
        // be evaluated) ends the search with what the steps before found, and says why
        match step::run(set, &spec, &opts, Some(refit)) {
            Ok(next) => steps.push(next),
            Err(e) => {
                let with: Vec<&str> = spec.effects.iter().map(|e| e.effect.name()).collect();
                stopped = Some(format!(
                    "step {} (with {} in the model) could not be run: {e}",
                    steps.len() + 1,
                    with.join(" + ")
                ));
                break;
            }
        }
    }
    // two effects that hide each other: every pair fitted jointly, as a challenge to what the
    // steps found, wherever there is something to explain
    let mut times = StageTimes::default();
    for s in &steps {
        times.add(&s.times);
    }
    let t_pairs = Instant::now();
    let pair = if options.max_effects >= 2 && something_to_explain(&steps) {
        let (dbic, fit) = steps_result(&steps);
        let settled = settled_effects(set, &steps);
        pairs::search(set, base_spec, options, &steps[0], &settled).and_then(|(p, id)| {
            crate::diagnostics::refits::pair::against_steps(
                p,
                dbic,
                fit,
                options.tie_margin,
                &id.summary,
            )
            .map(|p| (p, id))
        })
    } else {
        None
    };
    times.pairs_s = t_pairs.elapsed().as_secs_f64();
    let (spec0, opts0) = (steps[0].spec.clone(), steps[0].opts.clone());
    let mut run = assemble(set, steps, pair, options, t0);
    newtonian::newtonian_law(set, &spec0, &opts0, &mut run);
    run.diagnosis.stopped = stopped;
    times.rest_s = (run.diagnosis.wall_time_s - times.steps_s() - times.pairs_s).max(0.0);
    run.diagnosis.stage_times = times;
    Ok(run)
}

/// `profiles` (positions and residuals per experiment) without the points the noise model of
/// their fit flags as gross outliers (the report lists those on their own).
fn without_outliers(
    profiles: &[(Vec<f64>, Vec<f64>)],
    noise: &crate::data::noise_summary::NoiseSummary,
) -> Vec<(Vec<f64>, Vec<f64>)> {
    profiles
        .iter()
        .enumerate()
        .map(|(k, (s, r))| {
            s.iter()
                .zip(r)
                .enumerate()
                .filter(|(i, _)| !noise.is_outlier(k, *i))
                .map(|(_, (s, r))| (*s, *r))
                .unzip()
        })
        .collect()
}

/// The effects the forward search found where they settle the diagnosis: their joint fit
/// brings the residuals to the noise and each has one strength in every experiment (the
/// consistency test of stage 10). A pair that adds an effect to settled ones is not fitted
/// (parsimony); a result whose effect is a stand-in settles nothing, so every pair challenges
/// it (radiation under warm air: the warm air alone reached the noise as a stand-in, and
/// warm air with radiation, the truth, was never fitted).
fn settled_effects(set: &ExperimentSet, steps: &[step::Step]) -> Vec<String> {
    let Some(id) = final_refit(steps) else {
        return Vec::new();
    };
    let noise = &steps[0].base.summary.noise;
    if !verdict::explained(&id.summary, noise) {
        return Vec::new();
    }
    let found = found_effects(steps);
    if consistency::check(id, &found, set)
        .iter()
        .any(|c| !c.consistent())
    {
        return Vec::new();
    }
    found
}

/// The effects the steps named, in the order found.
fn found_effects(steps: &[step::Step]) -> Vec<String> {
    steps
        .iter()
        .filter_map(|s| s.named_candidate().map(|c| c.effect.clone()))
        .collect()
}

/// The steps' final fit: the last named refit (all found effects, fitted jointly), if any.
fn final_refit(steps: &[step::Step]) -> Option<&Identification> {
    steps
        .iter()
        .rev()
        .find_map(|s| s.named_refit.as_ref().map(|(_, id)| id))
}

/// Whether the user's residuals are systematic or an effect was named.
fn something_to_explain(steps: &[step::Step]) -> bool {
    steps
        .first()
        .is_some_and(|f| f.systematic || steps.iter().any(|s| s.named.is_some()))
}

/// `ΔBIC` against the user's model of the steps' final fit (all effects found), and that fit
/// (`0` and `None` when nothing was found).
fn steps_result(steps: &[step::Step]) -> (f64, Option<&crate::fit::FitSummary>) {
    let Some(first) = steps.first() else {
        return (0.0, None);
    };
    let Some(fit) = final_refit(steps) else {
        return (0.0, None);
    };
    let k: usize = steps
        .iter()
        .filter_map(|s| s.named_candidate().map(|c| c.extra_parameters))
        .sum();
    let n = first.base.fit.num_residuals() as f64;
    let dbic = crate::diagnostics::refits::pair::delta_bic(
        n,
        first.base.summary.cost,
        fit.summary.cost,
        k,
    );
    (dbic, Some(&fit.summary))
}

/// The diagnosis of the steps: the first step's records, the further steps', the effects
/// found, the final fit and the verdict.
fn assemble(
    set: &ExperimentSet,
    mut steps: Vec<step::Step>,
    pair: Option<(crate::diagnostics::refits::pair::PairFound, Identification)>,
    options: &DiagnoseOptions,
    t0: Instant,
) -> DiagnosisRun {
    let noise = steps[0].base.summary.noise.clone();
    let mut found = found_effects(&steps);
    let mut final_id: Option<Identification> = final_refit(&steps).cloned();
    let mut fit_options = steps.last().map(|s| s.opts.clone()).unwrap_or_default();
    let mut result_dbic = steps_result(&steps).0;
    // a pair found by the joint search replaces what the steps found when clearly better
    let pair = pair.map(|(p, id)| {
        if p.replaces {
            found = p.effects.to_vec();
            final_id = Some(id);
            fit_options = steps[0].opts.clone();
            result_dbic = p.delta_bic;
        }
        p
    });
    let first = steps.remove(0);
    // one strength for every experiment, or a stand-in for something else
    let consistency = final_id
        .as_ref()
        .map(|id| consistency::check(id, &found, set))
        .unwrap_or_default();
    let stand_ins: Vec<consistency::Consistency> = consistency
        .iter()
        .filter(|c| !c.consistent())
        .cloned()
        .collect();
    let mut verdict = verdict_of(&first, &found, final_id.as_ref(), &noise, stand_ins);
    let mut final_fit = final_id.as_ref().map(|id| id.summary.clone());
    let mut base_fit = first.base.summary.clone();
    // explanations the data cannot tell apart from the result that disagree on its law
    if let Some(f) = final_fit.as_mut() {
        verdict = flag_ambiguity(
            verdict,
            f,
            &first,
            &found,
            result_dbic,
            pair.as_ref(),
            options,
        );
    }
    warn_biased_law(&verdict, final_fit.as_mut(), &mut base_fit);
    let further = forward_steps(&steps);
    let residuals_before = linear::signature::named_residuals(&first.base);
    let residuals_after = final_id.as_ref().map(linear::signature::named_residuals);
    DiagnosisRun {
        diagnosis: Diagnosis {
            model: first.spec.law,
            base_fit,
            robust: first.weights.clone(),
            // a physical effect that explains part of the residuals significantly shows they
            // are systematic, even where the noise level is too uncertain for the RMS test
            systematic: first.systematic || first.named.is_some(),
            most_likely_missing: first.named_candidate().map(|c| c.effect.clone()),
            candidates: first.candidates,
            indistinguishable: first.indistinguishable,
            alternatives: first.alternatives,
            detection: first.detection,
            calibration: first.calibration,
            further_steps: further,
            found,
            pair,
            final_fit,
            consistency,
            stopped: None,
            verdict,
            wall_time_s: t0.elapsed().as_secs_f64(),
            stage_times: StageTimes::default(),
        },
        residuals_before,
        residuals_after,
        base: first.base,
        best: final_id,
        fit_options,
    }
}

/// The verdict with the explanations the data cannot tell apart from the result `f` that
/// disagree on its law (a warning on `f` too, where there are any).
fn flag_ambiguity(
    verdict: Verdict,
    f: &mut FitSummary,
    first: &step::Step,
    found: &[String],
    result_dbic: f64,
    pair: Option<&crate::diagnostics::refits::pair::PairFound>,
    options: &DiagnoseOptions,
) -> Verdict {
    let rivals =
        ambiguity::disagreeing_rivals(&first.candidates, found, f, result_dbic, pair, options);
    if rivals.is_empty() {
        return verdict;
    }
    let w = ambiguity::warning(f, &rivals);
    let verdict = ambiguity::verdict(verdict, f, &rivals);
    f.warnings.push(w);
    verdict
}

/// Under "none of the candidates", the warning on the final fit and on the user's fit
/// `base_fit` that the law of a model that does not describe the data is not a result.
fn warn_biased_law(
    verdict: &Verdict,
    final_fit: Option<&mut FitSummary>,
    base_fit: &mut FitSummary,
) {
    if let Verdict::NoneOfTheCandidates {
        rms_over_noise,
        stand_ins,
        ..
    } = verdict
    {
        // the law of a model that does not describe the data is biased by what it misses
        let w = match stand_ins.first() {
            Some(c) => consistency::warning(c),
            None => FitWarning::new(
                WarningCode::Implausible,
                format!(
                    "none of the candidate effects brings the residuals to the noise (RMS/noise \
                     {rms_over_noise:.2} with the best of them): the material law (n, kappa) of \
                     this model is biased by the missing effect and is not a result"
                ),
            ),
        };
        for s in final_fit.into_iter().chain(std::iter::once(base_fit)) {
            s.warnings.push(w.clone());
        }
    }
}

/// The records of the further steps `steps` (the first one removed).
fn forward_steps(steps: &[step::Step]) -> Vec<ForwardStep> {
    steps
        .iter()
        .map(|s| ForwardStep {
            model_effects: s
                .spec
                .effects
                .iter()
                .map(|e| e.effect.name().to_string())
                .collect(),
            base_fit: s.base.summary.clone(),
            candidates: s.candidates.clone(),
            named: s.named_candidate().map(|c| c.effect.clone()),
        })
        .collect()
}

/// The verdict of the steps (see [`verdict`]).
fn verdict_of(
    first: &step::Step,
    found: &[String],
    final_id: Option<&Identification>,
    noise: &NoiseSummary,
    stand_ins: Vec<consistency::Consistency>,
) -> Verdict {
    let fit = final_id.unwrap_or(&first.base);
    let noise = &verdict::noise_for(&fit.summary, noise);
    let (ratio, _) = verdict::at_noise(&fit.summary, noise);
    let at_noise = !found.is_empty() && verdict::explained(&fit.summary, noise);
    if at_noise && stand_ins.is_empty() {
        return Verdict::Explained {
            effects: found.to_vec(),
            rms_over_noise: ratio,
            noise_level: noise.level,
        };
    }
    if found.is_empty() && !first.systematic {
        return Verdict::Adequate;
    }
    let mut helps: Vec<Help> = first
        .candidates
        .iter()
        .filter(|c| c.refitted() && c.delta_bic < 0.0 && c.share_of_excess > 0.05)
        .map(|c| Help {
            effect: c.effect.clone(),
            share_of_excess: c.share_of_excess,
            delta_bic: c.delta_bic,
        })
        .collect();
    helps.sort_by(|a, b| b.share_of_excess.total_cmp(&a.share_of_excess));
    Verdict::NoneOfTheCandidates {
        helps,
        unexplained: verdict::unexplained(
            &without_outliers(&fit.residual_profiles, &fit.summary.noise),
            &fit.summary.experiments,
            noise.level,
        ),
        rms_over_noise: ratio,
        noise_level: noise.level,
        // effects that would explain the data but for their varying strength
        stand_ins: if at_noise { stand_ins } else { Vec::new() },
    }
}

//! One step of the search: the chain of stages on one model (the user's, or the user's with
//! the effects found so far), ending in the ranked candidates and the one it names.

use super::base::Context;
use super::linear::calibrate::{calibrate, Calibration, NullNoise};
use super::linear::linearise::{self, Linearisation};
use super::linear::signature;
use super::search;
use super::shapes;
use super::verdict::{
    noise_cost, share_of_excess, EXPLAINED_RMS_OVER_NOISE, MIN_SHARE_OF_EXCESS, STRUCTURE_Z,
};
use super::{judge, DiagnoseOptions};
use crate::diagnostics::candidate::{earns_its_place, rank_order, Candidate, Indistinguishable};
use crate::diagnostics::detection::{detection_limits, DetectionContext, DetectionLimits};
use crate::diagnostics::diagnosis::{RobustWeights, StageTimes};
use crate::diagnostics::scores::cosine;
use crate::diagnostics::ties::{alternatives_among, Alternative};
use crate::fit::{Estimate, Identification, IdentifyOptions, ParameterShift, RheometerError};
use crate::model::effects::{Effect, ModelSpec};
use crate::model::setup::ExperimentSet;
use std::time::Instant;

/// Largest false-alarm probability of the search at which an effect may be named.
pub const MAX_FALSE_ALARM: f64 = 0.05;

/// The outcome of one step.
pub(crate) struct Step {
    /// The step's model (the user's, plus the effects found before).
    pub spec: ModelSpec,
    /// Its fit.
    pub base: Identification,
    /// The candidates, best first.
    pub candidates: Vec<Candidate>,
    /// The named candidate's index in `candidates`.
    pub named: Option<usize>,
    /// The named candidate's refit and the variant (shape) it belongs to.
    pub named_refit: Option<(Effect, Identification)>,
    /// Candidates tied with the named one.
    pub alternatives: Vec<Alternative>,
    /// Pairs with nearly parallel signatures.
    pub indistinguishable: Vec<Indistinguishable>,
    /// Detection limits at this step.
    pub detection: DetectionLimits,
    /// The look-elsewhere calibration at this step.
    pub calibration: Calibration,
    /// Whether the residuals are systematic: by the noise test, or shown by a candidate that
    /// lowers `BIC` beyond the threshold (`reveals_misfit`).
    pub systematic: bool,
    /// The fit settings of this step (the noise weights included).
    pub opts: IdentifyOptions,
    /// How the robust loss weighted the points at this step (`None`: least squares).
    pub weights: Option<RobustWeights>,
    /// The step's stage times (fits, linearisation, scans, refits).
    pub times: StageTimes,
}

impl Step {
    /// The named candidate's record.
    pub fn named_candidate(&self) -> Option<&Candidate> {
        self.named.map(|i| &self.candidates[i])
    }
}

/// Runs the stages on `spec` (the candidates of `options`), starting from `warm` (a previous
/// step's refit with the effects found so far) if given.
pub(crate) fn run(
    set: &ExperimentSet,
    spec: &ModelSpec,
    options: &DiagnoseOptions,
    warm: Option<&Identification>,
) -> Result<Step, RheometerError> {
    let mut times = StageTimes::default();
    let t0 = Instant::now();
    let mut ctx = Context::new(set, spec, options)?;
    let base = ctx.fit_base(warm)?;
    let base = ctx.weighted_base(base)?;
    let ctx = ctx;
    times.fits_s = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let lin = linearise::linearise(&ctx, &base)?;
    let systematic = residuals_systematic(&base);
    let mut records = linearise::linear_candidates(&ctx, &lin);
    let detection = limits(&ctx, &lin, &base, &records);
    let sd = residual_noise(&ctx, &base);
    let j_noise = noise_cost(&sd, lin.q);
    let mut columns: Vec<(usize, Vec<f64>)> = ctx
        .cands
        .iter()
        .zip(&lin.cols)
        .map(|(e, c)| (e.extra_parameters(), c.clone()))
        .collect();
    columns.extend(linearise::shape_columns(&ctx, &base, &lin)?);
    let segments: Vec<usize> = ctx
        .rh
        .measurements
        .iter()
        .map(|m| m.positions.len())
        .collect();
    let null_noise = NullNoise {
        sd: &sd,
        correlation: base
            .summary
            .noise
            .model
            .as_ref()
            .map_or(0.0, |m| m.calibration_correlation()),
        segments: &segments,
    };
    let calibration = calibrate(
        &lin,
        &columns,
        &null_noise,
        options.calibration_replicates,
        0x5EED_D1A6,
    );
    times.linearised_s = t0.elapsed().as_secs_f64();
    let mut refits = search_and_judge(&ctx, &lin, &base, &mut records, &mut times);
    for r in records.iter_mut() {
        r.false_alarm = calibration.false_alarm(r.delta_bic);
        r.share_of_excess = share_of_excess(lin.cost_before, r.cost_after, j_noise);
    }
    let mut order: Vec<usize> = (0..records.len()).collect();
    order.sort_by(|&a, &b| rank_order(&records[a], &records[b]));
    // the share rule applies where the noise test finds an excess misfit at all
    let excess = systematic;
    let systematic = systematic || records.iter().any(|r| reveals_misfit(r, options));
    let named_orig = order
        .iter()
        .copied()
        .find(|&i| names(&records[i], options, excess));
    let alternatives = ties(&ctx, &lin, &records, named_orig);
    let indistinguishable = indistinguishable(&ctx, &lin);
    let named_refit = named_orig.and_then(|i| {
        let pos = refits.iter().position(|(j, _, _)| *j == i)?;
        let (_, variant, id) = refits.swap_remove(pos);
        Some((variant, id))
    });
    let candidates: Vec<Candidate> = order.iter().map(|&i| records[i].clone()).collect();
    let named = named_orig.and_then(|i| order.iter().position(|&j| j == i));
    Ok(Step {
        spec: ctx.spec.clone(),
        base,
        candidates,
        named,
        named_refit,
        alternatives,
        indistinguishable,
        detection,
        calibration,
        systematic,
        opts: ctx.opts.clone(),
        weights: ctx.weights.clone(),
        times,
    })
}

/// Whether a candidate may be named: it earns its place (credible strength and law, `ΔBIC`
/// below the threshold), the search over all candidates would produce such an effect on
/// effect-free data in at most [`MAX_FALSE_ALARM`] of cases, and — where the noise test finds
/// an excess misfit (`excess`) — it removes at least half of it (without a significant excess
/// the share is noise over noise).
fn names(c: &Candidate, options: &DiagnoseOptions, excess: bool) -> bool {
    earns_its_place(c, options.earn_threshold)
        && c.false_alarm.partial_cmp(&options.max_false_alarm) != Some(std::cmp::Ordering::Greater)
        && (!excess || c.share_of_excess >= MIN_SHARE_OF_EXCESS)
}

/// Whether the candidate `c` shows that the user's model misses something, whatever the
/// noise test says: its refit lowers `BIC` below the naming threshold, the search would find
/// such an effect on effect-free data in at most [`DiagnoseOptions::max_false_alarm`] of
/// cases, and its fit is no implausible law (its strength may lie outside its physical range
/// or at a bound, its shape at a bound: it is then not named, but the misfit it removes is
/// real). The noise test alone can miss such a misfit where the noise level is estimated from
/// the residuals: with few experiments a misfit that is smooth along the line can pass for
/// noise correlated along it, and the model would be called adequate with a law biased by the
/// missing effect.
fn reveals_misfit(c: &Candidate, options: &DiagnoseOptions) -> bool {
    c.refitted()
        && c.status.fit_is_evidence()
        && c.delta_bic < options.earn_threshold
        && c.false_alarm <= options.max_false_alarm
}

/// Stage 3: whether the user's residuals are systematic by the noise test (RMS over the noise
/// level above [`EXPLAINED_RMS_OVER_NOISE`], widened for noise correlated along the line, or
/// the lag-1 structure above [`STRUCTURE_Z`]; see
/// [`NoiseModel`](crate::data::noise_model::NoiseModel)).
fn residuals_systematic(base: &Identification) -> bool {
    let noise = &base.summary.noise;
    let m = noise.model.as_ref();
    let lag1_z = m.map_or(0.0, |m| m.lag1_z);
    let limit = m.map_or(EXPLAINED_RMS_OVER_NOISE, |m| {
        m.misfit_ratio_limit(EXPLAINED_RMS_OVER_NOISE)
    });
    noise.rms_over_noise > limit || lag1_z > STRUCTURE_Z
}

/// Each residual's noise level in the fit's residual units: the point's relative noise level
/// (the noise model's, or the declared one) over its weight `σ_j` in the fit.
fn residual_noise(ctx: &Context<'_>, base: &Identification) -> Vec<f64> {
    let noise = &base.summary.noise;
    let mut sd = Vec::new();
    for (k, meas) in ctx.rh.measurements.iter().enumerate() {
        let w = ctx.opts.point_sigmas(k, meas.positions.len(), ctx.sigma);
        for (i, &s) in meas.positions.iter().enumerate() {
            sd.push(noise.sigma_at(k, s) / w[i]);
        }
    }
    sd
}

/// Stage 3 (cont.): detection limits linearised at strength 0 and the bias an undetected
/// effect causes (without a determined fit — singular `JᵀJ` — the limits come without the
/// shifts).
fn limits(
    ctx: &Context<'_>,
    lin: &Linearisation,
    base: &Identification,
    records: &[Candidate],
) -> DetectionLimits {
    let dtheta: Vec<Vec<f64>> = match ParameterShift::new(&lin.x, lin.residuals(), lin.q) {
        Ok(shift) => lin
            .cols
            .iter()
            .map(|c| {
                shift
                    .derivative(&nalgebra::DVector::from_column_slice(c))
                    .iter()
                    .copied()
                    .collect()
            })
            .collect(),
        Err(_) => Vec::new(),
    };
    let extra: Vec<usize> = records.iter().map(|c| c.extra_parameters).collect();
    let s = &base.summary;
    let se = |e: &Estimate| if e.fitted { e.stderr } else { f64::NAN };
    detection_limits(
        &ctx.cands,
        &extra,
        &lin.scores,
        &dtheta,
        (ctx.column("n"), ctx.column("kappa")),
        &DetectionContext {
            sigma: s.noise.level / ctx.sigma,
            noise_level: s.noise.level,
            long_run_factor: s.noise.variance_inflation().sqrt(),
            cost_before: lin.cost_before,
            measurements: lin.residuals(),
            threshold: ctx.options.earn_threshold,
            stderr_n: se(&s.n),
            stderr_kappa: se(&s.kappa),
            shifts_withheld: (s.bound_of("n").is_some() || s.bound_of("kappa").is_some())
                .then_some(
                    "your fit's n or kappa is at a bound of its range, where the fit's \
                     linearisation does not hold and its standard errors are not valid",
                ),
        },
    )
}

/// Stages 4–6: search (scan and refine), choose shapes, judge; the refits' identifications
/// with their variants, by candidate.
fn search_and_judge(
    ctx: &Context<'_>,
    lin: &Linearisation,
    base: &Identification,
    records: &mut [Candidate],
    times: &mut StageTimes,
) -> Vec<(usize, Effect, Identification)> {
    let t0 = Instant::now();
    let searched = search::searched(ctx, lin);
    let scans = search::scan_all(ctx, base, lin, &searched, records);
    times.scans_s = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let refined = search::refine_all(ctx, base, lin, &scans, &searched, records);
    times.refits_s = t0.elapsed().as_secs_f64();
    count_starts(&refined, records);
    let extra: Vec<usize> = records.iter().map(|c| c.extra_parameters).collect();
    let choices = shapes::choose_shapes(ctx, lin, &scans, refined, &extra);
    let before = signature::named_residuals(base);
    let mut refits = Vec::new();
    for (i, (chosen, other)) in choices.into_iter().enumerate() {
        if let Some(choice) = chosen {
            let variant = choice.0.clone();
            let id = judge::judge(lin, &base.summary, &before, &mut records[i], choice, other);
            refits.push((i, variant, id));
        }
    }
    refits
}

/// Per candidate, how many refinements ran and how many reached its best cost (within 1e-4 of
/// it): a best reached from one start only is a warning sign of a rugged landscape.
fn count_starts(refined: &[search::Refined], records: &mut [Candidate]) {
    for (i, r) in records.iter_mut().enumerate() {
        let costs: Vec<f64> = refined
            .iter()
            .filter(|x| x.candidate == i)
            .map(|x| x.refit.cost)
            .collect();
        let best = costs.iter().copied().fold(f64::INFINITY, f64::min);
        let at_best = costs.iter().filter(|&&c| c <= best * (1.0 + 1e-4)).count();
        r.refit_starts = [costs.len(), at_best];
    }
}

/// Stage 8: the candidates tied with the named one.
fn ties(
    ctx: &Context<'_>,
    lin: &Linearisation,
    records: &[Candidate],
    named: Option<usize>,
) -> Vec<Alternative> {
    let Some(b) = named else {
        return Vec::new();
    };
    let mut ranked: Vec<Candidate> = records.to_vec();
    ranked.sort_by(rank_order);
    alternatives_among(
        &records[b],
        &ranked,
        ctx.options.earn_threshold,
        ctx.options.tie_margin,
        &ctx.cands,
        |name| match Effect::position(&ctx.cands, name) {
            Some(i) => cosine(&lin.scores[b].signature, &lin.scores[i].signature),
            None => f64::NAN,
        },
    )
}

/// Stage 8 (cont.): pairs of candidates with nearly parallel orthogonalised signatures.
fn indistinguishable(ctx: &Context<'_>, lin: &Linearisation) -> Vec<Indistinguishable> {
    let mut out = Vec::new();
    for a in 0..ctx.cands.len() {
        for b in a + 1..ctx.cands.len() {
            let c = cosine(&lin.scores[a].signature, &lin.scores[b].signature);
            if c.abs() > ctx.options.indistinguishable_cosine {
                out.push(Indistinguishable {
                    effects: [
                        ctx.cands[a].name().to_string(),
                        ctx.cands[b].name().to_string(),
                    ],
                    cosine: c,
                });
            }
        }
    }
    out
}

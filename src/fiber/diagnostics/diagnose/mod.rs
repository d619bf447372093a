//! `diagnose`: which physical effect is missing from a user's model — a chain of stages, each
//! in its own file, passing one record per candidate ([`Candidate`]) along.
//!
//! 1. **Fit the user's model** ([`base`]) with the principled estimator (raw relative residuals,
//!    take-up diameters fitted): the paper's smoothed-data estimator leaves residuals ~1.4× the
//!    noise even for a correct model, which would mask missing physics. The candidates are
//!    carried in the model at neutral strength (which reproduces the user's model exactly).
//! 2. **Linearise** ([`linearise`]): each candidate's exact sensitivity direction at the fit
//!    (one sensitivity solve per experiment, reusing the factorisation of the last Newton step,
//!    gives all of them), orthogonalised against the fitted parameters' directions; its
//!    projection of the residual is the cost it would remove to first order
//!    ([`scores`](super::scores)).
//! 3. **Test the noise**: are the residuals systematic? The RMS relative residual against the
//!    fit's one noise level (declared, else the noise model's estimate, outliers excluded) and
//!    the lag-1 autocorrelation of the residuals along each spin line (white noise:
//!    `ρ₁ √N ≈ N(0, 1)`); a candidate that earns its place (stage 6) also marks them
//!    systematic (the RMS test is weak when the noise is estimated). The detection limits of
//!    every candidate ([`detection`](super::detection)) come from the same linearisation.
//! 4. **Search** ([`search`]) every candidate globally, in parallel: its strength scanned over
//!    its search range (and, for effects with a shape, a few shapes), each grid point a
//!    warm-started refit of the material parameters with the strength fixed; the best grid
//!    points refined with the strength freed.
//! 5. **Choose shapes** ([`shapes`]): the default discrete shape unless another is better by
//!    more than the tie margin; the other one kept as a shape alternative where the data cannot
//!    choose.
//! 6. **Judge** ([`judge`]) each refit: achieved cost `J`, information criteria
//!    `ΔBIC = N ln(J_after/J_before) + Δk ln N`, `ΔAIC = N ln(J_after/J_before) + 2 Δk`
//!    (Gaussian errors with unknown variance; `Δk` extra parameters, 2 for strain thinning),
//!    whether the strength is credible ([`StrengthStatus::Physical`]: a best strength at a
//!    search bound or outside the physical range is reported as such and never named).
//! 7. **Rank** ([`rank_order`]): credible refits by `ΔBIC`, then the others. A candidate earns
//!    its place when `ΔBIC` is below [`DiagnoseOptions::earn_threshold`] (−10: "very strong"
//!    evidence on the Kass–Raftery scale) and its strength is credible.
//! 8. **Ties** ([`ties`](super::ties)): other candidates that earn their place with a `ΔBIC`
//!    less than [`DiagnoseOptions::tie_margin`] (6) above the named one's, and pairs whose
//!    orthogonalised signatures have `|cos|` above
//!    [`DiagnoseOptions::indistinguishable_cosine`] (0.9).

mod base;
mod judge;
mod linearise;
mod search;
mod shapes;
mod signature;

use super::detection::{detection_limits, DetectionContext, DetectionLimits};
use super::scan::ScanOptions;
use super::scores::cosine;
use super::ties::{alternatives, Alternative, DEFAULT_TIE_MARGIN};
use crate::fiber::effects::{Category, Effect, ModelSpec};
use crate::fiber::rheometer::{
    Estimator, Identification, IdentifyOptions, ParameterShift, RheometerError,
};
use crate::fiber::setup::ExperimentSet;
use base::Context;
use linearise::Linearisation;
use std::time::Instant;

pub use super::candidate::{
    earns_its_place, rank_order, strength_status, Candidate, Indistinguishable, ShapeAlternative,
    StrengthStatus, PHYSICAL_RANGE_SE,
};
pub use super::diagnosis::{Diagnosis, DiagnosisRun, ResidualProfiles};

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
    /// clearly prefer the named cause; see [`ties`](super::ties)).
    pub tie_margin: f64,
    /// Start `(n, κ)` of the user's Carreau fit (default: the paper's start heuristic).
    pub start: Option<[f64; 2]>,
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
        }
    }
}

/// Diagnoses which candidate effect is missing from the model `base_spec` on the data `set`
/// (the stages of the module documentation).
pub fn diagnose(
    set: &ExperimentSet,
    base_spec: &ModelSpec,
    options: &DiagnoseOptions,
) -> Result<DiagnosisRun, RheometerError> {
    let t0 = Instant::now();
    let ctx = Context::new(set, base_spec, options)?;
    let base = ctx.fit_base()?;
    let lin = linearise::linearise(&ctx, &base)?;
    let noise_systematic = residuals_systematic(&base);
    let mut records = linearise::linear_candidates(&ctx, &lin);
    let detection = limits(&ctx, &lin, &base, &records);
    let refits = search_and_judge(&ctx, &lin, &base, &mut records);
    let mut ranked: Vec<usize> = (0..records.len()).collect();
    ranked.sort_by(|&a, &b| rank_order(&records[a], &records[b]));
    let named = ranked
        .iter()
        .copied()
        .find(|&i| earns_its_place(&records[i], options.earn_threshold));
    let alternatives = ties(&ctx, &lin, &records, named);
    let candidates: Vec<Candidate> = ranked.iter().map(|&i| records[i].clone()).collect();
    let best = named.and_then(|i| refits.into_iter().find(|(j, _)| *j == i).map(|(_, id)| id));
    let residuals_before = signature::named_residuals(&ctx.rh, &base);
    Ok(DiagnosisRun {
        diagnosis: Diagnosis {
            model: ctx.spec.law,
            base_fit: base.summary.clone(),
            // a physical effect that explains part of the residuals significantly shows they
            // are systematic, even where the noise level is too uncertain for the RMS test
            systematic: noise_systematic || named.is_some(),
            candidates,
            indistinguishable: indistinguishable(&ctx, &lin),
            most_likely_missing: named.map(|i| ctx.cands[i].name().to_string()),
            alternatives,
            detection,
            wall_time_s: t0.elapsed().as_secs_f64(),
        },
        residuals_before,
        residuals_after: best
            .as_ref()
            .map(|id| signature::named_residuals(&ctx.rh, id)),
        base,
        best,
    })
}

/// Stage 3: whether the user's residuals are systematic by the noise test (RMS over the noise
/// level above 1.2, or the lag-1 autocorrelation `ρ₁ √pairs` above 3).
fn residuals_systematic(base: &Identification) -> bool {
    let noise = &base.summary.noise;
    let lag1_z = noise.model.as_ref().map_or(0.0, |m| m.lag1_z);
    noise.rms_over_noise > 1.2 || lag1_z > 3.0
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
    let se = |e: &crate::fiber::rheometer::Estimate| if e.fitted { e.stderr } else { f64::NAN };
    detection_limits(
        &ctx.cands,
        &extra,
        &lin.scores,
        &dtheta,
        (ctx.column("n"), ctx.column("kappa")),
        &DetectionContext {
            sigma: s.noise.level / ctx.sigma,
            noise_level: s.noise.level,
            cost_before: lin.cost_before,
            measurements: lin.residuals(),
            threshold: ctx.options.earn_threshold,
            stderr_n: se(&s.n),
            stderr_kappa: se(&s.kappa),
        },
    )
}

/// Stages 4–6: search (scan and refine), choose shapes, judge; the refits' identifications
/// by candidate.
fn search_and_judge(
    ctx: &Context<'_>,
    lin: &Linearisation,
    base: &Identification,
    records: &mut [Candidate],
) -> Vec<(usize, Identification)> {
    let searched = search::searched(ctx, lin);
    let scans = search::scan_all(ctx, base, lin, &searched, records);
    let refined = search::refine_all(ctx, lin, &scans, &searched, records);
    let extra: Vec<usize> = records.iter().map(|c| c.extra_parameters).collect();
    let choices = shapes::choose_shapes(ctx, lin, &scans, refined, &extra);
    let before = signature::named_residuals(&ctx.rh, base);
    let mut refits = Vec::new();
    for (i, (chosen, other)) in choices.into_iter().enumerate() {
        if let Some(choice) = chosen {
            let id = judge::judge(
                ctx,
                lin,
                &base.summary,
                &before,
                &mut records[i],
                choice,
                other,
            );
            refits.push((i, id));
        }
    }
    refits
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
    alternatives(
        &records[b],
        &ranked,
        ctx.options.earn_threshold,
        ctx.options.tie_margin,
        ctx.cands[b].category(),
        |name| match ctx.cands.iter().position(|e| e.name() == name) {
            Some(i) => (
                ctx.cands[i].category(),
                cosine(&lin.scores[b].signature, &lin.scores[i].signature),
            ),
            None => (Category::Physics, f64::NAN),
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

//! `diagnose`: which physical effect is missing from a user's model.
//!
//! 1. **Fit the user's model** with the principled estimator (raw relative residuals, take-up
//!    diameters fitted): the paper's smoothed-data estimator leaves residuals ~1.4× the noise
//!    even for a correct model, which would mask missing physics. The candidates are carried in
//!    the model at neutral strength (which reproduces the user's model exactly).
//! 2. **Are the residuals systematic?** RMS relative residual against the noise level
//!    (`relative_uncertainty` of the data set, else estimated from second differences of the
//!    residuals, which removes smooth misfit) and the lag-1 autocorrelation of the residuals
//!    along each spin line (white noise: `ρ₁ √N ≈ N(0, 1)`); a candidate that earns its place
//!    (step 4) also marks them systematic (the RMS test is weak when the noise is estimated).
//! 3. **Linearised scores** ([`scores`](super::scores)): each candidate's exact sensitivity
//!    direction at the fit (one sensitivity solve per experiment, reusing the factorisation of
//!    the last Newton step, gives all of them), orthogonalised against the fitted parameters'
//!    directions; its projection of the residual is the cost it would remove to first order.
//! 4. **Refits** of the top candidates with their strength freed and the material parameters
//!    refitted (warm-started from the user's fit): the achieved cost `J`, RMS, fitted strength
//!    with standard error, and information criteria
//!    `ΔBIC = N ln(J_after/J_before) + Δk ln N`, `ΔAIC = N ln(J_after/J_before) + 2 Δk`
//!    (Gaussian errors with unknown variance; `Δk` extra parameters, 2 for strain thinning:
//!    `n` and `κ`). A candidate earns its place when `ΔBIC` is below
//!    [`DiagnoseOptions::earn_threshold`] (−10: "very strong" evidence on the Kass–Raftery scale).
//! 5. **Indistinguishable** candidates: cosine of their orthogonalised signatures above
//!    [`DiagnoseOptions::indistinguishable_cosine`] (0.9) in absolute value.

use super::scores::{cosine, linear_scores};
use crate::fiber::effects::{Effect, LawChoice, ModelSpec, STRAIN_THINNING_REFERENCE_KAPPA};
use crate::fiber::rheometer::estimator::RelativeResidual;
use crate::fiber::rheometer::{
    AtBound, Estimator, FitReport, FitStart, Identification, IdentifyOptions, Layout, Rheometer,
    RheometerError,
};
use crate::fiber::setup::ExperimentSet;
use crate::fiber::statistics::{lag1_autocorrelation_about_zero, noise_rms_second_differences};
use crate::fiber::FiberError;
use crate::sensitivity::{residual_jacobian, Sensitivities};
use crate::solution::Solution;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Options of [`diagnose`].
#[derive(Debug, Clone)]
pub struct DiagnoseOptions {
    /// Fit settings (the estimator is always the principled one).
    pub identify: IdentifyOptions,
    /// The candidates (default: the six built-in effects).
    pub candidates: Vec<Effect>,
    /// How many of the best linearised candidates are refitted (default 3).
    pub refit_top: usize,
    /// `|cos|` of orthogonalised signatures above which two candidates are indistinguishable
    /// (default 0.9).
    pub indistinguishable_cosine: f64,
    /// `ΔBIC` a candidate must beat to earn its place (default −10).
    pub earn_threshold: f64,
    /// Start `(n, κ)` of the user's Carreau fit (default: the paper's start heuristic).
    pub start: Option<[f64; 2]>,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        DiagnoseOptions {
            identify: IdentifyOptions::with_estimator(Estimator::Principled),
            candidates: Effect::builtin(),
            refit_top: 3,
            indistinguishable_cosine: 0.9,
            earn_threshold: -10.0,
            start: None,
        }
    }
}

/// One candidate's result (JSON: an entry of `candidates`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CandidateResult {
    /// Canonical name.
    pub effect: String,
    /// Unit of the strength.
    pub unit: String,
    /// Whether the numbers come from a refit (else from the linearisation).
    pub refitted: bool,
    /// Linearised predicted reduction of `J`.
    pub linear_score: f64,
    /// Linearised strength.
    pub linear_strength: f64,
    /// Fitted (or, without refit, linearised) strength.
    pub strength: f64,
    /// Its standard error.
    pub stderr_strength: f64,
    /// `J` of the user's model.
    pub cost_before: f64,
    /// `J` with the effect (refit, or linear prediction).
    pub cost_after: f64,
    /// RMS relative residual with the effect (`NaN` without refit).
    pub rms_relative_residual_after: f64,
    /// Extra parameters.
    pub extra_parameters: usize,
    /// `ΔBIC` (negative: the effect earns its place).
    pub delta_bic: f64,
    /// `ΔAIC`.
    pub delta_aic: f64,
    /// Position \[m\] where the effect changes the residuals most.
    pub signature_peak_m: f64,
    /// Positions \[m\] between which 80% of its effect on the residuals lies (10%–90%).
    pub signature_range_m: [f64; 2],
    /// `(n, κ)` of the refit (`NaN` without refit or for a Newtonian refit).
    pub n: f64,
    /// `κ` of the refit.
    pub kappa: f64,
    /// 95% CI of `n` in the refit.
    pub ci95_n: [f64; 2],
    /// 95% CI of `κ` in the refit.
    pub ci95_kappa: [f64; 2],
    /// Estimates of the refit that ended at a bound of their search range (the strength among
    /// them means the data push the effect beyond its range: not a credible estimate; the
    /// intervals of those estimates are not valid).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub at_bound: Vec<AtBound>,
}

/// A pair of candidates the data cannot tell apart.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Indistinguishable {
    /// The two effects.
    pub effects: [String; 2],
    /// Cosine of their orthogonalised signatures.
    pub cosine: f64,
}

/// The diagnosis (what is written as JSON).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Diagnosis {
    /// The user's law.
    pub model: LawChoice,
    /// The user's fit.
    pub base_fit: FitReport,
    /// Noise level (relative) used for the judgement.
    pub noise_level: f64,
    /// `"data set"` (relative_uncertainty) or `"estimated"` (successive differences).
    pub noise_source: String,
    /// RMS relative residual of the user's fit over the noise level.
    pub rms_over_noise: f64,
    /// Pooled lag-1 autocorrelation of the residuals along the spin lines.
    pub lag1_autocorrelation: f64,
    /// Whether the residuals are systematic: `rms_over_noise > 1.2`, or `ρ₁ √N > 3`, or a
    /// candidate earns its place (its refit lowers BIC below the threshold).
    pub systematic: bool,
    /// The candidates, best first.
    pub candidates: Vec<CandidateResult>,
    /// Pairs of candidates with nearly parallel signatures.
    pub indistinguishable: Vec<Indistinguishable>,
    /// The most likely missing effect, if one earns its place.
    pub most_likely_missing: Option<String>,
    /// Wall time \[s\].
    pub wall_time_s: f64,
}

/// Relative residuals along the spin line, per experiment: `(name, [(s in m, residual)])`.
pub type ResidualProfiles = Vec<(String, Vec<(f64, f64)>)>;

/// A diagnosis with the data for figures.
#[derive(Debug, Clone)]
pub struct DiagnosisRun {
    /// The numbers.
    pub diagnosis: Diagnosis,
    /// Residuals of the user's fit.
    pub residuals_before: ResidualProfiles,
    /// Residuals after adding the best refitted candidate.
    pub residuals_after: Option<ResidualProfiles>,
    /// The user's fit.
    pub base: Identification,
    /// The refit with the best candidate.
    pub best: Option<Identification>,
}

fn residual_profiles(rh: &Rheometer, sols: &[Solution]) -> ResidualProfiles {
    sols.iter()
        .enumerate()
        .map(|(k, s)| {
            let r = rh.relative_residuals(k, s);
            (
                rh.experiments[k].name.clone(),
                rh.measurements[k]
                    .positions
                    .iter()
                    .copied()
                    .zip(r)
                    .collect(),
            )
        })
        .collect()
}

/// The residuals of each profile (without positions), for [`statistics`](crate::fiber::statistics).
fn residual_sequences(profiles: &ResidualProfiles) -> Vec<Vec<f64>> {
    profiles
        .iter()
        .map(|(_, p)| p.iter().map(|v| v.1).collect())
        .collect()
}

/// Where along `s` a residual change lies: the position of the largest pooled change and the
/// 10%–90% range of its cumulative weight.
fn signature_location(positions: &[f64], change: &[f64]) -> (f64, [f64; 2]) {
    let mut pts: Vec<(f64, f64)> = positions
        .iter()
        .zip(change)
        .map(|(&s, &d)| (s, d * d))
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    // pool equal positions
    let mut pooled: Vec<(f64, f64)> = Vec::new();
    for (s, w) in pts {
        match pooled.last_mut() {
            Some(l) if (l.0 - s).abs() < 1e-9 => l.1 += w,
            _ => pooled.push((s, w)),
        }
    }
    let total: f64 = pooled.iter().map(|p| p.1).sum();
    if pooled.is_empty() || total <= 0.0 {
        return (f64::NAN, [f64::NAN, f64::NAN]);
    }
    let peak = pooled
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(f64::NAN, |p| p.0);
    let (mut acc, mut lo, mut hi) = (0.0, f64::NAN, f64::NAN);
    for &(s, w) in &pooled {
        acc += w;
        if lo.is_nan() && acc >= 0.1 * total {
            lo = s;
        }
        if hi.is_nan() && acc >= 0.9 * total {
            hi = s;
        }
    }
    (peak, [lo, hi])
}

fn sim_err(rh: &Rheometer, k: usize, source: FiberError) -> RheometerError {
    RheometerError::Simulation {
        experiment: rh.experiments[k].name.clone(),
        n: f64::NAN,
        kappa: f64::NAN,
        source,
    }
}

/// `(r, X (row-major), columns of X, candidate columns)`.
type Linearisation = (Vec<f64>, Vec<f64>, usize, Vec<Vec<f64>>);

/// Residuals, the fitted parameters' Jacobian and the candidates' columns at the user's fit.
fn linearisation(
    rh: &Rheometer,
    layout: &Layout,
    base: &Identification,
    cands: &[Effect],
    sigma: f64,
) -> Result<Linearisation, RheometerError> {
    let m = rh.len();
    let ns = layout.num_shared();
    let q = ns + m;
    let cand_idx: Vec<(usize, f64)> = cands
        .iter()
        .map(|e| {
            rh.models[0]
                .param_index(e.model_param())
                .map(|i| (i, e.param_per_strength()))
                .ok_or_else(|| {
                    RheometerError::Data(format!("the model has no parameter for {}", e.name()))
                })
        })
        .collect::<Result<_, _>>()?;
    let parts: Vec<(Vec<f64>, Vec<f64>, usize)> = (0..m)
        .into_par_iter()
        .map(|k| {
            let model = &rh.models[k];
            let sol = &base.solutions[k];
            let lo = model.scaling.reference.length;
            let dd = model.scaling.diameter();
            let meas = &rh.measurements[k];
            let xs: Vec<f64> = meas.positions.iter().map(|v| v / lo).collect();
            let d: Vec<f64> = meas.diameters.iter().map(|v| v / dd).collect();
            let sens = Sensitivities::compute(model, sol)
                .map_err(|e| sim_err(rh, k, FiberError::from(e)))?;
            let g = RelativeResidual {
                model,
                d_meas: &d,
                sigma,
            };
            let (r, jl) = residual_jacobian(model, sol, &sens, &xs, &g)
                .map_err(|e| sim_err(rh, k, FiberError::from(e)))?;
            Ok((r, jl, model.param_layout().take_up_factor()))
        })
        .collect::<Result<_, RheometerError>>()?;
    let mut r = Vec::new();
    let mut x = Vec::new();
    let mut c: Vec<Vec<f64>> = vec![Vec::new(); cands.len()];
    for (k, (rk, jl, phi)) in parts.into_iter().enumerate() {
        let ql = jl.len() / rk.len().max(1);
        for i in 0..rk.len() {
            let row = &jl[i * ql..(i + 1) * ql];
            let mut xr = vec![0.0; q];
            for (col, &li) in layout.free.iter().enumerate() {
                xr[col] = row[li];
            }
            xr[ns + k] = row[phi];
            x.extend(xr);
            for (j, &(li, per)) in cand_idx.iter().enumerate() {
                c[j].push(row[li] * per);
            }
        }
        r.extend(rk);
    }
    Ok((r, x, q, c))
}

/// Diagnoses which candidate effect is missing from the model `base_spec` on the data `set`.
pub fn diagnose(
    set: &ExperimentSet,
    base_spec: &ModelSpec,
    options: &DiagnoseOptions,
) -> Result<DiagnosisRun, RheometerError> {
    let t0 = Instant::now();
    let mut opts = options.identify.clone();
    opts.estimator = Estimator::Principled;
    opts.simulate.factor_at_solution = true;
    let spec = base_spec.clone().with_candidates(&options.candidates);
    let rh = Rheometer::with_spec(set, spec.clone())?;
    let sigma = opts
        .relative_uncertainty
        .or(rh.relative_uncertainty)
        .unwrap_or(1.0);
    let law0 = match spec.law {
        LawChoice::Carreau => match options.start {
            Some(s) => s,
            None => rh.start_heuristic(&opts)?.start,
        },
        LawChoice::Newtonian => [1.0, STRAIN_THINNING_REFERENCE_KAPPA],
    };
    let base = rh.identify(law0, &opts)?;
    let base_report = FitReport::new(&base);
    let layout = Layout::new(&rh.models[0], &rh.spec, &FitStart::at(law0), &opts)?;
    let cands = spec.candidates.clone();
    let (r, x, q, cols) = linearisation(&rh, &layout, &base, &cands, sigma)?;
    let n_res = r.len();
    let cost_before: f64 = r.iter().map(|v| v * v).sum();
    let lin = linear_scores(&r, &x, q, &cols);
    let dof = n_res.saturating_sub(q).max(1) as f64;
    let s2 = cost_before / dof;

    // systematic?
    let before = residual_profiles(&rh, &base.solutions);
    let sequences = residual_sequences(&before);
    let sequences: Vec<&[f64]> = sequences.iter().map(Vec::as_slice).collect();
    let (noise_level, noise_source) = match opts.relative_uncertainty.or(rh.relative_uncertainty) {
        Some(u) => (u, "data set"),
        None => (noise_rms_second_differences(&sequences), "estimated"),
    };
    let rms0 = base.rms_relative_residual;
    let (rho1, pairs) = lag1_autocorrelation_about_zero(&sequences);
    let rms_over_noise = rms0 / noise_level;
    let mut systematic = rms_over_noise > 1.2 || rho1 * (pairs as f64).sqrt() > 3.0;

    let positions: Vec<f64> = rh
        .measurements
        .iter()
        .flat_map(|m| m.positions.iter().copied())
        .collect();
    let ln_n = (n_res as f64).ln();
    let ic = |after: f64, k: usize| {
        let l = n_res as f64 * (after.max(1e-300) / cost_before).ln();
        (l + k as f64 * ln_n, l + 2.0 * k as f64)
    };
    let mut results: Vec<CandidateResult> = cands
        .iter()
        .zip(&lin)
        .map(|(e, l)| {
            // shape parameters fitted with the strength count as extra parameters too
            let k = if matches!(e, Effect::StrainThinning) {
                2
            } else {
                1 + e.free_shapes().len()
            };
            let after = (cost_before - l.score).max(0.0);
            let (bic, aic) = ic(after, k);
            let change: Vec<f64> = l.signature.iter().map(|v| v * l.strength).collect();
            let (peak, range) = signature_location(&positions, &change);
            CandidateResult {
                effect: e.name().to_string(),
                unit: e.unit().to_string(),
                refitted: false,
                linear_score: l.score,
                linear_strength: l.strength,
                strength: l.strength,
                stderr_strength: if l.norm > 0.0 {
                    (s2).sqrt() / l.norm
                } else {
                    f64::INFINITY
                },
                cost_before,
                cost_after: after,
                rms_relative_residual_after: f64::NAN,
                extra_parameters: k,
                delta_bic: bic,
                delta_aic: aic,
                signature_peak_m: peak,
                signature_range_m: range,
                n: f64::NAN,
                kappa: f64::NAN,
                ci95_n: [f64::NAN; 2],
                ci95_kappa: [f64::NAN; 2],
                at_bound: Vec::new(),
            }
        })
        .collect();
    let mut order: Vec<usize> = (0..cands.len()).collect();
    order.sort_by(|&a, &b| lin[b].score.total_cmp(&lin[a].score));

    // refits of the top candidates
    let mut refits: Vec<(usize, Identification)> = Vec::new();
    for &i in order.iter().take(options.refit_top) {
        let e = &cands[i];
        let (lo, hi) = e.bounds();
        let s_lin = lin[i].strength;
        let s_start = if matches!(e, Effect::StrainThinning) {
            s_lin.clamp(0.05, 0.5)
        } else {
            s_lin.clamp(
                lo + 0.25 * (e.neutral() - lo),
                hi - 0.25 * (hi - e.neutral()),
            )
        };
        let mk = |s: f64| FitStart {
            law: [base.n, base.kappa],
            free_candidates: vec![e.name().to_string()],
            strengths: vec![(e.name().to_string(), s)],
            warm: Some(base.solutions.clone()),
        };
        let id = match rh.identify_from(&mk(s_start), &opts) {
            Ok(id) => Ok(id),
            Err(_) => rh.identify_from(
                &mk(if matches!(e, Effect::StrainThinning) {
                    0.05
                } else {
                    e.neutral()
                }),
                &opts,
            ),
        };
        let id = match id {
            Ok(id) => id,
            Err(_) => continue, // stays a linearised result
        };
        let rep = FitReport::new(&id);
        let after = 2.0 * id.fit.cost;
        let res = &mut results[i];
        let (bic, aic) = ic(after, res.extra_parameters);
        let er = rep.effects.iter().find(|x| x.effect == e.name());
        res.refitted = true;
        res.strength = er.map_or(f64::NAN, |x| x.strength);
        res.stderr_strength = er.map_or(f64::NAN, |x| x.stderr_strength);
        res.cost_after = after;
        res.rms_relative_residual_after = id.rms_relative_residual;
        res.at_bound = rep.at_bound.clone();
        res.delta_bic = bic;
        res.delta_aic = aic;
        if rep.stderr_n.is_finite() || spec.law == LawChoice::Carreau {
            res.n = rep.n;
            res.kappa = rep.kappa;
            res.ci95_n = rep.ci95_n;
            res.ci95_kappa = rep.ci95_kappa;
        }
        let a = residual_profiles(&rh, &id.solutions);
        let change: Vec<f64> = a
            .iter()
            .zip(&before)
            .flat_map(|(pa, pb)| pa.1.iter().zip(&pb.1).map(|(x, y)| x.1 - y.1))
            .collect();
        let (peak, range) = signature_location(&positions, &change);
        res.signature_peak_m = peak;
        res.signature_range_m = range;
        refits.push((i, id));
    }
    // best first: refitted by ΔBIC, then the rest by linear score
    let mut ranked: Vec<usize> = (0..cands.len()).collect();
    ranked.sort_by(|&a, &b| {
        let (ra, rb) = (&results[a], &results[b]);
        match (ra.refitted, rb.refitted) {
            (true, true) => ra.delta_bic.total_cmp(&rb.delta_bic),
            (true, false) => std::cmp::Ordering::Less,
            (false, true) => std::cmp::Ordering::Greater,
            (false, false) => rb.linear_score.total_cmp(&ra.linear_score),
        }
    });
    let mut indist = Vec::new();
    for a in 0..cands.len() {
        for b in a + 1..cands.len() {
            let c = cosine(&lin[a].signature, &lin[b].signature);
            if c.abs() > options.indistinguishable_cosine {
                indist.push(Indistinguishable {
                    effects: [cands[a].name().to_string(), cands[b].name().to_string()],
                    cosine: c,
                });
            }
        }
    }
    let best_i = ranked
        .first()
        .copied()
        .filter(|&i| results[i].refitted && results[i].delta_bic < options.earn_threshold);
    let most_likely = best_i.map(|i| cands[i].name().to_string());
    // a physical effect that explains part of the residuals significantly shows they are
    // systematic, even where the noise level is too uncertain for the RMS test
    systematic |= most_likely.is_some();
    let (residuals_after, best) = match best_i {
        Some(i) => match refits.into_iter().find(|(j, _)| *j == i) {
            Some((_, id)) => (Some(residual_profiles(&rh, &id.solutions)), Some(id)),
            None => (None, None),
        },
        None => (None, None),
    };
    let candidates: Vec<CandidateResult> = ranked.iter().map(|&i| results[i].clone()).collect();
    Ok(DiagnosisRun {
        diagnosis: Diagnosis {
            model: spec.law,
            base_fit: base_report,
            noise_level,
            noise_source: noise_source.to_string(),
            rms_over_noise,
            lag1_autocorrelation: rho1,
            systematic,
            candidates,
            indistinguishable: indist,
            most_likely_missing: most_likely,
            wall_time_s: t0.elapsed().as_secs_f64(),
        },
        residuals_before: before,
        residuals_after,
        base,
        best,
    })
}

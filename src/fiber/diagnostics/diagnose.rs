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
//! 4. **Global search and refits** ([`scan`](super::scan)) of every candidate, in parallel: its
//!    strength scanned over its search range (and, for effects with a shape, a few shapes), each
//!    grid point a warm-started refit of the material parameters with the strength fixed; the
//!    best grid points refined with the strength freed (the lowest, the next ones close to it,
//!    and the lowest ones on the other side of the neutral value where they already earn their
//!    place: the two signs are different regimes; a grid point whose `n` sits at a bound is
//!    refined from the start law, since at `n = 1` the fit cannot move). The best refit gives the achieved cost
//!    `J`, RMS, fitted strength with standard error, and information criteria
//!    `ΔBIC = N ln(J_after/J_before) + Δk ln N`, `ΔAIC = N ln(J_after/J_before) + 2 Δk`
//!    (Gaussian errors with unknown variance; `Δk` extra parameters, 2 for strain thinning:
//!    `n` and `κ`; one more for a shape chosen among several). Candidates are ranked by `ΔBIC`,
//!    credible ones first. A candidate earns its place when `ΔBIC` is below
//!    [`DiagnoseOptions::earn_threshold`] (−10: "very strong" evidence on the Kass–Raftery scale)
//!    **and** its strength is credible ([`StrengthStatus::Physical`]): a best strength at a
//!    search bound or outside the physical range is reported as such and never named.
//! 5. **Indistinguishable** candidates: cosine of their orthogonalised signatures above
//!    [`DiagnoseOptions::indistinguishable_cosine`] (0.9) in absolute value.
//! 6. **Ties** ([`ties`](super::ties)): other candidates that earn their place with a `ΔBIC`
//!    less than [`DiagnoseOptions::tie_margin`] (6) above the named one's are listed as
//!    [`Diagnosis::alternatives`], with their refits' `(n, κ)` and the shifts from the named
//!    refit's in its standard errors (the named cause stays the best by `ΔBIC`).

use super::detection::{detection_limits, DetectionContext, DetectionLimits};
use super::scan::{
    physical, refine, scan_profile, search_range, shape_variants, GridStart, Profile, ProfileScan,
    Refit, ScanOptions, ShapeParameter,
};
use super::scores::{cosine, linear_scores};
use super::ties::{alternatives_among, Alternative, DEFAULT_TIE_MARGIN};
use crate::fiber::effects::{Effect, LawChoice, ModelSpec, NEWTONIAN_LAW};
use crate::fiber::noise_model::Outlier;
use crate::fiber::rheometer::estimator::RelativeResidual;
use crate::fiber::rheometer::report::bound_side;
use crate::fiber::rheometer::{
    AtBound, Estimator, FitReport, FitStart, Identification, IdentifyOptions, Layout,
    ParameterShift, Rheometer, RheometerError,
};
use crate::fiber::setup::ExperimentSet;
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
    /// Whether the refitted strength is credible: physical and inside its search range (only a
    /// [`StrengthStatus::Physical`] candidate can be named as the missing effect).
    #[serde(default)]
    pub status: StrengthStatus,
    /// Why the strength is not credible, in words (`"radiation would need 2.0000 > 1: not
    /// physical"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub status_note: Option<String>,
    /// Physical range of the strength (the effect's unit).
    pub physical_range: [f64; 2],
    /// Search range of the strength (the effect's unit).
    pub search_range: [f64; 2],
    /// Shape of the best variant (e.g. the co-flow's decay length in m; empty for effects
    /// without a shape).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shape: Vec<ShapeParameter>,
    /// The best refit with another discrete shape (the co-flow's tail) where the data cannot
    /// choose between them (`ΔBIC` gap below the tie margin): its shape and material estimate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape_alternative: Option<ShapeAlternative>,
    /// Profiles of `J` against the strength, one per scanned shape.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub profiles: Vec<Profile>,
    /// Scans that could not start (one per variant, in words).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub scan_errors: Vec<String>,
}

/// A candidate's refit with another value of a discrete shape (the co-flow's tail `r`: 0 the
/// exponential, 0.5 the inverse-square decay) that the data cannot tell from the one reported:
/// `ΔBIC` within the tie margin. The reported refit keeps the default shape unless the other
/// is better by more than the margin.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShapeAlternative {
    /// Its shape parameters.
    pub shape: Vec<ShapeParameter>,
    /// Its `ΔBIC` minus the reported refit's (positive: worse).
    pub delta_bic_gap: f64,
    /// Its strength (the effect's unit) and standard error.
    pub strength: f64,
    /// Standard error of `strength`.
    pub stderr_strength: f64,
    /// `n` of its refit.
    pub n: f64,
    /// `κ` of its refit.
    pub kappa: f64,
    /// 95% CI of `n`.
    pub ci95_n: [f64; 2],
    /// 95% CI of `κ`.
    pub ci95_kappa: [f64; 2],
}

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
}

impl StrengthStatus {
    /// The status as written in JSON (`"physical"`, `"at_bound"`, ...).
    pub fn name(&self) -> &'static str {
        match self {
            StrengthStatus::NotRefitted => "not_refitted",
            StrengthStatus::Physical => "physical",
            StrengthStatus::AtBound => "at_bound",
            StrengthStatus::Unphysical => "unphysical",
        }
    }
}

/// How many standard errors a strength may lie beyond its physical range and still count as
/// consistent with it (the two-sided 95 % normal quantile): an emissivity estimated as
/// 1.02 ± 0.09 is consistent with ε ≤ 1, one of 2.0 ± 0.1 is not.
pub const PHYSICAL_RANGE_SE: f64 = 1.96;

/// The status of a refitted `strength` (standard error `stderr`) of `effect` with the fit's
/// estimates at a bound: at a search bound (listed in `at_bound`, or within the report's
/// tolerance of the range) comes first, then outside the physical range by more than
/// [`PHYSICAL_RANGE_SE`] standard errors. A strength beyond the physical range by less is
/// [`StrengthStatus::Physical`] with a note saying so (noise alone puts a true value at the
/// limit that far beyond it).
pub fn strength_status(
    effect: &Effect,
    strength: f64,
    stderr: f64,
    at_bound: &[AtBound],
) -> (StrengthStatus, Option<String>) {
    let (lo, hi) = search_range(effect);
    let unit = effect.unit();
    let side = at_bound
        .iter()
        .find(|b| b.parameter == effect.name())
        .map(|b| (b.side, b.bound))
        .or_else(|| {
            bound_side(strength, lo, hi).map(|s| {
                let b = if s.name() == "lower" { lo } else { hi };
                (s, b)
            })
        });
    if let Some((s, b)) = side {
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
        Err(why) => {
            let (plo, phi) = effect.physical_range();
            let (limit, beyond) = if strength > phi {
                (phi, strength - phi)
            } else {
                (plo, plo - strength)
            };
            let se_ok = stderr.is_finite() && stderr > 0.0;
            let u = if unit == "-" {
                String::new()
            } else {
                format!(" {unit}")
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
    }
}

/// Whether every discrete shape of `variant` (scanned, not fitted: the co-flow's tail) is at
/// its default.
fn discrete_shapes_at_defaults(variant: &Effect) -> bool {
    variant
        .shape_values()
        .iter()
        .filter(|(sp, _)| sp.scanned && !sp.fitted_with_strength)
        .all(|(sp, v)| *v == sp.default)
}

/// Whether a candidate may be named as the missing effect: refitted, `ΔBIC` below `threshold`,
/// and its strength credible (never one at a search bound or outside the physical range).
pub fn earns_its_place(c: &CandidateResult, threshold: f64) -> bool {
    c.refitted && c.status == StrengthStatus::Physical && c.delta_bic < threshold
}

/// Ranking: credible refits by `ΔBIC`, then refits that are not credible by `ΔBIC`, then
/// candidates without a refit by linear score.
pub fn rank_order(a: &CandidateResult, b: &CandidateResult) -> std::cmp::Ordering {
    let class = |c: &CandidateResult| match (c.refitted, c.status) {
        (true, StrengthStatus::Physical) => 0,
        (true, _) => 1,
        (false, _) => 2,
    };
    class(a)
        .cmp(&class(b))
        .then_with(|| match (a.refitted, b.refitted) {
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

/// The diagnosis (what is written as JSON).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Diagnosis {
    /// The user's law.
    pub model: LawChoice,
    /// The user's fit.
    pub base_fit: FitReport,
    /// Noise level (relative) used for the judgement.
    pub noise_level: f64,
    /// `"data set"` (relative_uncertainty) or `"estimated"` (the
    /// [`NoiseModel`](crate::fiber::noise_model::NoiseModel) of the residuals: RMS of the local
    /// noise level along the line, from second differences, outliers excluded).
    pub noise_source: String,
    /// RMS relative residual of the user's fit (outliers excluded) over the noise level.
    pub rms_over_noise: f64,
    /// Pooled lag-1 autocorrelation of the noise-normalised residuals along the spin lines
    /// (about zero, outliers excluded).
    pub lag1_autocorrelation: f64,
    /// Gross outliers of the user's fit, by experiment and position (left out of the noise
    /// level, the RMS and the autocorrelation; a robust loss in `fit` down-weights them).
    #[serde(default)]
    pub outliers: Vec<Outlier>,
    /// Whether the residuals are systematic: `rms_over_noise > 1.2`, or `ρ₁ √N > 3`, or a
    /// candidate earns its place (its refit lowers BIC below the threshold).
    pub systematic: bool,
    /// The candidates, best first.
    pub candidates: Vec<CandidateResult>,
    /// Pairs of candidates with nearly parallel signatures.
    pub indistinguishable: Vec<Indistinguishable>,
    /// The most likely missing effect, if one earns its place (the best by `ΔBIC`).
    pub most_likely_missing: Option<String>,
    /// Other candidates about as consistent with the data as the named one: they earn their
    /// place too, with a `ΔBIC` less than [`DiagnoseOptions::tie_margin`] above the named
    /// one's (best first; empty when nothing is named or nothing ties; see
    /// [`ties`](super::ties)).
    #[serde(default)]
    pub alternatives: Vec<Alternative>,
    /// What these data could have missed: per candidate, the strength named with 50 % and
    /// 95 % probability (linearised at strength 0) and the shift of `(n, κ)` an undetected
    /// effect of the 95 % strength would cause ([`detection`](super::detection)). Empty in
    /// diagnoses written before it existed.
    #[serde(default)]
    pub detection: DetectionLimits,
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

/// The residuals of a fit on its own model (a refit's parameter vector belongs to the
/// candidate's model, not to the diagnosis' one), named by experiment.
fn own_residual_profiles(rh: &Rheometer, id: &Identification) -> ResidualProfiles {
    id.residual_profiles
        .iter()
        .enumerate()
        .map(|(k, (s, r))| {
            (
                rh.experiments[k].name.clone(),
                s.iter().copied().zip(r.iter().copied()).collect(),
            )
        })
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
        LawChoice::Newtonian => NEWTONIAN_LAW,
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
    // the one noise model of compare and diagnose: robust, varying along the line, outliers
    // flagged and left out of the RMS, the noise level and the lag-1 autocorrelation
    let nm = rh.noise_model(&base.residual_profiles)?;
    let (noise_level, noise_source, rms_over_noise) =
        match opts.relative_uncertainty.or(rh.relative_uncertainty) {
            Some(u) => (u, "data set", nm.rms / u),
            None => (nm.noise_rms, "estimated", nm.rms_over_noise),
        };
    let (rho1, pairs) = (nm.lag1, nm.lag1_pairs);
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
            let k = e.extra_parameters();
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
                status: StrengthStatus::NotRefitted,
                status_note: None,
                physical_range: {
                    let r = super::scan::physical_range(e);
                    [r.0, r.1]
                },
                search_range: {
                    let r = search_range(e);
                    [r.0, r.1]
                },
                shape: Vec::new(),
                shape_alternative: None,
                profiles: Vec::new(),
                scan_errors: Vec::new(),
            }
        })
        .collect();
    // detection limits (linearised at strength 0) and the bias an undetected effect causes
    let detection = {
        // without a determined fit (singular JᵀJ) the limits come without the shifts
        let dtheta: Vec<Vec<f64>> = match ParameterShift::new(&x, n_res, q) {
            Ok(shift) => cols
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
        let col = |name: &str| layout.names.iter().position(|s| s == name);
        let extra: Vec<usize> = results.iter().map(|c| c.extra_parameters).collect();
        detection_limits(
            &cands,
            &extra,
            &lin,
            &dtheta,
            (col("n"), col("kappa")),
            &DetectionContext {
                sigma: noise_level / sigma,
                noise_level,
                cost_before,
                measurements: n_res,
                threshold: options.earn_threshold,
                stderr_n: base_report.stderr_n,
                stderr_kappa: base_report.stderr_kappa,
            },
        )
    };
    let mut order: Vec<usize> = (0..cands.len()).collect();
    order.sort_by(|&a, &b| lin[b].score.total_cmp(&lin[a].score));

    // global search of each candidate (best linearised first, at most `refit_top`), all
    // variants in parallel
    let scanned: Vec<usize> = order.iter().copied().take(options.refit_top).collect();
    // spin-line length \[m\] that bounds the shapes (the shortest line)
    let length = rh
        .experiments
        .iter()
        .map(|e| e.spinline_length)
        .fold(f64::INFINITY, f64::min);
    let jobs: Vec<(usize, Effect, Vec<ShapeParameter>)> = scanned
        .iter()
        .flat_map(|&i| {
            shape_variants(&cands[i], options.scan.scan_shapes, length)
                .into_iter()
                .map(move |(v, s)| (i, v, s))
        })
        .collect();
    let scans: Vec<(usize, Result<ProfileScan, RheometerError>)> = jobs
        .into_par_iter()
        .map(|(i, v, s)| {
            (
                i,
                scan_profile(
                    &rh,
                    &cands[i],
                    &v,
                    s,
                    &base,
                    cost_before,
                    &opts,
                    &options.scan,
                ),
            )
        })
        .collect();
    let mut variants = vec![0usize; cands.len()];
    let mut ok_scans: Vec<(usize, ProfileScan)> = Vec::new();
    for (i, sc) in scans {
        variants[i] += 1;
        match sc {
            Ok(sc) => {
                results[i].profiles.push(sc.profile.clone());
                ok_scans.push((i, sc));
            }
            Err(e) => results[i].scan_errors.push(e.to_string()),
        }
    }
    // refine each candidate's best grid points over all its shapes, in parallel
    // (the variants with the discrete shapes at their defaults and those with other values are
    // refined apart: the choice between them needs the best refit of each)
    let mut refine_jobs: Vec<(usize, usize, usize)> = Vec::new(); // (candidate, scan, start)
    for (i, kind) in scanned.iter().flat_map(|&i| [(i, false), (i, true)]) {
        let mut starts: Vec<(usize, usize, f64)> = ok_scans
            .iter()
            .enumerate()
            .filter(|(_, (c, sc))| *c == i && discrete_shapes_at_defaults(&sc.effect) != kind)
            .flat_map(|(j, (_, sc))| {
                sc.starts
                    .iter()
                    .enumerate()
                    .map(move |(k, st)| (j, k, st.cost))
            })
            .collect();
        starts.sort_by(|a, b| a.2.total_cmp(&b.2));
        // the lowest start, and the next ones only where their J is close to it
        let lowest = starts.first().map_or(f64::INFINITY, |s| s.2);
        let chosen: Vec<(usize, usize, f64)> = starts
            .iter()
            .copied()
            .take(options.scan.refine.max(1))
            .filter(|s| s.2 <= lowest * (1.0 + options.scan.refine_within))
            .collect();
        // the two signs of a strength are different regimes (a co-flow faster than the fiber
        // reverses the relative speed; warmer or colder air): the lowest starts on the other
        // side of the neutral value (as many as `refine`, over all shapes) are refined too
        // where they already earn their place at their grid point (a grid point's J, with the
        // strength and shape fixed, bounds its refit's from above)
        let neutral = cands[i].neutral();
        let side = |&(j, k, _): &(usize, usize, f64)| {
            (ok_scans[j].1.starts[k].strength - neutral).signum()
        };
        let other: Vec<(usize, usize, f64)> = match chosen.first().map(side) {
            Some(first) => starts
                .iter()
                .copied()
                .filter(|s| side(s) != first)
                .take(options.scan.refine.max(1))
                .filter(|s| ic(s.2, results[i].extra_parameters).0 < options.earn_threshold)
                .collect(),
            None => Vec::new(),
        };
        refine_jobs.extend(chosen.into_iter().chain(other).map(|(j, k, _)| (i, j, k)));
    }
    let n_bounds = layout
        .names
        .iter()
        .position(|s| s == "n")
        .map(|c| (layout.lower[c], layout.upper[c]));
    let refined: Vec<(usize, usize, Refit)> = refine_jobs
        .into_par_iter()
        .filter_map(|(i, j, k)| {
            let sc = &ok_scans[j].1;
            // a grid point whose n sits at a bound of its range (the Newtonian limit n = 1,
            // where κ has no effect: the fit cannot leave it) is refined from the diagnosis'
            // start law instead, with its own strength, shape and warm solutions
            let start = &sc.starts[k];
            let at_n_bound = n_bounds
                .is_some_and(|(lo, hi)| start.law[0] <= lo + 1e-6 || start.law[0] >= hi - 1e-6);
            let moved;
            let start = if at_n_bound && spec.law == LawChoice::Carreau {
                moved = GridStart {
                    law: law0,
                    ..start.clone()
                };
                &moved
            } else {
                start
            };
            refine(sc, start, &opts).ok().map(|r| (i, j, r))
        })
        .collect();
    // per candidate, the best refit with the discrete shapes (scanned, not fitted: the
    // co-flow's tail) at their defaults and the best with other values; the other is reported
    // only where it is better by more than the tie margin, else listed as the shape alternative
    // if within it
    let mut best_by_kind: Vec<[Option<(Effect, Refit)>; 2]> = vec![[None, None]; cands.len()];
    for (i, j, r) in refined {
        let variant = &ok_scans[j].1.effect;
        let kind = usize::from(!discrete_shapes_at_defaults(variant));
        if best_by_kind[i][kind]
            .as_ref()
            .is_none_or(|(_, b)| r.cost < b.cost)
        {
            best_by_kind[i][kind] = Some((variant.clone(), r));
        }
    }
    let mut best_refit: Vec<Option<(Effect, Refit)>> = Vec::with_capacity(cands.len());
    let mut other_shape: Vec<Option<(Effect, Refit)>> = Vec::with_capacity(cands.len());
    for (i, [dflt, alt]) in best_by_kind.into_iter().enumerate() {
        let k = results[i].extra_parameters;
        let (chosen, other) = match (dflt, alt) {
            (Some(d), Some(a)) => {
                let gap = ic(a.1.cost, k).0 - ic(d.1.cost, k).0;
                if gap < -options.tie_margin {
                    (Some(a), Some(d))
                } else {
                    (Some(d), Some(a))
                }
            }
            (d, a) => (d.or(a), None),
        };
        let other = other.filter(|o| {
            chosen
                .as_ref()
                .is_some_and(|c| (ic(o.1.cost, k).0 - ic(c.1.cost, k).0).abs() < options.tie_margin)
        });
        best_refit.push(chosen);
        other_shape.push(other);
    }
    let mut refits: Vec<(usize, Identification)> = Vec::new();
    for (i, br) in best_refit.into_iter().enumerate() {
        let Some((variant, refit)) = br else { continue };
        let e = &cands[i];
        let rep = &refit.report;
        let id = refit.identification;
        let after = refit.cost;
        let res = &mut results[i];
        let (bic, aic) = ic(after, res.extra_parameters);
        let er = rep.effects.iter().find(|x| x.effect == e.name());
        res.refitted = true;
        res.strength = er.map_or(f64::NAN, |x| x.strength);
        res.stderr_strength = er.map_or(f64::NAN, |x| x.stderr_strength);
        // the refit's shapes (fitted ones freed again by the refinement, counted in
        // `extra_parameters` through `free_shapes`)
        res.shape = er
            .map(|x| {
                x.shapes
                    .iter()
                    .map(|sh| ShapeParameter {
                        name: sh.name.clone(),
                        value: sh.value,
                        unit: sh.unit.clone(),
                    })
                    .collect()
            })
            .unwrap_or_default();
        res.cost_after = after;
        res.rms_relative_residual_after = id.rms_relative_residual;
        res.at_bound = rep.at_bound.clone();
        res.delta_bic = bic;
        res.delta_aic = aic;
        let (mut status, mut note) =
            strength_status(&variant, res.strength, res.stderr_strength, &res.at_bound);
        // a shape parameter at a bound of its range is no credible estimate either
        if status == StrengthStatus::Physical {
            let prefix = format!("{}.", e.name());
            if let Some(b) = res
                .at_bound
                .iter()
                .find(|b| b.parameter.starts_with(&prefix))
            {
                status = StrengthStatus::AtBound;
                note = Some(format!(
                    "its shape parameter {} is best at its {} bound {}: the data push the \
                     effect's shape beyond its range",
                    b.parameter,
                    b.side.name(),
                    b.bound
                ));
            }
        }
        res.status = status;
        res.status_note = note;
        if rep.stderr_n.is_finite() || spec.law == LawChoice::Carreau {
            res.n = rep.n;
            res.kappa = rep.kappa;
            res.ci95_n = rep.ci95_n;
            res.ci95_kappa = rep.ci95_kappa;
        }
        let a = own_residual_profiles(&rh, &id);
        let change: Vec<f64> = a
            .iter()
            .zip(&before)
            .flat_map(|(pa, pb)| pa.1.iter().zip(&pb.1).map(|(x, y)| x.1 - y.1))
            .collect();
        let (peak, range) = signature_location(&positions, &change);
        res.signature_peak_m = peak;
        res.signature_range_m = range;
        if let Some((_, o)) = other_shape[i].take() {
            let orep = &o.report;
            // only a credible other shape (its strength and shape inside their ranges) is an
            // alternative
            let prefix = format!("{}.", e.name());
            let credible = !orep
                .at_bound
                .iter()
                .any(|b| b.parameter == e.name() || b.parameter.starts_with(&prefix));
            if let Some(oe) = orep
                .effects
                .iter()
                .find(|x| credible && x.effect == e.name())
            {
                res.shape_alternative = Some(ShapeAlternative {
                    shape: oe
                        .shapes
                        .iter()
                        .map(|sh| ShapeParameter {
                            name: sh.name.clone(),
                            value: sh.value,
                            unit: sh.unit.clone(),
                        })
                        .collect(),
                    delta_bic_gap: ic(o.cost, res.extra_parameters).0 - bic,
                    strength: oe.strength,
                    stderr_strength: oe.stderr_strength,
                    n: orep.n,
                    kappa: orep.kappa,
                    ci95_n: orep.ci95_n,
                    ci95_kappa: orep.ci95_kappa,
                });
            }
        }
        refits.push((i, id));
    }
    // best first: credible refits by ΔBIC, then refits not credible (at a bound or not
    // physical) by ΔBIC, then the rest by linear score
    let mut ranked: Vec<usize> = (0..cands.len()).collect();
    ranked.sort_by(|&a, &b| rank_order(&results[a], &results[b]));
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
        .iter()
        .copied()
        .find(|&i| earns_its_place(&results[i], options.earn_threshold));
    let most_likely = best_i.map(|i| cands[i].name().to_string());
    let candidates: Vec<CandidateResult> = ranked.iter().map(|&i| results[i].clone()).collect();
    // other candidates about as consistent with the data as the named one
    let alternatives: Vec<Alternative> = match best_i {
        Some(b) => alternatives_among(
            &results[b],
            &candidates,
            options.earn_threshold,
            options.tie_margin,
            &cands,
            |name| match cands.iter().position(|e| e.name() == name) {
                Some(i) => cosine(&lin[b].signature, &lin[i].signature),
                None => f64::NAN,
            },
        ),
        None => Vec::new(),
    };
    // a physical effect that explains part of the residuals significantly shows they are
    // systematic, even where the noise level is too uncertain for the RMS test
    systematic |= most_likely.is_some();
    let (residuals_after, best) = match best_i {
        Some(i) => match refits.into_iter().find(|(j, _)| *j == i) {
            Some((_, id)) => (Some(own_residual_profiles(&rh, &id)), Some(id)),
            None => (None, None),
        },
        None => (None, None),
    };
    Ok(DiagnosisRun {
        diagnosis: Diagnosis {
            model: spec.law,
            base_fit: base_report,
            noise_level,
            noise_source: noise_source.to_string(),
            rms_over_noise,
            lag1_autocorrelation: rho1,
            outliers: nm.outliers.clone(),
            systematic,
            candidates,
            indistinguishable: indist,
            most_likely_missing: most_likely,
            alternatives,
            detection,
            wall_time_s: t0.elapsed().as_secs_f64(),
        },
        residuals_before: before,
        residuals_after,
        base,
        best,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fiber::rheometer::BoundSide;

    fn result(
        effect: &str,
        refitted: bool,
        status: StrengthStatus,
        dbic: f64,
        lin: f64,
    ) -> CandidateResult {
        CandidateResult {
            effect: effect.into(),
            unit: "-".into(),
            refitted,
            linear_score: lin,
            linear_strength: 0.0,
            strength: 0.5,
            stderr_strength: 0.1,
            cost_before: 1.0,
            cost_after: 0.5,
            rms_relative_residual_after: f64::NAN,
            extra_parameters: 1,
            delta_bic: dbic,
            delta_aic: dbic,
            signature_peak_m: 0.0,
            signature_range_m: [0.0, 0.0],
            n: f64::NAN,
            kappa: f64::NAN,
            ci95_n: [f64::NAN; 2],
            ci95_kappa: [f64::NAN; 2],
            at_bound: Vec::new(),
            status,
            status_note: None,
            physical_range: [0.0, 1.0],
            search_range: [0.0, 1.0],
            shape: Vec::new(),
            shape_alternative: None,
            profiles: Vec::new(),
            scan_errors: Vec::new(),
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
        let (s, note) = strength_status(&rad, 0.9, 0.1, &[]);
        assert_eq!((s, note), (StrengthStatus::Physical, None));
        let (s, note) = strength_status(&rad, 1.6, 0.1, &[]);
        assert_eq!(s, StrengthStatus::Unphysical);
        assert!(note.unwrap().contains("> 1: not physical"));
        // beyond the limit by less than 1.96 standard errors: consistent with it, said so
        let (s, note) = strength_status(&rad, 1.02, 0.09, &[]);
        assert_eq!(s, StrengthStatus::Physical);
        let note = note.unwrap();
        assert!(
            note.contains("radiation = 1.0200 +/- 0.0900 lies beyond its physical limit 1 by 0.22 standard errors"),
            "{note}"
        );
        let (s, _) = strength_status(&rad, -0.19, 0.1, &[]);
        assert_eq!(s, StrengthStatus::Physical);
        // by more, or without a valid standard error: not physical
        assert_eq!(
            strength_status(&rad, 1.2, 0.1, &[]).0,
            StrengthStatus::Unphysical
        );
        assert_eq!(
            strength_status(&rad, 1.02, f64::NAN, &[]).0,
            StrengthStatus::Unphysical
        );
        // at the search bound 2 (found by value, without an at_bound entry)
        let (s, note) = strength_status(&rad, 2.0, 0.5, &[]);
        assert_eq!(s, StrengthStatus::AtBound);
        assert!(note.unwrap().contains("upper bound 2"));
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
        let (s, note) = strength_status(&c, -5.0, 1.0, &[ab]);
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
            strength_status(&c, 3.0, 1.0, &[other]).0,
            StrengthStatus::Physical
        );
    }
}

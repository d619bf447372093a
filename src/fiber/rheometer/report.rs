//! Uncertainty and reports of an identification.
//!
//! Standard errors come from the Gauss–Newton approximation of the covariance,
//! `σ̂² (JᵀJ)⁻¹` with the residual variance `σ̂² = ‖r‖²/(N − p)`; 95% confidence intervals are
//! `± 1.96` standard errors (normal approximation; `N` is in the hundreds). For `K = e^κ` the
//! interval is the image of κ's. For the paper's estimator the residuals are weighted distances
//! to smoothed data, not measurement errors: its standard errors are shown for comparison only.
//!
//! # Checks: a bad fit is never printed as a good one
//!
//! * **Estimates at a bound.** An estimate within [`AT_BOUND_TOLERANCE`] of the width of its
//!   search range from a bound is listed in [`FitReport::at_bound`] and marked `AT LOWER BOUND`
//!   / `AT UPPER BOUND` in the text. The optimum then lies at or beyond the search range, and
//!   the normal-approximation interval is not valid: its `ci95_*` fields are `NaN` (`null` in
//!   JSON) and the text prints no interval for it.
//! * **Misfit far above the noise.** The RMS relative residual is compared with the noise level:
//!   the declared `relative_uncertainty` (options or TOML) if given, else the robust estimate of
//!   [`noise_mad_second_differences`] (second differences of the residuals along each spin line). Above
//!   [`MISFIT_RATIO`] times the noise the report warns and names the worst experiments.
//! * **Huge standard errors**: `SE(n) >` [`LARGE_STDERR_N`], `SE(κ) >` [`LARGE_STDERR_KAPPA`],
//!   a fitted strength with a standard error above [`LARGE_STDERR_STRENGTH_FRACTION`] of its
//!   search range, or a `K` interval reaching `0` or `∞`.
//! * **A singular or ill-conditioned covariance** (no standard errors, or a correlation matrix
//!   with reciprocal condition number below [`ILL_CONDITIONED_RCOND`]).
//! * **Data the model cannot describe**: measured diameters that do not decrease along the spin
//!   line ([`Rheometer::data_warnings`](super::Rheometer::data_warnings)).
//!
//! Each finding is a [`FitWarning`] (a [`WarningCode`] and a message naming the parameter or
//! experiment) in [`FitReport::warnings`], printed in a `[[Warnings]]` section of the text.
//! The report states the law that was fitted ([`FitReport::law`]); it never infers it from the
//! values (a Carreau fit that ends at `n = 1` stays a Carreau fit, at its bound).

use super::error_budget::ErrorBudget;
use super::estimator::Estimator;
use super::identify::Identification;
pub use super::options::{FitWarning, WarningCode};
use crate::fiber::effects::LawChoice;
use crate::fiber::statistics::noise_mad_second_differences;
use crate::least_squares::Loss;
use nalgebra::{DMatrix, SymmetricEigen};
use serde::{Deserialize, Serialize};

/// An estimate counts as at a bound when it is within this fraction of the width of its search
/// range from the bound (e.g. `0.001` for `n ∈ [0, 1]`, `0.013` for `κ ∈ [7, 20]`).
pub const AT_BOUND_TOLERANCE: f64 = 1e-3;
/// The report warns when the RMS relative residual exceeds this multiple of the noise level.
pub const MISFIT_RATIO: f64 = 3.0;
/// Without any noise level (too few points to estimate it), the report warns when the RMS
/// relative residual exceeds this \[-\].
pub const MISFIT_WITHOUT_NOISE: f64 = 0.1;
/// A standard error of `n` above this \[-\] is reported as huge.
pub const LARGE_STDERR_N: f64 = 0.2;
/// A standard error of `κ` above this \[-\] (a factor `e` in `K`) is reported as huge.
pub const LARGE_STDERR_KAPPA: f64 = 1.0;
/// A fitted strength whose standard error exceeds this fraction of its search range is
/// reported as undetermined.
pub const LARGE_STDERR_STRENGTH_FRACTION: f64 = 0.25;
/// A correlation matrix whose smallest/largest eigenvalue ratio is below this is reported as
/// ill-conditioned.
pub const ILL_CONDITIONED_RCOND: f64 = 1e-10;

/// Which bound of its search range an estimate sits at.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BoundSide {
    /// The lower bound.
    Lower,
    /// The upper bound.
    Upper,
}

impl BoundSide {
    /// `"lower"` or `"upper"`.
    pub fn name(&self) -> &'static str {
        match self {
            BoundSide::Lower => "lower",
            BoundSide::Upper => "upper",
        }
    }

    fn flipped(self) -> Self {
        match self {
            BoundSide::Lower => BoundSide::Upper,
            BoundSide::Upper => BoundSide::Lower,
        }
    }
}

/// An estimate at a bound of its search range (JSON:
/// `{"parameter": "kappa", "side": "lower", "bound": 7.0, "value": 7.0}`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AtBound {
    /// `"n"`, `"kappa"`, an effect's name, or `"take_up_factor[EXPERIMENT]"`.
    pub parameter: String,
    /// Which bound.
    pub side: BoundSide,
    /// The bound (in the reported unit: the effect's strength unit for effects, \[-\] else).
    pub bound: f64,
    /// The estimate (same unit).
    pub value: f64,
}

/// Which bound `value` is at (within [`AT_BOUND_TOLERANCE`] of the range width), if any.
pub fn bound_side(value: f64, lower: f64, upper: f64) -> Option<BoundSide> {
    let width = upper - lower;
    let tol = if width.is_finite() && width > 0.0 {
        AT_BOUND_TOLERANCE * width
    } else {
        AT_BOUND_TOLERANCE * value.abs().max(1.0)
    };
    if lower.is_finite() && value - lower <= tol {
        Some(BoundSide::Lower)
    } else if upper.is_finite() && upper - value <= tol {
        Some(BoundSide::Upper)
    } else {
        None
    }
}

/// The numbers of an identification, as written to JSON.
///
/// Fields added after the first release (`law`, `fitted`, `experiments`, `noise_level`, ...,
/// `at_bound`, `warnings`) default when missing, so older reports still read. Standard errors
/// and intervals that do not exist (a singular covariance, an estimate at a bound) are `NaN`,
/// written as `null`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FitReport {
    /// Estimator (`"paper"` or `"principled"`).
    pub estimator: Estimator,
    /// The viscosity law of the fitted model (`"carreau"` or `"newtonian"`), as chosen for the
    /// fit (`None` only in reports written before this field existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub law: Option<LawChoice>,
    /// Names of the fitted shared parameters (`"n"`, `"kappa"`, effect names); the take-up
    /// factors of the principled estimator are fitted too.
    #[serde(default)]
    pub fitted: Vec<String>,
    /// Experiment names, in the order of `take_up_factors`.
    #[serde(default)]
    pub experiments: Vec<String>,
    /// Start point `(n, κ)`.
    pub start: [f64; 2],
    /// Power index `n` \[-\].
    pub n: f64,
    /// `κ = ln(K / 1 Pa)` \[-\].
    pub kappa: f64,
    /// `K = e^κ` \[Pa\].
    #[serde(rename = "K_Pa")]
    pub k_pa: f64,
    /// Standard error of `n`.
    #[serde(deserialize_with = "nullable::f64")]
    pub stderr_n: f64,
    /// Standard error of `κ`.
    #[serde(deserialize_with = "nullable::f64")]
    pub stderr_kappa: f64,
    /// 95% confidence interval of `n` (`NaN` when `n` is at a bound or has no standard error).
    #[serde(deserialize_with = "nullable::pair")]
    pub ci95_n: [f64; 2],
    /// 95% confidence interval of `κ` (`NaN` when `κ` is at a bound or has no standard error).
    #[serde(deserialize_with = "nullable::pair")]
    pub ci95_kappa: [f64; 2],
    /// 95% confidence interval of `K` \[Pa\] (`NaN` when `κ`'s is).
    #[serde(rename = "ci95_K_Pa", deserialize_with = "nullable::pair")]
    pub ci95_k_pa: [f64; 2],
    /// Correlation of `n` and `κ`.
    #[serde(deserialize_with = "nullable::f64")]
    pub correlation_n_kappa: f64,
    /// Cost `J = ‖r‖²` of the estimator at the optimum (`C² Σ ρ((rᵢ/C)²)` under a robust loss).
    pub cost: f64,
    /// RMS of `(d_model − d_meas)/d_meas` over all raw measurements \[-\].
    pub rms_relative_residual: f64,
    /// RMS relative residual of each experiment \[-\], in the order of `experiments`.
    #[serde(default)]
    pub rms_relative_residual_by_experiment: Vec<f64>,
    /// Relative noise level the misfit is judged against \[-\] (`NaN` if unknown).
    #[serde(default = "nan", deserialize_with = "nullable::f64")]
    pub noise_level: f64,
    /// Where `noise_level` comes from (`"declared relative_uncertainty"` or
    /// `"estimated from second differences of the residuals"`).
    #[serde(default)]
    pub noise_source: String,
    /// Take-up factors `φ_k = d_out,k/d_fit,k(L)` (1 for the paper's estimator).
    pub take_up_factors: Vec<f64>,
    /// Number of residuals.
    pub residuals: usize,
    /// Gauss–Newton iterations (trial steps).
    pub iterations: usize,
    /// Trial points where a BVP failed (rejected steps).
    pub failed_evaluations: usize,
    /// Wall time \[s\].
    pub wall_time_s: f64,
    /// Why the fit stopped.
    pub termination: String,
    /// The model's extra effects with their strengths (empty for the paper's model).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub effects: Vec<EffectReport>,
    /// The estimates at a bound of their search range (their intervals are `NaN`).
    #[serde(default)]
    pub at_bound: Vec<AtBound>,
    /// Everything that makes this fit doubtful (empty for a good fit).
    #[serde(default)]
    pub warnings: Vec<FitWarning>,
    /// The loss of the fit (`"linear"`, `"soft_l1"`, `"huber"`, `"cauchy"`).
    #[serde(default)]
    pub loss: Loss,
    /// Soft margin `C` of a robust loss \[-\] (relative residual; `null` for linear).
    #[serde(default = "nan", deserialize_with = "nullable::f64")]
    pub f_scale: f64,
    /// Where `f_scale` came from (empty for linear).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub f_scale_source: String,
    /// Residuals beyond the soft margin, down-weighted by the robust loss (0 for linear).
    #[serde(default)]
    pub down_weighted: usize,
    /// The systematic uncertainty from what the data cannot identify (process conditions,
    /// instrument, material data), if computed ([`with_error_budget`](Self::with_error_budget)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error_budget: Option<ErrorBudget>,
}

fn nan() -> f64 {
    f64::NAN
}

/// Reading numbers that JSON writes as `null` when they are `NaN` (no standard error, no valid
/// interval), so that a written report reads back.
mod nullable {
    use serde::{Deserialize, Deserializer};

    /// `null` → `NaN`.
    pub fn f64<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
    }

    /// `[null, null]` → `[NaN, NaN]`.
    pub fn pair<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
        let [a, b] = <[Option<f64>; 2]>::deserialize(d)?;
        Ok([a.unwrap_or(f64::NAN), b.unwrap_or(f64::NAN)])
    }
}

/// An effect's strength in a fit report.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EffectReport {
    /// Canonical name (e.g. `"radiation"`).
    pub effect: String,
    /// Strength (in the effect's unit, see `unit`).
    pub strength: f64,
    /// Its standard error (`0` if fixed).
    #[serde(deserialize_with = "nullable::f64")]
    pub stderr_strength: f64,
    /// 95% confidence interval (`NaN` at a bound or without a standard error).
    #[serde(deserialize_with = "nullable::pair")]
    pub ci95_strength: [f64; 2],
    /// Unit of the strength.
    pub unit: String,
    /// Whether it was fitted (else fixed).
    pub fitted: bool,
    /// The bound of its search range the fitted strength sits at, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at_bound: Option<BoundSide>,
    /// Category of the effect (`"physics"`, `"process"`, `"instrument"`; `None` in reports
    /// written before categories existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub category: Option<crate::fiber::effects::Category>,
    /// Its shape parameters (decay lengths, onset), fitted or fixed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shapes: Vec<ShapeReport>,
}

/// A shape parameter of an effect in a fit report.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShapeReport {
    /// Shape name in settings (e.g. `"decay_length"`).
    pub name: String,
    /// Its value (in `unit`).
    pub value: f64,
    /// Its standard error (`0` if fixed).
    #[serde(deserialize_with = "nullable::f64")]
    pub stderr: f64,
    /// Unit (`"m"`).
    pub unit: String,
    /// Whether it was fitted (else fixed).
    pub fitted: bool,
}

/// A symmetric 95% interval, or `NaN` where it is not valid.
fn interval(value: f64, se: f64, valid: bool) -> [f64; 2] {
    let z = 1.96;
    if valid && se.is_finite() {
        [value - z * se, value + z * se]
    } else {
        [f64::NAN; 2]
    }
}

/// `v` with 6 significant digits, trailing zeros trimmed (`1e5` and above or below `1e-3` in
/// exponent notation).
fn fmt_g(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    if v != 0.0 && (v.abs() >= 1e5 || v.abs() < 1e-3) {
        return format!("{v:.4e}");
    }
    let digits = if v == 0.0 {
        0
    } else {
        (5 - v.abs().log10().floor() as i64).clamp(0, 8) as usize
    };
    let t = format!("{v:.digits$}");
    if t.contains('.') {
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        t
    }
}

impl FitReport {
    /// Builds the report of an identification, with its checks (see the module documentation).
    pub fn new(id: &Identification) -> Self {
        let np = id.fit.p.len();
        let se_opt = id.fit.standard_errors();
        let se = se_opt.clone().unwrap_or_else(|| vec![f64::NAN; np]);
        let corr_m = id.fit.correlation();
        let col = |name: &str| id.names.iter().position(|n| n == name);
        let (ni, ki) = (col("n"), col("kappa"));
        let corr = match (ni, ki, &corr_m) {
            (Some(a), Some(b), Some(c)) => c[a * np + b],
            _ => f64::NAN,
        };
        // which fitted parameter sits at a bound
        let sides: Vec<Option<BoundSide>> = (0..np)
            .map(|c| match (id.lower.get(c), id.upper.get(c)) {
                (Some(&lo), Some(&hi)) => bound_side(id.fit.p[c], lo, hi),
                _ => None,
            })
            .collect();
        let side_of = |c: Option<usize>| c.and_then(|c| sides[c]);
        let sn = ni.map_or(f64::NAN, |i| se[i]);
        let sk = ki.map_or(f64::NAN, |i| se[i]);
        let ns = id.names.len();
        let mut at_bound = Vec::new();
        for c in 0..np {
            let Some(side) = sides[c] else { continue };
            let bound_param = match side {
                BoundSide::Lower => id.lower[c],
                BoundSide::Upper => id.upper[c],
            };
            let entry = if c < ns {
                let name = id.names[c].clone();
                match id.effects.iter().find(|e| e.column == Some(c)) {
                    Some(slot) if name != "n" && name != "kappa" => {
                        let e = &slot.effect;
                        AtBound {
                            parameter: name,
                            side: if e.param_per_strength() < 0.0 {
                                side.flipped()
                            } else {
                                side
                            },
                            bound: e.strength_of(bound_param),
                            value: e.strength_of(id.fit.p[c]),
                        }
                    }
                    _ => AtBound {
                        parameter: name,
                        side,
                        bound: bound_param,
                        value: id.fit.p[c],
                    },
                }
            } else {
                let k = c - ns;
                let exp = id
                    .experiment_names
                    .get(k)
                    .cloned()
                    .unwrap_or_else(|| format!("#{}", k + 1));
                AtBound {
                    parameter: format!("take_up_factor[{exp}]"),
                    side,
                    bound: bound_param,
                    value: id.fit.p[c],
                }
            };
            at_bound.push(entry);
        }
        let effects: Vec<EffectReport> = id
            .effects
            .iter()
            .map(|slot| {
                let e = &slot.effect;
                let strength = e.strength_of(id.local_params[slot.local]);
                let sd = slot.column.map_or(0.0, |c| se[c]);
                let side = side_of(slot.column).map(|s| {
                    if e.param_per_strength() < 0.0 {
                        s.flipped()
                    } else {
                        s
                    }
                });
                EffectReport {
                    effect: e.name().to_string(),
                    strength,
                    stderr_strength: sd,
                    ci95_strength: if slot.column.is_some() {
                        interval(strength, sd, side.is_none())
                    } else {
                        [strength; 2]
                    },
                    unit: e.unit().to_string(),
                    fitted: slot.column.is_some(),
                    at_bound: side,
                    category: Some(e.category()),
                    shapes: slot
                        .shapes
                        .iter()
                        .map(|sh| ShapeReport {
                            name: sh.parameter.name.to_string(),
                            value: id.local_params[sh.local],
                            stderr: sh.column.map_or(0.0, |c| se[c]),
                            unit: sh.parameter.unit.to_string(),
                            fitted: sh.column.is_some(),
                        })
                        .collect(),
                }
            })
            .collect();
        let ci95_kappa = interval(id.kappa, sk, side_of(ki).is_none());
        let rms_by: Vec<f64> = id
            .residual_profiles
            .iter()
            .map(|(_, r)| (r.iter().map(|v| v * v).sum::<f64>() / r.len().max(1) as f64).sqrt())
            .collect();
        let (noise_level, noise_source) = match id.relative_uncertainty {
            Some(s) => (s, "declared relative_uncertainty".to_string()),
            None => (
                noise_mad_second_differences(&id.residual_profiles),
                "estimated from second differences of the residuals".to_string(),
            ),
        };
        let mut rep = FitReport {
            estimator: id.estimator,
            law: Some(id.law),
            fitted: id.names.clone(),
            experiments: id.experiment_names.clone(),
            start: id.start,
            n: id.n,
            kappa: id.kappa,
            k_pa: id.kappa.exp(),
            stderr_n: sn,
            stderr_kappa: sk,
            ci95_n: interval(id.n, sn, side_of(ni).is_none()),
            ci95_kappa,
            ci95_k_pa: [ci95_kappa[0].exp(), ci95_kappa[1].exp()],
            correlation_n_kappa: corr,
            cost: 2.0 * id.fit.cost,
            rms_relative_residual: id.rms_relative_residual,
            rms_relative_residual_by_experiment: rms_by,
            noise_level,
            noise_source,
            take_up_factors: id.take_up_factors.clone(),
            residuals: id.fit.num_residuals(),
            iterations: id.fit.iterations,
            failed_evaluations: id.fit.failed_evaluations,
            wall_time_s: id.wall_time_s,
            termination: id.fit.termination.to_string(),
            effects,
            at_bound,
            warnings: Vec::new(),
            loss: id.loss,
            f_scale: id.f_scale,
            f_scale_source: id.f_scale_source.clone(),
            down_weighted: id.down_weighted,
            error_budget: None,
        };
        let mut w = id.data_warnings.clone();
        rep.check_bounds(&mut w);
        rep.check_uncertainty(id, se_opt.is_some(), corr_m.as_deref(), &mut w);
        rep.check_misfit(&mut w);
        rep.warnings = w;
        rep
    }

    fn law_fitted(&self) -> bool {
        self.fitted.iter().any(|n| n == "n" || n == "kappa")
    }

    fn check_bounds(&self, w: &mut Vec<FitWarning>) {
        for b in &self.at_bound {
            let mut m = format!(
                "{} = {} is AT ITS {} BOUND {}: the optimum lies at or beyond the search range, \
                 so its standard error and 95% interval are not valid",
                b.parameter,
                fmt_g(b.value),
                b.side.name().to_uppercase(),
                fmt_g(b.bound)
            );
            if b.parameter == "n"
                && b.side == BoundSide::Upper
                && b.bound >= 1.0
                && self.law_fitted()
            {
                m.push_str(
                    "; n = 1 is the Newtonian limit of the Carreau-type law, where kappa (K) no \
                     longer enters: the data show no strain thinning, or the model misses \
                     something (is the air hotter than the melt, are the data right?)",
                );
            } else if b.parameter == "kappa" {
                m.push_str(&format!(
                    "; K = e^kappa = {:.4e} Pa sits at its {} limit: the data ask for K outside \
                     the search range",
                    b.value.exp(),
                    b.side.name()
                ));
            } else if b.parameter.starts_with("take_up_factor[") {
                m.push_str(
                    "; the fitted take-up diameter is that far from d_fit(L) (or from the TOML's \
                     take_up_* value): check this experiment's take-up condition and data",
                );
            }
            w.push(FitWarning::new(WarningCode::AtBound, m));
        }
    }

    fn check_uncertainty(
        &self,
        id: &Identification,
        have_se: bool,
        corr: Option<&[f64]>,
        w: &mut Vec<FitWarning>,
    ) {
        let np = id.fit.p.len();
        if !have_se && np > 0 {
            w.push(FitWarning::new(
                WarningCode::SingularCovariance,
                format!(
                    "the covariance is singular (J^T J cannot be inverted): the data do not \
                     determine all of the fitted parameters ({}{}); no standard errors or \
                     confidence intervals",
                    self.fitted.join(", "),
                    if self.estimator == Estimator::Principled {
                        ", take-up factors"
                    } else {
                        ""
                    }
                ),
            ));
        } else if let Some(c) = corr {
            let m = DMatrix::from_row_slice(np, np, c);
            if m.iter().all(|v| v.is_finite()) {
                let ev = SymmetricEigen::new(m).eigenvalues;
                let max = ev.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                let min = ev.iter().fold(f64::INFINITY, |a, v| a.min(v.abs()));
                if max > 0.0 && min / max < ILL_CONDITIONED_RCOND {
                    w.push(FitWarning::new(
                        WarningCode::IllConditioned,
                        format!(
                            "the covariance is ill-conditioned (reciprocal condition number \
                             {:.1e} of the correlation matrix): some combination of the fitted \
                             parameters is not determined by the data; standard errors are \
                             unreliable",
                            min / max
                        ),
                    ));
                }
            } else {
                w.push(FitWarning::new(
                    WarningCode::IllConditioned,
                    "the correlation matrix of the fitted parameters is not finite: standard \
                     errors are unreliable"
                        .to_string(),
                ));
            }
        }
        let at = |name: &str| self.at_bound.iter().any(|b| b.parameter == name);
        if self.fitted.iter().any(|n| n == "n") && self.stderr_n > LARGE_STDERR_N {
            w.push(FitWarning::new(
                WarningCode::LargeUncertainty,
                format!(
                    "the standard error of n is {} (> {LARGE_STDERR_N}): the data do not \
                     determine n",
                    fmt_g(self.stderr_n)
                ),
            ));
        }
        if self.fitted.iter().any(|n| n == "kappa") {
            if self.stderr_kappa > LARGE_STDERR_KAPPA {
                w.push(FitWarning::new(
                    WarningCode::LargeUncertainty,
                    format!(
                        "the standard error of kappa is {} (> {LARGE_STDERR_KAPPA}, a factor \
                         {:.3} in K): the data do not determine kappa or K",
                        fmt_g(self.stderr_kappa),
                        LARGE_STDERR_KAPPA.exp()
                    ),
                ));
            }
            let [a, b] = self.ci95_k_pa;
            if !at("kappa") && self.stderr_kappa.is_finite() && (a <= 0.0 || b.is_infinite()) {
                w.push(FitWarning::new(
                    WarningCode::LargeUncertainty,
                    format!(
                        "the 95% interval of K is [{a:.4e}, {b:.4e}] Pa: unbounded, K is not \
                         determined"
                    ),
                ));
            }
        }
        for (slot, e) in id.effects.iter().zip(&self.effects) {
            if !e.fitted || e.at_bound.is_some() {
                continue;
            }
            let (lo, hi) = slot.effect.bounds();
            let limit = LARGE_STDERR_STRENGTH_FRACTION * (hi - lo).abs();
            if e.stderr_strength > limit && !(slot.column == Some(0) && at("n")) {
                w.push(FitWarning::new(
                    WarningCode::LargeUncertainty,
                    format!(
                        "the standard error of the {} strength is {} {} (more than {}% of its \
                         search range [{lo}, {hi}]): the data do not determine it",
                        e.effect,
                        fmt_g(e.stderr_strength),
                        e.unit,
                        100.0 * LARGE_STDERR_STRENGTH_FRACTION
                    ),
                ));
            }
        }
    }

    fn check_misfit(&self, w: &mut Vec<FitWarning>) {
        let rms = self.rms_relative_residual;
        let noise = self.noise_level;
        let (bad, limit) = if noise.is_finite() && noise > 0.0 {
            (rms > MISFIT_RATIO * noise, MISFIT_RATIO * noise)
        } else {
            (rms > MISFIT_WITHOUT_NOISE, MISFIT_WITHOUT_NOISE)
        };
        if !(bad || rms.is_nan()) {
            return;
        }
        let mut worst: Vec<(usize, f64)> = self
            .rms_relative_residual_by_experiment
            .iter()
            .copied()
            .enumerate()
            .filter(|(_, r)| r.is_nan() || *r > limit)
            .collect();
        worst.sort_by(|a, b| b.1.total_cmp(&a.1));
        let names: Vec<String> = worst
            .iter()
            .take(5)
            .map(|(k, r)| {
                let name = self
                    .experiments
                    .get(*k)
                    .cloned()
                    .unwrap_or_else(|| format!("#{}", k + 1));
                format!("{name} ({:.3} %)", 100.0 * r)
            })
            .collect();
        let noise_text = if noise.is_finite() && noise > 0.0 {
            format!(
                "{:.1} times the noise level {:.3} % ({})",
                rms / noise,
                100.0 * noise,
                self.noise_source
            )
        } else {
            format!(
                "above {:.0} % (no noise level: too few points to estimate it)",
                100.0 * MISFIT_WITHOUT_NOISE
            )
        };
        let mut m = format!(
            "misfit far above the noise: the RMS relative residual {:.3} % is {noise_text}; the \
             model does not describe these data",
            100.0 * rms
        );
        if !names.is_empty() {
            m.push_str(&format!(
                "; experiments with RMS above {:.3} %: {}{}",
                100.0 * limit,
                names.join(", "),
                if worst.len() > names.len() {
                    format!(" and {} more", worst.len() - names.len())
                } else {
                    String::new()
                }
            ));
        }
        if self.noise_source.starts_with("declared") {
            m.push_str(" (or the declared relative_uncertainty is too small)");
        }
        m.push_str(": check their data, TOML entries (temperatures, take-up) and the model");
        w.push(FitWarning::new(WarningCode::Misfit, m));
    }

    /// The report with the error budget `budget`: its section in the text, its object in JSON,
    /// and a [`WarningCode::Systematic`] warning for each source that shifts `κ` or `n` by more
    /// than the statistical standard error.
    pub fn with_error_budget(mut self, budget: ErrorBudget) -> Self {
        self.warnings.extend(budget.warnings());
        self.error_budget = Some(budget);
        self
    }

    /// Whether `(n, κ)` lies in the 95% confidence region box (false where an interval is not
    /// valid).
    pub fn covers(&self, n: f64, kappa: f64) -> bool {
        n >= self.ci95_n[0]
            && n <= self.ci95_n[1]
            && kappa >= self.ci95_kappa[0]
            && kappa <= self.ci95_kappa[1]
    }

    /// Whether any check found something (see [`warnings`](Self::warnings)).
    pub fn has_warnings(&self) -> bool {
        !self.warnings.is_empty()
    }

    fn bound_of(&self, parameter: &str) -> Option<&AtBound> {
        self.at_bound.iter().find(|b| b.parameter == parameter)
    }

    fn variable_line(&self, label: &str, name: &str, value: f64, se: f64, ci: [f64; 2]) -> String {
        if let Some(b) = self.bound_of(name) {
            format!(
                "    {label} {value:.5} AT {} BOUND {} ({}no valid 95% CI: the optimum lies at or \
                 beyond the search range)\n",
                b.side.name().to_uppercase(),
                fmt_g(b.bound),
                if se.is_finite() {
                    format!("+/- {} not valid; ", fmt_g(se))
                } else {
                    String::new()
                }
            )
        } else if !se.is_finite() {
            format!("    {label} {value:.5} +/- (no standard error: singular covariance)\n")
        } else if se >= 1e5 {
            format!(
                "    {label} {value:.5} +/- {se:.3e}  95% CI [{:.3e}, {:.3e}] (not determined)\n",
                ci[0], ci[1]
            )
        } else {
            format!(
                "    {label} {value:.5} +/- {se:.5} ({:.2}%)  95% CI [{:.5}, {:.5}]\n",
                100.0 * se / value.abs(),
                ci[0],
                ci[1]
            )
        }
    }

    /// An lmfit-style text report, with a `[[Warnings]]` section when a check found something.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        s.push_str(&format!("[[Fit: {} estimator]]\n", self.estimator.name()));
        if let Some(law) = self.law {
            s.push_str(&format!(
                "    model law         = {}{}\n",
                match law {
                    LawChoice::Carreau => "Carreau-type",
                    LawChoice::Newtonian => "Newtonian",
                },
                if self.fitted.is_empty() {
                    String::new()
                } else {
                    format!(" (fitted: {})", self.fitted.join(", "))
                }
            ));
        }
        s.push_str(&format!(
            "    start             = (n, kappa) = ({}, {})\n",
            self.start[0], self.start[1]
        ));
        s.push_str(&format!("    termination       = {}\n", self.termination));
        s.push_str(&format!(
            "    iterations        = {} ({} failed BVP trial points)\n",
            self.iterations, self.failed_evaluations
        ));
        s.push_str(&format!(
            "    wall time         = {:.3} s\n",
            self.wall_time_s
        ));
        s.push_str(&format!("    residuals         = {}\n", self.residuals));
        s.push_str(&format!("    cost J            = {:.6e}\n", self.cost));
        if !self.loss.is_linear() {
            s.push_str(&format!(
                "    loss              = {} (f_scale {:.3} % relative residual, {}; {} of {} \
                 residuals beyond it, down-weighted; CIs from the sandwich covariance)\n",
                self.loss,
                100.0 * self.f_scale,
                self.f_scale_source,
                self.down_weighted,
                self.residuals
            ));
        }
        s.push_str(&format!(
            "    RMS (d_model - d_meas)/d_meas = {:.4} %\n",
            100.0 * self.rms_relative_residual
        ));
        if self.noise_level.is_finite() {
            s.push_str(&format!(
                "    noise level       = {:.4} % ({})\n",
                100.0 * self.noise_level,
                self.noise_source
            ));
        }
        if !self.warnings.is_empty() {
            s.push_str(&format!(
                "[[Warnings: {} — do not use these estimates without checking]]\n",
                self.warnings.len()
            ));
            for w in &self.warnings {
                s.push_str(&format!("    WARNING {w}\n"));
            }
        }
        s.push_str("[[Variables]]\n");
        let n_fitted = self.fitted.iter().any(|n| n == "n");
        let k_fitted = self.fitted.iter().any(|n| n == "kappa");
        let law_known = self.law.is_some();
        if law_known && !n_fitted && !k_fitted && self.law == Some(LawChoice::Newtonian) {
            s.push_str("    law:   Newtonian (n = 1 fixed; kappa and K do not enter)\n");
        } else {
            if n_fitted || !law_known {
                s.push_str(&self.variable_line("n:    ", "n", self.n, self.stderr_n, self.ci95_n));
            } else {
                s.push_str(&format!("    n:     {:.5} (fixed)\n", self.n));
            }
            s.push_str(&self.variable_line(
                "kappa:",
                "kappa",
                self.kappa,
                self.stderr_kappa,
                self.ci95_kappa,
            ));
            if self.ci95_k_pa.iter().all(|v| !v.is_nan()) {
                s.push_str(&format!(
                    "    K:     {:.5e} Pa  95% CI [{:.5e}, {:.5e}] Pa\n",
                    self.k_pa, self.ci95_k_pa[0], self.ci95_k_pa[1]
                ));
            } else {
                s.push_str(&format!(
                    "    K:     {:.5e} Pa  (no valid 95% CI)\n",
                    self.k_pa
                ));
            }
        }
        if self.estimator == Estimator::Principled {
            let f: Vec<String> = self
                .take_up_factors
                .iter()
                .map(|v| format!("{v:.4}"))
                .collect();
            s.push_str(&format!(
                "    take-up factors d_out/d_fit(L): [{}]\n",
                f.join(", ")
            ));
            for b in self
                .at_bound
                .iter()
                .filter(|b| b.parameter.starts_with("take_up_factor["))
            {
                s.push_str(&format!(
                    "    {}: {:.4} AT {} BOUND {}\n",
                    b.parameter,
                    b.value,
                    b.side.name().to_uppercase(),
                    fmt_g(b.bound)
                ));
            }
        }
        for e in &self.effects {
            if !e.fitted {
                s.push_str(&format!(
                    "    {}: {:.5} {} (fixed)\n",
                    e.effect, e.strength, e.unit
                ));
            } else if let Some(side) = e.at_bound {
                let bound = self
                    .bound_of(&e.effect)
                    .map_or(String::new(), |b| format!(" {}", fmt_g(b.bound)));
                s.push_str(&format!(
                    "    {}: {:.5} {} AT {} BOUND{bound} (no valid 95% CI)\n",
                    e.effect,
                    e.strength,
                    e.unit,
                    side.name().to_uppercase(),
                ));
            } else {
                s.push_str(&format!(
                    "    {}: {:.5} +/- {:.5} {}  95% CI [{:.5}, {:.5}]\n",
                    e.effect,
                    e.strength,
                    e.stderr_strength,
                    e.unit,
                    e.ci95_strength[0],
                    e.ci95_strength[1]
                ));
            }
            for sh in &e.shapes {
                if sh.fitted {
                    s.push_str(&format!(
                        "      {}.{}: {:.5} +/- {:.5} {}\n",
                        e.effect, sh.name, sh.value, sh.stderr, sh.unit
                    ));
                } else {
                    s.push_str(&format!(
                        "      {}.{}: {:.5} {} (fixed)\n",
                        e.effect, sh.name, sh.value, sh.unit
                    ));
                }
            }
        }
        if self.correlation_n_kappa.is_finite() {
            s.push_str("[[Correlations]]\n");
            s.push_str(&format!(
                "    C(n, kappa) = {:+.4}\n",
                self.correlation_n_kappa
            ));
        }
        if let Some(b) = &self.error_budget {
            s.push_str(&b.to_text());
        }
        s
    }
}

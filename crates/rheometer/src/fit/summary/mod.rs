//! The outcome of a fit as one value: [`FitSummary`].
//!
//! An identification ([`Rheometer::identify`](crate::fit::Rheometer::identify)) produces it once;
//! the text report renders it ([`FitSummary::to_text`]), the JSON serialises it, and the next
//! step reads it back (`compare --fit`, `fit --from`, `diagnose`, the Python package). Nothing
//! copies its numbers into other structs: a diagnosis' refits hold their own summaries.
//!
//! Standard errors come from the Gauss–Newton approximation of the covariance,
//! `σ̂² (JᵀJ)⁻¹` with the residual variance `σ̂² = ‖r‖²/(N − p)` (the sandwich covariance
//! under a robust loss); 95% confidence intervals are `± 1.96` standard errors (normal
//! approximation; `N` is in the hundreds). For `K = e^κ` the interval is the image of κ's. For
//! the paper's estimator the residuals are weighted distances to smoothed data, not
//! measurement errors: its standard errors are shown for comparison only. The checks that make
//! a fit doubtful are in [`summary::checks`](crate::fit::summary::checks).

pub(crate) mod build;
pub(crate) mod checks;
pub(crate) mod finding;
pub(crate) mod read;
pub(crate) mod text;

use crate::data::noise_summary::NoiseSummary;
use crate::fit::estimator::Estimator;
pub use crate::fit::options::{BoundSide, FitWarning, WarningCode};
use crate::fit::values::budget::ErrorBudget;
use crate::fit::values::coverage::StrainRateCoverage;
use crate::fit::values::curve::FlowCurve;
use crate::fit::values::likelihood::{NewtonianTest, ProfileInterval};
use crate::model::effects::{Category, LawChoice};
use crate::report::serde_nan;
use diffbvp::least_squares::{Loss, Termination};
use serde::{Deserialize, Deserializer, Serialize};

/// Half-width of a two-sided 95 % normal interval in standard errors.
pub(crate) const Z95: f64 = 1.959_963_984_540_054;

/// An estimate at a bound of its search range (JSON:
/// `{"parameter": "kappa", "side": "lower", "bound": 7.0, "value": 7.0}`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AtBound {
    /// `"n"`, `"kappa"`, an effect's name, `"effect.shape"`, or
    /// `"take_up_factor[EXPERIMENT]"`.
    pub parameter: String,
    /// Which bound.
    pub side: BoundSide,
    /// The bound (in the reported unit: the effect's strength unit for effects, \[-\] else).
    pub bound: f64,
    /// The estimate (same unit).
    pub value: f64,
}

/// A named parameter of a fit with its uncertainty (JSON: `{"name": "n", "value": 0.804,
/// "unit": "-", "stderr": 0.007, "ci95": [0.790, 0.818], "fitted": true}`).
///
/// A fixed parameter has `stderr = 0` and the degenerate interval `[value, value]`; a fitted
/// one at a bound (`at_bound`) or without a standard error (singular covariance) has no valid
/// interval (`NaN`, written `null`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Estimate {
    /// Name (`"n"`, `"kappa"`, `"K"`, an effect's name, a shape's name).
    pub name: String,
    /// Value (in `unit`).
    pub value: f64,
    /// Unit (`"-"` for dimensionless, `"Pa"`, `"m/s"`, `"K"`, `"m"`, ...).
    pub unit: String,
    /// Standard error (same unit; `0` if fixed, `NaN` if none).
    pub stderr: f64,
    /// 95 % confidence interval (`NaN` where not valid).
    pub ci95: [f64; 2],
    /// Whether it was fitted (else fixed or derived from fitted ones).
    pub fitted: bool,
    /// The bound of its search range a fitted estimate sits at, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at_bound: Option<BoundSide>,
}

/// The JSON form of an [`Estimate`] (reports written before estimates were objects give a
/// bare number, read as a value without uncertainty).
#[derive(Deserialize)]
#[serde(untagged)]
enum EstimateForm {
    Object {
        #[serde(default)]
        name: String,
        value: f64,
        #[serde(default)]
        unit: String,
        #[serde(default = "serde_nan::nan", deserialize_with = "serde_nan::f64")]
        stderr: f64,
        #[serde(default = "nan_pair", deserialize_with = "serde_nan::pair")]
        ci95: [f64; 2],
        #[serde(default)]
        fitted: bool,
        #[serde(default)]
        at_bound: Option<BoundSide>,
    },
    Number(f64),
}

fn nan_pair() -> [f64; 2] {
    [f64::NAN; 2]
}

impl<'de> Deserialize<'de> for Estimate {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Ok(match EstimateForm::deserialize(d)? {
            EstimateForm::Object {
                name,
                value,
                unit,
                stderr,
                ci95,
                fitted,
                at_bound,
            } => Estimate {
                name,
                value,
                unit,
                stderr,
                ci95,
                fitted,
                at_bound,
            },
            EstimateForm::Number(value) => Estimate {
                value,
                ..Estimate::fixed("", value, "-")
            },
        })
    }
}

impl Estimate {
    /// A fixed (not fitted) parameter: standard error 0, interval `[value, value]`.
    pub fn fixed(name: &str, value: f64, unit: &str) -> Self {
        Estimate {
            name: name.into(),
            value,
            unit: unit.into(),
            stderr: 0.0,
            ci95: [value; 2],
            fitted: false,
            at_bound: None,
        }
    }

    /// A fitted parameter with standard error `stderr` (`NaN`: none) and, unless `at_bound`,
    /// the symmetric 95 % interval.
    pub fn fitted(
        name: &str,
        value: f64,
        unit: &str,
        stderr: f64,
        at_bound: Option<BoundSide>,
    ) -> Self {
        let ci95 = if at_bound.is_none() && stderr.is_finite() {
            [value - Z95 * stderr, value + Z95 * stderr]
        } else {
            [f64::NAN; 2]
        };
        Estimate {
            name: name.into(),
            value,
            unit: unit.into(),
            stderr,
            ci95,
            fitted: true,
            at_bound,
        }
    }

    /// The standard error where the 95 % interval is valid (finite), `NaN` else.
    pub fn valid_stderr(&self) -> f64 {
        if self.ci95.iter().all(|v| v.is_finite()) {
            self.stderr
        } else {
            f64::NAN
        }
    }

    /// An estimate not known (a report written before it existed): `NaN` everywhere.
    pub fn unknown() -> Self {
        Estimate {
            name: String::new(),
            value: f64::NAN,
            unit: String::new(),
            stderr: f64::NAN,
            ci95: [f64::NAN; 2],
            fitted: false,
            at_bound: None,
        }
    }

    /// Whether its interval is valid (finite).
    pub fn has_interval(&self) -> bool {
        self.ci95.iter().all(|v| v.is_finite())
    }

    /// Whether `v` lies in its 95 % interval (false where the interval is not valid).
    pub fn covers(&self, v: f64) -> bool {
        self.has_interval() && v >= self.ci95[0] && v <= self.ci95[1]
    }
}

/// An effect of the fitted model with its strength and shapes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EffectEstimate {
    /// Canonical name (e.g. `"radiation"`).
    pub effect: String,
    /// Category of the effect (`None` in reports written before categories existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub category: Option<Category>,
    /// Its strength (named after the effect, in the effect's unit).
    pub strength: Estimate,
    /// Its shape parameters (decay lengths, onset, tail), fitted or fixed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shapes: Vec<Estimate>,
}

/// Covariance of the fitted shared parameters in their reported units (the strengths in the
/// effects' units), rows and columns in the order of `names`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Covariance {
    /// Parameter names (`"n"`, `"kappa"`, effect names, `"effect.shape"`).
    pub names: Vec<String>,
    /// The matrix, row-major (`names.len()²` entries).
    pub matrix: Vec<f64>,
}

impl SolverRecord {
    /// Why the fit stopped, in words (`"not recorded"` for a record without it).
    pub fn termination_text(&self) -> String {
        self.termination
            .as_ref()
            .map_or_else(|| "not recorded".to_string(), |t| t.to_string())
    }
}

impl Covariance {
    /// The entry of parameters `a` and `b` (`None` if either is not fitted).
    pub fn get(&self, a: &str, b: &str) -> Option<f64> {
        let i = self.names.iter().position(|n| n == a)?;
        let j = self.names.iter().position(|n| n == b)?;
        self.matrix.get(i * self.names.len() + j).copied()
    }
}

/// How the fit ran: iterations, termination, time, discretisation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SolverRecord {
    /// Gauss–Newton trial steps.
    pub iterations: usize,
    /// Trial points where a BVP failed (rejected steps).
    pub failed_evaluations: usize,
    /// Why the fit stopped (`None` only in a record without it).
    pub termination: Option<Termination>,
    /// Wall time \[s\].
    pub wall_time_s: f64,
    /// BVP tolerance of the final solves \[-\].
    #[serde(default = "serde_nan::nan", deserialize_with = "serde_nan::f64")]
    pub bvp_tolerance: f64,
    /// Mesh nodes of each experiment's final solution.
    #[serde(default)]
    pub nodes: Vec<usize>,
    /// The largest shift of a fitted shared parameter, in its standard errors, by the
    /// discretisation error of the BVPs, estimated at the optimum by re-solving every
    /// experiment on its mesh with every interval halved (Richardson; `NaN`: not checked).
    #[serde(default = "serde_nan::nan", deserialize_with = "serde_nan::f64")]
    pub discretisation_shift_se: f64,
    /// Mesh nodes of each experiment's halved mesh in the discretisation check (empty: not
    /// checked).
    #[serde(default)]
    pub check_nodes: Vec<usize>,
}

/// The outcome of an identification (the JSON of `rheometer fit --json`).
///
/// Fields added after the first release default when missing, so older reports still read
/// (there `n` and `kappa` are bare numbers, read as estimates without uncertainty). Standard
/// errors and intervals that do not exist (a singular covariance, an estimate at a bound) are
/// `NaN`, written as `null`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FitSummary {
    /// Estimator (`"paper"` or `"principled"`).
    pub estimator: Estimator,
    /// The viscosity law of the fitted model, as chosen for the fit (never inferred from the
    /// values).
    #[serde(default)]
    pub law: LawChoice,
    /// Names of the fitted shared parameters (`"n"`, `"kappa"`, effect names, shapes); the
    /// take-up factors of the principled estimator are fitted too.
    #[serde(default)]
    pub fitted: Vec<String>,
    /// Experiment names, in the order of `take_up_factors`.
    #[serde(default)]
    pub experiments: Vec<String>,
    /// A digest of the data the fit was made on ([`data_digest`](crate::fit::data_digest): the
    /// experiments' names, conditions and measurements), so that a reader can tell this
    /// fit's data from other data with the same experiment names (empty: not recorded).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub data_digest: String,
    /// Start point `(n, κ)`.
    #[serde(default = "nan_pair", deserialize_with = "serde_nan::pair")]
    pub start: [f64; 2],
    /// Power index `n` \[-\] of the Carreau-type law.
    pub n: Estimate,
    /// `κ = ln(K / 1 Pa)` \[-\].
    pub kappa: Estimate,
    /// `K = e^κ` \[Pa\] (its interval is the image of κ's; its standard error `K·se(κ)`).
    #[serde(rename = "K_Pa", default = "Estimate::unknown")]
    pub k_pa: Estimate,
    /// Correlation of `n` and `κ` (`NaN` if either is not fitted or no covariance).
    #[serde(default = "serde_nan::nan", deserialize_with = "serde_nan::f64")]
    pub correlation_n_kappa: f64,
    /// Covariance of the fitted shared parameters (`None` when singular or none fitted).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub covariance: Option<Covariance>,
    /// The model's extra effects with their strengths (empty for the paper's model).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub effects: Vec<EffectEstimate>,
    /// Take-up factors `φ_k = d_out,k/d_fit,k(L)` \[-\] (1 for the paper's estimator).
    #[serde(default)]
    pub take_up_factors: Vec<f64>,
    /// Cost `J = ‖r‖²` of the estimator at the optimum (`C² Σ ρ((rᵢ/C)²)` under a robust loss).
    #[serde(default = "serde_nan::nan", deserialize_with = "serde_nan::f64")]
    pub cost: f64,
    /// RMS of `(d_model − d_meas)/d_meas` over all raw measurements \[-\].
    #[serde(default = "serde_nan::nan", deserialize_with = "serde_nan::f64")]
    pub rms_relative_residual: f64,
    /// RMS relative residual of each experiment \[-\], in the order of `experiments`.
    #[serde(default)]
    pub rms_relative_residual_by_experiment: Vec<f64>,
    /// Number of residuals.
    #[serde(default)]
    pub residuals: usize,
    /// The one noise level of these data and this model, and the noise model behind it.
    #[serde(default)]
    pub noise: NoiseSummary,
    /// How the fit ran.
    #[serde(default)]
    pub solver: SolverRecord,
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
    #[serde(default = "serde_nan::nan", deserialize_with = "serde_nan::f64")]
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
    /// The strain rates the data cover (`None` in reports written before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub strain_rates: Option<StrainRateCoverage>,
    /// Profile-likelihood intervals of the fitted law parameters and strengths, with the
    /// reasons the linearised interval is not trusted where it is not (see
    /// `profile`); empty where the model misses the data by several times
    /// the noise ([`likelihood_skipped`](Self::likelihood_skipped)).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub intervals: Vec<ProfileInterval>,
    /// The likelihood-ratio test against the nested Newtonian law, where `n` is fitted (and
    /// not [`likelihood_skipped`](Self::likelihood_skipped)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub newtonian_test: Option<NewtonianTest>,
    /// The identified law as a flow curve `η_E(ε̇)` with its bands.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flow_curve: Option<FlowCurve>,
}

impl Default for SolverRecord {
    fn default() -> Self {
        SolverRecord {
            iterations: 0,
            failed_evaluations: 0,
            termination: None,
            wall_time_s: f64::NAN,
            bvp_tolerance: f64::NAN,
            nodes: Vec::new(),
            discretisation_shift_se: f64::NAN,
            check_nodes: Vec::new(),
        }
    }
}

impl FitSummary {
    /// The summary with the error budget `budget`: its section in the text, its object in
    /// JSON, and a [`WarningCode::Systematic`] warning where the systematic uncertainty
    /// dominates ([`ErrorBudget::warnings`]).
    pub fn with_error_budget(mut self, budget: ErrorBudget) -> Self {
        self.warnings.extend(budget.warnings());
        self.error_budget = Some(budget);
        self
    }

    /// `(n, κ)` of the fitted model.
    pub fn law_params(&self) -> [f64; 2] {
        [self.n.value, self.kappa.value]
    }

    /// Whether `(n, κ)` lies in the 95 % confidence box (false where an interval is not valid).
    pub fn covers(&self, n: f64, kappa: f64) -> bool {
        self.n.covers(n) && self.kappa.covers(kappa)
    }

    /// Whether any check found something (see [`warnings`](Self::warnings)).
    pub fn has_warnings(&self) -> bool {
        !self.warnings.is_empty()
    }

    /// The effect named `name`, if the model has it.
    pub fn effect(&self, name: &str) -> Option<&EffectEstimate> {
        self.effects.iter().find(|e| e.effect == name)
    }

    /// Every named estimate: `n`, `κ`, then each effect's strength and shapes (shapes named
    /// `effect.shape`).
    pub fn parameters(&self) -> Vec<Estimate> {
        let mut v = vec![self.n.clone(), self.kappa.clone()];
        for e in &self.effects {
            v.push(e.strength.clone());
            for s in &e.shapes {
                v.push(Estimate {
                    name: format!("{}.{}", e.effect, s.name),
                    ..s.clone()
                });
            }
        }
        v
    }

    /// Whether `n` or `κ` was fitted.
    pub fn law_fitted(&self) -> bool {
        self.fitted.iter().any(|n| n == "n" || n == "kappa")
    }

    /// Number of parameters the fit adjusted to the data: the shared ones and, for the
    /// principled estimator, one take-up factor per experiment.
    pub fn fitted_parameters(&self) -> usize {
        self.fitted.len()
            + match self.estimator {
                Estimator::Principled => self.take_up_factors.len(),
                Estimator::Paper => 0,
            }
    }

    /// The bound entry of `parameter`, if it sits at one.
    pub fn bound_of(&self, parameter: &str) -> Option<&AtBound> {
        self.at_bound.iter().find(|b| b.parameter == parameter)
    }

    /// The law parameter (`n` or `kappa`) at a bound of its range, if any: such a law has no
    /// valid interval and is no material result.
    pub fn law_at_bound(&self) -> Option<&AtBound> {
        self.bound_of("n").or_else(|| self.bound_of("kappa"))
    }

    /// Why this fit's material law is not a result, if it is not: `n` or `κ` at a bound of
    /// its range (no valid interval there), an `implausible` warning (an `n` no polymer melt
    /// has, a law that jumped far from the plain fit for no gain, a stand-in effect, two
    /// explanations that disagree on the law), or a `misfit` warning (the model misses the
    /// data by several times the noise: the law compensates what the model lacks): the
    /// warning's finding up to its first colon.
    /// `None` where the law was not fitted or is a result; where the likelihood-ratio test
    /// prefers the Newtonian law ([`newtonian_on_data`](Self::newtonian_on_data)) a bound of
    /// `n` or `κ` is no reason (the result is the Newtonian law within the data's strain rates). The one rule for the fit's text,
    /// figures, flow curve and HTML page.
    pub fn law_not_a_result(&self) -> Option<String> {
        if !self.law_fitted() {
            return None;
        }
        // where the Newtonian law is preferred the result is that law, not (n, κ): a bound
        // of theirs is one of its corners
        if let Some(b) = self.law_at_bound().filter(|_| !self.newtonian_on_data()) {
            let newtonian = b.parameter == "n" && b.side == BoundSide::Upper && b.bound == 1.0;
            return Some(format!(
                "{} is at its {} bound {}, where the fit has no valid interval{}",
                b.parameter,
                b.side.name(),
                crate::report::format::fmt_g(b.bound),
                if !newtonian {
                    ""
                } else if self.misfit_warned() {
                    " (the Carreau-type law is Newtonian there and kappa is not determined)"
                } else {
                    " (the Carreau-type law is Newtonian there and kappa is not determined; \
                     whether the Newtonian law fits is said below)"
                }
            ));
        }
        // an implausible law first, then a misfit (RMS beyond MISFIT_RATIO times the noise:
        // the model does not describe the data, and the law compensates what it lacks)
        [WarningCode::Implausible, WarningCode::Misfit]
            .iter()
            .find_map(|code| self.warnings.iter().find(|w| w.code == *code))
            .map(|w| match w.message.split_once(':') {
                Some((head, _)) => head.trim().to_string(),
                None => w.message.trim().to_string(),
            })
    }

    /// Why the profile-likelihood intervals and the likelihood-ratio test against the
    /// Newtonian law are not computed for this fit: a `misfit` warning (the RMS relative
    /// residual beyond `MISFIT_RATIO` times the
    /// noise). Both read the deviance as a likelihood of a model that describes the data up to the
    /// noise; where it misses them by several times the noise they would be statements about
    /// a wrong model (the law is no result either, see [`law_not_a_result`](Self::law_not_a_result)),
    /// and their refits of such a model are slow (each walks far from the optimum of a model
    /// that does not fit). `None`: they are computed.
    pub fn likelihood_skipped(&self) -> Option<String> {
        self.misfit_warned().then(|| {
            let noise = self.noise.level;
            let times = if noise.is_finite() && noise > 0.0 {
                format!("{:.1} times the noise", self.rms_relative_residual / noise)
            } else {
                "far more than the noise".to_string()
            };
            format!(
                "the model misses the data by {times} (warning misfit): likelihood \
                     intervals and tests of a model that does not describe the data would be no \
                     result"
            )
        })
    }

    /// Whether the law was fitted and the fit carries a `misfit` warning (the one condition
    /// of [`likelihood_skipped`](Self::likelihood_skipped)).
    fn misfit_warned(&self) -> bool {
        self.law_fitted() && self.warnings.iter().any(|w| w.code == WarningCode::Misfit)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::data::noise_summary::{NoiseSource, ESTIMATED_NOISE_WORDS};

    /// A summary of a refit with `effect` at `(strength, se)`, `n` and `κ` at `(value, se)`.
    pub(crate) fn refit_summary(
        effect: &str,
        strength: (f64, f64),
        n: (f64, f64),
        kappa: (f64, f64),
    ) -> FitSummary {
        let kp = Estimate::fitted("kappa", kappa.0, "-", kappa.1, None);
        FitSummary {
            data_digest: String::new(),
            estimator: Estimator::Principled,
            law: LawChoice::Carreau,
            fitted: vec!["n".into(), "kappa".into(), effect.into()],
            experiments: vec!["a".into()],
            start: [0.5, 12.0],
            n: Estimate::fitted("n", n.0, "-", n.1, None),
            k_pa: Estimate {
                name: "K".into(),
                value: kappa.0.exp(),
                unit: "Pa".into(),
                stderr: kappa.0.exp() * kappa.1,
                ci95: [kp.ci95[0].exp(), kp.ci95[1].exp()],
                fitted: true,
                at_bound: None,
            },
            kappa: kp,
            correlation_n_kappa: 0.5,
            covariance: None,
            effects: vec![EffectEstimate {
                effect: effect.into(),
                category: None,
                strength: Estimate::fitted(effect, strength.0, "-", strength.1, None),
                shapes: Vec::new(),
            }],
            take_up_factors: vec![1.0],
            cost: 0.5,
            rms_relative_residual: 0.015,
            rms_relative_residual_by_experiment: vec![0.015],
            residuals: 100,
            noise: NoiseSummary {
                level: 0.015,
                source: NoiseSource::Estimated,
                estimator: ESTIMATED_NOISE_WORDS.into(),
                rms_over_noise: 1.0,
                model: None,
            },
            solver: SolverRecord {
                iterations: 5,
                failed_evaluations: 0,
                termination: Some(Termination::CostChange),
                wall_time_s: 0.0,
                bvp_tolerance: 1e-6,
                nodes: vec![100],
                discretisation_shift_se: f64::NAN,
                check_nodes: Vec::new(),
            },
            at_bound: Vec::new(),
            warnings: Vec::new(),
            loss: Loss::Linear,
            f_scale: f64::NAN,
            f_scale_source: String::new(),
            down_weighted: 0,
            error_budget: None,
            strain_rates: None,
            intervals: Vec::new(),
            newtonian_test: None,
            flow_curve: None,
        }
    }

    /// A refit summary with strength 0.5 ± 0.1, `n` 0.8 ± 0.01, `κ` 11.7 ± 0.1.
    pub(crate) fn example() -> FitSummary {
        refit_summary("a", (0.5, 0.1), (0.8, 0.01), (11.7, 0.1))
    }

    #[test]
    fn estimates_read_back_and_legacy_numbers_read_as_values() {
        let s = example();
        let js = serde_json::to_string(&s).unwrap();
        let back: FitSummary = serde_json::from_str(&js).unwrap();
        assert_eq!(back.n, s.n);
        assert_eq!(back.effects, s.effects);
        assert_eq!(back.noise, s.noise);
        let legacy: Estimate = serde_json::from_str("0.8").unwrap();
        assert_eq!(legacy.value, 0.8);
        assert!(!legacy.fitted && legacy.stderr == 0.0);
        let null_se: Estimate =
            serde_json::from_str(r#"{"value": 1.0, "stderr": null, "ci95": [null, null]}"#)
                .unwrap();
        assert!(null_se.stderr.is_nan() && !null_se.has_interval());
    }
}

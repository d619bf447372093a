//! The one noise level of a fit: what the misfit of every command (`fit`, `compare`,
//! `diagnose`) is judged against, from the one [`NoiseModel`] of the residuals.
//!
//! * **Declared**: the data set's `relative_uncertainty` (or an option) \[-\].
//! * **Estimated**: the RMS of the local noise `σ(sᵢ/L)` of the [`NoiseModel`] over the
//!   measurement points, outliers excluded ([`NoiseModel::noise_rms`]): robust (from
//!   spacing-normalised second differences, which cancel a smooth misfit), and like with like
//!   with the RMS of the residuals it judges, also when the noise grows toward the take-up.
//!
//! The noise model is always estimated (also with a declared level): it flags the outliers,
//! describes the noise along the line and gives the lag-1 autocorrelation.

use crate::data::noise_model::{NoiseModel, NoiseOptions, ResidualSeries};
use serde::{Deserialize, Serialize};

/// Where a noise level comes from (JSON: `"declared"`, `"estimated"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseSource {
    /// Given: the data set's `relative_uncertainty` or an option.
    #[serde(alias = "given")]
    Declared,
    /// Estimated from the residuals by the noise model.
    Estimated,
}

/// The words naming the estimator of an estimated noise level (printed once per report).
pub const ESTIMATED_NOISE_WORDS: &str =
    "estimated: RMS of the local noise along the line, from second differences of the \
     residuals, outliers excluded";

/// The words naming a declared noise level.
pub const DECLARED_NOISE_WORDS: &str = "declared relative_uncertainty";

/// The noise level of a fit or comparison and the noise model behind it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoiseSummary {
    /// Relative noise level `σ` \[-\] the misfit is judged against (`NaN` when there are too
    /// few points to estimate it and none is declared).
    #[serde(deserialize_with = "crate::report::serde_nan::f64")]
    pub level: f64,
    /// Where `level` comes from.
    pub source: NoiseSource,
    /// How `level` was obtained, in words.
    pub estimator: String,
    /// RMS of the residuals (outliers excluded) over `level` \[-\] (≈ 1 for noise; `NaN`
    /// without a level).
    #[serde(deserialize_with = "crate::report::serde_nan::f64")]
    pub rms_over_noise: f64,
    /// The noise model of the residuals (`None` with too few points).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<NoiseModel>,
}

impl Default for NoiseSummary {
    /// No noise level (a report written before noise summaries existed).
    fn default() -> Self {
        NoiseSummary {
            level: f64::NAN,
            source: NoiseSource::Estimated,
            estimator: String::new(),
            rms_over_noise: f64::NAN,
            model: None,
        }
    }
}

impl NoiseSummary {
    /// The noise summary of `series` (the residual profiles of one model on one data set)
    /// with the `declared` relative uncertainty, if any. Errors: a declared level that is not
    /// positive and finite.
    pub fn of(
        series: &[ResidualSeries],
        declared: Option<f64>,
        options: &NoiseOptions,
    ) -> Result<Self, String> {
        let model = NoiseModel::estimate(series, options).ok();
        match declared {
            Some(s) if !(s > 0.0 && s.is_finite()) => Err(format!(
                "the relative uncertainty must be positive and finite, got {s}"
            )),
            Some(s) => Ok(NoiseSummary {
                level: s,
                source: NoiseSource::Declared,
                estimator: DECLARED_NOISE_WORDS.into(),
                rms_over_noise: model
                    .as_ref()
                    .map_or_else(|| rms_all(series) / s, |m| m.rms / s),
                model,
            }),
            None => {
                let (level, ratio) = model
                    .as_ref()
                    .map_or((f64::NAN, f64::NAN), |m| (m.noise_rms, m.rms_over_noise));
                Ok(NoiseSummary {
                    level,
                    source: NoiseSource::Estimated,
                    estimator: ESTIMATED_NOISE_WORDS.into(),
                    rms_over_noise: ratio,
                    model,
                })
            }
        }
    }

    /// Whether the level was declared.
    pub fn declared(&self) -> bool {
        self.source == NoiseSource::Declared
    }

    /// The declared level, if the level was declared \[-\].
    pub fn declared_level(&self) -> Option<f64> {
        self.declared().then_some(self.level)
    }

    /// The noise SD \[-\] at position `s` \[m\] of experiment `k`: the declared level, else the
    /// noise model's local level (the overall level without a model).
    pub fn sigma_at(&self, k: usize, s: f64) -> f64 {
        match (&self.model, self.source) {
            (Some(m), NoiseSource::Estimated) => m.local_sigma_at(k, s),
            _ => self.level,
        }
    }

    /// The along-line correlation of the noise the model uses
    /// ([`NoiseModel::correlation_used`]; 0 for white noise or without a model) \[-\].
    pub fn correlation(&self) -> f64 {
        self.model.as_ref().map_or(0.0, |m| m.correlation_used)
    }

    /// The factor on parameter variances for this noise
    /// ([`NoiseModel::variance_inflation`]; 1 for white noise or without a model) \[-\].
    pub fn variance_inflation(&self) -> f64 {
        self.model.as_ref().map_or(1.0, |m| m.variance_inflation())
    }

    /// Whether point `i` of experiment `k` is a gross outlier of the noise model.
    pub fn is_outlier(&self, k: usize, i: usize) -> bool {
        self.model.as_ref().is_some_and(|m| m.is_outlier(k, i))
    }

    /// The level in words for a report line: `"1.579 % (estimated: ...)"`, with the
    /// along-line correlation where the noise model found one (module docs of
    /// [`NoiseModel`], item 6).
    pub fn describe(&self) -> String {
        if self.level.is_finite() {
            let correlated = match &self.model {
                Some(m) if m.correlation_used > 0.0 => format!(
                    "; the noise is correlated along the line, lag-1 autocorrelation {:.2} \
                     (white noise gives 0 ± {:.2}), so intervals are {:.2} times as wide as \
                     for white noise",
                    m.correlation_used,
                    m.correlation_se,
                    m.variance_inflation().sqrt()
                ),
                _ => String::new(),
            };
            format!("{} % ({}{correlated})", percent(self.level), self.estimator)
        } else {
            "unknown (too few points to estimate it; declare relative_uncertainty)".into()
        }
    }
}

/// A relative level \[-\] in percent for reports: three decimals (`"1.483"`), or three
/// significant digits below 0.001 % (`"3.18e-6"`), never `"0.000"` for a positive level.
pub fn percent(level: f64) -> String {
    let p = 100.0 * level;
    if p != 0.0 && p.abs() < 1e-3 {
        format!("{p:.2e}")
    } else {
        format!("{p:.3}")
    }
}

/// RMS of all residuals of `series` \[-\].
fn rms_all(series: &[ResidualSeries]) -> f64 {
    let (mut s2, mut n) = (0.0, 0usize);
    for r in series.iter().flat_map(|s| &s.residuals) {
        s2 += r * r;
        n += 1;
    }
    (s2 / n.max(1) as f64).sqrt()
}

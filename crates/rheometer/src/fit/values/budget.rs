//! The error budget of a fit as a value: its sources with their shifts of `(n, κ, K)`, as a
//! table, in words, and as a warning where the systematic uncertainty dominates. Computed by
//! [`error_budget`](crate::fit::error_budget()).

use super::thresholds::{LARGE_STDERR_KAPPA, LARGE_STDERR_N};
use crate::data::uncertainty::{Origin, Scope, Source, SOURCES};
use crate::fit::options::{FitWarning, WarningCode};
use serde::{Deserialize, Serialize};

/// How a source's sensitivity was obtained (or why it was not).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SourceStatus {
    /// From the sensitivity of the effect's strength (dual numbers).
    Effect,
    /// From the measurement model of the principled estimator (gauge scale and offset).
    MeasurementModel,
    /// No effect represents the source in this build: not in the budget.
    NotAvailable,
    /// The source applies to none of the experiments (e.g. `inlet_velocity_rel` when every
    /// experiment gives an inlet diameter).
    NotApplicable,
    /// The effect is fitted in this model: its uncertainty is part of the statistical one.
    Fitted,
}

impl SourceStatus {
    /// Whether the entry has sensitivities.
    pub fn has_numbers(&self) -> bool {
        matches!(self, SourceStatus::Effect | SourceStatus::MeasurementModel)
    }
}

/// A source's sensitivity in one experiment.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ExperimentSensitivity {
    /// The experiment.
    pub experiment: String,
    /// Its standard uncertainty of the source (in the source's unit).
    pub sigma: f64,
    /// `dn/dq_k` per unit of the source in this experiment only.
    pub dn_dq: Option<f64>,
    /// `dκ/dq_k`.
    pub dkappa_dq: Option<f64>,
}

/// One source of the budget (JSON: an entry of `error_budget.sources`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BudgetEntry {
    /// Key in `[uncertainty]` (e.g. `"inlet_temperature_K"`).
    pub key: String,
    /// Unit of `sigma` and of `q` in the derivatives (`"K"`, `"-"` for relative, `"µm"`).
    pub unit: String,
    /// What the source is, in words.
    pub what: String,
    /// Common to all experiments or independent per experiment.
    pub scope: Scope,
    /// The effect that represents it.
    pub effect: String,
    /// How its sensitivity was obtained, or why not.
    pub status: SourceStatus,
    /// Standard uncertainty at the data-set level (in `unit`).
    pub sigma: f64,
    /// Whether `sigma` was declared or is the default.
    pub origin: Origin,
    /// Experiments that declare their own value.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub overridden_in: Vec<String>,
    /// `dn/dq` \[1/unit\]: the change of `n` when `q` changes by one unit in every experiment
    /// it applies to (`null` where not available or `n` is not fitted).
    pub dn_dq: Option<f64>,
    /// `dκ/dq` \[1/unit\] (also the relative change of `K` per unit).
    pub dkappa_dq: Option<f64>,
    /// Shift of `n` at one standard uncertainty (non-negative).
    pub shift_n: Option<f64>,
    /// Shift of `κ` at one standard uncertainty (non-negative; the relative shift of `K`).
    pub shift_kappa: Option<f64>,
    /// Per experiment (where the source applies).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub by_experiment: Vec<ExperimentSensitivity>,
    /// The source (its words and remedy for the text; not in JSON, where a built-in source is
    /// found by its key).
    #[serde(skip)]
    pub source: Option<Source>,
}

impl BudgetEntry {
    /// Its source: the one it was made from, else the built-in one with its key.
    fn source(&self) -> Option<Source> {
        self.source
            .or_else(|| SOURCES.iter().find(|s| s.key == self.key).copied())
    }
}

/// The error budget (JSON: `error_budget`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ErrorBudget {
    /// Whether any uncertainty was declared in the data set (else all are defaults).
    pub declared: bool,
    /// The sources, in the order of `SOURCES`, then user-written effects'
    /// (`budget_sources`).
    pub sources: Vec<BudgetEntry>,
    /// Systematic standard uncertainty of `n`: root-sum-square of the sources' shifts.
    pub systematic_n: Option<f64>,
    /// Systematic standard uncertainty of `κ`.
    pub systematic_kappa: Option<f64>,
    /// Relative systematic uncertainty of `K` \[-\] (= that of `κ`, first order).
    #[serde(rename = "systematic_K_rel")]
    pub systematic_k_rel: Option<f64>,
    /// Statistical standard error of `n` (the fit's).
    pub statistical_n: Option<f64>,
    /// Statistical standard error of `κ`.
    pub statistical_kappa: Option<f64>,
    /// Relative statistical uncertainty of `K` \[-\].
    #[serde(rename = "statistical_K_rel")]
    pub statistical_k_rel: Option<f64>,
    /// `√(statistical² + systematic²)` of `n`.
    pub total_n: Option<f64>,
    /// `√(statistical² + systematic²)` of `κ`.
    pub total_kappa: Option<f64>,
    /// Wall time of the budget \[s\].
    pub wall_time_s: f64,
}

/// `v` rounded to 3 significant digits for sentences.
fn g3(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i64).clamp(0, 10) as usize;
    if v.abs() >= 1e4 || v.abs() < 1e-4 {
        format!("{v:.2e}")
    } else {
        format!("{v:.digits$}")
    }
}

impl ErrorBudget {
    /// The sources with sensitivities.
    pub fn available(&self) -> impl Iterator<Item = &BudgetEntry> {
        self.sources.iter().filter(|e| e.status.has_numbers())
    }

    /// One warning when the systematic standard uncertainty of `κ` or `n` dominates the
    /// statistical one (is larger) and is itself large by the limits the fit's checks apply to
    /// statistical errors (SE(κ) > 1, SE(n) > 0.2): the law is then not
    /// determined by these data and this knowledge of the process, instrument and material.
    /// Below that the budget is a table, and the systematic uncertainty is quoted beside the
    /// estimates. The warning names the largest sources and the remedy of the largest.
    pub fn warnings(&self) -> Vec<FitWarning> {
        let mut parts = Vec::new();
        for (label, sys, stat, limit) in [
            (
                "kappa",
                self.systematic_kappa,
                self.statistical_kappa,
                LARGE_STDERR_KAPPA,
            ),
            ("n", self.systematic_n, self.statistical_n, LARGE_STDERR_N),
        ] {
            if let (Some(sys), Some(stat)) = (sys, stat) {
                if sys > stat && sys > limit {
                    parts.push(format!(
                        "{label} ± {} systematic against ± {} statistical (limit {limit})",
                        g3(sys),
                        g3(stat)
                    ));
                }
            }
        }
        if parts.is_empty() {
            return Vec::new();
        }
        let weight = |e: &BudgetEntry| {
            (e.shift_kappa.unwrap_or(0.0) / LARGE_STDERR_KAPPA)
                .max(e.shift_n.unwrap_or(0.0) / LARGE_STDERR_N)
        };
        let mut sources: Vec<(&BudgetEntry, Source)> = self
            .available()
            .filter_map(|e| Some((e, e.source()?)))
            .collect();
        sources.sort_by(|a, b| weight(b.0).total_cmp(&weight(a.0)));
        let named: Vec<String> = sources
            .iter()
            .take(3)
            .map(|(e, s)| {
                let origin = match e.origin {
                    Origin::Default => "default",
                    _ => "declared",
                };
                match overrides_words(e, s) {
                    Some(own) => format!(
                        "the {} ({}, {origin}; {own})",
                        s.what,
                        sigma_words(s, e.sigma)
                    ),
                    None => format!("the {} ({}, {origin})", s.what, sigma_words(s, e.sigma)),
                }
            })
            .collect();
        let remedy = sources.first().map_or("", |(_, s)| s.remedy);
        vec![FitWarning::new(
            WarningCode::Systematic,
            format!(
                "the systematic uncertainty dominates and leaves the law undetermined: {}; \
                 largest sources: {}; the data cannot tell these: {remedy}, or declare the \
                 uncertainties you know in [uncertainty]",
                parts.join(", "),
                named.join(", ")
            ),
        )]
    }

    /// The sensitivities in words: "κ shifts by … per K of inlet temperature, …".
    pub fn sentences(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (label, get) in [
            (
                "kappa",
                (|e: &BudgetEntry| e.dkappa_dq) as fn(&BudgetEntry) -> Option<f64>,
            ),
            ("n", |e: &BudgetEntry| e.dn_dq),
        ] {
            let parts: Vec<String> = self
                .available()
                .filter_map(|e| {
                    let s = e.source()?;
                    let d = get(e)? * s.word_unit.1;
                    Some(format!(
                        "by {} per {} of {}",
                        sign(d),
                        s.word_unit.0,
                        s.what
                    ))
                })
                .collect();
            if !parts.is_empty() {
                out.push(format!("{label} shifts {}", parts.join(", ")));
            }
        }
        out
    }

    /// The budget as text (a `[[Error budget]]` section of the fit report): per source its
    /// standard uncertainty, the sensitivities of `n` and `κ` per unit (K, %, µm) and their
    /// shifts at one standard uncertainty; the totals; the sensitivities in words.
    pub fn to_text(&self) -> String {
        let mut s = format!(
            "[[Error budget: what the data cannot identify ({}; {:.3} s)]]\n",
            if self.declared {
                "declared uncertainties, defaults for the rest"
            } else {
                "no uncertainties declared: defaults"
            },
            self.wall_time_s
        );
        s.push_str(&format!(
            "    {:<21} {:<18} {:<14} {:<14} {:<10} {}\n",
            "source", "sigma", "dn/dq", "dkappa/dq", "shift n", "shift kappa"
        ));
        let abs = |v: Option<f64>| v.map_or("-".to_string(), g3);
        for e in &self.sources {
            let Some(src) = e.source() else {
                continue;
            };
            let origin = match e.origin {
                Origin::Default => "default",
                Origin::Declared => "declared",
                Origin::Experiment => "experiment",
            };
            let sigma = format!("{} ({origin})", sigma_words(&src, e.sigma));
            let per = |v: Option<f64>| {
                v.map_or("-".to_string(), |v| {
                    format!("{}/{}", sign(v * src.word_unit.1), src.word_unit.0)
                })
            };
            if e.status.has_numbers() {
                s.push_str(&format!(
                    "    {:<21} {:<18} {:<14} {:<14} {:<10} {}\n",
                    e.key,
                    sigma,
                    per(e.dn_dq),
                    per(e.dkappa_dq),
                    abs(e.shift_n),
                    abs(e.shift_kappa)
                ));
            } else {
                let why = match e.status {
                    SourceStatus::NotApplicable => "does not apply to these experiments".into(),
                    SourceStatus::Fitted => {
                        format!("{} is fitted: in the statistical error", e.effect)
                    }
                    _ => format!("not available (no effect {} in this build)", e.effect),
                };
                s.push_str(&format!("    {:<21} {:<18} {why}\n", e.key, sigma));
            }
            if let Some(own) = overrides_words(e, &src) {
                s.push_str(&format!("    {:<21} {own}\n", ""));
            }
        }
        let line = |label: &str, sys: Option<f64>, stat: Option<f64>, tot: Option<f64>| {
            format!(
                "    {label}: systematic {}  statistical {}  total {}\n",
                abs(sys),
                abs(stat),
                abs(tot)
            )
        };
        if self.systematic_n.is_some() {
            s.push_str(&line(
                "n    ",
                self.systematic_n,
                self.statistical_n,
                self.total_n,
            ));
        }
        if self.systematic_kappa.is_some() {
            s.push_str(&line(
                "kappa",
                self.systematic_kappa,
                self.statistical_kappa,
                self.total_kappa,
            ));
            let pct = |v: Option<f64>| v.map_or("-".into(), |v| format!("{:.3} %", 100.0 * v));
            s.push_str(&format!(
                "    K:     relative systematic {}  statistical {}\n",
                pct(self.systematic_k_rel),
                pct(self.statistical_k_rel),
            ));
        }
        for line in self.sentences() {
            s.push_str(&format!("    {line}\n"));
        }
        s
    }
}

fn sign(v: f64) -> String {
    if v >= 0.0 {
        format!("+{}", g3(v))
    } else {
        g3(v)
    }
}

/// `σ` in words: "3 K", "2 %", "1 µm".
fn sigma_words(s: &Source, sigma: f64) -> String {
    format!("{} {}", g3(sigma / s.word_unit.1), s.word_unit.0)
}

/// The experiments that declare their own standard uncertainty for `e`, in words (`None` if
/// none does): `"own value in v0p27_p1: 5.00 %"`, at most three named, so that a shift caused
/// by an override is not attributed to the data-set value alone.
fn overrides_words(e: &BudgetEntry, s: &Source) -> Option<String> {
    if e.overridden_in.is_empty() {
        return None;
    }
    let own = |name: &String| {
        e.by_experiment
            .iter()
            .find(|x| &x.experiment == name)
            .map_or(name.clone(), |x| {
                format!("{name}: {}", sigma_words(s, x.sigma))
            })
    };
    let named: Vec<String> = e.overridden_in.iter().take(3).map(own).collect();
    let more = e.overridden_in.len().saturating_sub(3);
    let rest = if more > 0 {
        format!(" and {more} more")
    } else {
        String::new()
    };
    let plural = if e.overridden_in.len() > 1 { "s" } else { "" };
    Some(format!("own value{plural} in {}{rest}", named.join(", ")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_significant_digits() {
        assert_eq!(g3(0.16234), "0.162");
        assert_eq!(g3(12.345), "12.3");
        assert_eq!(g3(-0.0012345), "-0.00123");
        assert_eq!(sign(0.5), "+0.500");
    }
}

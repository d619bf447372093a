//! The error budget of a fit: what the data cannot identify (process conditions, instrument,
//! material data), propagated through exact sensitivities into `(n, κ, K)` as a systematic
//! uncertainty beside the statistical one.
//!
//! At the fitted parameters `θ` (the law's `n, κ`, fitted strengths and the take-up factors),
//! the estimate moves with a source `q` (e.g. the inlet temperature) by
//!
//! ```text
//! dθ/dq = −(JᵀJ)⁻¹ Jᵀ ∂r/∂q
//! ```
//!
//! with `J` the fit's residual Jacobian and `∂r/∂q` the residuals' derivative with respect to
//! the strength of the effect that represents `q` ([`SOURCES`]), carried in the model at its
//! neutral (or fixed) value — the same dual-number sensitivities as the fit's Jacobian, one
//! warm-started solve and one sensitivity solve per experiment for all sources together. The
//! gauge's scale and offset, where no effect represents them, use the exact derivative of the
//! principled estimator's residual (no solve).
//!
//! Each source's column is split by experiment: `s_k = dθ/dq_k`. A *common* source (one error
//! shared by all experiments) shifts `θ` by `|Σ_k s_k σ_k|` at one standard uncertainty; a
//! *per-experiment* one by `√(Σ_k (s_k σ_k)²)`. Sources are independent: the systematic standard
//! uncertainty is the root-sum-square of the sources' shifts. For `K = e^κ` the relative
//! uncertainty is that of `κ` (first order). A source whose shift of `κ` or `n` exceeds the
//! statistical standard error is a [`WarningCode::Systematic`] warning: the data cannot tell.

use super::data::Rheometer;
use super::estimator::Estimator;
use super::identify::Identification;
use super::layout::FitStart;
use super::options::{FitWarning, IdentifyOptions, RheometerError, WarningCode};
use super::parameter_shift::ParameterShift;
use crate::fiber::effects::{Effect, EffectSetting, ModelSpec};
use crate::fiber::uncertainty::{GaugeColumn, Origin, Scope, Source, Uncertainties, SOURCES};
use crate::least_squares::LeastSquaresProblem;
use nalgebra::DVector;
use serde::{Deserialize, Serialize};
use std::time::Instant;

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
}

/// The error budget (JSON: `error_budget`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ErrorBudget {
    /// Whether any uncertainty was declared in the data set (else all are defaults).
    pub declared: bool,
    /// The sources, in the order of [`SOURCES`].
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

/// How a source's column is obtained.
enum Column {
    /// Column `usize` of the augmented objective's Jacobian.
    Effect(usize),
    Gauge(GaugeColumn),
    None(SourceStatus),
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

/// The error budget of the fit `id` of `rh` for the declared uncertainties `unc` (defaults for
/// the rest); `options` are the fit's options (BVP settings, σ).
pub fn error_budget(
    rh: &Rheometer,
    id: &Identification,
    unc: &Uncertainties,
    options: &IdentifyOptions,
) -> Result<ErrorBudget, RheometerError> {
    let t0 = Instant::now();
    let m = rh.len();
    // which sources need which effect
    let mut spec = rh.spec.clone();
    let mut free: Vec<String> = Vec::new();
    let mut strengths: Vec<(String, f64)> = id
        .effects
        .iter()
        .filter(|s| s.column.is_some())
        .map(|s| {
            (
                s.effect.name().to_string(),
                s.effect.strength_of(id.local_params[s.local]),
            )
        })
        .collect();
    let mut plan: Vec<Result<String, SourceStatus>> = Vec::new();
    for s in SOURCES {
        let applies = rh.experiments.iter().any(|e| (s.per_unit)(e).is_some());
        let status = if !applies {
            Err(SourceStatus::NotApplicable)
        } else if let Some(set) = spec
            .effects
            .iter_mut()
            .find(|x| x.effect.name() == s.effect)
        {
            match set.value {
                None if !free.iter().any(|f| f == s.effect) => Err(SourceStatus::Fitted),
                None => Ok(s.effect.to_string()),
                Some(v) => {
                    // a fixed effect: its column at the fixed strength
                    *set = EffectSetting::fitted(set.effect.clone());
                    strengths.push((s.effect.to_string(), v));
                    free.push(s.effect.to_string());
                    Ok(s.effect.to_string())
                }
            }
        } else if spec.candidates.iter().any(|c| c.name() == s.effect) {
            if !free.iter().any(|f| f == s.effect) {
                free.push(s.effect.to_string());
            }
            Ok(s.effect.to_string())
        } else {
            match s.effect.parse::<Effect>() {
                Ok(e) => {
                    spec = spec.with_candidates(&[e]);
                    free.push(s.effect.to_string());
                    Ok(s.effect.to_string())
                }
                Err(_) => Err(SourceStatus::NotAvailable),
            }
        };
        plan.push(status);
    }
    let principled = id.estimator == Estimator::Principled;
    let dense = id.fit.dense_jacobian();
    let (r, x, q) = (&id.fit.residuals, &dense, id.fit.p.len());
    let n_res = r.len();
    // rows of each experiment
    let counts: Vec<usize> = (0..m)
        .map(|k| match id.estimator {
            Estimator::Principled => rh.measurements[k].positions.len(),
            Estimator::Paper => options.n_opt_points,
        })
        .collect();
    if counts.iter().sum::<usize>() != n_res || x.len() != n_res * q {
        return Err(RheometerError::Data(format!(
            "error budget: the fit has {n_res} residuals and {q} parameters, the data {} rows",
            counts.iter().sum::<usize>()
        )));
    }
    // the effects' columns from the augmented model at the fitted point
    let mut aug: Option<(Vec<f64>, usize, Vec<String>)> = None;
    if !free.is_empty() {
        aug = Some(effect_columns(rh, id, spec, free, strengths, options)?);
    }
    let sigma_r = id.relative_uncertainty.unwrap_or(1.0);
    let columns: Vec<Column> = SOURCES
        .iter()
        .zip(&plan)
        .map(|(s, p)| match (p, &aug) {
            (Ok(name), Some((_, _, names))) => names
                .iter()
                .position(|n| n == name)
                .map_or(Column::None(SourceStatus::NotAvailable), Column::Effect),
            (Err(SourceStatus::NotAvailable), _) => match s.fallback {
                Some(g) if principled => Column::Gauge(g),
                _ => Column::None(SourceStatus::NotAvailable),
            },
            (Err(st), _) => Column::None(*st),
            (Ok(_), None) => Column::None(SourceStatus::NotAvailable),
        })
        .collect();

    let prop = ParameterShift::new(x, n_res, q)?;
    let col_of = |name: &str| id.names.iter().position(|n| n == name);
    let (ni, ki) = (col_of("n"), col_of("kappa"));
    let se = id.fit.standard_errors();
    let stat = |c: Option<usize>| c.and_then(|c| se.as_ref().map(|s| s[c]));
    let (stat_n, stat_k) = (stat(ni), stat(ki));

    let mut offsets = vec![0usize; m + 1];
    for k in 0..m {
        offsets[k + 1] = offsets[k] + counts[k];
    }
    let mut entries = Vec::new();
    for (s, col) in SOURCES.iter().zip(&columns) {
        let (sigma, origin) = unc
            .sigma(s.key, usize::MAX)
            .unwrap_or((s.default, Origin::Default));
        let overridden_in: Vec<String> = (0..m)
            .filter(|&k| matches!(unc.sigma(s.key, k), Some((_, Origin::Experiment))))
            .map(|k| rh.experiments[k].name.clone())
            .collect();
        let mut entry = BudgetEntry {
            key: s.key.into(),
            unit: s.unit.into(),
            what: s.what.into(),
            scope: s.scope,
            effect: s.effect.into(),
            status: SourceStatus::NotAvailable,
            sigma,
            origin,
            overridden_in,
            dn_dq: None,
            dkappa_dq: None,
            shift_n: None,
            shift_kappa: None,
            by_experiment: Vec::new(),
        };
        entry.status = match col {
            Column::None(st) => *st,
            Column::Effect(_) => SourceStatus::Effect,
            Column::Gauge(_) => SourceStatus::MeasurementModel,
        };
        if !entry.status.has_numbers() {
            entries.push(entry);
            continue;
        }
        let mut per: Vec<(f64, f64, f64)> = Vec::new(); // (σ_k, dn, dκ)
        for k in 0..m {
            let e = &rh.experiments[k];
            let Some(factor) = (s.per_unit)(e) else {
                continue;
            };
            let mut c = DVector::zeros(n_res);
            for i in offsets[k]..offsets[k + 1] {
                c[i] = factor * column_value(col, &aug, i, r, rh, k, i - offsets[k], sigma_r);
            }
            let d = prop.derivative(&c);
            let sk = unc.sigma(s.key, k).map_or(s.default, |v| v.0);
            let (dn, dk) = (ni.map(|i| d[i]), ki.map(|i| d[i]));
            entry.by_experiment.push(ExperimentSensitivity {
                experiment: e.name.clone(),
                sigma: sk,
                dn_dq: dn,
                dkappa_dq: dk,
            });
            per.push((sk, dn.unwrap_or(f64::NAN), dk.unwrap_or(f64::NAN)));
        }
        let total = |f: &dyn Fn(&(f64, f64, f64)) -> f64| per.iter().map(f).sum::<f64>();
        let shift = |f: &dyn Fn(&(f64, f64, f64)) -> f64| match s.scope {
            Scope::Common => total(&|p| p.0 * f(p)).abs(),
            Scope::PerExperiment => total(&|p| (p.0 * f(p)).powi(2)).sqrt(),
        };
        if ni.is_some() {
            entry.dn_dq = Some(total(&|p| p.1));
            entry.shift_n = Some(shift(&|p| p.1));
        }
        if ki.is_some() {
            entry.dkappa_dq = Some(total(&|p| p.2));
            entry.shift_kappa = Some(shift(&|p| p.2));
        }
        entries.push(entry);
    }
    let rss = |f: fn(&BudgetEntry) -> Option<f64>, fitted: bool| {
        fitted.then(|| {
            entries
                .iter()
                .filter_map(f)
                .map(|v| v * v)
                .sum::<f64>()
                .sqrt()
        })
    };
    let systematic_n = rss(|e| e.shift_n, ni.is_some());
    let systematic_kappa = rss(|e| e.shift_kappa, ki.is_some());
    let both = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(a), Some(b)) => Some(a.hypot(b)),
        _ => None,
    };
    Ok(ErrorBudget {
        declared: unc.any_declared(),
        sources: entries,
        systematic_n,
        systematic_kappa,
        systematic_k_rel: systematic_kappa,
        statistical_n: stat_n,
        statistical_kappa: stat_k,
        statistical_k_rel: stat_k,
        total_n: both(stat_n, systematic_n),
        total_kappa: both(stat_k, systematic_kappa),
        wall_time_s: t0.elapsed().as_secs_f64(),
    })
}

/// Row `i` (row `j` of experiment `k`) of a source's column, before its per-unit factor.
#[allow(clippy::too_many_arguments)]
fn column_value(
    col: &Column,
    aug: &Option<(Vec<f64>, usize, Vec<String>)>,
    i: usize,
    r: &[f64],
    rh: &Rheometer,
    k: usize,
    j: usize,
    sigma: f64,
) -> f64 {
    match col {
        Column::Effect(c) => aug.as_ref().map_or(0.0, |(jac, w, _)| jac[i * w + c]),
        // r = (d/d_meas − 1)/σ and the gauge reads (1 + a) d: ∂r/∂a = d/(σ d_meas) = r + 1/σ
        Column::Gauge(GaugeColumn::Scale) => r[i] + 1.0 / sigma,
        // the gauge reads d + b, b in µm: ∂r/∂b = 1e-6/(σ d_meas)
        Column::Gauge(GaugeColumn::OffsetMicrometre) => {
            1e-6 / (sigma * rh.measurements[k].diameters[j])
        }
        Column::None(_) => 0.0,
    }
}

/// The Jacobian (row-major, its width and column names) of the model `spec` (the fit's model
/// with the sources' effects freed at their neutral or fixed strengths) at the fitted point:
/// one warm-started solve and one sensitivity solve per experiment.
fn effect_columns(
    rh: &Rheometer,
    id: &Identification,
    spec: ModelSpec,
    free: Vec<String>,
    strengths: Vec<(String, f64)>,
    options: &IdentifyOptions,
) -> Result<(Vec<f64>, usize, Vec<String>), RheometerError> {
    let aug = rh.respecified(spec).map_err(|e| match e {
        RheometerError::Simulation {
            experiment, source, ..
        } => RheometerError::Simulation {
            experiment,
            n: id.n,
            kappa: id.kappa,
            source,
        },
        other => other,
    })?;
    let mut opts = options.clone();
    opts.estimator = id.estimator;
    opts.relative_uncertainty = id.relative_uncertainty;
    opts.simulate.factor_at_solution = true;
    let start = FitStart {
        law: [id.n, id.kappa],
        free_candidates: free,
        strengths,
        warm: Some(id.solutions.clone()),
    };
    let mut obj = aug.objective_from(&start, &opts)?;
    let layout = obj.layout().clone();
    let ns_fit = id.names.len();
    let mut p: Vec<f64> = layout
        .names
        .iter()
        .zip(layout.shared_start())
        .map(|(name, start)| {
            id.names
                .iter()
                .position(|n| n == name)
                .map_or(start, |j| id.fit.p[j])
        })
        .collect();
    if id.estimator == Estimator::Principled {
        p.extend_from_slice(&id.fit.p[ns_fit..]);
    }
    let (_, jac) = obj.evaluate(&p)?;
    let width = p.len();
    Ok((jac, width, layout.names))
}

impl ErrorBudget {
    /// The sources with sensitivities.
    pub fn available(&self) -> impl Iterator<Item = &BudgetEntry> {
        self.sources.iter().filter(|e| e.status.has_numbers())
    }

    /// A warning for each source that shifts `κ` or `n` by more than its statistical standard
    /// error at its (declared or default) standard uncertainty.
    pub fn warnings(&self) -> Vec<FitWarning> {
        let mut w = Vec::new();
        for e in self.available() {
            let Some(s) = SOURCES.iter().find(|s| s.key == e.key) else {
                continue;
            };
            let mut parts = Vec::new();
            for (label, shift, stat) in [
                ("kappa", e.shift_kappa, self.statistical_kappa),
                ("n", e.shift_n, self.statistical_n),
            ] {
                if let (Some(shift), Some(stat)) = (shift, stat) {
                    if stat > 0.0 && shift > stat {
                        parts.push(format!(
                            "shift {label} by {}, {:.1} times its statistical uncertainty",
                            g3(shift),
                            shift / stat
                        ));
                    }
                }
            }
            if parts.is_empty() {
                continue;
            }
            w.push(FitWarning::new(
                WarningCode::Systematic,
                format!(
                    "a {} uncertainty of the {} ({}) would {}: the data cannot tell; {}",
                    sigma_words(s, e.sigma),
                    s.what,
                    match e.origin {
                        Origin::Default => "default",
                        _ => "declared",
                    },
                    parts.join(" and "),
                    s.remedy
                ),
            ));
        }
        w
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
                    let s = SOURCES.iter().find(|s| s.key == e.key)?;
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
            let Some(src) = SOURCES.iter().find(|x| x.key == e.key) else {
                continue;
            };
            let origin = match e.origin {
                Origin::Default => "default",
                Origin::Declared => "declared",
                Origin::Experiment => "experiment",
            };
            let sigma = format!("{} ({origin})", sigma_words(src, e.sigma));
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

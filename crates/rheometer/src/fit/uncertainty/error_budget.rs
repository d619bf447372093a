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
//! the strength of the effect that represents `q` (its descriptor's budget source: the built-in
//! [`SOURCES`], then those of user-written effects in the model), carried in the model at its
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
//! statistical standard error is a [`WarningCode::Systematic`](crate::fit::WarningCode::Systematic)
//! warning: the data cannot tell.

use crate::data::uncertainty::{GaugeColumn, Origin, Scope, Source, Uncertainties, SOURCES};
use crate::fit::data::Rheometer;
use crate::fit::estimator::Estimator;
use crate::fit::identify::gauss_newton::Identification;
use crate::fit::layout::FitStart;
use crate::fit::options::{IdentifyOptions, RheometerError};
use crate::model::effects::{Effect, ModelSpec};
use diffbvp::least_squares::LeastSquaresProblem;
use diffbvp::least_squares::LinearResponse;
use std::time::Instant;

pub use crate::fit::values::budget::{
    BudgetEntry, ErrorBudget, ExperimentSensitivity, SourceStatus,
};

mod plan;

use plan::{source_columns, Column, SourcePlan};

/// The error-budget sources for a model `spec`: the built-in [`SOURCES`], then the budget
/// sources of the user-written effects in the model (fitted, fixed or candidates; their
/// uncertainty is the descriptor's default).
pub fn budget_sources(spec: &ModelSpec) -> Vec<Source> {
    let mut out: Vec<Source> = SOURCES.to_vec();
    let users = spec
        .effects
        .iter()
        .map(|s| &s.effect)
        .chain(&spec.candidates);
    for e in users.filter(|e| matches!(e, Effect::Custom(_))) {
        if let Some(src) = Source::of(e.descriptor()) {
            if !out.iter().any(|s| s.key == src.key) {
                out.push(src);
            }
        }
    }
    out
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
    let sources = budget_sources(&rh.spec);
    let plan = SourcePlan::new(rh, id, &sources);
    let (r, q) = (&id.fit.residuals, id.fit.p.len());
    let offsets = row_offsets(rh, id, options, r.len() * q, q)?;
    // the effects' columns from the augmented model at the fitted point
    let mut aug: Option<(Vec<f64>, usize, Vec<String>)> = None;
    if !plan.free.is_empty() {
        aug = Some(effect_columns(
            rh,
            id,
            plan.spec,
            plan.free,
            plan.strengths,
            options,
        )?);
    }
    let principled = id.summary.estimator == Estimator::Principled;
    let columns = source_columns(&sources, &plan.status, &aug, principled);
    let col_of = |name: &str| id.names.iter().position(|n| n == name);
    let propagation = Propagation {
        rh,
        unc,
        aug: &aug,
        r,
        sigma_r: id.summary.noise.declared_level().unwrap_or(1.0),
        // through the Schur complement for a block-arrow fit: linear in the experiments
        prop: id.fit.linear_response_map().ok_or_else(|| {
            RheometerError::Data(
                "JᵀJ of the fit is singular (the fit's parameters are not determined)".into(),
            )
        })?,
        offsets,
        shared: id.names.len(),
        ni: col_of("n"),
        ki: col_of("kappa"),
    };
    let entries: Vec<BudgetEntry> = sources
        .iter()
        .zip(&columns)
        .map(|(s, col)| propagation.entry(s, col))
        .collect();
    let se = id.fit.standard_errors();
    let stat = |c: Option<usize>| c.and_then(|c| se.as_ref().map(|s| s[c]));
    let (stat_n, stat_k) = (stat(propagation.ni), stat(propagation.ki));
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
    let systematic_n = rss(|e| e.shift_n, propagation.ni.is_some());
    let systematic_kappa = rss(|e| e.shift_kappa, propagation.ki.is_some());
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

/// The first row of each experiment's residuals (and the total at the end), checked against
/// the fit's `n_jac` Jacobian entries for `q` parameters.
fn row_offsets(
    rh: &Rheometer,
    id: &Identification,
    options: &IdentifyOptions,
    n_jac: usize,
    q: usize,
) -> Result<Vec<usize>, RheometerError> {
    let m = rh.len();
    let n_res = id.fit.residuals.len();
    let counts: Vec<usize> = (0..m)
        .map(|k| match id.summary.estimator {
            Estimator::Principled => rh.measurements[k].positions.len(),
            Estimator::Paper => options.n_opt_points,
        })
        .collect();
    if counts.iter().sum::<usize>() != n_res || n_jac != n_res * q {
        return Err(RheometerError::Data(format!(
            "error budget: the fit has {n_res} residuals and {q} parameters, the data {} rows",
            counts.iter().sum::<usize>()
        )));
    }
    let mut offsets = vec![0usize; m + 1];
    for k in 0..m {
        offsets[k + 1] = offsets[k] + counts[k];
    }
    Ok(offsets)
}

/// What propagating a source's column into the estimate needs.
struct Propagation<'a> {
    rh: &'a Rheometer,
    unc: &'a Uncertainties,
    /// The augmented Jacobian (row-major, its width and column names).
    aug: &'a Option<(Vec<f64>, usize, Vec<String>)>,
    /// The fit's residuals.
    r: &'a [f64],
    /// The declared relative noise level (1 without one).
    sigma_r: f64,
    /// `−(JᵀJ)⁻¹ Jᵀ` of the fit.
    prop: LinearResponse<'a>,
    /// The number of shared fitted parameters (`n`, `κ`, strengths, shapes: the first).
    shared: usize,
    /// The first row of each experiment.
    offsets: Vec<usize>,
    /// The columns of `n` and `κ` in the fit's parameters.
    ni: Option<usize>,
    ki: Option<usize>,
}

impl Propagation<'_> {
    /// The budget entry of source `s` (its column `col`): its sensitivities per experiment
    /// and the shifts of `n` and `κ` at one standard uncertainty.
    fn entry(&self, s: &Source, col: &Column) -> BudgetEntry {
        let (rh, unc, m) = (self.rh, self.unc, self.rh.len());
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
            effect: s.effect.name().into(),
            status: SourceStatus::NotAvailable,
            sigma,
            origin,
            overridden_in,
            dn_dq: None,
            dkappa_dq: None,
            shift_n: None,
            shift_kappa: None,
            by_experiment: Vec::new(),
            source: Some(*s),
        };
        entry.status = match col {
            Column::None(st) => *st,
            Column::Effect(_) => SourceStatus::Effect,
            Column::Gauge(_) => SourceStatus::MeasurementModel,
        };
        if !entry.status.has_numbers() {
            return entry;
        }
        let per = self.sensitivities(s, col, &mut entry.by_experiment);
        let total = |f: &dyn Fn(&(f64, f64, f64)) -> f64| per.iter().map(f).sum::<f64>();
        let shift = |f: &dyn Fn(&(f64, f64, f64)) -> f64| match s.scope {
            Scope::Common => total(&|p| p.0 * f(p)).abs(),
            Scope::PerExperiment => total(&|p| (p.0 * f(p)).powi(2)).sqrt(),
        };
        if self.ni.is_some() {
            entry.dn_dq = Some(total(&|p| p.1));
            entry.shift_n = Some(shift(&|p| p.1));
        }
        if self.ki.is_some() {
            entry.dkappa_dq = Some(total(&|p| p.2));
            entry.shift_kappa = Some(shift(&|p| p.2));
        }
        entry
    }

    /// The sensitivities of `n` and `κ` to source `s` (column `col`) in each experiment it
    /// applies to, pushed to `by_experiment`; returns them as `(σ_k, dn, dκ)`.
    fn sensitivities(
        &self,
        s: &Source,
        col: &Column,
        by_experiment: &mut Vec<ExperimentSensitivity>,
    ) -> Vec<(f64, f64, f64)> {
        let (rh, offsets, n_res) = (self.rh, &self.offsets, self.r.len());
        let mut per: Vec<(f64, f64, f64)> = Vec::new(); // (σ_k, dn, dκ)
        for k in 0..rh.len() {
            let e = &rh.experiments[k];
            let Some(factor) = (s.per_unit)(e) else {
                continue;
            };
            let mut c = vec![0.0; n_res];
            for i in offsets[k]..offsets[k + 1] {
                c[i] = factor
                    * column_value(
                        col,
                        self.aug,
                        i,
                        self.r,
                        rh,
                        k,
                        i - offsets[k],
                        self.sigma_r,
                    );
            }
            // `c` has one entry per residual, so the map applies; `n` and `κ` are shared
            // parameters (the first columns)
            let d = self.prop.apply_shared(&c, self.shared).unwrap_or_default();
            let sk = self.unc.sigma(s.key, k).map_or(s.default, |v| v.0);
            let at = |i: usize| d.get(i).copied().unwrap_or(f64::NAN);
            let (dn, dk) = (self.ni.map(at), self.ki.map(at));
            by_experiment.push(ExperimentSensitivity {
                experiment: e.name.clone(),
                sigma: sk,
                dn_dq: dn,
                dkappa_dq: dk,
            });
            per.push((sk, dn.unwrap_or(f64::NAN), dk.unwrap_or(f64::NAN)));
        }
        per
    }
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
            n: id.law()[0],
            kappa: id.law()[1],
            source,
        },
        other => other,
    })?;
    let mut opts = options.clone();
    opts.estimator = id.summary.estimator;
    opts.relative_uncertainty = id.summary.noise.declared_level();
    opts.simulate.factor_at_solution = true;
    let start = FitStart {
        law: id.law(),
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
    if id.summary.estimator == Estimator::Principled {
        p.extend_from_slice(&id.fit.p[ns_fit..]);
    }
    let (_, jac) = obj.evaluate(&p)?;
    let width = p.len();
    Ok((jac, width, layout.names))
}

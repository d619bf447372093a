//! Stage 2: the linearisation at the user's fit — residuals, the fitted parameters'
//! Jacobian, each candidate's exact sensitivity column — the linearised scores, and the
//! information criteria every later stage uses.

use super::signature::signature_location;
use crate::diagnostics::candidate::{Candidate, StrengthStatus};
use crate::diagnostics::diagnose::base::Context;
use crate::diagnostics::refits::scan::{physical_range, search_range, shape_variants};
use crate::diagnostics::scores::{linear_scores, LinearScore};
use crate::fit::estimator::RelativeResidual;
use crate::fit::{Identification, IdentifyOptions, Rheometer, RheometerError};
use crate::in_order::CollectInOrder;
use crate::FiberError;
use diffbvp::sensitivity::{residual_jacobian, Sensitivities};
use rayon::prelude::*;

/// The user's fit, linearised.
pub(crate) struct Linearisation {
    /// Residuals `(d_model − d_meas)/(σ d_meas)`.
    pub r: Vec<f64>,
    /// Jacobian of the fitted parameters (row-major, `q` columns: shared, then take-up).
    pub x: Vec<f64>,
    /// Columns of `x`.
    pub q: usize,
    /// Each candidate's sensitivity column (per unit strength).
    pub cols: Vec<Vec<f64>>,
    /// Each candidate's linearised score.
    pub scores: Vec<LinearScore>,
    /// `J = Σ r²` of the user's fit.
    pub cost_before: f64,
    /// Measurement positions \[m\], in the order of `r`.
    pub positions: Vec<f64>,
}

impl Linearisation {
    /// Number of residuals.
    pub fn residuals(&self) -> usize {
        self.r.len()
    }

    /// `(ΔBIC, ΔAIC)` of a model with `k` extra parameters reaching `J = after`:
    /// `N ln(J_after/J_before) + k ln N` and `... + 2k` (Gaussian errors, unknown variance).
    pub fn ic(&self, after: f64, k: usize) -> (f64, f64) {
        let n = self.residuals() as f64;
        let l = n * (after.max(1e-300) / self.cost_before).ln();
        (l + k as f64 * n.ln(), l + 2.0 * k as f64)
    }

    /// `s² = J/(N − q)`, the residual variance of the user's fit.
    pub fn residual_variance(&self) -> f64 {
        self.cost_before / self.residuals().saturating_sub(self.q).max(1) as f64
    }
}

fn sim_err(rh: &Rheometer, k: usize, source: FiberError) -> RheometerError {
    RheometerError::Simulation {
        experiment: rh.experiments[k].name.clone(),
        n: f64::NAN,
        kappa: f64::NAN,
        source,
    }
}

/// One experiment's residuals, local Jacobian and take-up column.
type Part = (Vec<f64>, Vec<f64>, usize);

/// Stage 2: residuals, the fitted parameters' Jacobian and the candidates' columns at the
/// user's fit (one sensitivity solve per experiment, reusing the factorisation of the last
/// Newton step), and the linearised scores.
pub(crate) fn linearise(
    ctx: &Context<'_>,
    base: &Identification,
) -> Result<Linearisation, RheometerError> {
    let rh = &ctx.rh;
    let m = rh.len();
    let ns = ctx.layout.num_shared();
    let q = ns + m;
    let cand_idx: Vec<(usize, f64)> = ctx
        .cands
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
    let parts: Vec<Part> = (0..m)
        .into_par_iter()
        .map(|k| experiment_part(rh, base, k, &ctx.opts, ctx.sigma))
        .collect_in_order()?;
    let mut r = Vec::new();
    let mut x = Vec::new();
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); ctx.cands.len()];
    for (k, (rk, jl, phi)) in parts.into_iter().enumerate() {
        let ql = jl.len() / rk.len().max(1);
        for i in 0..rk.len() {
            let row = &jl[i * ql..(i + 1) * ql];
            let mut xr = vec![0.0; q];
            for (col, &li) in ctx.layout.free.iter().enumerate() {
                xr[col] = row[li];
            }
            xr[ns + k] = row[phi];
            x.extend(xr);
            for (j, &(li, per)) in cand_idx.iter().enumerate() {
                cols[j].push(row[li] * per);
            }
        }
        r.extend(rk);
    }
    let cost_before = r.iter().map(|v| v * v).sum();
    let scores = linear_scores(&r, &x, q, &cols);
    let positions = rh
        .measurements
        .iter()
        .flat_map(|m| m.positions.iter().copied())
        .collect();
    Ok(Linearisation {
        r,
        x,
        q,
        cols,
        scores,
        cost_before,
        positions,
    })
}

fn experiment_part(
    rh: &Rheometer,
    base: &Identification,
    k: usize,
    opts: &IdentifyOptions,
    sigma: f64,
) -> Result<Part, RheometerError> {
    let (r, jl) = experiment_part_at(rh, &base.solutions[k], k, opts, sigma)?;
    Ok((r, jl, rh.models[k].param_layout().take_up_factor()))
}

/// Experiment `k`'s residuals and their Jacobian (row-major, all model parameters) at the
/// solution `sol`.
fn experiment_part_at(
    rh: &Rheometer,
    sol: &diffbvp::solution::Solution,
    k: usize,
    opts: &IdentifyOptions,
    sigma: f64,
) -> Result<(Vec<f64>, Vec<f64>), RheometerError> {
    let model = &rh.models[k];
    let lo = model.scaling.reference.length;
    let dd = model.scaling.diameter();
    let meas = &rh.measurements[k];
    let xs: Vec<f64> = meas.positions.iter().map(|v| v / lo).collect();
    let d: Vec<f64> = meas.diameters.iter().map(|v| v / dd).collect();
    let sens =
        Sensitivities::compute(model, sol).map_err(|e| sim_err(rh, k, FiberError::from(e)))?;
    let sigmas = opts.point_sigmas(k, d.len(), sigma);
    let g = RelativeResidual {
        model,
        d_meas: &d,
        sigma: &sigmas,
    };
    residual_jacobian(model, sol, &sens, &xs, &g).map_err(|e| sim_err(rh, k, FiberError::from(e)))
}

/// The candidates' records from the linearisation alone (refits fill them in later).
pub(crate) fn linear_candidates(ctx: &Context<'_>, lin: &Linearisation) -> Vec<Candidate> {
    let s2 = lin.residual_variance();
    ctx.cands
        .iter()
        .zip(&lin.scores)
        .map(|(e, l)| {
            let k = e.extra_parameters();
            let after = (lin.cost_before - l.score).max(0.0);
            let (bic, aic) = lin.ic(after, k);
            let change: Vec<f64> = l.signature.iter().map(|v| v * l.strength).collect();
            let (peak, range) = signature_location(&lin.positions, &change);
            let (plo, phi) = physical_range(e);
            let (slo, shi) = search_range(e);
            Candidate {
                effect: e.name().to_string(),
                unit: e.unit().to_string(),
                linear_score: l.score,
                linear_strength: l.strength,
                linear_stderr: if l.norm > 0.0 {
                    s2.sqrt() / l.norm
                } else {
                    f64::INFINITY
                },
                cost_before: lin.cost_before,
                cost_after: after,
                extra_parameters: k,
                delta_bic: bic,
                delta_aic: aic,
                signature_peak_m: peak,
                signature_range_m: range,
                status: StrengthStatus::NotRefitted,
                status_note: None,
                physical_range: [plo, phi],
                search_range: [slo, shi],
                refit: None,
                shape_alternative: None,
                profiles: Vec::new(),
                scan_errors: Vec::new(),
                refit_starts: [0, 0],
                false_alarm: f64::NAN,
                share_of_excess: f64::NAN,
            }
        })
        .collect()
}

/// The candidates' columns at the other shapes the global search scans (each shaped candidate
/// at each of its shape variants, except the default one, which is in `lin.cols`): at strength
/// 0 the solution does not depend on the shape, only the residuals' derivative with respect to
/// the strength does, so one sensitivity solve per variant and experiment at the user's fit
/// gives each column. For the look-elsewhere calibration.
pub(crate) fn shape_columns(
    ctx: &Context<'_>,
    base: &Identification,
    lin: &Linearisation,
) -> Result<Vec<(usize, Vec<f64>)>, RheometerError> {
    let mut jobs: Vec<(usize, Vec<(usize, f64)>)> = Vec::new();
    for (i, e) in ctx.cands.iter().enumerate() {
        if e.free_shapes().is_empty() {
            continue;
        }
        for (variant, _) in shape_variants(e, ctx.options.scan.scan_shapes, ctx.length) {
            let values: Vec<(usize, f64)> = variant
                .shape_values()
                .iter()
                .filter_map(|(sp, v)| {
                    ctx.rh.models[0]
                        .param_index(sp.model_param)
                        .map(|p| (p, *v))
                })
                .collect();
            let default = variant
                .shape_values()
                .iter()
                .all(|(sp, v)| *v == sp.default);
            if !default && !values.is_empty() {
                jobs.push((i, values));
            }
        }
    }
    let cand_idx: Vec<Option<(usize, f64)>> = ctx
        .cands
        .iter()
        .map(|e| {
            ctx.rh.models[0]
                .param_index(e.model_param())
                .map(|p| (p, e.param_per_strength()))
        })
        .collect();
    jobs.into_par_iter()
        .filter_map(|(i, values)| {
            let (pi, per) = cand_idx[i]?;
            let mut col = Vec::with_capacity(lin.residuals());
            for k in 0..ctx.rh.len() {
                let mut sol = base.solutions[k].clone();
                for &(p, v) in &values {
                    if let Some(x) = sol.params.get_mut(p) {
                        *x = v;
                    }
                }
                let (r, jl) = match experiment_part_at(&ctx.rh, &sol, k, &ctx.opts, ctx.sigma) {
                    Ok(part) => part,
                    Err(e) => return Some(Err(e)),
                };
                let ql = jl.len() / r.len().max(1);
                col.extend((0..r.len()).map(|row| jl[row * ql + pi] * per));
            }
            Some(Ok((ctx.cands[i].extra_parameters(), col)))
        })
        .collect_in_order()
}

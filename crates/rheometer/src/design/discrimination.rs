//! Design for discrimination: which experiment tells rival explanations of the same data apart
//! (T-optimality, linearised), e.g. the base model plus a mass-flow error against the base
//! model plus a scaled Nusselt law, the tie `diagnose` reports when their signatures are
//! nearly parallel.
//!
//! Every rival is fitted to the current data. For a candidate experiment, each rival predicts
//! its readings at its own fitted parameters (take-up factor 1). If rival `A` is the truth, the
//! data of the current experiments and the candidate follow `A`'s prediction; rival `B` is then
//! refitted to them. Linearised at `B`'s fit, what `B` cannot follow is the difference of the
//! predicted log-readings `δ = ln d_A − ln d_B` projected onto the orthogonal complement of
//! `B`'s Jacobian (its shared parameters and every experiment's take-up factor, the candidate's
//! included), over the relative noise `σ`:
//!
//! `λ(A | B) = ‖(I − P_B) δ‖² / σ²`,
//!
//! the non-centrality of the cost difference `J_B − J_A` in units of `σ²`. The take-up factor
//! of an experiment enters only its own points, so it is projected out experiment by experiment
//! (Frisch–Waugh–Lovell) before the shared columns. With `N` points and `q` fitted parameters
//! (take-up factors included) the expected `ΔBIC = BIC_A − BIC_B` is about
//! `−N ln(1 + λ/(N − q))` (rivals with the same number of parameters). The candidates are
//! ranked by the smallest `λ` over the ordered pairs: the separation reached whichever rival is
//! the truth. Derivatives are exact (forward sensitivities of the BVP, dual numbers at the
//! measurement points), as for the design for estimation.
//!
//! The noise level is the one of the first rival's fit ([`FitSummary`]'s noise, declared or
//! estimated by the noise model), unless given.
//!
//! [`FitSummary`]: crate::fit::FitSummary

use super::candidates::{rows_in_order, Candidate, CandidateGrid, DesignEstimate};
use super::estimation::{candidate_information, candidate_positions, shared_columns};
use super::information::{experiment_information, Columns, ExperimentInformation};
use crate::fit::{Identification, Rheometer, RheometerError};
use crate::in_order::CollectInOrder;
use crate::model::simulate::SimulateOptions;
use diffbvp::solution::Solution;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;

/// One rival explanation: a model (the base model plus its effect) and its fit to the current
/// data.
#[derive(Debug, Clone, Copy)]
pub struct Rival<'a> {
    /// Its name in reports (e.g. the effect added to the base model).
    pub name: &'a str,
    /// The model on the current data.
    pub rheometer: &'a Rheometer,
    /// Its fit to the current data.
    pub fit: &'a Identification,
}

/// What to design for discrimination.
#[derive(Debug, Clone)]
pub struct DiscriminationRequest {
    /// The candidate experiments.
    pub grid: CandidateGrid,
    /// BVP settings of the candidates' solves.
    pub simulate: SimulateOptions,
    /// Relative noise level \[-\]; `None` (default): the first rival's fit summary's level.
    pub noise: Option<f64>,
}

impl DiscriminationRequest {
    /// The request for `grid` with default solver settings and the fit's noise level.
    pub fn new(grid: CandidateGrid) -> Self {
        DiscriminationRequest {
            grid,
            simulate: SimulateOptions::default(),
            noise: None,
        }
    }
}

/// The predicted separation of one ordered pair of rivals.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Separation {
    /// The rival taken as the truth.
    pub truth: String,
    /// The rival refitted to the truth's data.
    pub refitted: String,
    /// `λ = ‖(I − P) δ‖²/σ²` \[-\]: the refitted rival's excess cost in units of `σ²`.
    pub lambda: f64,
    /// Expected `BIC_truth − BIC_refitted` \[-\], `−N ln(1 + λ/(N − q))` (negative: the truth is
    /// preferred).
    pub expected_delta_bic: f64,
}

/// A rival's fit to the current data, as the report shows it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RivalFit {
    /// The rival's name.
    pub name: String,
    /// Its fitted `n` \[-\].
    pub n: f64,
    /// Its fitted `κ` \[-\].
    pub kappa: f64,
    /// Its fitted effect strengths: (effect, value, standard error, unit).
    pub strengths: Vec<(String, f64, f64, String)>,
    /// Its cost `J` (the fit's objective).
    pub cost: f64,
    /// `BIC` relative to the best rival \[-\] (`N ln J + k ln N`, same `N`).
    pub delta_bic: f64,
}

/// One candidate's outcome.
#[derive(Debug, Clone, Serialize)]
pub struct DiscriminationOutcome {
    /// Where it sits in the grid and its conditions.
    #[serde(flatten)]
    pub candidate: Candidate,
    /// The experiment's name in reports.
    pub name: String,
    /// The separation of every ordered pair after adding it (empty if infeasible).
    pub separations: Vec<Separation>,
    /// The smallest `λ` over the ordered pairs \[-\] (`NaN` if infeasible): the ranking score.
    pub min_lambda: f64,
    /// Its place in the ranking (1 = best; `None` if infeasible).
    pub rank: Option<usize>,
    /// Why a rival's model could not be solved for it, if one could not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub infeasible: Option<String>,
}

/// The outcome of a design for discrimination (text: [`Discrimination::to_text`]; JSON: serde).
#[derive(Debug, Clone, Serialize)]
pub struct Discrimination {
    /// The rivals' fits to the current data.
    pub rivals: Vec<RivalFit>,
    /// Relative noise level \[-\] of the prediction.
    pub noise_level: f64,
    /// Where the noise level comes from, in words.
    pub noise_source: String,
    /// The template experiment of the candidates.
    pub template: String,
    /// The candidate grid.
    pub grid: CandidateGrid,
    /// The separation of every ordered pair on the current data alone.
    pub current: Vec<Separation>,
    /// Every candidate, in grid order (mass flow slowest).
    pub candidates: Vec<DiscriminationOutcome>,
    /// Indices into [`candidates`](Self::candidates), best first (feasible ones only).
    pub ranking: Vec<usize>,
    /// Notes on the prediction's assumptions.
    pub notes: Vec<String>,
    /// Wall time \[s\].
    pub wall_time_s: f64,
}

impl Discrimination {
    /// The best candidate, if any is feasible.
    pub fn best(&self) -> Option<&DiscriminationOutcome> {
        self.ranking.first().map(|&i| &self.candidates[i])
    }
}

/// One experiment's predicted log-readings and relative sensitivities under one rival.
#[derive(Debug, Clone)]
struct Rows {
    /// `ln d(s_j)` at the rival's fit.
    log: Vec<f64>,
    /// `∂ ln d/∂θ`, row-major `points × p` (the rival's shared parameters).
    shared: Vec<f64>,
    /// `∂ ln d/∂φ` (empty when the take-up factor is held).
    nuisance: Vec<f64>,
}

impl From<ExperimentInformation> for Rows {
    fn from(i: ExperimentInformation) -> Self {
        Rows {
            log: i.readings.iter().map(|d| d.ln()).collect(),
            shared: i.sensitivities,
            nuisance: i.nuisance_sensitivities,
        }
    }
}

/// The normal equations of one ordered pair accumulated over experiments: `G = X̃ᵀX̃`,
/// `b = X̃ᵀδ̃`, `dd = δ̃ᵀδ̃` (take-up factors projected out, weights `1/σ`).
#[derive(Debug, Clone)]
struct Normal {
    g: DMatrix<f64>,
    b: DVector<f64>,
    dd: f64,
}

impl Normal {
    fn zero(p: usize) -> Self {
        Normal {
            g: DMatrix::zeros(p, p),
            b: DVector::zeros(p),
            dd: 0.0,
        }
    }

    /// Adds one experiment: `truth` and `refit` its rows under the two rivals.
    fn add(&mut self, truth: &Rows, refit: &Rows, sigma: f64) {
        let m = truth.log.len();
        let p = self.b.len();
        let w = 1.0 / sigma;
        let mut d: Vec<f64> = (0..m).map(|j| w * (truth.log[j] - refit.log[j])).collect();
        let mut x = DMatrix::from_fn(m, p, |j, a| w * refit.shared[j * p + a]);
        if refit.nuisance.len() == m {
            let z: Vec<f64> = refit.nuisance.iter().map(|v| w * v).collect();
            let zz: f64 = z.iter().map(|v| v * v).sum();
            if zz > 0.0 {
                let zd: f64 = z.iter().zip(&d).map(|(a, b)| a * b).sum();
                for (dj, zj) in d.iter_mut().zip(&z) {
                    *dj -= zj * zd / zz;
                }
                for a in 0..p {
                    let zx: f64 = (0..m).map(|j| z[j] * x[(j, a)]).sum();
                    for (j, zj) in z.iter().enumerate() {
                        x[(j, a)] -= zj * zx / zz;
                    }
                }
            }
        }
        let dv = DVector::from_vec(d);
        self.g += x.transpose() * &x;
        self.b += x.transpose() * &dv;
        self.dd += dv.norm_squared();
    }

    fn plus(&self, other: &Normal) -> Normal {
        Normal {
            g: &self.g + &other.g,
            b: &self.b + &other.b,
            dd: self.dd + other.dd,
        }
    }

    /// `λ = δ̃ᵀδ̃ − bᵀG⁻¹b` (what the refit cannot follow), `NaN` when `G` is singular.
    fn lambda(&self) -> f64 {
        match self.g.clone().cholesky() {
            Some(ch) => {
                let x = ch.solve(&self.b);
                (self.dd - self.b.dot(&x)).max(0.0)
            }
            None => f64::NAN,
        }
    }
}

/// What one rival contributes: its columns, local parameters of a candidate and the rows of
/// the current experiments.
struct RivalData<'a> {
    rival: Rival<'a>,
    columns: Columns,
    params: Vec<f64>,
    current: Vec<Rows>,
    /// Fitted parameters, take-up factors included.
    q: usize,
}

fn rival_data<'a>(rival: Rival<'a>, sigma: f64) -> Result<RivalData<'a>, RheometerError> {
    let rh = rival.rheometer;
    let id = rival.fit;
    let model0 = rh
        .models
        .first()
        .ok_or_else(|| RheometerError::Data("the data set has no experiments".into()))?;
    let columns = Columns {
        shared: shared_columns(model0, id)
            .map_err(|e| RheometerError::Data(format!("rival {}: {e}", rival.name)))?,
        nuisance: Some(model0.take_up_factor_index()),
    };
    let current: Result<Vec<Rows>, RheometerError> = (0..rh.len())
        .into_par_iter()
        .map(|k| {
            let pos = &rh.measurements[k].positions;
            let sig = vec![sigma; pos.len()];
            experiment_information(&rh.models[k], &id.solutions[k], pos, &sig, &columns)
                .map(Rows::from)
                .map_err(|source| RheometerError::Simulation {
                    experiment: rh.experiments[k].name.clone(),
                    n: id.law()[0],
                    kappa: id.law()[1],
                    source,
                })
        })
        .collect_in_order();
    let mut params = id.local_params.clone();
    params[model0.take_up_factor_index()] = 1.0;
    Ok(RivalData {
        rival,
        columns,
        params,
        current: current?,
        q: id.fit.p.len(),
    })
}

/// The expected `ΔBIC` of separation `lambda` with `n` points and `q` fitted parameters.
fn expected_delta_bic(lambda: f64, n: usize, q: usize) -> f64 {
    let dof = n.saturating_sub(q).max(1) as f64;
    -(n as f64) * (lambda / dof).ln_1p()
}

/// Ranks the candidates of `request` by how well adding each would tell the `rivals` (at
/// least two, fitted to the same data) apart: the smallest linearised separation `λ` over the
/// ordered pairs (see the module documentation).
///
/// Errors: fewer than two rivals, rivals on different data, a bad grid or template, no noise
/// level, a rival's current data that do not determine its parameters.
pub fn design_for_discrimination(
    rivals: &[Rival<'_>],
    request: &DiscriminationRequest,
) -> Result<Discrimination, RheometerError> {
    design_for_discrimination_with(rivals, request, &|_| {})
}

/// [`design_for_discrimination`], telling `report` how long the candidates will take once
/// the first rows are done (see `rows_in_order`).
pub(crate) fn design_for_discrimination_with(
    rivals: &[Rival<'_>],
    request: &DiscriminationRequest,
    report: &(dyn Fn(&DesignEstimate) + Sync),
) -> Result<Discrimination, RheometerError> {
    let t0 = Instant::now();
    if rivals.len() < 2 {
        return Err(RheometerError::Data(
            "discrimination needs at least two rival models".into(),
        ));
    }
    let first = rivals[0];
    let rh0 = first.rheometer;
    check_same_data(rivals)?;
    let grid = &request.grid;
    grid.validate().map_err(RheometerError::Data)?;
    let template = rh0.experiments.get(grid.template).ok_or_else(|| {
        RheometerError::Data(format!(
            "template experiment {} of a data set with {} experiments",
            grid.template,
            rh0.len()
        ))
    })?;
    let (sigma, noise_source) = design_noise(first, request)?;
    let data: Vec<RivalData> = rivals
        .iter()
        .map(|&r| rival_data(r, sigma))
        .collect::<Result<_, _>>()?;
    let n_now: usize = rh0.measurements.iter().map(|m| m.positions.len()).sum();
    let pairs: Vec<(usize, usize)> = (0..data.len())
        .flat_map(|a| {
            (0..data.len())
                .filter(move |&b| b != a)
                .map(move |b| (a, b))
        })
        .collect();
    // the current experiments' normal equations, per ordered pair
    let now: Vec<Normal> = pairs
        .iter()
        .map(|&(a, b)| {
            let mut acc = Normal::zero(data[b].columns.shared.len());
            for (ra, rb) in data[a].current.iter().zip(&data[b].current) {
                acc.add(ra, rb, sigma);
            }
            acc
        })
        .collect();
    let separation = |(a, b): (usize, usize), lambda: f64, n: usize, extra_q: usize| Separation {
        truth: data[a].rival.name.to_string(),
        refitted: data[b].rival.name.to_string(),
        lambda,
        expected_delta_bic: expected_delta_bic(lambda, n, data[a].q + extra_q),
    };
    let current: Vec<Separation> = pairs
        .iter()
        .zip(&now)
        .map(|(&pair, acc)| separation(pair, acc.lambda(), n_now, 0))
        .collect();
    let positions = candidate_positions(rh0, grid)?;
    let sigmas = vec![sigma; positions.len()];
    let n_new = n_now + positions.len();
    let nt = grid.take_up.values().len();
    let all = grid.candidates();
    let mut candidates: Vec<DiscriminationOutcome> = rows_in_order(
        &all,
        nt,
        |row| {
            // each rival's solutions warm-start its next candidate along the take-up axis
            let mut last: Vec<Option<Solution>> = vec![None; data.len()];
            row.iter()
                .map(|c| {
                    let exp = grid.experiment(template, c);
                    let mut out = DiscriminationOutcome {
                        candidate: c.clone(),
                        name: exp.name.clone(),
                        separations: Vec::new(),
                        min_lambda: f64::NAN,
                        rank: None,
                        infeasible: None,
                    };
                    let mut rows = Vec::with_capacity(data.len());
                    for (r, warm) in data.iter().zip(last.iter_mut()) {
                        match candidate_information(
                            r.rival.rheometer,
                            &exp,
                            &r.params,
                            (&positions, &sigmas),
                            &r.columns,
                            warm.as_ref(),
                            &request.simulate,
                        ) {
                            Ok((info, sol)) => {
                                rows.push(Rows::from(info));
                                *warm = Some(sol);
                            }
                            Err(e) => {
                                out.infeasible = Some(format!("rival {}: {e}", r.rival.name));
                                return out;
                            }
                        }
                    }
                    out.separations = pairs
                        .iter()
                        .zip(&now)
                        .map(|(&(a, b), acc)| {
                            let mut add = Normal::zero(data[b].columns.shared.len());
                            add.add(&rows[a], &rows[b], sigma);
                            separation((a, b), acc.plus(&add).lambda(), n_new, 1)
                        })
                        .collect();
                    out.min_lambda = out
                        .separations
                        .iter()
                        .map(|s| s.lambda)
                        .fold(f64::INFINITY, f64::min);
                    out
                })
                .collect::<Vec<_>>()
        },
        report,
    );
    let ranking = rank_by_separation(&mut candidates);
    let rival_fits = rival_fits(rivals, n_now);
    let notes = design_notes(sigma, &noise_source);
    Ok(Discrimination {
        rivals: rival_fits,
        noise_level: sigma,
        noise_source,
        template: template.name.clone(),
        grid: grid.clone(),
        current,
        candidates,
        ranking,
        notes,
        wall_time_s: t0.elapsed().as_secs_f64(),
    })
}

/// Errors unless every rival is fitted to the first one's experiments and positions.
fn check_same_data(rivals: &[Rival<'_>]) -> Result<(), RheometerError> {
    let first = rivals[0];
    let rh0 = first.rheometer;
    for r in &rivals[1..] {
        let same = r.rheometer.len() == rh0.len()
            && r.rheometer
                .measurements
                .iter()
                .zip(&rh0.measurements)
                .all(|(a, b)| a.positions == b.positions);
        if !same {
            return Err(RheometerError::Data(format!(
                "rivals {} and {} are not fitted to the same data",
                first.name, r.name
            )));
        }
    }
    Ok(())
}

/// The relative noise level σ \[-\] of the predictions (given, else the first rival's one
/// noise level) and where it comes from.
fn design_noise(
    first: Rival<'_>,
    request: &DiscriminationRequest,
) -> Result<(f64, String), RheometerError> {
    let summary_noise = &first.fit.summary.noise;
    let sigma = request.noise.unwrap_or(summary_noise.level);
    if !(sigma > 0.0 && sigma.is_finite()) {
        return Err(RheometerError::Data(format!(
            "no noise level for the design ({sigma}): declare relative_uncertainty in the data \
             set or give the noise level"
        )));
    }
    let source = if request.noise.is_some() {
        "given".to_string()
    } else {
        format!("the fit's: {}", summary_noise.describe())
    };
    Ok((sigma, source))
}

/// Ranks the feasible candidates by their smallest separation, largest first (sets each
/// candidate's `rank`; returns the indices in rank order).
fn rank_by_separation(candidates: &mut [DiscriminationOutcome]) -> Vec<usize> {
    let mut ranking: Vec<usize> = (0..candidates.len())
        .filter(|&i| candidates[i].min_lambda.is_finite())
        .collect();
    ranking.sort_by(|&a, &b| {
        candidates[b]
            .min_lambda
            .total_cmp(&candidates[a].min_lambda)
    });
    for (r, &i) in ranking.iter().enumerate() {
        candidates[i].rank = Some(r + 1);
    }
    ranking
}

/// What the predictions assume, in words.
fn design_notes(sigma: f64, noise_source: &str) -> Vec<String> {
    vec![
        format!(
            "predictions assume relative Gaussian noise of {:.3} % on every point ({noise_source}) \
             and a take-up factor fitted per experiment; they are linearised at each rival's fit",
            100.0 * sigma
        ),
        "lambda(A|B): the excess cost, in units of the noise variance, of rival B refitted to \
         data that follow rival A; expected dBIC = BIC_A - BIC_B = -N ln(1 + lambda/(N - q)); \
         ranked by the smaller lambda of the two orders (whichever rival is the truth)"
            .into(),
    ]
}

/// The rivals' fits, their `BIC` relative to the best (`N` points).
fn rival_fits(rivals: &[Rival<'_>], n: usize) -> Vec<RivalFit> {
    let bic: Vec<f64> = rivals
        .iter()
        .map(|r| {
            (n as f64) * r.fit.fit.cost.max(1e-300).ln()
                + (r.fit.fit.p.len() as f64) * (n as f64).ln()
        })
        .collect();
    let best = bic.iter().copied().fold(f64::INFINITY, f64::min);
    rivals
        .iter()
        .zip(&bic)
        .map(|(r, b)| {
            let s = &r.fit.summary;
            RivalFit {
                name: r.name.to_string(),
                n: s.n.value,
                kappa: s.kappa.value,
                strengths: s
                    .effects
                    .iter()
                    .map(|e| {
                        (
                            e.effect.clone(),
                            e.strength.value,
                            e.strength.stderr,
                            e.strength.unit.clone(),
                        )
                    })
                    .collect(),
                cost: r.fit.fit.cost,
                delta_bic: b - best,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// λ is the residual sum of squares of regressing δ on the refitted rival's columns: a δ in
    /// their span (take-up column included) gives 0; an orthogonal part survives whole.
    #[test]
    fn lambda_is_what_the_refit_cannot_follow() {
        let truth = Rows {
            log: vec![1.0, 2.0, 4.0, 3.0],
            shared: vec![],
            nuisance: vec![],
        };
        // refit rows: log 0, one shared column x, take-up column 1
        let x = [0.0, 1.0, 2.0, 3.0];
        let refit = Rows {
            log: vec![0.0; 4],
            shared: x.to_vec(),
            nuisance: vec![1.0; 4],
        };
        let mut acc = Normal::zero(1);
        acc.add(&truth, &refit, 0.5);
        // the least-squares residual of [1, 2, 4, 3] on (1, x): slope 0.8, intercept 1.3
        let fit: Vec<f64> = x.iter().map(|v| 1.3 + 0.8 * v).collect();
        let rss: f64 = truth
            .log
            .iter()
            .zip(&fit)
            .map(|(a, b)| (a - b).powi(2))
            .sum();
        assert!(
            (acc.lambda() - rss / 0.25).abs() < 1e-12,
            "{}",
            acc.lambda()
        );
        // a difference the refit can follow exactly
        let follow = Rows {
            log: x.iter().map(|v| 2.0 - 0.3 * v).collect(),
            ..truth.clone()
        };
        let mut acc = Normal::zero(1);
        acc.add(&follow, &refit, 0.5);
        assert!(acc.lambda().abs() < 1e-12);
        // the expected ΔBIC is −N ln(1 + λ/(N − q)): about −λ N/(N − q) for λ ≪ N
        let e = expected_delta_bic(2.0, 1000, 10);
        assert!((e + 1000.0 * (2.0f64 / 990.0).ln_1p()).abs() < 1e-12, "{e}");
        assert!((e + 2.0 * 1000.0 / 990.0).abs() < 5e-3, "{e}");
    }
}

//! Design for estimation: the predicted uncertainty of the fitted parameters after adding each
//! candidate experiment to the data of a fit, ranked by a design criterion.
//!
//! Every experiment of the fit contributes its information about the shared parameters
//! (`experiment_information`, take-up factor profiled out); a candidate is simulated at the
//! fitted parameters and its information added. The candidates of one mass flow are solved in
//! order of the take-up axis, each warm-started from its neighbour (cold start where that
//! fails); the mass flows run in parallel (rayon). A candidate whose model cannot be built or
//! solved is reported as infeasible, with the reason.

use super::candidates::{rows_in_order, Candidate, CandidateGrid, DesignEstimate};
use super::criteria::{sandwich, Criterion, Prediction, Reference};
use super::information::{experiment_information_under, Columns, ExperimentInformation};
use crate::data::noise_model::NoiseModel;
use crate::fit::{CarreauFiber, Identification, Rheometer, RheometerError};
use crate::in_order::CollectInOrder;
use crate::model::bvp::FiberModel;
use crate::model::material_law::CarreauLike;
use crate::model::simulate::{simulate_params, SimulateOptions};
use diffbvp::solution::Solution;
use diffbvp::solve::{Guess, Solver};
use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;

/// What to design.
#[derive(Debug, Clone)]
pub struct DesignRequest {
    /// The candidate experiments.
    pub grid: CandidateGrid,
    /// The criterion that ranks them.
    pub criterion: Criterion,
    /// BVP settings of the candidates' solves (default: tolerance 1e-6).
    pub simulate: SimulateOptions,
    /// Relative noise level \[-\] of the measurements, current and new, the same on every point
    /// (an assumption, labelled so in the report); `None` (default): the data set's declared
    /// level (uniform, also an assumption), else the noise the fit estimates along the line
    /// (see `NoisePlan`).
    pub noise: Option<f64>,
}

impl DesignRequest {
    /// The request for `grid` ranked by `criterion`, default solver settings.
    pub fn new(grid: CandidateGrid, criterion: Criterion) -> Self {
        DesignRequest {
            grid,
            criterion,
            simulate: SimulateOptions::default(),
            noise: None,
        }
    }
}

/// One candidate's outcome (JSON: the candidate's conditions, its prediction or why it is
/// infeasible).
#[derive(Debug, Clone, Serialize)]
pub struct CandidateOutcome {
    /// Where it sits in the grid and its conditions.
    #[serde(flatten)]
    pub candidate: Candidate,
    /// The experiment's name in reports.
    pub name: String,
    /// The predicted uncertainty with this experiment added (`None` if infeasible or if its
    /// information is singular).
    pub prediction: Option<Prediction>,
    /// The gain under the ranking criterion \[-\] (`NaN` without prediction).
    pub gain: f64,
    /// Its place in the ranking (1 = best; `None` without prediction).
    pub rank: Option<usize>,
    /// Why the model could not be solved for it, if it could not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub infeasible: Option<String>,
    /// Predicted gauge reading at the take-up end \[m\] (`NaN` if infeasible).
    pub take_up_reading_m: f64,
}

/// The outcome of a design for estimation (text: [`Design::to_text`]; JSON: serde).
#[derive(Debug, Clone, Serialize)]
pub struct Design {
    /// The fitted shared parameters the prediction is about (`"n"`, `"kappa"`, strengths).
    pub parameters: Vec<String>,
    /// Their fitted values (model units).
    pub values: Vec<f64>,
    /// The standard errors the fit reported (`NaN` where none), for comparison with
    /// [`current`](Self::current).
    pub fit_stderr: Vec<f64>,
    /// Relative noise level \[-\] of the prediction ([`noise_level`]): the uniform level, or
    /// for the fitted noise model the RMS of its `σ_j` over the current points.
    pub noise_level: f64,
    /// Which noise the prediction uses, in words (`NoisePlan::words`): `"fitted along the
    /// line (…)"`, `"assumed: declared uniform …"` or `"assumed: given uniform … (--noise)"`.
    pub noise_model: String,
    /// Where that noise comes from: `"fitted"`, `"declared"` or `"given"`.
    pub noise_source: NoiseSource,
    /// The relative noise SD \[-\] the prediction uses at each candidate measurement position
    /// (the template's positions on its line, or the grid's), in order.
    pub candidate_noise: Vec<f64>,
    /// The template experiment of the candidates.
    pub template: String,
    /// The ranking criterion.
    pub criterion: Criterion,
    /// The candidate grid.
    pub grid: CandidateGrid,
    /// The predicted uncertainty of the current data alone.
    pub current: Prediction,
    /// Every candidate, in grid order (mass flow slowest).
    pub candidates: Vec<CandidateOutcome>,
    /// Indices into [`candidates`](Self::candidates), best first (feasible ones only).
    pub ranking: Vec<usize>,
    /// Notes on the prediction's assumptions.
    pub notes: Vec<String>,
    /// Wall time \[s\].
    pub wall_time_s: f64,
}

impl Design {
    /// The best candidate, if any is feasible.
    pub fn best(&self) -> Option<&CandidateOutcome> {
        self.ranking.first().map(|&i| &self.candidates[i])
    }

    /// The worst feasible candidate.
    pub fn worst(&self) -> Option<&CandidateOutcome> {
        self.ranking.last().map(|&i| &self.candidates[i])
    }

    /// Index of parameter `name` in [`parameters`](Self::parameters).
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.parameters.iter().position(|p| p == name)
    }
}

/// The local model-parameter index of each shared fitted parameter of `id` (in fit order).
pub(crate) fn shared_columns(
    model: &CarreauFiber,
    id: &Identification,
) -> Result<Vec<usize>, String> {
    let layout = model.param_layout();
    (0..id.names.len())
        .map(|c| {
            let slot = id.effects.iter().find_map(|e| {
                (e.column == Some(c)).then_some(e.local).or_else(|| {
                    e.shapes
                        .iter()
                        .find(|s| s.column == Some(c))
                        .map(|s| s.local)
                })
            });
            match (slot, id.names[c].as_str()) {
                (Some(l), _) => Ok(l),
                (None, "n") => Ok(layout.law_param(CarreauLike::N)),
                (None, "kappa") => Ok(layout.law_param(CarreauLike::KAPPA)),
                (None, other) => Err(format!("cannot place the fitted parameter {other}")),
            }
        })
        .collect()
}

/// The relative noise level \[-\] of a design: `given`, else the data set's declared level
/// (both uniform), else the fit's residual level (the RMS scale of the fitted noise along the
/// line, see `NoisePlan`) `σ̂ = √(Σ r²/(N − P))` over the relative residuals
/// (`P` fitted parameters, take-up factors included) — the level the fit's own standard errors
/// use, so that the design's prediction for the current data is the fit's. The noise model's
/// level (second differences, robust to a smooth misfit) is what a misfit is judged against,
/// not what a design predicts with: it can read well below the noise on a few short
/// experiments, and standard errors predicted from it would then come out too low.
pub fn noise_level(id: &Identification, given: Option<f64>) -> f64 {
    if let Some(s) = given.or(id.summary.noise.declared_level()) {
        return s;
    }
    let (mut ss, mut n) = (0.0, 0usize);
    for (_, r) in &id.residual_profiles {
        ss += r.iter().map(|v| v * v).sum::<f64>();
        n += r.len();
    }
    let dof = n.saturating_sub(id.fit.p.len());
    if dof == 0 {
        return f64::NAN;
    }
    (ss / dof as f64).sqrt()
}

/// Where the noise of a design's prediction comes from (JSON: `"fitted"`, `"declared"`,
/// `"given"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseSource {
    /// The noise model the fit estimates along the line (no level declared or given).
    Fitted,
    /// The data set's declared `relative_uncertainty`, uniform: an assumption.
    Declared,
    /// The request's level ([`DesignRequest::noise`], `--noise`), uniform: an assumption.
    Given,
}

/// The noise a design's prediction uses: a relative SD \[-\] at every current and candidate
/// measurement point.
///
/// * Declared or given level: that level on every point.
/// * Otherwise the fit's noise model ([`NoiseModel::local_sigma`], a function of `s/L`, the
///   take-up region typically noisier) gives the shape `f(s/L)`, and its scale is the fit's
///   residual level ([`noise_level`]): `σ_j = c f(s_j/L)` with `c` such that the mean of `σ_j²`
///   over the current points is that level squared. The shape is the noise model's because
///   only it separates noise from a smooth misfit along the line; the scale is the residual
///   level's because the noise model's own level (second differences) read 1.18 % for 1.5 %
///   noise on three experiments of 26 points, 25 % low.
/// * The points are independent: the fit's record holds no estimate of the noise's
///   correlation (its lag-1 autocorrelation of the residuals is a test for a misfit, which
///   raises it as much as a correlated noise does).
#[derive(Debug, Clone)]
pub(crate) struct NoisePlan {
    /// Where the noise comes from.
    pub source: NoiseSource,
    /// The uniform level, or the RMS of `σ_j` over the current points \[-\].
    pub level: f64,
    /// The shape `f(s/L)` and the scale `c` \[-\] of the fitted noise (`None`: uniform).
    shape: Option<(NoiseModel, f64)>,
}

impl NoisePlan {
    /// The noise of a design on the fit `id` with the request's level `given` \[-\], if any.
    /// Errors: no positive finite level.
    pub fn of(id: &Identification, given: Option<f64>) -> Result<Self, RheometerError> {
        let level = noise_level(id, given);
        if !(level > 0.0 && level.is_finite()) {
            return Err(RheometerError::Data(format!(
                "no noise level for the design ({level}): declare relative_uncertainty in the \
                 data set or give the noise level"
            )));
        }
        let source = if given.is_some() {
            NoiseSource::Given
        } else if id.summary.noise.declared() {
            NoiseSource::Declared
        } else {
            NoiseSource::Fitted
        };
        let shape = match (source, &id.summary.noise.model) {
            (NoiseSource::Fitted, Some(m)) => {
                let (mut sum, mut count) = (0.0, 0usize);
                for (k, (s, _)) in id.residual_profiles.iter().enumerate() {
                    for &sj in s {
                        sum += m.local_sigma_at(k, sj).powi(2);
                        count += 1;
                    }
                }
                let ms = sum / count.max(1) as f64;
                (ms > 0.0 && ms.is_finite()).then(|| (m.clone(), level / ms.sqrt()))
            }
            _ => None,
        };
        Ok(NoisePlan {
            source,
            level,
            shape,
        })
    }

    /// The relative noise SD \[-\] at `x = s/L` (position over the spin-line length).
    pub fn sigma(&self, x: f64) -> f64 {
        match &self.shape {
            Some((m, c)) => c * m.local_sigma(x),
            None => self.level,
        }
    }

    /// The noise SD \[-\] at each of `positions` \[m\] on a line of length `length` \[m\].
    pub fn sigmas(&self, positions: &[f64], length: f64) -> Vec<f64> {
        positions.iter().map(|s| self.sigma(s / length)).collect()
    }

    /// Which noise it is, in words for the report.
    pub fn words(&self) -> String {
        let pct = |v: f64| format!("{:.3} %", 100.0 * v);
        match (&self.shape, self.source) {
            (Some((m, _)), _) => {
                let along: Vec<String> = m
                    .bins
                    .iter()
                    .map(|b| format!("{} at s/L {:.2}", pct(self.sigma(b.centre)), b.centre))
                    .collect();
                format!(
                    "fitted along the line (the fit's noise model as a function of s/L, scaled \
                     to the fit's residual level {}: {}; points independent)",
                    pct(self.level),
                    if along.is_empty() {
                        "no bins, uniform".to_string()
                    } else {
                        along.join(", ")
                    }
                )
            }
            (None, NoiseSource::Fitted) => format!(
                "fitted, uniform {} (the fit's residual level; the fit has no noise model)",
                pct(self.level)
            ),
            (None, NoiseSource::Declared) => format!(
                "assumed: declared uniform {} on every point (the data set's \
                 relative_uncertainty)",
                pct(self.level)
            ),
            (None, NoiseSource::Given) => format!(
                "assumed: given uniform {} on every point (--noise)",
                pct(self.level)
            ),
        }
    }
}

/// The measurement positions \[m\] of the candidates of `grid`: the grid's or its template's,
/// those on the template's spin line. Errors: none on the line.
pub(super) fn candidate_positions(
    rh: &Rheometer,
    grid: &CandidateGrid,
) -> Result<Vec<f64>, RheometerError> {
    let template = &rh.experiments[grid.template];
    let positions: Vec<f64> = grid
        .positions
        .clone()
        .unwrap_or_else(|| rh.measurements[grid.template].positions.clone())
        .into_iter()
        .filter(|&s| s <= template.spinline_length)
        .collect();
    if positions.is_empty() {
        return Err(RheometerError::Data(format!(
            "no candidate measurement position lies on the spin line (0 to {} m)",
            template.spinline_length
        )));
    }
    Ok(positions)
}

/// The information `A` and score covariance `B` of the current data (each `p × p` row-major):
/// the sums of every experiment's, the fit weighting every point alike by the plan's level and
/// the noise the plan's.
fn current_information(
    rh: &Rheometer,
    id: &Identification,
    columns: &Columns,
    noise: &NoisePlan,
) -> Result<(Vec<f64>, Vec<f64>), RheometerError> {
    let parts: Result<Vec<ExperimentInformation>, RheometerError> = (0..rh.len())
        .into_par_iter()
        .map(|k| {
            let pos = &rh.measurements[k].positions;
            let fit = vec![noise.level; pos.len()];
            let sig = noise.sigmas(pos, rh.experiments[k].spinline_length);
            experiment_information_under(
                &rh.models[k],
                &id.solutions[k],
                pos,
                (&fit, &sig),
                columns,
            )
            .map_err(|source| RheometerError::Simulation {
                experiment: rh.experiments[k].name.clone(),
                n: id.law()[0],
                kappa: id.law()[1],
                source,
            })
        })
        .collect_in_order();
    let p = columns.shared.len();
    let mut a = vec![0.0; p * p];
    let mut b = vec![0.0; p * p];
    for part in parts? {
        add(&mut a, &part.matrix);
        add(&mut b, &part.noise_matrix);
    }
    Ok((a, b))
}

/// `total += part`, element by element.
fn add(total: &mut [f64], part: &[f64]) {
    for (t, v) in total.iter_mut().zip(part) {
        *t += v;
    }
}

/// Predicts, for every candidate of `request` added to the data of the fit `id` on `rh`, the
/// uncertainty of the fitted parameters, and ranks the candidates by `request.criterion`.
///
/// The prediction is for the principled estimator weighting every point alike (as the fit
/// does), each experiment's take-up factor fitted, under relative Gaussian noise as
/// `NoisePlan` says (the fitted noise model along the line unless a level is declared or
/// given): the covariance `A⁻¹ B A⁻¹` (see `information`). Errors: a fit
/// without noise level or standard errors (the current data must determine every fitted
/// parameter), a bad grid.
pub fn design_for_estimation(
    rh: &Rheometer,
    id: &Identification,
    request: &DesignRequest,
) -> Result<Design, RheometerError> {
    design_for_estimation_with(rh, id, request, &|_| {})
}

/// [`design_for_estimation`], telling `report` how long the candidates will take once the
/// first rows are done (see `rows_in_order`).
pub(crate) fn design_for_estimation_with(
    rh: &Rheometer,
    id: &Identification,
    request: &DesignRequest,
    report: &(dyn Fn(&DesignEstimate) + Sync),
) -> Result<Design, RheometerError> {
    let t0 = Instant::now();
    let grid = &request.grid;
    grid.validate().map_err(RheometerError::Data)?;
    let template = rh.experiments.get(grid.template).ok_or_else(|| {
        RheometerError::Data(format!(
            "template experiment {} of a data set with {} experiments",
            grid.template,
            rh.len()
        ))
    })?;
    let noise = NoisePlan::of(id, request.noise)?;
    let level = noise.level;
    let model0 = rh
        .models
        .first()
        .ok_or_else(|| RheometerError::Data("the data set has no experiments".into()))?;
    let columns = Columns {
        shared: shared_columns(model0, id).map_err(RheometerError::Data)?,
        nuisance: Some(model0.take_up_factor_index()),
    };
    if columns.shared.is_empty() {
        return Err(RheometerError::Data(
            "the fit has no fitted shared parameter: nothing to design for".into(),
        ));
    }
    let p = columns.shared.len();
    let (current_info, current_score) = current_information(rh, id, &columns, &noise)?;
    let current_cov = sandwich(&current_info, &current_score, p);
    let reference = current_cov
        .as_deref()
        .and_then(|c| Reference::from_covariance(c, &id.names))
        .ok_or_else(|| {
            RheometerError::Data(format!(
                "the current data do not determine every fitted parameter ({}): their information \
             is singular; fix or drop a parameter before designing",
                id.names.join(", ")
            ))
        })?;
    let current = current_cov
        .as_deref()
        .and_then(|c| reference.predict_covariance(c))
        .ok_or_else(|| {
            RheometerError::Data("the current information is not positive definite".into())
        })?;
    let positions = candidate_positions(rh, grid)?;
    let fit_sigmas = vec![level; positions.len()];
    let sigmas = noise.sigmas(&positions, template.spinline_length);
    let mut params = id.local_params.clone();
    params[model0.take_up_factor_index()] = 1.0;
    let ctx = Context {
        rh,
        grid,
        params: &params,
        positions: &positions,
        sigmas: (&fit_sigmas, &sigmas),
        columns: &columns,
        current: (&current_info, &current_score),
        reference: &reference,
        options: &request.simulate,
    };
    let all = grid.candidates();
    let nt = grid.take_up.values().len();
    let mut candidates: Vec<CandidateOutcome> =
        rows_in_order(&all, nt, |row| ctx.row(row, template), report);
    let crit = request.criterion;
    let ranking = rank_by_gain(&mut candidates, crit, &current);
    let notes = estimation_notes(&noise, id);
    Ok(Design {
        parameters: id.names.clone(),
        values: columns.shared.iter().map(|&l| id.local_params[l]).collect(),
        fit_stderr: id
            .fit
            .standard_errors()
            .unwrap_or_else(|| vec![f64::NAN; id.fit.p.len()])[..id.names.len()]
            .to_vec(),
        noise_level: level,
        noise_model: noise.words(),
        noise_source: noise.source,
        candidate_noise: sigmas,
        template: template.name.clone(),
        criterion: crit,
        grid: grid.clone(),
        current,
        candidates,
        ranking,
        notes,
        wall_time_s: t0.elapsed().as_secs_f64(),
    })
}

/// Each candidate's gain over the `current` prediction under `crit`, its rank by the
/// criterion's score (best first), and the ranking (the candidates with a prediction, best first).
fn rank_by_gain(
    candidates: &mut [CandidateOutcome],
    crit: Criterion,
    current: &Prediction,
) -> Vec<usize> {
    for c in candidates.iter_mut() {
        c.gain = c
            .prediction
            .as_ref()
            .map_or(f64::NAN, |p| p.gain(crit, current));
    }
    let mut ranking: Vec<usize> = (0..candidates.len())
        .filter(|&i| candidates[i].prediction.is_some())
        .collect();
    ranking.sort_by(|&a, &b| {
        let s = |i: usize| {
            candidates[i]
                .prediction
                .as_ref()
                .map_or(f64::NAN, |p| p.score(crit))
        };
        s(b).total_cmp(&s(a))
    });
    for (r, &i) in ranking.iter().enumerate() {
        candidates[i].rank = Some(r + 1);
    }
    ranking
}

/// The design's notes: the noise the predictions assume, what of the fit's noise they leave
/// out, and the estimator they are for.
fn estimation_notes(noise: &NoisePlan, id: &Identification) -> Vec<String> {
    let mut notes = vec![format!(
        "predictions assume relative Gaussian noise, {}, a fit weighting every point alike and \
         a take-up factor fitted per experiment, as the principled estimator does",
        noise.words()
    )];
    if noise.source == NoiseSource::Fitted {
        let lag1 = id.summary.noise.model.as_ref().map_or(f64::NAN, |m| m.lag1);
        notes.push(format!(
            "the fit's record holds no estimate of the noise's correlation along the line (its \
             lag-1 autocorrelation of the residuals, {lag1:+.2}, tests for a misfit, which \
             raises it as much as a correlated noise does): the points are taken as independent"
        ));
    } else {
        notes.push(format!(
            "the noise the fit estimates along the line is not used (the level is {}); the \
             noise model's level is {:.3} %",
            if noise.source == NoiseSource::Given {
                "given"
            } else {
                "declared"
            },
            100.0
                * id.summary
                    .noise
                    .model
                    .as_ref()
                    .map_or(f64::NAN, |m| m.noise_rms)
        ));
    }
    if id.summary.estimator != crate::fit::Estimator::Principled {
        notes.push(
            "the fit used the paper's estimator; the predictions are for the principled one".into(),
        );
    }
    notes
}

/// What every candidate's evaluation shares.
struct Context<'a> {
    rh: &'a Rheometer,
    grid: &'a CandidateGrid,
    params: &'a [f64],
    positions: &'a [f64],
    /// The fit's weights `τ` and the noise `σ` \[-\] at the candidate positions.
    sigmas: (&'a [f64], &'a [f64]),
    columns: &'a Columns,
    /// The current data's information `A` and score covariance `B`.
    current: (&'a [f64], &'a [f64]),
    reference: &'a Reference,
    options: &'a SimulateOptions,
}

impl Context<'_> {
    /// The candidates of one mass flow, in order, each warm-started from the last solved one.
    fn row(
        &self,
        row: &[Candidate],
        template: &crate::model::setup::Experiment,
    ) -> Vec<CandidateOutcome> {
        let mut last: Option<Solution> = None;
        row.iter()
            .map(|c| {
                let exp = self.grid.experiment(template, c);
                let mut out = CandidateOutcome {
                    candidate: c.clone(),
                    name: exp.name.clone(),
                    prediction: None,
                    gain: f64::NAN,
                    rank: None,
                    infeasible: None,
                    take_up_reading_m: f64::NAN,
                };
                match candidate_information_under(
                    self.rh,
                    &exp,
                    self.params,
                    (self.positions, self.sigmas),
                    self.columns,
                    last.as_ref(),
                    self.options,
                ) {
                    Ok((info, sol)) => {
                        let mut a = self.current.0.to_vec();
                        let mut b = self.current.1.to_vec();
                        add(&mut a, &info.matrix);
                        add(&mut b, &info.noise_matrix);
                        out.prediction = sandwich(&a, &b, self.columns.shared.len())
                            .and_then(|c| self.reference.predict_covariance(&c));
                        out.take_up_reading_m = info.readings.last().copied().unwrap_or(f64::NAN);
                        last = Some(sol);
                    }
                    Err(reason) => out.infeasible = Some(reason),
                }
                out
            })
            .collect()
    }
}

/// The information of candidate experiment `exp` under the model of `rh` at the local
/// parameters `params` (take-up factor 1), measured at `positions` \[m\] with relative noise
/// `sigmas` \[-\] (the fit weighting the points by it), and its solution; or why it has none.
/// The BVP is warm-started from `warm` when that is a solution on the same spin line (a cold
/// start where that fails).
pub(super) fn candidate_information(
    rh: &Rheometer,
    exp: &crate::model::setup::Experiment,
    params: &[f64],
    (positions, sigmas): (&[f64], &[f64]),
    columns: &Columns,
    warm: Option<&Solution>,
    options: &SimulateOptions,
) -> Result<(ExperimentInformation, Solution), String> {
    candidate_information_under(
        rh,
        exp,
        params,
        (positions, (sigmas, sigmas)),
        columns,
        warm,
        options,
    )
}

/// [`candidate_information`] for a fit weighting point `j` by `1/τ_j²` while its noise is
/// `σ_j` (`(τ, σ)` \[-\], see [`experiment_information_under`]).
fn candidate_information_under(
    rh: &Rheometer,
    exp: &crate::model::setup::Experiment,
    params: &[f64],
    (positions, sigmas): (&[f64], (&[f64], &[f64])),
    columns: &Columns,
    warm: Option<&Solution>,
    options: &SimulateOptions,
) -> Result<(ExperimentInformation, Solution), String> {
    let physics = rh.spec.physics().map_err(|e| e.to_string())?;
    let model: CarreauFiber =
        FiberModel::new(&rh.material, &rh.air, exp, CarreauLike::new(), physics)
            .map_err(|e| e.to_string())?;
    let sol = solve_candidate(&model, params, warm, options)?;
    let info = experiment_information_under(&model, &sol, positions, sigmas, columns)
        .map_err(|e| format!("sensitivities: {e}"))?;
    if info.readings.iter().any(|d| !(d.is_finite() && *d > 0.0)) {
        return Err("the predicted diameter is not positive along the line".into());
    }
    Ok((info, sol))
}

/// Warm start from a neighbour on the same spin line, else (or if that fails) a cold start.
fn solve_candidate(
    model: &CarreauFiber,
    params: &[f64],
    warm: Option<&Solution>,
    options: &SimulateOptions,
) -> Result<Solution, String> {
    let length = model.length();
    if let Some(w) = warm.filter(|w| w.x.last().is_some_and(|x| (x - length).abs() < 1e-12)) {
        let opts = options.solve_options();
        let mut solver = Solver::new(model, opts.clone());
        if let Ok(sol) = solver.solve_with(params, &Guess::from(w), &opts) {
            return Ok(sol);
        }
    }
    simulate_params(model, params, None, options)
        .map(|s| s.solution)
        .map_err(|e| e.to_string())
}

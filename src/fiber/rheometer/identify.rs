//! Identification of `(n, κ)`: the objective over all experiments, the start heuristic (paper
//! Algorithm 2) and the bounded trust-region Gauss–Newton fit.
//!
//! Every evaluation solves the `M` fiber BVPs in parallel (rayon), each warm-started from its
//! last accepted solution (no continuation inside the fit, as in the paper), and builds the exact
//! residual Jacobian from forward sensitivities (one extra solve with the kept factorisation per
//! experiment). A BVP that fails at a trial point makes the whole trial point fail, which the
//! driver treats as a rejected step.

use super::estimator::{Estimator, PaperResidual, RelativeResidual};
use super::layout::{EffectSlot, FitStart, Layout};
use crate::fiber::diagnostics::candidates::ModelSpec;
use crate::fiber::error::FiberError;
use crate::fiber::material_law::CarreauLike;
use crate::fiber::model::FiberModel;
use crate::fiber::setup::{Air, Experiment, ExperimentSet, Material, Measurements, TakeUp};
use crate::fiber::simulate::{simulate_params, SimulateOptions};
use crate::fiber::smoothing::{smooth, SmoothFit, SmoothingError};
use crate::least_squares::{fit, FitError, FitOptions, FitResult, LeastSquaresProblem};
use crate::sensitivity::{residual_jacobian, PointFunction, Sensitivities};
use crate::solution::Solution;
use crate::solve::{Guess, Solver};
use rayon::prelude::*;
use std::time::Instant;
use thiserror::Error;

/// The fiber model the rheometer identifies: Carreau-type law (a Newtonian model is `n = 1`),
/// the paper's physics plus the effects of its [`ModelSpec`].
pub type CarreauFiber = FiberModel<CarreauLike>;

/// What can go wrong in the rheometer.
#[derive(Debug, Error)]
pub enum RheometerError {
    /// Unusable data.
    #[error("{0}")]
    Data(String),
    /// Smoothing an experiment's data failed.
    #[error("experiment {experiment}: {source}")]
    Smoothing {
        /// Experiment name.
        experiment: String,
        /// Cause.
        source: SmoothingError,
    },
    /// A fiber simulation failed.
    #[error("experiment {experiment}: simulation at (n, κ) = ({n}, {kappa}) failed: {source}")]
    Simulation {
        /// Experiment name.
        experiment: String,
        /// Power index.
        n: f64,
        /// κ = ln K.
        kappa: f64,
        /// Cause.
        source: FiberError,
    },
    /// The least-squares fit could not run.
    #[error("fit: {0}")]
    Fit(#[from] FitError),
}

/// Options of the identification.
#[derive(Debug, Clone)]
pub struct IdentifyOptions {
    /// The cost to minimise.
    pub estimator: Estimator,
    /// Regular optimisation points per experiment for the paper's cost (`n_o`, default 20).
    pub n_opt_points: usize,
    /// BVP settings (tolerance 1e-6 by default).
    pub simulate: SimulateOptions,
    /// Lower bounds of `(n, κ)` (default `(0, 7)`, the paper's Ω).
    pub lower: [f64; 2],
    /// Upper bounds of `(n, κ)` (default `(1, 20)`).
    pub upper: [f64; 2],
    /// Bounds of the take-up factors `φ_k = d_out,k / d_fit,k(L)` (principled estimator;
    /// default `(0.5, 1.5)`).
    pub take_up_bounds: [f64; 2],
    /// Gauss–Newton iteration limit (default 100).
    pub max_iterations: usize,
    /// Relative measurement uncertainty σ of the diameters; `None`: the data set's value, or 1.
    pub relative_uncertainty: Option<f64>,
}

impl Default for IdentifyOptions {
    fn default() -> Self {
        let simulate = SimulateOptions {
            factor_at_solution: true,
            ..SimulateOptions::default()
        };
        IdentifyOptions {
            estimator: Estimator::Principled,
            n_opt_points: 20,
            simulate,
            lower: [0.0, 7.0],
            upper: [1.0, 20.0],
            take_up_bounds: [0.5, 1.5],
            max_iterations: 100,
            relative_uncertainty: None,
        }
    }
}

impl IdentifyOptions {
    /// Default options with the given estimator.
    pub fn with_estimator(estimator: Estimator) -> Self {
        IdentifyOptions {
            estimator,
            ..Default::default()
        }
    }
}

/// The eleven start points `(n, κ)` of the paper's Table 3 (κ = ln 10⁴, ln 10⁵, ln 10⁶).
pub const PAPER_TABLE3_STARTS: [[f64; 2]; 11] = [
    [0.5, 9.21],
    [0.7, 9.21],
    [0.9, 9.21],
    [0.3, 11.51],
    [0.5, 11.51],
    [0.7, 11.51],
    [0.9, 11.51],
    [0.3, 13.82],
    [0.5, 13.82],
    [0.7, 13.82],
    [0.9, 13.82],
];

/// Prepared data: smoothed measurements and one fiber model per experiment.
#[derive(Debug)]
pub struct Rheometer {
    /// The polymer.
    pub material: Material,
    /// The air.
    pub air: Air,
    /// Experiments (take-up condition set to `d_fit(L)` where the data set gives none).
    pub experiments: Vec<Experiment>,
    /// Raw measurements.
    pub measurements: Vec<Measurements>,
    /// Ansatz fits of the measurements.
    pub smoothing: Vec<SmoothFit>,
    /// One model per experiment.
    pub models: Vec<CarreauFiber>,
    /// Relative measurement uncertainty from the data set, if given.
    pub relative_uncertainty: Option<f64>,
    /// The model: law, effects, neutral candidates.
    pub spec: ModelSpec,
}

impl Rheometer {
    /// Smooths every experiment's data and builds its model (the paper's: Carreau-type law,
    /// no extra effects). Experiments without measurements are an error (the rheometer needs
    /// data for each).
    pub fn new(set: &ExperimentSet) -> Result<Self, RheometerError> {
        Self::with_spec(set, ModelSpec::default())
    }

    /// As [`new`](Self::new) with the model `spec` (law, effects fitted or fixed, neutral
    /// candidates).
    pub fn with_spec(set: &ExperimentSet, spec: ModelSpec) -> Result<Self, RheometerError> {
        spec.validate().map_err(RheometerError::Data)?;
        if set.experiments.is_empty() {
            return Err(RheometerError::Data(
                "the data set has no experiments".into(),
            ));
        }
        let mut experiments = Vec::new();
        let mut measurements = Vec::new();
        let mut smoothing = Vec::new();
        let mut models = Vec::new();
        for (e, m) in set.experiments.iter().zip(&set.measurements) {
            let m = m.as_ref().ok_or_else(|| {
                RheometerError::Data(format!("experiment {} has no measurements", e.name))
            })?;
            let f =
                smooth(&m.positions, &m.diameters).map_err(|source| RheometerError::Smoothing {
                    experiment: e.name.clone(),
                    source,
                })?;
            let mut e = e.clone();
            if e.take_up.is_none() {
                e.take_up = Some(TakeUp::Diameter(f.diameter(e.spinline_length)));
            }
            let model = FiberModel::new(
                &set.material,
                &set.air,
                &e,
                CarreauLike::new(),
                spec.physics(),
            )
            .map_err(|source| RheometerError::Simulation {
                experiment: e.name.clone(),
                n: f64::NAN,
                kappa: f64::NAN,
                source,
            })?;
            experiments.push(e);
            measurements.push(m.clone());
            smoothing.push(f);
            models.push(model);
        }
        Ok(Rheometer {
            material: set.material.clone(),
            air: set.air.clone(),
            experiments,
            measurements,
            smoothing,
            models,
            relative_uncertainty: set.relative_uncertainty,
            spec,
        })
    }

    /// Number of experiments.
    pub fn len(&self) -> usize {
        self.models.len()
    }

    /// Whether there are no experiments.
    pub fn is_empty(&self) -> bool {
        self.models.is_empty()
    }

    /// An objective at start point `(n, κ)` (cold starts of all experiments, in parallel).
    pub fn objective(
        &self,
        start: [f64; 2],
        options: &IdentifyOptions,
    ) -> Result<Objective<'_>, RheometerError> {
        Objective::new(self, &FitStart::at(start), options)
    }

    /// An objective for a general start (free candidates, start strengths, warm starts).
    pub fn objective_from(
        &self,
        start: &FitStart,
        options: &IdentifyOptions,
    ) -> Result<Objective<'_>, RheometerError> {
        Objective::new(self, start, options)
    }

    /// Runs the identification from `start = (n, κ)`.
    pub fn identify(
        &self,
        start: [f64; 2],
        options: &IdentifyOptions,
    ) -> Result<Identification, RheometerError> {
        self.identify_from(&FitStart::at(start), options)
    }

    /// Runs the identification from a general start.
    pub fn identify_from(
        &self,
        start: &FitStart,
        options: &IdentifyOptions,
    ) -> Result<Identification, RheometerError> {
        let t0 = Instant::now();
        let mut obj = self.objective_from(start, options)?;
        let p0 = obj.initial_parameters();
        let (lower, upper) = obj.bounds();
        let fo = FitOptions {
            initial_radius: 0.3,
            max_radius: 1.0,
            max_iterations: options.max_iterations,
            ..FitOptions::with_bounds(lower, upper)
        };
        let fit_result = fit(&mut obj, &p0, &fo)?;
        let solutions: Vec<Solution> = obj.runs.iter().map(|r| r.accepted.clone()).collect();
        let rms = self.rms_relative_residual(&solutions);
        let ns = obj.layout.num_shared();
        let local = obj.layout.local(
            &fit_result.p[..ns],
            1.0,
            self.models[0].take_up_factor_index(),
        );
        Ok(Identification {
            estimator: options.estimator,
            start: start.law,
            n: local[1],
            kappa: local[2],
            take_up_factors: if options.estimator == Estimator::Principled {
                fit_result.p[ns..].to_vec()
            } else {
                vec![1.0; self.len()]
            },
            names: obj.layout.names.clone(),
            effects: obj.layout.effects.clone(),
            local_params: local,
            rms_relative_residual: rms,
            solutions,
            fit: fit_result,
            wall_time_s: t0.elapsed().as_secs_f64(),
        })
    }

    /// Paper Algorithm 2: with `n = n_init` (0.5), walk κ down from the upper bound in steps of
    /// 1 until the cost differs from the Newtonian cost by more than 10%.
    pub fn start_heuristic(&self, options: &IdentifyOptions) -> Result<StartPoint, RheometerError> {
        let n_init = 0.5;
        let (k_lo, k_hi) = (options.lower[1], options.upper[1]);
        let mut obj = self.objective([1.0, k_hi], options)?;
        let j1 = obj.cost_at(1.0, k_hi)?;
        let mut kappa = k_hi;
        let mut j2 = obj.cost_at(n_init, kappa)?;
        let mut trace = vec![(kappa, j2)];
        while ((j1 - j2) / j1).abs() < 0.1 && kappa > k_lo {
            kappa = (kappa - 1.0).max(k_lo);
            j2 = obj.cost_at(n_init, kappa)?;
            trace.push((kappa, j2));
        }
        Ok(StartPoint {
            start: [n_init, kappa],
            newtonian_cost: j1,
            trace,
        })
    }

    /// RMS of `(d_model − d_meas)/d_meas` over all measurements for the given solutions.
    pub fn rms_relative_residual(&self, solutions: &[Solution]) -> f64 {
        let (mut sum, mut count) = (0.0, 0usize);
        for (k, sol) in solutions.iter().enumerate() {
            for r in self.relative_residuals(k, sol) {
                sum += r * r;
                count += 1;
            }
        }
        (sum / count.max(1) as f64).sqrt()
    }

    /// `(d_model − d_meas)/d_meas` at the measurement positions of experiment `k`.
    pub fn relative_residuals(&self, k: usize, sol: &Solution) -> Vec<f64> {
        let model = &self.models[k];
        let lo = model.scaling.reference.length;
        let m = &self.measurements[k];
        let mut y = [0.0; 4];
        let mut yp = [0.0; 4];
        m.positions
            .iter()
            .zip(&m.diameters)
            .map(|(&s, &d)| {
                sol.eval_into(s / lo, &mut y, &mut yp);
                let dm = model.diameter(y[0], model.density(y[2])) * model.scaling.diameter();
                dm / d - 1.0
            })
            .collect()
    }
}

/// Residuals and row-major Jacobian of one experiment.
type ResidualsAndJacobian = (Vec<f64>, Vec<f64>);

/// Result of the start heuristic.
#[derive(Debug, Clone)]
pub struct StartPoint {
    /// The start point `(n_init, κ)`.
    pub start: [f64; 2],
    /// The Newtonian reference cost `J(1, κ_upper)`.
    pub newtonian_cost: f64,
    /// `(κ, J(n_init, κ))` for every κ tried.
    pub trace: Vec<(f64, f64)>,
}

/// Result of an identification.
#[derive(Debug, Clone)]
pub struct Identification {
    /// The estimator used.
    pub estimator: Estimator,
    /// Start point `(n, κ)`.
    pub start: [f64; 2],
    /// Identified power index `n` \[-\].
    pub n: f64,
    /// Identified `κ = ln(K / 1 Pa)` \[-\].
    pub kappa: f64,
    /// Take-up factors `φ_k = d_out,k / d_fit,k(L)` (all 1 for the paper's estimator).
    pub take_up_factors: Vec<f64>,
    /// Names of the shared fitted parameters (the first entries of `fit.p`; the take-up factors
    /// follow).
    pub names: Vec<String>,
    /// The model's effects (fixed or fitted) and where their strengths sit.
    pub effects: Vec<EffectSlot>,
    /// The fitted local model parameters `[c, n, κ, strengths..., φ = 1]`.
    pub local_params: Vec<f64>,
    /// RMS of `(d_model − d_meas)/d_meas` over all raw measurements \[-\].
    pub rms_relative_residual: f64,
    /// Final fiber solutions, one per experiment.
    pub solutions: Vec<Solution>,
    /// The least-squares result (cost, Jacobian, iterations, termination).
    pub fit: FitResult,
    /// Wall time \[s\], including the cold starts.
    pub wall_time_s: f64,
}

struct Run<'a> {
    model: &'a CarreauFiber,
    solver: Solver<'a, CarreauFiber>,
    accepted: Solution,
    pending: Option<Solution>,
    /// Evaluation points (dimensionless `s̃`).
    points: Vec<f64>,
    /// Paper: `d_fit` at the points; principled: measured diameters (dimensionless).
    targets: Vec<f64>,
    sqrt_delta: Vec<f64>,
    name: String,
}

/// The least-squares objective of the rheometer over all experiments.
pub struct Objective<'a> {
    estimator: Estimator,
    runs: Vec<Run<'a>>,
    options: IdentifyOptions,
    sigma: f64,
    layout: Layout,
}

impl<'a> Objective<'a> {
    fn new(
        rheo: &'a Rheometer,
        fit_start: &FitStart,
        options: &IdentifyOptions,
    ) -> Result<Self, RheometerError> {
        let start = fit_start.law;
        let layout = Layout::new(&rheo.models[0], &rheo.spec, fit_start, options)?;
        if let Some(w) = &fit_start.warm {
            if w.len() != rheo.len() {
                return Err(RheometerError::Data(format!(
                    "{} warm-start solutions for {} experiments",
                    w.len(),
                    rheo.len()
                )));
            }
        }
        let shared0 = layout.shared_start();
        if options.n_opt_points < 1 {
            return Err(RheometerError::Data(
                "n_opt_points must be at least 1".into(),
            ));
        }
        let sigma = options
            .relative_uncertainty
            .or(rheo.relative_uncertainty)
            .unwrap_or(1.0);
        let runs: Result<Vec<Run<'a>>, RheometerError> = rheo
            .models
            .par_iter()
            .enumerate()
            .map(|(k, model)| {
                let p = layout.local(&shared0, 1.0, model.take_up_factor_index());
                let warm = fit_start.warm.as_ref().map(|w| &w[k]);
                let sol =
                    simulate_params(model, &p, warm, &options.simulate).map_err(|source| {
                        RheometerError::Simulation {
                            experiment: rheo.experiments[k].name.clone(),
                            n: start[0],
                            kappa: start[1],
                            source,
                        }
                    })?;
                let lo = model.scaling.reference.length;
                let dd = model.scaling.diameter();
                let length = rheo.experiments[k].spinline_length;
                let (points, targets, sqrt_delta) = match options.estimator {
                    Estimator::Paper => {
                        let no = options.n_opt_points;
                        let delta = length / no as f64;
                        let s: Vec<f64> = (1..=no).map(|i| i as f64 * delta).collect();
                        (
                            s.iter().map(|v| v / lo).collect(),
                            s.iter()
                                .map(|&v| rheo.smoothing[k].diameter(v) / dd)
                                .collect(),
                            vec![(delta / lo).sqrt(); no],
                        )
                    }
                    Estimator::Principled => {
                        let m = &rheo.measurements[k];
                        (
                            m.positions.iter().map(|v| v / lo).collect(),
                            m.diameters.iter().map(|v| v / dd).collect(),
                            Vec::new(),
                        )
                    }
                };
                Ok(Run {
                    model,
                    solver: Solver::new(model, options.simulate.solve_options()),
                    accepted: sol.solution,
                    pending: None,
                    points,
                    targets,
                    sqrt_delta,
                    name: rheo.experiments[k].name.clone(),
                })
            })
            .collect();
        Ok(Objective {
            estimator: options.estimator,
            runs: runs?,
            options: options.clone(),
            sigma,
            layout,
        })
    }

    /// The parameter layout of this objective.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    fn initial_parameters(&self) -> Vec<f64> {
        let mut p = self.layout.shared_start();
        if self.estimator == Estimator::Principled {
            p.extend(std::iter::repeat_n(1.0, self.runs.len()));
        }
        p
    }

    /// Global parameters at `(n, κ)` (overriding the template's law values), strengths at their
    /// start values, take-up factors 1.
    fn global_at(&mut self, n: f64, kappa: f64) -> Vec<f64> {
        self.layout.template[1] = n;
        self.layout.template[2] = kappa;
        self.initial_parameters()
    }

    fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let mut lo = self.layout.lower.clone();
        let mut hi = self.layout.upper.clone();
        if self.estimator == Estimator::Principled {
            lo.extend(std::iter::repeat_n(
                self.options.take_up_bounds[0],
                self.runs.len(),
            ));
            hi.extend(std::iter::repeat_n(
                self.options.take_up_bounds[1],
                self.runs.len(),
            ));
        }
        (lo, hi)
    }

    /// Residuals (and the Jacobian if `with_jacobian`) at global parameters `p`; the solutions
    /// become pending (accepted by [`LeastSquaresProblem::accept`]).
    fn eval(
        &mut self,
        p: &[f64],
        with_jacobian: bool,
    ) -> Result<(Vec<f64>, Vec<f64>), RheometerError> {
        let np = p.len();
        let ns = self.layout.num_shared();
        let layout = &self.layout;
        let probe = layout.local(&p[..ns], 1.0, layout.template.len() - 1);
        let (n, kappa) = (probe[1], probe[2]);
        let estimator = self.estimator;
        let sigma = self.sigma;
        let parts: Result<Vec<ResidualsAndJacobian>, RheometerError> = self
            .runs
            .par_iter_mut()
            .enumerate()
            .map(|(k, run)| {
                let phi = if estimator == Estimator::Principled {
                    p[ns + k]
                } else {
                    1.0
                };
                let err = |source: FiberError| RheometerError::Simulation {
                    experiment: run.name.clone(),
                    n,
                    kappa,
                    source,
                };
                let lp = layout.local(&p[..ns], phi, run.model.take_up_factor_index());
                let sol = run
                    .solver
                    .solve(&lp, &Guess::from(&run.accepted))
                    .map_err(|e| err(FiberError::from(e)))?;
                let (r, jl) = if with_jacobian {
                    let sens = Sensitivities::compute(run.model, &sol)
                        .map_err(|e| err(FiberError::from(e)))?;
                    match estimator {
                        Estimator::Paper => residual_jacobian(
                            run.model,
                            &sol,
                            &sens,
                            &run.points,
                            &PaperResidual {
                                model: run.model,
                                sqrt_delta: &run.sqrt_delta,
                                d_fit: &run.targets,
                            },
                        ),
                        Estimator::Principled => residual_jacobian(
                            run.model,
                            &sol,
                            &sens,
                            &run.points,
                            &RelativeResidual {
                                model: run.model,
                                d_meas: &run.targets,
                                sigma,
                            },
                        ),
                    }
                    .map_err(|e| err(FiberError::from(e)))?
                } else {
                    let r = match estimator {
                        Estimator::Paper => values(
                            &sol,
                            &run.points,
                            &PaperResidual {
                                model: run.model,
                                sqrt_delta: &run.sqrt_delta,
                                d_fit: &run.targets,
                            },
                        ),
                        Estimator::Principled => values(
                            &sol,
                            &run.points,
                            &RelativeResidual {
                                model: run.model,
                                d_meas: &run.targets,
                                sigma,
                            },
                        ),
                    };
                    (r, Vec::new())
                };
                // map local parameter columns (c, n, κ, strengths, φ) to global ones
                let q = lp.len();
                let phi_idx = run.model.take_up_factor_index();
                let mut jg = Vec::new();
                if with_jacobian {
                    jg = vec![0.0; r.len() * np];
                    for i in 0..r.len() {
                        for (c, &li) in layout.free.iter().enumerate() {
                            jg[i * np + c] = jl[i * q + li];
                        }
                        if estimator == Estimator::Principled {
                            jg[i * np + ns + k] = jl[i * q + phi_idx];
                        }
                    }
                }
                run.pending = Some(sol);
                Ok((r, jg))
            })
            .collect();
        let parts = parts?;
        let mut r = Vec::new();
        let mut j = Vec::new();
        for (ri, ji) in parts {
            r.extend(ri);
            j.extend(ji);
        }
        Ok((r, j))
    }

    /// The cost `J = Σ r²` at `(n, κ)` with take-up factors 1, accepting the solutions as new
    /// warm starts (falls back to a cold start for experiments whose warm solve fails).
    pub fn cost_at(&mut self, n: f64, kappa: f64) -> Result<f64, RheometerError> {
        let p = self.global_at(n, kappa);
        let r = match self.eval(&p, false) {
            Ok((r, _)) => r,
            Err(_) => {
                // cold starts
                let opts = self.options.simulate.clone();
                let layout = &self.layout;
                let ns = layout.num_shared();
                let res: Result<Vec<()>, RheometerError> = self
                    .runs
                    .par_iter_mut()
                    .map(|run| {
                        let lp = layout.local(&p[..ns], 1.0, run.model.take_up_factor_index());
                        let sol =
                            simulate_params(run.model, &lp, None, &opts).map_err(|source| {
                                RheometerError::Simulation {
                                    experiment: run.name.clone(),
                                    n,
                                    kappa,
                                    source,
                                }
                            })?;
                        run.accepted = sol.solution;
                        Ok(())
                    })
                    .collect();
                res?;
                self.eval(&p, false)?.0
            }
        };
        self.accept_pending();
        Ok(r.iter().map(|v| v * v).sum())
    }

    /// Cost at `(n, κ)` from the current warm starts only (no cold-start fallback); on success
    /// the solutions become the new warm starts.
    pub fn try_cost_at(&mut self, n: f64, kappa: f64) -> Result<f64, RheometerError> {
        let p = self.global_at(n, kappa);
        let (r, _) = self.eval(&p, false)?;
        self.accept_pending();
        Ok(r.iter().map(|v| v * v).sum())
    }

    /// The current warm-start solutions, one per experiment.
    pub fn solutions(&self) -> Vec<Solution> {
        self.runs.iter().map(|r| r.accepted.clone()).collect()
    }

    /// Replaces the warm-start solutions (same order as [`solutions`](Self::solutions)).
    pub fn set_solutions(&mut self, sols: &[Solution]) {
        for (r, s) in self.runs.iter_mut().zip(sols) {
            r.accepted = s.clone();
        }
    }

    fn accept_pending(&mut self) {
        for run in &mut self.runs {
            if let Some(s) = run.pending.take() {
                run.accepted = s;
            }
        }
    }
}

fn values<G: PointFunction>(sol: &Solution, xs: &[f64], g: &G) -> Vec<f64> {
    let p = sol.full_params();
    let mut y = [0.0; 4];
    let mut yp = [0.0; 4];
    xs.iter()
        .enumerate()
        .map(|(j, &x)| {
            sol.eval_into(x, &mut y, &mut yp);
            g.eval(j, x, &y, &p)
        })
        .collect()
}

impl LeastSquaresProblem for Objective<'_> {
    type Error = RheometerError;
    fn num_params(&self) -> usize {
        match self.estimator {
            Estimator::Paper => self.layout.num_shared(),
            Estimator::Principled => self.layout.num_shared() + self.runs.len(),
        }
    }
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), RheometerError> {
        self.eval(p, true)
    }
    fn accept(&mut self, _p: &[f64]) {
        self.accept_pending();
    }
}

//! The rheometer's least-squares objective over all experiments: one warm-started solver per
//! experiment, residuals of the chosen estimator at the evaluation points, and their exact
//! Jacobian from forward sensitivities, evaluated in parallel (rayon). A failed BVP at a trial
//! point is reported to the driver as a failed evaluation (a rejected step), and the last
//! accepted solutions stay the warm starts.

use super::data::Rheometer;
use super::estimator::{Estimator, PaperResidual, RelativeResidual};
use super::layout::{FitStart, Layout};
use super::options::{CarreauFiber, IdentifyOptions, RheometerError};
use crate::fiber::error::FiberError;
use crate::fiber::simulate::simulate_params;
use crate::least_squares::LeastSquaresProblem;
use crate::sensitivity::{residual_jacobian, PointFunction, Sensitivities};
use crate::solution::Solution;
use crate::solve::{Guess, Solver};
use rayon::prelude::*;

/// Residuals and row-major Jacobian of one experiment.
type ResidualsAndJacobian = (Vec<f64>, Vec<f64>);

pub(super) struct Run<'a> {
    model: &'a CarreauFiber,
    solver: Solver<'a, CarreauFiber>,
    pub(super) accepted: Solution,
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
    pub(super) runs: Vec<Run<'a>>,
    options: IdentifyOptions,
    sigma: f64,
    pub(super) layout: Layout,
}

impl Rheometer {
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
}

impl<'a> Objective<'a> {
    pub(super) fn new(
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

    pub(super) fn initial_parameters(&self) -> Vec<f64> {
        let mut p = self.layout.shared_start();
        if self.estimator == Estimator::Principled {
            p.extend(std::iter::repeat_n(1.0, self.runs.len()));
        }
        p
    }

    /// Global parameters at `(n, κ)` (overriding the template's law values), strengths at their
    /// start values, take-up factors 1.
    fn global_at(&mut self, n: f64, kappa: f64) -> Vec<f64> {
        self.layout.set_law(n, kappa);
        self.initial_parameters()
    }

    pub(super) fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
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
        self.eval_from(p, with_jacobian, None)
    }

    /// [`eval`](Self::eval) warm-started from `starts` (one per experiment) instead of the
    /// accepted solutions.
    fn eval_from(
        &mut self,
        p: &[f64],
        with_jacobian: bool,
        starts: Option<&[Guess]>,
    ) -> Result<(Vec<f64>, Vec<f64>), RheometerError> {
        if let Some(g) = starts {
            if g.len() != self.runs.len() {
                return Err(RheometerError::Data(format!(
                    "{} warm starts for {} experiments",
                    g.len(),
                    self.runs.len()
                )));
            }
        }
        let np = p.len();
        let ns = self.layout.num_shared();
        let layout = &self.layout;
        let probe = layout.local(&p[..ns], 1.0, layout.params.take_up_factor());
        let [n, kappa] = layout.law_of(&probe);
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
                let own;
                let guess = match starts {
                    Some(g) => &g[k],
                    None => {
                        own = Guess::from(&run.accepted);
                        &own
                    }
                };
                let sol = run
                    .solver
                    .solve(&lp, guess)
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

    /// Cost at `(n, κ)` warm-started from `starts` (one per experiment, e.g. predicted by
    /// [`secant_guess`](crate::continuation::secant_guess)) instead of the current warm starts;
    /// on success the solutions become the new warm starts, on failure the warm starts are
    /// unchanged.
    pub fn try_cost_from(
        &mut self,
        n: f64,
        kappa: f64,
        starts: &[Guess],
    ) -> Result<f64, RheometerError> {
        let p = self.global_at(n, kappa);
        let (r, _) = self.eval_from(&p, false, Some(starts))?;
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

//! The rheometer's least-squares objective over all experiments: one warm-started solver per
//! experiment, residuals of the chosen estimator at the evaluation points, and their exact
//! Jacobian from forward sensitivities, evaluated in parallel (rayon). A failed BVP at a trial
//! point is reported to the driver as a failed evaluation (a rejected step), and the last
//! accepted solutions stay the warm starts.

use super::data::Rheometer;
use super::estimator::{Estimator, PaperResidual, RelativeResidual};
use super::layout::{FitStart, Layout};
use super::options::{CarreauFiber, FitProgress, IdentifyOptions, RheometerError};
use crate::error::FiberError;
use crate::in_order::CollectInOrder;
use crate::model::simulate::{simulate_params, SimulateOptions, Simulator};
use diffbvp::least_squares::{
    BvpResiduals, BvpRun, Jacobian, LeastSquaresProblem, ParamMap, RunError,
};
use diffbvp::sensitivity::PointFunction;
use diffbvp::solution::Solution;
use diffbvp::solve::{GrowthLimit, Guess, Solver};
use num_dual::DualNum;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The residual of one experiment at its evaluation points: the estimator's residual with the
/// experiment's data (owned, so that a [`BvpRun`] can hold it).
pub(super) enum FiberResidual<'a> {
    /// [`PaperResidual`]: `√Δ_j` and `d_fit(s_j)` (dimensionless).
    Paper {
        model: &'a CarreauFiber,
        sqrt_delta: Vec<f64>,
        d_fit: Vec<f64>,
    },
    /// [`RelativeResidual`]: measured diameters (dimensionless) and each point's `σ_j`.
    Relative {
        model: &'a CarreauFiber,
        d_meas: Vec<f64>,
        sigma: Vec<f64>,
    },
}

impl PointFunction for FiberResidual<'_> {
    #[inline]
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, j: usize, x: f64, y: &[D], p: &[D]) -> D {
        match self {
            FiberResidual::Paper {
                model,
                sqrt_delta,
                d_fit,
            } => PaperResidual {
                model: *model,
                sqrt_delta,
                d_fit,
            }
            .eval(j, x, y, p),
            FiberResidual::Relative {
                model,
                d_meas,
                sigma,
            } => RelativeResidual {
                model: *model,
                d_meas,
                sigma,
            }
            .eval(j, x, y, p),
        }
    }
}

/// The least-squares objective of the rheometer over all experiments: a [`BvpResiduals`] with
/// one run per experiment (the local parameters `[c, n, κ, strengths..., φ]` of experiment `k`
/// map the shared free parameters and, for the principled estimator, `φ_k`), plus the
/// rheometer's parameter layout and error reporting.
pub struct Objective<'a> {
    estimator: Estimator,
    pub(super) runs: BvpResiduals<'a, CarreauFiber, FiberResidual<'a>>,
    names: Vec<String>,
    options: IdentifyOptions,
    pub(super) layout: Layout,
}

impl Rheometer {
    /// An objective at start point `(n, κ)` (cold starts of all experiments, in parallel).
    pub fn objective(
        &self,
        start: [f64; 2],
        options: &IdentifyOptions,
    ) -> Result<Objective<'_>, RheometerError> {
        Objective::new(self, &FitStart::at(start), options, &[])
    }

    /// An objective for a general start (free candidates, start strengths, warm starts).
    pub fn objective_from(
        &self,
        start: &FitStart,
        options: &IdentifyOptions,
    ) -> Result<Objective<'_>, RheometerError> {
        Objective::new(self, start, options, &[])
    }

    /// [`objective_from`](Self::objective_from) for a fit that starts at the take-up factors
    /// `take_up` (one per experiment, principled estimator; empty: all 1); with `solve_there`
    /// the experiments are solved at them where their warm starts were, so that the fit's
    /// first evaluation re-solves nothing.
    pub(crate) fn objective_at_take_up(
        &self,
        start: &FitStart,
        options: &IdentifyOptions,
        take_up: &[f64],
        solve_there: bool,
    ) -> Result<Objective<'_>, RheometerError> {
        // not solving there: the start as a plain fit's, at take-up factors 1 and not
        // linearised, because start solutions linearised for a tangent towards the take-up
        // factors slow the profile walk of a fit at its bound
        Objective::new(
            self,
            start,
            options,
            if solve_there { take_up } else { &[] },
        )
    }
}

impl<'a> Objective<'a> {
    /// The objective of a fit from `fit_start`, every experiment solved at the start law and
    /// strengths and at its take-up factor in `take_up` where its warm start was solved at that
    /// factor (the fit then starts there and its first evaluation re-solves nothing), else at 1
    /// (`take_up` empty: all at 1).
    pub(super) fn new(
        rheo: &'a Rheometer,
        fit_start: &FitStart,
        options: &IdentifyOptions,
        take_up: &[f64],
    ) -> Result<Self, RheometerError> {
        if !take_up.is_empty()
            && (take_up.len() != rheo.len() || options.estimator != Estimator::Principled)
        {
            return Err(RheometerError::Data(format!(
                "{} start take-up factors for {} experiments (principled estimator only)",
                take_up.len(),
                rheo.len()
            )));
        }
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
        let estimator = options.estimator;
        let ns = layout.num_shared();
        let simulated = AtomicUsize::new(0);
        let runs: Result<Vec<BvpRun<'a, CarreauFiber, FiberResidual<'a>>>, RheometerError> = rheo
            .models
            .par_iter()
            .enumerate()
            .map(|(k, model)| {
                let phi_idx = model.take_up_factor_index();
                let warm = fit_start.warm.as_ref().map(|w| &w[k]);
                // at the fit's start take-up factor where the warm start was solved at it (a
                // warm fit continuing the fit it comes from); else at 1, as a cold start is
                let phi = match (take_up.get(k), warm) {
                    (Some(&t), Some(w)) if w.params.get(phi_idx) == Some(&t) => t,
                    _ => 1.0,
                };
                let p = layout.local(&shared0, phi, phi_idx);
                let sim_err = |source: FiberError| RheometerError::Simulation {
                    experiment: rheo.experiments[k].name.clone(),
                    n: start[0],
                    kappa: start[1],
                    source,
                };
                let map = Self::param_map(&layout, estimator, ns, k, phi_idx);
                // where the fit's first evaluation is at these parameters (its take-up factor
                // included), it re-solves this solution without a Newton step and linearises it
                // then: the start solution is not linearised; elsewhere it is, in the
                // parameters the fit frees, for that evaluation's tangent predictor
                let at_start = take_up.get(k).is_none_or(|&t| t == phi);
                let sim = &SimulateOptions {
                    factor_at_solution: options.simulate.factor_at_solution && !at_start,
                    linearization_params: Some(map.linked_models().into()),
                    ..options.simulate.clone()
                };
                // a fit with loose inner iterations at the continuation's own loose tolerance:
                // the cold start's loose end point is the calibration's loose solve
                let loose_start = options.loose_tolerance.filter(|&t| {
                    warm.is_none()
                        && t == sim.continuation.intermediate_tol
                        && sim.tol < t
                        && sim.required_positions.is_empty()
                });
                let (sol, loose) = match loose_start {
                    Some(_) => {
                        let (sol, loose) = Simulator::new(model, sim.clone())
                            .cold_with_loose(&p)
                            .map_err(&sim_err)?;
                        (sol, Some(loose))
                    }
                    None => (
                        simulate_params(model, &p, warm, sim).map_err(&sim_err)?,
                        None,
                    ),
                };
                if let Some(hook) = &options.progress {
                    let done = simulated.fetch_add(1, Ordering::Relaxed) + 1;
                    hook.report(&FitProgress::Simulated {
                        done,
                        total: rheo.len(),
                    });
                }
                let (points, residual) =
                    Self::observations(rheo, k, model, estimator, options, sigma);
                let run = BvpRun::new(
                    Solver::new(model, options.simulate.solve_options()),
                    sol.solution,
                    points,
                    residual,
                    map,
                )
                .map_err(|e| sim_err(FiberError::from(e)))?;
                Ok(match (loose_start, loose) {
                    (Some(t), Some(l)) => run.with_loose_solution(t, l),
                    _ => run,
                })
            })
            .collect_in_order();
        let num_params = match estimator {
            Estimator::Paper => ns,
            Estimator::Principled => ns + rheo.len(),
        };
        let mut fit = BvpResiduals::new(num_params);
        fit.set_loose_tolerance(options.loose_tolerance);
        fit.set_thread_workspaces(true);
        for run in runs? {
            fit.push(run)
                .map_err(|e| RheometerError::Data(format!("parameter layout: {e}")))?;
        }
        if estimator == Estimator::Principled {
            // the take-up factors are the experiments' own parameters: block-arrow normal
            // equations, solved through the Schur complement (linear in the experiments)
            fit.declare_blocks(Some(ns))
                .map_err(|e| RheometerError::Data(format!("parameter layout: {e}")))?;
        }
        Ok(Objective {
            estimator,
            runs: fit,
            names: rheo.experiments.iter().map(|e| e.name.clone()).collect(),
            options: options.clone(),
            layout,
        })
    }

    /// Experiment `k`'s observation points (dimensionless positions) and residual for the
    /// estimator: the paper's `n_opt_points` evaluation points of the smoothed diameter, or the
    /// measurements with their noise levels (`sigma` the relative uncertainty).
    fn observations(
        rheo: &'a Rheometer,
        k: usize,
        model: &'a CarreauFiber,
        estimator: Estimator,
        options: &IdentifyOptions,
        sigma: f64,
    ) -> (Vec<f64>, FiberResidual<'a>) {
        let lo = model.scaling.reference.length;
        let dd = model.scaling.diameter();
        let length = rheo.experiments[k].spinline_length;
        match estimator {
            Estimator::Paper => {
                let no = options.n_opt_points;
                let delta = length / no as f64;
                let s: Vec<f64> = (1..=no).map(|i| i as f64 * delta).collect();
                (
                    s.iter().map(|v| v / lo).collect(),
                    FiberResidual::Paper {
                        model,
                        sqrt_delta: vec![(delta / lo).sqrt(); no],
                        d_fit: s
                            .iter()
                            .map(|&v| rheo.smoothing[k].diameter(v) / dd)
                            .collect(),
                    },
                )
            }
            Estimator::Principled => {
                let m = &rheo.measurements[k];
                (
                    m.positions.iter().map(|v| v / lo).collect(),
                    FiberResidual::Relative {
                        model,
                        d_meas: m.diameters.iter().map(|v| v / dd).collect(),
                        sigma: options.point_sigmas(k, m.diameters.len(), sigma),
                    },
                )
            }
        }
    }

    /// Experiment `k`'s local parameters `[c, n, κ, strengths..., φ]` as a map of the fit
    /// parameters `[shared free..., φ_1, ..., φ_M]`: the template, the shared free parameters
    /// linked to their columns, `φ = 1` (paper) or linked to column `ns + k` (principled).
    fn param_map(
        layout: &Layout,
        estimator: Estimator,
        ns: usize,
        k: usize,
        phi_idx: usize,
    ) -> ParamMap {
        let mut base = layout.template.clone();
        base[phi_idx] = 1.0;
        let mut map = ParamMap::new(base);
        for (c, &li) in layout.free.iter().enumerate() {
            map = map.link(li, c);
        }
        if estimator == Estimator::Principled {
            map = map.link(phi_idx, ns + k);
        }
        map
    }

    /// Copies the layout's template (changed by [`global_at`](Self::global_at)) into the runs'
    /// parameter maps.
    fn sync_maps(&mut self) {
        let template = &self.layout.template;
        for run in self.runs.runs_mut() {
            let phi_idx = run.problem().take_up_factor_index();
            let base = &mut run.map_mut().base;
            base.copy_from_slice(template);
            base[phi_idx] = 1.0;
        }
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
        self.sync_maps();
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

    /// `(n, κ)` at global parameters `p` (for error messages).
    fn law_at(&self, p: &[f64]) -> (f64, f64) {
        let ns = self.layout.num_shared();
        let probe = self
            .layout
            .local(&p[..ns], 1.0, self.layout.template.len() - 1);
        (probe[1], probe[2])
    }

    /// A failed run as the rheometer's error (naming the experiment).
    fn run_error(&self, p: &[f64], e: RunError) -> RheometerError {
        let (n, kappa) = self.law_at(p);
        RheometerError::Simulation {
            experiment: self.names[e.run.min(self.names.len() - 1)].clone(),
            n,
            kappa,
            source: FiberError::from(e.source),
        }
    }

    /// The residuals alone at global parameters `p` (no Jacobian, no sensitivities); the
    /// solutions become pending.
    pub(super) fn residuals_only(&mut self, p: &[f64]) -> Result<Vec<f64>, RheometerError> {
        Ok(self.eval(p, false)?.0)
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
        self.runs
            .evaluate_from(p, with_jacobian, starts)
            .map_err(|e| self.run_error(p, e))
    }

    /// The cost `J = Σ r²` at `(n, κ)` with take-up factors 1, accepting the solutions as new
    /// warm starts (falls back to a cold start for experiments whose warm solve fails).
    pub fn cost_at(&mut self, n: f64, kappa: f64) -> Result<f64, RheometerError> {
        let p = self.global_at(n, kappa);
        let r = match self.eval(&p, false) {
            Ok((r, _)) => r,
            Err(_) => {
                // cold starts
                let opts = &self.options.simulate;
                let names = &self.names;
                let res: Result<Vec<()>, RheometerError> =
                    self.runs
                        .runs_mut()
                        .par_iter_mut()
                        .enumerate()
                        .map(|(k, run)| {
                            let lp = run.map().model_params(&p);
                            let sol = simulate_params(run.problem(), &lp, None, opts).map_err(
                                |source| RheometerError::Simulation {
                                    experiment: names[k].clone(),
                                    n,
                                    kappa,
                                    source,
                                },
                            )?;
                            run.set_accepted(sol.solution);
                            Ok(())
                        })
                        .collect_in_order();
                res?;
                self.eval(&p, false)?.0
            }
        };
        self.runs.accept_pending();
        Ok(r.iter().map(|v| v * v).sum())
    }

    /// Sets the BVP tolerance and the mesh growth limit of the next solves of every experiment
    /// (a landscape's far points, its first attempt at a point). A boundary tolerance of the
    /// objective's options is kept where it is looser than `tol` and raised to `tol` where it
    /// is tighter; without one the boundary conditions are held to `tol`.
    pub fn set_solve_accuracy(&mut self, tol: f64, growth_limit: Option<GrowthLimit>) {
        let bc_tol = self.options.simulate.bc_tol.map(|b| b.max(tol));
        for r in self.runs.runs_mut() {
            let o = &mut r.solver_mut().options;
            o.tol = tol;
            o.bc_tol = bc_tol;
            o.growth_limit = growth_limit;
        }
    }

    /// Cost at `(n, κ)` from the current warm starts only (no cold-start fallback); on success
    /// the solutions become the new warm starts.
    pub fn try_cost_at(&mut self, n: f64, kappa: f64) -> Result<f64, RheometerError> {
        let p = self.global_at(n, kappa);
        let (r, _) = self.eval(&p, false)?;
        self.runs.accept_pending();
        Ok(r.iter().map(|v| v * v).sum())
    }

    /// Cost at `(n, κ)` warm-started from `starts` (one per experiment, e.g. predicted by
    /// [`secant_guess`](diffbvp::continuation::secant_guess)) instead of the current warm starts;
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
        self.runs.accept_pending();
        Ok(r.iter().map(|v| v * v).sum())
    }

    /// The current warm-start solutions, one per experiment.
    pub fn solutions(&self) -> Vec<Solution> {
        self.runs.solutions()
    }

    /// The mesh nodes of each experiment's current warm-start solution (no copies).
    pub fn nodes(&self) -> Vec<usize> {
        self.runs
            .runs()
            .iter()
            .map(|r| r.accepted().nodes())
            .collect()
    }

    /// Replaces the warm-start solutions (same order as [`solutions`](Self::solutions)).
    pub fn set_solutions(&mut self, sols: &[Solution]) {
        self.runs.set_solutions(sols);
    }
}

impl LeastSquaresProblem for Objective<'_> {
    type Error = RheometerError;
    fn num_params(&self) -> usize {
        self.runs.num_params()
    }
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), RheometerError> {
        self.eval(p, true)
    }
    fn evaluate_jacobian(&mut self, p: &[f64]) -> Result<(Vec<f64>, Jacobian), RheometerError> {
        self.runs
            .evaluate_jacobian_from(p, None)
            .map_err(|e| self.run_error(p, e))
    }
    fn accept(&mut self, _p: &[f64]) {
        self.runs.accept_pending();
    }
    fn set_accuracy(&mut self, rms_error: Option<f64>) -> bool {
        self.runs.set_accuracy(rms_error)
    }
}

//! [`BvpResiduals`]: a [`LeastSquaresProblem`] whose residuals come from BVP solves.

use super::blocks::{BlockJacobian, BlockStructure};
use super::{Jacobian, LeastSquaresProblem};
use crate::error::BvpError;
use crate::problem::Bvp;
use crate::sensitivity::{residual_jacobian, tangent_guess, PointFunction, Sensitivities};
use crate::solution::Solution;
use crate::solve::{Guess, SolveOptions, Solver};
use std::sync::Arc;

/// One affine link of a [`ParamMap`]: model parameter `q[model] = offset + scale · p[fit]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamLink {
    /// Index of the model parameter (in the BVP's `params`).
    pub model: usize,
    /// Index of the fit parameter.
    pub fit: usize,
    /// `∂q[model]/∂p[fit]`.
    pub scale: f64,
    /// Value of `q[model]` at `p[fit] = 0`.
    pub offset: f64,
}

/// How one run's model parameters `q` follow from the fit parameters `p`: an affine map
///
/// ```text
/// q_m = offset_l + scale_l · p_{fit_l}   if model parameter m has a link l,
/// q_m = base_m                           otherwise,
/// ```
///
/// with Jacobian `∂q_m/∂p_i = scale_l` for the link `l = (m, i)` and 0 else. Fit parameters
/// shared by several runs (a material law) link to the same `fit` index in every run;
/// run-specific ones (a per-experiment factor) to an index of their own. Each model parameter
/// has at most one link.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamMap {
    /// Values of the model parameters without a link (the links' entries are ignored).
    pub base: Vec<f64>,
    /// The links.
    pub links: Vec<ParamLink>,
}

impl ParamMap {
    /// All model parameters fixed at `base`; add links with [`link`](Self::link).
    pub fn new(base: Vec<f64>) -> Self {
        ParamMap {
            base,
            links: Vec::new(),
        }
    }

    /// The model parameters with a link, increasing (each once): the columns a fit through this
    /// map differentiates in.
    pub fn linked_models(&self) -> Vec<usize> {
        let mut m: Vec<usize> = self.links.iter().map(|l| l.model).collect();
        m.sort_unstable();
        m.dedup();
        m
    }

    /// Adds the identity link `q[model] = p[fit]`.
    pub fn link(self, model: usize, fit: usize) -> Self {
        self.link_affine(model, fit, 1.0, 0.0)
    }

    /// Adds the link `q[model] = offset + scale · p[fit]`.
    pub fn link_affine(mut self, model: usize, fit: usize, scale: f64, offset: f64) -> Self {
        self.links.push(ParamLink {
            model,
            fit,
            scale,
            offset,
        });
        self
    }

    /// Writes `q = M(p)` into `q` (length `base.len()`).
    pub fn model_params_into(&self, p: &[f64], q: &mut [f64]) {
        q.copy_from_slice(&self.base);
        for l in &self.links {
            q[l.model] = if l.scale == 1.0 && l.offset == 0.0 {
                p[l.fit]
            } else {
                l.offset + l.scale * p[l.fit]
            };
        }
    }

    /// `q = M(p)`.
    pub fn model_params(&self, p: &[f64]) -> Vec<f64> {
        let mut q = vec![0.0; self.base.len()];
        self.model_params_into(p, &mut q);
        q
    }

    /// Checks the map against `num_model` model and `num_fit` fit parameters.
    pub fn validate(&self, num_model: usize, num_fit: usize) -> Result<(), BvpError> {
        if self.base.len() != num_model {
            return Err(BvpError::InvalidInput(format!(
                "ParamMap: {} base values for a problem with {num_model} model parameters",
                self.base.len()
            )));
        }
        for (i, l) in self.links.iter().enumerate() {
            if l.model >= num_model || l.fit >= num_fit {
                return Err(BvpError::InvalidInput(format!(
                    "ParamMap: link {i} maps fit parameter {} to model parameter {}, but there are {num_fit} fit and {num_model} model parameters",
                    l.fit, l.model
                )));
            }
            if !(l.scale.is_finite() && l.offset.is_finite()) {
                return Err(BvpError::InvalidInput(format!(
                    "ParamMap: link {i} has a non-finite scale or offset"
                )));
            }
            if self.links[..i].iter().any(|o| o.model == l.model) {
                return Err(BvpError::InvalidInput(format!(
                    "ParamMap: model parameter {} has more than one link",
                    l.model
                )));
            }
        }
        Ok(())
    }
}

/// A failed evaluation of a [`BvpResiduals`]: the run whose BVP solve (or sensitivity or residual
/// evaluation) failed, and why. With runs solved in parallel and several failing, one of them.
/// Input errors that concern no single run (a parameter vector of the wrong length) name run 0;
/// a wrong number of warm starts names the first run without one.
#[derive(Debug, Clone, thiserror::Error)]
#[error("run {run}: {source}")]
pub struct RunError {
    /// Index of the run.
    pub run: usize,
    /// The failure.
    #[source]
    pub source: BvpError,
}

/// One run of a [`BvpResiduals`]: a BVP with its warm-started solver, accepted and pending
/// solutions, observation points, residual function and parameter map.
pub struct BvpRun<'a, P: Bvp, G> {
    solver: Solver<'a, P>,
    accepted: Solution,
    pending: Option<Solution>,
    points: Vec<f64>,
    residual: G,
    map: ParamMap,
    // scratch: model parameters, state and slope at a point, (unknowns, model parameters)
    q: Vec<f64>,
    y: Vec<f64>,
    yp: Vec<f64>,
    full: Vec<f64>,
    // the mesh of the last solve at the solver's own tolerance, and whether the accepted and the
    // pending solutions come from loose solves (a tight solve from a loose solution starts on
    // that mesh, not on the loose solution's coarse one)
    tight_mesh: Vec<f64>,
    accepted_loose: bool,
    pending_loose: bool,
    // the last tight accepted solution while the accepted one is loose: a tight solve from
    // the loose one that fails is retried from it
    last_tight: Option<Solution>,
    // the calibration's loose solve at the accepted solution's parameters and its tolerance
    // (the first loose evaluation, at the same point, reuses it)
    calibration: Option<(f64, Solution)>,
    // the model parameters each solve's linearisation is seeded in (those the map links to fit
    // parameters, and any unlinked one whose base value has changed since: the tangent
    // predictor needs its column), the position in them of each link's model parameter (the
    // column of the run's `dr/dq`), and the unlinked ones seen changing
    seeds: Arc<[usize]>,
    link_slots: Vec<usize>,
    varied: Vec<usize>,
}

impl<'a, P: Bvp, G: PointFunction> BvpRun<'a, P, G> {
    /// A run solved by `solver` (its options are those of every solve), starting from the
    /// solution `start` (the first warm start, e.g. solved at the fit's start point, possibly by
    /// continuation), with residuals `residual(j, x_j, y(x_j), (u, q))` at `points` and model
    /// parameters `q = map(p)`.
    pub fn new(
        solver: Solver<'a, P>,
        start: Solution,
        points: Vec<f64>,
        residual: G,
        map: ParamMap,
    ) -> Result<Self, BvpError> {
        let problem = solver.problem();
        let (n, k, q) = (problem.dim(), problem.num_unknowns(), problem.num_params());
        if start.n != n || start.unknowns.len() != k || start.params.len() != q {
            return Err(BvpError::InvalidInput(
                "BvpRun: the start solution does not belong to this problem (dimensions differ)"
                    .into(),
            ));
        }
        if let Some(j) = points.iter().position(|x| !x.is_finite()) {
            return Err(BvpError::InvalidInput(format!(
                "BvpRun: observation point {j} is not finite"
            )));
        }
        map.validate(q, usize::MAX)?;
        let tight_mesh = start.x.clone();
        Ok(BvpRun {
            solver,
            accepted: start,
            pending: None,
            points,
            residual,
            map,
            q: vec![0.0; q],
            y: vec![0.0; n],
            yp: vec![0.0; n],
            full: vec![0.0; k + q],
            tight_mesh,
            accepted_loose: false,
            pending_loose: false,
            last_tight: None,
            calibration: None,
            seeds: Arc::from([]),
            link_slots: Vec::new(),
            varied: Vec::new(),
        })
    }

    /// Brings the seeds and the links' columns up to date with the map (whose links may change
    /// through [`map_mut`](Self::map_mut)) and with the unlinked model parameters whose values
    /// in `self.q` differ from the accepted solution's.
    fn update_seeds(&mut self) {
        let links = &self.map.links;
        let linked = |j: usize| links.iter().any(|l| l.model == j);
        for (j, (a, b)) in self.q.iter().zip(&self.accepted.params).enumerate() {
            if a != b && !linked(j) && !self.varied.contains(&j) {
                self.varied.push(j);
            }
        }
        let varied = &self.varied;
        let mut wanted = (0..self.q.len()).filter(|&j| linked(j) || varied.contains(&j));
        let same = self.seeds.iter().all(|&j| wanted.next() == Some(j)) && wanted.next().is_none();
        if !same {
            let seeds: Vec<usize> = (0..self.q.len())
                .filter(|&j| linked(j) || varied.contains(&j))
                .collect();
            self.seeds = Arc::from(seeds);
        }
        let seeds = &self.seeds;
        self.link_slots.clear();
        self.link_slots.extend(
            links
                .iter()
                .map(|l| seeds.partition_point(|&j| j < l.model)),
        );
    }

    /// Supplies a solve at the start solution's own parameters with tolerance `tol`, e.g. the
    /// end point of the loose continuation path that led to the start solution (builder style).
    /// The calibration of [`BvpResiduals::set_loose_tolerance`] at `tol` then uses it instead of
    /// re-solving the start solution loosely (and the first loose evaluation reuses it, as it
    /// reuses the calibration's own solve). It must meet `tol` under this run's solver options
    /// with `tol` as their tolerance; it is ignored unless its model and unknown parameters are
    /// those of the start solution.
    pub fn with_loose_solution(mut self, tol: f64, loose: Solution) -> Self {
        let fits = loose.n == self.accepted.n
            && loose.params == self.accepted.params
            && loose.unknowns.len() == self.accepted.unknowns.len();
        self.calibration = (fits && tol.is_finite() && tol > 0.0).then_some((tol, loose));
        self
    }

    /// The problem.
    pub fn problem(&self) -> &'a P {
        self.solver.problem()
    }

    /// The solver (e.g. to change its options).
    pub fn solver_mut(&mut self) -> &mut Solver<'a, P> {
        &mut self.solver
    }

    /// The accepted solution: the solution at the current iterate and the warm start of the
    /// next evaluation.
    pub fn accepted(&self) -> &Solution {
        &self.accepted
    }

    /// Replaces the accepted solution (e.g. by a cold-started one) and drops the pending one.
    pub fn set_accepted(&mut self, solution: Solution) {
        self.tight_mesh = solution.x.clone();
        self.calibration = None;
        self.accepted = solution;
        self.accepted_loose = false;
        self.last_tight = None;
        self.pending = None;
    }

    /// Promotes the pending solution, if any.
    fn accept_pending(&mut self) {
        if let Some(s) = self.pending.take() {
            let old = std::mem::replace(&mut self.accepted, s);
            if !self.pending_loose {
                self.last_tight = None;
            } else if !self.accepted_loose {
                self.last_tight = Some(old);
            }
            self.accepted_loose = self.pending_loose;
        }
    }

    /// The solution of the last successful evaluation not accepted yet.
    pub fn pending(&self) -> Option<&Solution> {
        self.pending.as_ref()
    }

    /// The observation points.
    pub fn points(&self) -> &[f64] {
        &self.points
    }

    /// The residual function.
    pub fn residual(&self) -> &G {
        &self.residual
    }

    /// The parameter map.
    pub fn map(&self) -> &ParamMap {
        &self.map
    }

    /// The parameter map, to change its base values (e.g. fixed parameters set between fits).
    pub fn map_mut(&mut self) -> &mut ParamMap {
        &mut self.map
    }

    /// Number of residuals of this run (= observation points).
    pub fn num_residuals(&self) -> usize {
        self.points.len()
    }

    /// Solves at fit parameters `p` from `start` (default: the accepted solution), keeps the
    /// solution as pending and returns the residuals and, if `jacobian`, `dr/dq` (row-major,
    /// residuals × model parameters; empty otherwise).
    fn eval(
        &mut self,
        p: &[f64],
        jacobian: bool,
        start: Option<&Guess>,
        tol: Option<f64>,
    ) -> Result<(Vec<f64>, Vec<f64>), BvpError> {
        self.map.model_params_into(p, &mut self.q);
        self.update_seeds();
        let own;
        let mut predicted = false;
        let guess = match start {
            Some(g) => g,
            None if tol.is_none() && self.accepted_loose => {
                // a tight solve from a loose solution: its values on the last tight mesh
                let (acc, n) = (&self.accepted, self.y.len());
                let mut yp = vec![0.0; n];
                own = Guess::from_fn(self.tight_mesh.clone(), n, |x, y| {
                    acc.eval_into(x, y, &mut yp)
                })
                .with_unknowns(&acc.unknowns);
                &own
            }
            None => {
                // the tangent predictor from the accepted solution when its linearisation is
                // cached (it is after a Jacobian evaluation): one linear solve, and Newton needs
                // about half the iterations of a start from the accepted solution itself
                let tangent = match self.accepted.factorization() {
                    Some(_) => tangent_guess(self.solver.problem(), &self.accepted, &self.q).ok(),
                    None => None,
                };
                predicted = tangent.is_some();
                own = tangent.unwrap_or_else(|| Guess::from(&self.accepted));
                &own
            }
        };
        self.pending = None;
        let cached = match (start, tol, self.calibration.take()) {
            (None, Some(t), Some((tc, sol))) if t == tc && sol.params == self.q => Some(sol),
            _ => None,
        };
        let sol = match cached {
            Some(sol) => sol,
            None => {
                let mut opts = match tol {
                    Some(t) => self.loose_options(t),
                    None => self.solver.options.clone(),
                };
                if opts.linearization_params.is_none() {
                    opts.linearization_params = Some(self.seeds.clone());
                }
                if self.q == self.accepted.params {
                    // a re-solve at the accepted solution's own parameters (at another
                    // tolerance): its mesh grows with the tolerance, not because the start is far
                    opts.growth_limit = None;
                }
                // simplified Newton from the accepted solution's factorisation: its exact one
                // with the tangent predictor, or its last Newton matrix
                // (SolveOptions::keep_newton_matrix) for a start on its mesh
                let near =
                    predicted || (self.accepted.has_newton_matrix() && guess.x == self.accepted.x);
                if near {
                    match self
                        .solver
                        .solve_near(&self.q, guess, &self.accepted, &opts)
                    {
                        Ok(sol) => sol,
                        // a predictor that led Newton astray: the accepted solution itself; a
                        // start the kept matrix did not converge from: fresh Jacobians
                        Err(_) if predicted => {
                            let plain = Guess::from(&self.accepted);
                            self.solver.solve_with(&self.q, &plain, &opts)?
                        }
                        Err(_) => self.solver.solve_with(&self.q, guess, &opts)?,
                    }
                } else {
                    match self.solver.solve_with(&self.q, guess, &opts) {
                        Ok(sol) => sol,
                        // a tight solve from the loose solution's values that fails (the loose
                        // phase may end where a tight solve from them does not converge): once
                        // more from the last tight solution
                        Err(e) => match (&self.last_tight, start, tol) {
                            (Some(t), None, None) if self.accepted_loose => {
                                let from = Guess::from(t);
                                self.solver
                                    .solve_with(&self.q, &from, &opts)
                                    .map_err(|_| e)?
                            }
                            _ => return Err(e),
                        },
                    }
                }
            }
        };
        self.pending_loose = tol.is_some();
        if tol.is_none() {
            self.tight_mesh.clone_from(&sol.x);
        }
        let problem = self.solver.problem();
        let out = if jacobian {
            let sens = Sensitivities::compute_for(problem, &sol, &self.seeds)?;
            residual_jacobian(problem, &sol, &sens, &self.points, &self.residual)?
        } else {
            (self.residuals_of(&sol), Vec::new())
        };
        self.pending = Some(sol);
        Ok(out)
    }

    /// The solver's options with tolerance `tol` (a boundary tolerance of its own at least
    /// `tol`).
    fn loose_options(&self, tol: f64) -> SolveOptions {
        let mut opts = self.solver.options.clone();
        opts.tol = tol;
        opts.bc_tol = opts.bc_tol.map(|b| b.max(tol));
        opts
    }

    /// The residuals of solution `sol` at the observation points.
    fn residuals_of(&mut self, sol: &Solution) -> Vec<f64> {
        let k = sol.unknowns.len();
        self.full[..k].copy_from_slice(&sol.unknowns);
        self.full[k..].copy_from_slice(&sol.params);
        let mut r = Vec::with_capacity(self.points.len());
        for (j, &x) in self.points.iter().enumerate() {
            sol.eval_into(x, &mut self.y, &mut self.yp);
            r.push(self.residual.eval(j, x, &self.y, &self.full));
        }
        r
    }

    /// Squared differences, summed, between the residuals of the accepted solution and those
    /// of a re-solve at its own parameters with tolerance `tol` (the calibration of
    /// [`BvpResiduals::set_loose_tolerance`]), and the number of residuals.
    fn loose_error(&mut self, tol: f64) -> Result<(f64, usize), BvpError> {
        let accepted = self.accepted.clone();
        let tight = self.residuals_of(&accepted);
        let sol = match self.calibration.take() {
            // a loose solve supplied with the start solution (`with_loose_solution`)
            Some((tc, sol)) if tc == tol && sol.params == accepted.params => sol,
            _ => {
                let opts = self.loose_options(tol);
                self.solver
                    .solve_with(&accepted.params, &Guess::from(&accepted), &opts)?
            }
        };
        let loose = self.residuals_of(&sol);
        let d2 = tight
            .iter()
            .zip(&loose)
            .map(|(a, b)| (a - b) * (a - b))
            .sum();
        self.calibration = Some((tol, sol));
        Ok((d2, tight.len()))
    }
}

/// A [`LeastSquaresProblem`] over BVP runs: residuals of every run at the fit parameters `p`,
/// exact Jacobian from forward sensitivities, warm starts from the last accepted solutions.
///
/// A fit has parameters `p ∈ ℝⁿᵖ` and one or more *runs* (experiments, data sets). Run `k` is a
/// BVP `y' = f(x, y, q_k)`, `g(y(a), y(b), q_k) = 0` with model parameters `q_k = M_k(p)` (an
/// affine [`ParamMap`]), observation points `x_{k,j}` and residuals
///
/// ```text
/// r_{k,j}(p) = g_k(j, x_{k,j}, y_k(x_{k,j}; q_k), (u_k, q_k))
/// ```
///
/// (`g_k` a [`PointFunction`], `u_k` the unknown parameters of the BVP). The residual vector is
/// the concatenation of the runs' residuals, in run order. Its Jacobian is exact, by the chain
/// rule through the forward [`Sensitivities`] `D_q Y` of each solution (dual numbers and one
/// linear solve with the factorisation kept by the solve, never finite differences):
///
/// ```text
/// ∂r_{k,j}/∂p_i = Σ_{links l of run k with fit index i} scale_l · (dr_{k,j}/dq)_{model index of l}
/// ```
///
/// Each run keeps a warm-started [`Solver`] and two solutions: the *accepted* one (the solution
/// at the current iterate of the fit, the warm start of every evaluation) and a *pending* one (the
/// solution at the last evaluated trial point). [`LeastSquaresProblem::accept`] promotes the
/// pending solutions; a rejected trial step leaves the accepted ones alone, so a bad trial point
/// never spoils the warm start. A BVP that does not converge at a trial point is a failed
/// evaluation ([`RunError`] naming the run): the driver rejects the step and shrinks its trust
/// region.
///
/// With the `parallel` cargo feature (on with `rheometer`) the runs are solved in parallel
/// (rayon); without it, one after the other. The results are the same either way.
///
/// ```
/// use diffbvp::least_squares::{fit, BvpResiduals, BvpRun, FitOptions, ParamMap};
/// use diffbvp::mesh::linspace;
/// use diffbvp::sensitivity::PointFunction;
/// use diffbvp::{Bvp, DualNum, Guess, SolveOptions, Solver};
///
/// /// y' = −a y, y(0) = b: y = b e^{−a x}, model parameters (a, b).
/// struct Decay;
/// impl Bvp for Decay {
///     fn dim(&self) -> usize { 1 }
///     fn num_params(&self) -> usize { 2 }
///     fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
///         f[0] = -p[0] * y[0];
///     }
///     fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], _yb: &[D], p: &[D], r: &mut [D]) {
///         r[0] = ya[0] - p[1];
///     }
/// }
/// /// r_j = y(x_j) − data_j
/// struct Misfit(Vec<f64>);
/// impl PointFunction for Misfit {
///     fn eval<D: DualNum<Primitive = f64> + Copy>(&self, j: usize, _x: f64, y: &[D], _p: &[D]) -> D {
///         y[0] - self.0[j]
///     }
/// }
///
/// let xs: Vec<f64> = (1..=10).map(|i| i as f64 / 10.0).collect();
/// let data = xs.iter().map(|x| 2.0 * (-1.5 * x).exp()).collect();
/// let mut solver = Solver::new(&Decay, SolveOptions::with_tol(1e-8));
/// let start = solver.solve(&[1.0, 1.0], &Guess::constant(linspace(0.0, 1.0, 5), &[1.0]))?;
/// // model parameters (a, b) = fit parameters (p0, p1)
/// let map = ParamMap::new(vec![0.0; 2]).link(0, 0).link(1, 1);
/// let run = BvpRun::new(solver, start, xs, Misfit(data), map)?;
/// let mut problem = BvpResiduals::new(2).with_run(run)?;
/// let result = fit(&mut problem, &[1.0, 1.0], &FitOptions::with_bounds(vec![0.0; 2], vec![5.0; 2]))?;
/// assert!((result.p[0] - 1.5).abs() < 1e-6 && (result.p[1] - 2.0).abs() < 1e-6);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct BvpResiduals<'a, P: Bvp, G> {
    num_params: usize,
    runs: Vec<BvpRun<'a, P, G>>,
    parallel: bool,
    // loose evaluations: the loosest BVP tolerance, the calibrated RMS residual error per unit
    // of tolerance, the tolerance of the next evaluations (`None`: the solvers' own)
    loosest: Option<f64>,
    error_per_tol: Option<f64>,
    tol: Option<f64>,
    // the declared block-arrow structure (`declare_blocks`)
    blocks: Option<Arc<BlockStructure>>,
    thread_workspaces: bool,
}

impl<'a, P: Bvp + Sync, G: PointFunction + Send> BvpResiduals<'a, P, G> {
    /// An empty problem with `num_params` fit parameters; add runs with
    /// [`with_run`](Self::with_run) or [`push`](Self::push).
    pub fn new(num_params: usize) -> Self {
        BvpResiduals {
            num_params,
            runs: Vec::new(),
            parallel: true,
            loosest: None,
            error_per_tol: None,
            tol: None,
            blocks: None,
            thread_workspaces: false,
        }
    }

    /// Adds a run (builder style).
    pub fn with_run(mut self, run: BvpRun<'a, P, G>) -> Result<Self, BvpError> {
        self.push(run)?;
        Ok(self)
    }

    /// Adds a run; its parameter map must refer to fit parameters `< num_params`.
    pub fn push(&mut self, mut run: BvpRun<'a, P, G>) -> Result<(), BvpError> {
        run.map.validate(run.q.len(), self.num_params)?;
        if self.thread_workspaces {
            run.solver.use_thread_workspace(true);
        }
        self.runs.push(run);
        if let Some(ns) = self.blocks.as_ref().map(|b| b.num_shared()) {
            match self.structure_for(ns, false) {
                Ok(st) => self.blocks = Some(Arc::new(st)),
                Err(e) => {
                    self.runs.pop();
                    return Err(e);
                }
            }
        }
        Ok(())
    }

    /// Declares the block-arrow structure (see [`blocks`](super::blocks)): fit parameters
    /// `0..num_shared` are shared by the runs, and every other fit parameter belongs to exactly
    /// one run, the runs' own parameters following each other in run order (run 0's first). The
    /// fit then evaluates a [`Jacobian::Blocks`] and solves its steps and covariance through
    /// the Schur complement, in time and memory linear in the number of runs. Runs pushed later
    /// must keep the pattern. `None` turns it off (dense Jacobians, the default).
    ///
    /// Errors: a run linking to another run's own parameter, own parameters out of run order,
    /// fit parameters no run links to.
    pub fn declare_blocks(&mut self, num_shared: Option<usize>) -> Result<(), BvpError> {
        self.blocks = match num_shared {
            None => None,
            Some(ns) => Some(Arc::new(self.structure_for(ns, true)?)),
        };
        Ok(())
    }

    /// The declared block-arrow structure, if any ([`declare_blocks`](Self::declare_blocks)).
    pub fn block_structure(&self) -> Option<&Arc<BlockStructure>> {
        self.blocks.as_ref()
    }

    /// The block-arrow structure of the runs with `ns` shared fit parameters (`cover`: every
    /// fit parameter must belong to the shared ones or a run).
    fn structure_for(&self, ns: usize, cover: bool) -> Result<BlockStructure, BvpError> {
        if ns > self.num_params {
            return Err(BvpError::InvalidInput(format!(
                "declare_blocks: {ns} shared parameters, but the problem has {}",
                self.num_params
            )));
        }
        let mut next = ns;
        let mut shape = Vec::with_capacity(self.runs.len());
        for (k, run) in self.runs.iter().enumerate() {
            let mut own: Vec<usize> = run
                .map
                .links
                .iter()
                .map(|l| l.fit)
                .filter(|&f| f >= ns)
                .collect();
            own.sort_unstable();
            own.dedup();
            if own.iter().enumerate().any(|(i, &f)| f != next + i) {
                return Err(BvpError::InvalidInput(format!(
                    "declare_blocks: run {k} links to fit parameters {own:?}, but its own \
                     parameters must follow the previous run's, from index {next} on, \
                     without gaps (shared parameters are 0..{ns})"
                )));
            }
            next += own.len();
            shape.push((run.points.len(), own.len()));
        }
        if cover && next != self.num_params {
            return Err(BvpError::InvalidInput(format!(
                "declare_blocks: fit parameters {next}..{} belong to no run",
                self.num_params
            )));
        }
        Ok(BlockStructure::new(ns, shape))
    }

    /// Whether the runs' solvers borrow their thread's workspace for every solve instead of
    /// keeping one each ([`Solver::use_thread_workspace`]): for fits of many runs, whose
    /// Newton-matrix workspaces would otherwise dominate the memory (default off; results are
    /// the same). Applies to the runs present and those pushed later.
    pub fn set_thread_workspaces(&mut self, on: bool) {
        self.thread_workspaces = on;
        for run in &mut self.runs {
            run.solver.use_thread_workspace(on);
        }
    }

    /// Solves the runs in parallel (default) or one after the other. Without the `parallel`
    /// cargo feature the runs are always solved one after the other.
    pub fn set_parallel(&mut self, parallel: bool) {
        self.parallel = parallel;
    }

    /// Allows loose evaluations ([`LeastSquaresProblem::set_accuracy`], used by
    /// [`Accuracy::Scheduled`](super::Accuracy::Scheduled)) with BVP tolerances up to
    /// `loosest` (`None`: every solve with the solvers' own options, the default).
    ///
    /// An allowed RMS residual error `e` becomes the BVP tolerance
    /// `clamp(e / c, tol_run, loosest)` (`tol_run` the smallest of the solvers' own
    /// tolerances), where `c` is the RMS residual error per unit of tolerance, calibrated once
    /// at the first loose request: every run's accepted solution is re-solved at its own
    /// parameters with tolerance `loosest` and `c = RMS(r_loose − r_accepted)/loosest`. The
    /// discretisation error falls at least linearly with the tolerance (a fourth-order
    /// collocation: `h⁴` against a residual of `h³`), so below `loosest` the map overestimates
    /// the error. A failed calibration solve turns the loose evaluations off.
    pub fn set_loose_tolerance(&mut self, loosest: Option<f64>) {
        self.loosest = loosest.filter(|t| t.is_finite() && *t > 0.0);
        self.error_per_tol = None;
        self.tol = None;
    }

    /// The BVP tolerance of the next evaluations (`None`: the solvers' own).
    pub fn current_tolerance(&self) -> Option<f64> {
        self.tol
    }

    /// The calibrated RMS residual error per unit of BVP tolerance (see
    /// [`set_loose_tolerance`](Self::set_loose_tolerance); `None` before the first loose
    /// request).
    pub fn error_per_tolerance(&self) -> Option<f64> {
        self.error_per_tol
    }

    /// The smallest of the runs' own tolerances.
    fn tight_tol(&self) -> f64 {
        self.runs
            .iter()
            .map(|r| r.solver.options.tol)
            .fold(f64::INFINITY, f64::min)
    }

    /// Calibrates [`error_per_tolerance`](Self::error_per_tolerance) at tolerance `loosest`.
    fn calibrate(&mut self, loosest: f64) -> Result<f64, RunError> {
        let one = |(k, run): (usize, &mut BvpRun<'a, P, G>)| {
            run.loose_error(loosest)
                .map_err(|source| RunError { run: k, source })
        };
        #[cfg(feature = "parallel")]
        let parts: Result<Vec<(f64, usize)>, RunError> = if self.parallel && self.runs.len() > 1 {
            use rayon::prelude::*;
            self.runs.par_iter_mut().enumerate().map(one).collect()
        } else {
            self.runs.iter_mut().enumerate().map(one).collect()
        };
        #[cfg(not(feature = "parallel"))]
        let parts: Result<Vec<(f64, usize)>, RunError> =
            self.runs.iter_mut().enumerate().map(one).collect();
        let (d2, n) = parts?
            .into_iter()
            .fold((0.0, 0), |(a, b), (c, d)| (a + c, b + d));
        Ok((d2 / n.max(1) as f64).sqrt() / loosest)
    }

    /// The runs.
    pub fn runs(&self) -> &[BvpRun<'a, P, G>] {
        &self.runs
    }

    /// The runs, mutable (accepted solutions, parameter maps, solver options).
    pub fn runs_mut(&mut self) -> &mut [BvpRun<'a, P, G>] {
        &mut self.runs
    }

    /// Number of runs.
    pub fn len(&self) -> usize {
        self.runs.len()
    }

    /// Whether there are no runs.
    pub fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }

    /// Total number of residuals.
    pub fn num_residuals(&self) -> usize {
        self.runs.iter().map(|r| r.points.len()).sum()
    }

    /// Residuals `r(p)` and, if `jacobian`, `∂r/∂p` (row-major, residuals × fit parameters;
    /// empty otherwise), warm-started from `starts` (one guess per run, e.g. predicted by
    /// [`secant_guess`](crate::continuation::secant_guess)) or, if `None`, from the accepted
    /// solutions. The new solutions become pending (promoted by
    /// [`accept_pending`](Self::accept_pending)); on failure no solution is pending.
    pub fn evaluate_from(
        &mut self,
        p: &[f64],
        jacobian: bool,
        starts: Option<&[Guess]>,
    ) -> Result<(Vec<f64>, Vec<f64>), RunError> {
        self.check_input(p, starts)?;
        let parts = self.eval_runs(p, jacobian, starts);
        let parts = match parts {
            Ok(parts) => parts,
            Err(e) => {
                self.discard_pending();
                return Err(e);
            }
        };
        let np = self.num_params;
        let rows: usize = parts.iter().map(|(r, _)| r.len()).sum();
        let mut r = Vec::with_capacity(rows);
        let mut jac = if jacobian {
            vec![0.0; rows * np]
        } else {
            Vec::new()
        };
        for (run, (rk, jk)) in self.runs.iter().zip(parts) {
            if jacobian {
                let q = run.seeds.len();
                let off = r.len();
                for i in 0..rk.len() {
                    let row = &mut jac[(off + i) * np..(off + i + 1) * np];
                    for (l, &c) in run.map.links.iter().zip(&run.link_slots) {
                        row[l.fit] += if l.scale == 1.0 {
                            jk[i * q + c]
                        } else {
                            l.scale * jk[i * q + c]
                        };
                    }
                }
            }
            r.extend(rk);
        }
        Ok((r, jac))
    }

    /// Residuals `r(p)` and the block-arrow Jacobian of the declared structure
    /// ([`declare_blocks`](Self::declare_blocks)), warm-started as
    /// [`evaluate_from`](Self::evaluate_from); the dense Jacobian if no structure is declared.
    pub fn evaluate_jacobian_from(
        &mut self,
        p: &[f64],
        starts: Option<&[Guess]>,
    ) -> Result<(Vec<f64>, Jacobian), RunError> {
        let Some(structure) = self.blocks.clone() else {
            let (r, j) = self.evaluate_from(p, true, starts)?;
            return Ok((r, Jacobian::Dense(j)));
        };
        self.check_input(p, starts)?;
        if structure.num_params() != self.num_params {
            return Err(RunError {
                run: self.runs.len().saturating_sub(1),
                source: BvpError::InvalidInput(format!(
                    "declared blocks: fit parameters {}..{} belong to no run",
                    structure.num_params(),
                    self.num_params
                )),
            });
        }
        let parts = match self.eval_runs(p, true, starts) {
            Ok(parts) => parts,
            Err(e) => {
                self.discard_pending();
                return Err(e);
            }
        };
        let ns = structure.num_shared();
        let mut jac = BlockJacobian::zeros(structure.clone());
        let mut r = Vec::with_capacity(structure.num_residuals());
        for (k, ((run, (rk, jk)), (sh, lo))) in self
            .runs
            .iter()
            .zip(parts)
            .zip(jac.blocks_mut())
            .enumerate()
        {
            let q = run.seeds.len();
            let own = structure.locals(k);
            let nl = own.len();
            for i in 0..rk.len() {
                for (l, &c) in run.map.links.iter().zip(&run.link_slots) {
                    let v = if l.scale == 1.0 {
                        jk[i * q + c]
                    } else {
                        l.scale * jk[i * q + c]
                    };
                    if l.fit < ns {
                        sh[i * ns + l.fit] += v;
                    } else {
                        lo[i * nl + (l.fit - own.start)] += v;
                    }
                }
            }
            r.extend(rk);
        }
        Ok((r, Jacobian::Blocks(jac)))
    }

    /// Checks the parameter vector's length and the number of warm starts.
    fn check_input(&self, p: &[f64], starts: Option<&[Guess]>) -> Result<(), RunError> {
        if p.len() != self.num_params {
            return Err(RunError {
                run: 0,
                source: BvpError::InvalidInput(format!(
                    "{} fit parameters given, the problem has {}",
                    p.len(),
                    self.num_params
                )),
            });
        }
        if let Some(g) = starts {
            if g.len() != self.runs.len() {
                return Err(RunError {
                    run: g.len().min(self.runs.len()),
                    source: BvpError::InvalidInput(format!(
                        "{} warm starts for {} runs",
                        g.len(),
                        self.runs.len()
                    )),
                });
            }
        }
        Ok(())
    }

    #[allow(clippy::type_complexity)]
    fn eval_runs(
        &mut self,
        p: &[f64],
        jacobian: bool,
        starts: Option<&[Guess]>,
    ) -> Result<Vec<(Vec<f64>, Vec<f64>)>, RunError> {
        let tol = self.tol;
        let one = |(k, run): (usize, &mut BvpRun<'a, P, G>)| {
            run.eval(p, jacobian, starts.map(|g| &g[k]), tol)
                .map_err(|source| RunError { run: k, source })
        };
        #[cfg(feature = "parallel")]
        if self.parallel && self.runs.len() > 1 {
            use rayon::prelude::*;
            return self.runs.par_iter_mut().enumerate().map(one).collect();
        }
        #[cfg(not(feature = "parallel"))]
        let _ = self.parallel;
        self.runs.iter_mut().enumerate().map(one).collect()
    }

    /// Residuals `r(p)` only (no sensitivities), warm-started from the accepted solutions; the
    /// solutions become pending.
    pub fn residuals(&mut self, p: &[f64]) -> Result<Vec<f64>, RunError> {
        Ok(self.evaluate_from(p, false, None)?.0)
    }

    /// Makes the pending solutions the accepted ones (the warm starts of the next evaluation).
    pub fn accept_pending(&mut self) {
        for run in &mut self.runs {
            run.accept_pending();
        }
    }

    /// Drops the pending solutions.
    pub fn discard_pending(&mut self) {
        for run in &mut self.runs {
            run.pending = None;
        }
    }

    /// The accepted solutions, one per run.
    pub fn solutions(&self) -> Vec<Solution> {
        self.runs.iter().map(|r| r.accepted.clone()).collect()
    }

    /// Replaces the accepted solutions (same order as [`solutions`](Self::solutions); extra
    /// entries are ignored).
    pub fn set_solutions(&mut self, solutions: &[Solution]) {
        for (r, s) in self.runs.iter_mut().zip(solutions) {
            r.set_accepted(s.clone());
        }
    }
}

impl<P: Bvp + Sync, G: PointFunction + Send> LeastSquaresProblem for BvpResiduals<'_, P, G> {
    type Error = RunError;
    fn num_params(&self) -> usize {
        self.num_params
    }
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), RunError> {
        self.evaluate_from(p, true, None)
    }
    fn evaluate_jacobian(&mut self, p: &[f64]) -> Result<(Vec<f64>, Jacobian), RunError> {
        self.evaluate_jacobian_from(p, None)
    }
    fn accept(&mut self, _p: &[f64]) {
        self.accept_pending();
    }
    fn set_accuracy(&mut self, rms_error: Option<f64>) -> bool {
        let (Some(e), Some(loosest)) = (rms_error, self.loosest) else {
            self.tol = None;
            return false;
        };
        let c = match self.error_per_tol {
            Some(c) => c,
            None => match self.calibrate(loosest) {
                Ok(c) => {
                    self.error_per_tol = Some(c);
                    c
                }
                Err(_) => {
                    self.loosest = None;
                    self.tol = None;
                    return false;
                }
            },
        };
        let tight = self.tight_tol();
        let tol = if c > 0.0 { e / c } else { loosest };
        let tol = tol.min(loosest);
        self.tol = (tol > tight).then_some(tol);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::least_squares::{fit, fit_observed, FitIteration, FitOptions};
    use crate::mesh::linspace;
    use crate::solve::SolveOptions;
    use num_dual::DualNum;

    /// y' = −a y, y(0) = b: y = b e^{−a x}; model parameters (a, b).
    struct Decay;
    impl Bvp for Decay {
        fn dim(&self) -> usize {
            1
        }
        fn num_params(&self) -> usize {
            2
        }
        fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
            f[0] = -p[0] * y[0];
        }
        fn bc<D: DualNum<Primitive = f64> + Copy>(
            &self,
            ya: &[D],
            _yb: &[D],
            p: &[D],
            r: &mut [D],
        ) {
            r[0] = ya[0] - p[1];
        }
    }

    /// r_j = w (y(x_j) − data_j)
    struct Misfit {
        data: Vec<f64>,
        w: f64,
    }
    impl PointFunction for Misfit {
        fn eval<D: DualNum<Primitive = f64> + Copy>(
            &self,
            j: usize,
            _x: f64,
            y: &[D],
            _p: &[D],
        ) -> D {
            (y[0] - self.data[j]) * self.w
        }
    }

    fn exact(a: f64, b: f64, x: f64) -> f64 {
        b * (-a * x).exp()
    }

    /// Two runs sharing the rate `a = p0`: run 0 has `b = p1`, run 1 `b = 0.5 + 2 p1`.
    /// Data are the exact solution at the truth `p = (1.3, 0.8)`.
    fn two_runs(start: [f64; 2]) -> BvpResiduals<'static, Decay, Misfit> {
        let truth = [1.3, 0.8];
        let maps = [
            ParamMap::new(vec![0.0; 2]).link(0, 0).link(1, 1),
            ParamMap::new(vec![0.0; 2])
                .link(0, 0)
                .link_affine(1, 1, 2.0, 0.5),
        ];
        let mut problem = BvpResiduals::new(2);
        for (k, map) in maps.into_iter().enumerate() {
            let xs: Vec<f64> = (1..=8).map(|i| i as f64 / 8.0 - 0.03 * k as f64).collect();
            let qt = map.model_params(&truth);
            let data = xs.iter().map(|&x| exact(qt[0], qt[1], x)).collect();
            let mut solver = Solver::new(&Decay, SolveOptions::with_tol(1e-9));
            let q0 = map.model_params(&start);
            let guess = Guess::constant(linspace(0.0, 1.0, 6), &[q0[1]]);
            let sol = solver.solve(&q0, &guess).unwrap();
            let misfit = Misfit {
                data,
                w: 1.0 + k as f64,
            };
            problem
                .push(BvpRun::new(solver, sol, xs, misfit, map).unwrap())
                .unwrap();
        }
        problem
    }

    #[test]
    fn fits_an_exact_solution() {
        let mut problem = two_runs([1.0, 1.0]);
        let opts = FitOptions::with_bounds(vec![0.0, 0.0], vec![5.0, 5.0]);
        let res = fit(&mut problem, &[1.0, 1.0], &opts).unwrap();
        assert!((res.p[0] - 1.3).abs() < 1e-7, "{:?}", res.p);
        assert!((res.p[1] - 0.8).abs() < 1e-7, "{:?}", res.p);
        assert!(res.cost < 1e-14, "{}", res.cost);
        assert_eq!(res.residuals.len(), 16);
        // the accepted solutions are those at the optimum
        let q1 = problem.runs()[1].accepted().params.clone();
        assert!((q1[1] - (0.5 + 2.0 * res.p[1])).abs() < 1e-12, "{q1:?}");
    }

    #[test]
    fn jacobian_is_the_chain_rule_through_the_map() {
        let p = [1.1, 0.7];
        let mut problem = two_runs(p);
        let (r, jac) = problem.evaluate(&p).unwrap();
        assert_eq!((r.len(), jac.len()), (16, 32));
        // analytic: y = b e^{−a x}, ∂y/∂a = −x y, ∂y/∂b = e^{−a x}; run 1: ∂b/∂p1 = 2
        for (k, run) in problem.runs().iter().enumerate() {
            let q = run.map().model_params(&p);
            let w = 1.0 + k as f64;
            let db = [1.0, 2.0][k];
            for (j, &x) in run.points().iter().enumerate() {
                let i = 8 * k + j;
                let y = exact(q[0], q[1], x);
                let ja = w * (-x * y);
                let jb = w * db * (-q[0] * x).exp();
                assert!(
                    (jac[2 * i] - ja).abs() < 1e-6,
                    "{i}: {} vs {ja}",
                    jac[2 * i]
                );
                assert!((jac[2 * i + 1] - jb).abs() < 1e-6, "{i}");
            }
        }
        // central differences of re-solved residuals (in this test only)
        let h = 1e-6;
        for c in 0..2 {
            let (mut pp, mut pm) = (p, p);
            pp[c] += h;
            pm[c] -= h;
            let rp = problem.residuals(&pp).unwrap();
            let rm = problem.residuals(&pm).unwrap();
            for i in 0..r.len() {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                let scale = 1.0 + fd.abs();
                assert!(
                    (jac[2 * i + c] - fd).abs() < 1e-6 * scale,
                    "row {i} col {c}: {} vs {fd}",
                    jac[2 * i + c]
                );
            }
        }
    }

    #[test]
    fn a_rejected_step_keeps_the_warm_start() {
        let p1 = [1.0, 1.0];
        let mut problem = two_runs(p1);
        problem.evaluate(&[1.2, 0.9]).unwrap();
        problem.accept(&[1.2, 0.9]);
        let accepted = problem.solutions();
        assert_eq!(accepted[0].params, vec![1.2, 0.9]);
        assert!(problem.runs()[0].pending().is_none());
        // a trial point evaluated but not accepted (a rejected step)
        problem.evaluate(&[2.0, 0.3]).unwrap();
        assert_eq!(problem.runs()[0].pending().unwrap().params, vec![2.0, 0.3]);
        for (run, old) in problem.runs().iter().zip(&accepted) {
            assert_eq!(run.accepted().params, old.params);
            assert_eq!(run.accepted().y, old.y);
        }
        // a failed evaluation (non-finite parameter): an error naming a run, nothing pending
        let err = problem.evaluate(&[f64::NAN, 0.3]).unwrap_err();
        assert!(err.run < 2, "{err}");
        assert!(problem.runs().iter().all(|r| r.pending().is_none()));
        // accepting now changes nothing
        problem.accept(&[f64::NAN, 0.3]);
        assert_eq!(problem.solutions()[1].params, accepted[1].params);
        // a wrong number of warm starts is an error
        let starts = vec![Guess::from(&accepted[0])];
        assert!(problem.evaluate_from(&p1, false, Some(&starts)).is_err());
    }

    #[test]
    fn observer_sees_every_iteration() {
        let mut problem = two_runs([0.2, 3.0]);
        let opts = FitOptions::with_bounds(vec![0.0, 0.0], vec![5.0, 5.0]);
        let mut seen = Vec::new();
        let mut observer = |it: &FitIteration| seen.push((it.iteration, it.accepted, it.cost));
        let res = fit_observed(&mut problem, &[0.2, 3.0], &opts, &mut observer).unwrap();
        assert_eq!(seen.len(), res.iterations);
        assert!(res.iterations > 1);
        let numbers: Vec<usize> = seen.iter().map(|s| s.0).collect();
        assert_eq!(numbers, (1..=res.iterations).collect::<Vec<_>>());
        for (s, h) in seen.iter().zip(&res.history) {
            assert_eq!((s.1, s.2), (h.accepted, h.cost));
        }
        assert_eq!(
            seen.iter().filter(|s| s.1).count(),
            res.accepted_steps,
            "{:?}",
            res.history
        );
    }

    #[test]
    fn sequential_and_parallel_agree() {
        let p = [1.1, 0.7];
        let mut a = two_runs(p);
        let mut b = two_runs(p);
        b.set_parallel(false);
        assert_eq!(a.evaluate(&p).unwrap(), b.evaluate(&p).unwrap());
    }

    #[test]
    fn bad_maps_are_rejected() {
        let mut problem = two_runs([1.0, 1.0]);
        let mut solver = Solver::new(&Decay, SolveOptions::with_tol(1e-6));
        let guess = Guess::constant(linspace(0.0, 1.0, 4), &[1.0]);
        let sol = solver.solve(&[1.0, 1.0], &guess).unwrap();
        let misfit = || Misfit {
            data: vec![0.0],
            w: 1.0,
        };
        // fit index out of range (2 fit parameters)
        let map = ParamMap::new(vec![0.0; 2]).link(0, 2);
        let run = BvpRun::new(
            Solver::new(&Decay, SolveOptions::default()),
            sol.clone(),
            vec![0.5],
            misfit(),
            map,
        );
        assert!(problem.push(run.unwrap()).is_err());
        // model index out of range, duplicate link, wrong base length
        for map in [
            ParamMap::new(vec![0.0; 2]).link(2, 0),
            ParamMap::new(vec![0.0; 2]).link(0, 0).link(0, 1),
            ParamMap::new(vec![0.0; 3]),
        ] {
            let run = BvpRun::new(
                Solver::new(&Decay, SolveOptions::default()),
                sol.clone(),
                vec![0.5],
                misfit(),
                map,
            );
            assert!(run.is_err());
        }
        assert_eq!(problem.len(), 2);
        let _ = &mut solver;
    }
}

//! The adaptive solve loop: Newton on the current mesh, residual estimate, refine (or coarsen),
//! repeat until the scaled RMS residual is below `tol` on every interval and the boundary
//! residuals below `bc_tol`.

use crate::collocation::Collocation;
use crate::error::{BvpError, MeshCycle};
use crate::error_control::rms_residuals;
use crate::linear::{Factorization, LinearSolverKind, LinearSystem, Pattern};
use crate::linearization::Linearization;
use crate::mesh;
use crate::mesh_cycle::MeshControl;
use crate::newton::{max_bc, newton, NewtonReport, NewtonSettings, NewtonWork, Start};
use crate::problem::Bvp;
use crate::singular::Singular;
use crate::solution::{resample, Solution, SolveStats};
use std::cell::RefCell;
use std::sync::{Arc, OnceLock};

/// How collocation residuals are scaled per component before comparison with `tol`:
/// residual component `c` is divided by `s_c + |f_c|`.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum ResidualScale {
    /// `s_c = 1` for all components: scipy's `solve_bvp` measure `r / (1 + |f|)`.
    #[default]
    Relative,
    /// `s_c = max(1, max_i |y_{i,c}|)`, recomputed on every mesh: a state of magnitude 1e4 is
    /// measured relative to 1e4, not to 1.
    Auto,
    /// User-supplied typical magnitudes `s_c > 0` (one per state).
    PerComponent(Vec<f64>),
}

/// Options of [`Solver`].
#[derive(Debug, Clone)]
pub struct SolveOptions {
    /// Tolerance on the scaled RMS residual of every interval (default 1e-3, as scipy; must lie
    /// in (0, 1): the residual is relative, see [`ResidualScale`]).
    pub tol: f64,
    /// Tolerance on the absolute boundary residuals (default: `tol`).
    pub bc_tol: Option<f64>,
    /// Maximum number of mesh nodes (default 10 000).
    pub max_nodes: usize,
    /// Maximum number of mesh iterations (Newton + error estimate) (default 40).
    pub max_mesh_iterations: usize,
    /// Residual scaling per component.
    pub scale: ResidualScale,
    /// Adapt the mesh (default `true`). With `false` the mesh of the guess is kept and the
    /// solve succeeds when Newton converges on it.
    pub adapt: bool,
    /// Remove nodes where the residual is far below tolerance (default `true`).
    pub coarsen: bool,
    /// Factorisations allowed per Newton run on one mesh (default 4, as scipy; 25 on a fixed mesh).
    pub max_jacobians_per_mesh: usize,
    /// Newton iterations allowed per mesh (default 8; 50 on a fixed mesh).
    pub max_newton_iterations_per_mesh: usize,
    /// Additionally require the last Newton correction to be below
    /// `newton_step_tol (1 + ‖Y‖∞)` (default: off).
    pub newton_step_tol: Option<f64>,
    /// Compute the solution's linearisation at the end of the solve, with the solver's own
    /// workspace: the Jacobians in the states, the unknowns and the model parameters (one
    /// dual-number pass seeded in all of them) and the factorisation of the Newton matrix, kept
    /// in the [`Solution`] ([`Solution::factorization`]) and used as they are by
    /// [`Sensitivities`](crate::sensitivity::Sensitivities) and adjoint gradients (no further
    /// evaluation). Default `false`: the solve does none of this work (a plain solve is 20–35 %
    /// faster on the benchmark problems), and the first sensitivity or adjoint request on the
    /// solution computes the same linearisation once (with a fresh workspace) and caches it in
    /// the solution for every later request. Set it when derivatives will follow every solve
    /// (a fit): the solver's workspace is then reused.
    pub factor_at_solution: bool,
    /// The model parameters (indices into the `q` model parameters, strictly increasing) the
    /// linearisation at the solution is seeded in, besides the states and the unknowns
    /// (default `None`: all of them). A fit that frees 3 of a model's 7 parameters needs only
    /// their columns: the dual pass then takes one evaluation per point where all 7 take two
    /// (the right-hand side with 4 states is evaluated 8 derivatives at a time). Derivative
    /// requests for other parameters stay exact: they compute the full linearisation once,
    /// with a fresh workspace, and cache it beside this one.
    pub linearization_params: Option<Arc<[usize]>>,
    /// Keep the factorised Newton matrix of the last Newton step in the [`Solution`] (default
    /// `false`; ignored with [`factor_at_solution`](Self::factor_at_solution), whose exact
    /// linearisation serves the same purpose). That matrix is the Jacobian at an iterate near
    /// the solution, not at it: it gives no sensitivities, but a solve nearby on the same mesh
    /// ([`Solver::solve_near`]) starts simplified Newton from it, with no Jacobian evaluation
    /// and no factorisation until the contraction test asks for one. A walk over many nearby
    /// parameter values that needs only the solutions (a cost landscape) saves most of its
    /// dual-number passes; the copy costs one allocation per solve.
    pub keep_newton_matrix: bool,
    /// Progress on stderr: 0 silent (default), 1 one line per mesh, 2 also Newton iterations.
    pub verbose: u8,
    /// Linear solver for the Newton matrix (default [`LinearSolverKind::Auto`]: structured
    /// elimination for separated boundary conditions, faer's sparse LU otherwise).
    pub linear_solver: LinearSolverKind,
    /// How the mesh is refined when the residual is above `tol` (default: equidistribution of
    /// the predicted residual, [`MeshOptions::default`](crate::mesh::MeshOptions::default);
    /// [`MeshOptions::scipy`](crate::mesh::MeshOptions::scipy) gives scipy's 1-or-2-node rule).
    pub mesh: mesh::MeshOptions,
    /// How far the mesh may grow beyond the mesh of the guess (default `None`: up to
    /// `max_nodes`). A warm start whose solution needs many times its nodes was far from it:
    /// at a trial point of a fit or a continuation step beyond the region where the problem
    /// has a solution, the mesh otherwise refines towards `max_nodes` before the solve fails,
    /// at a cost of hundreds of ordinary solves. With a limit such a solve fails early with
    /// [`BvpError::MeshGrowthLimit`] and the caller takes a shorter step.
    pub growth_limit: Option<GrowthLimit>,
}

/// A limit on the growth of the mesh within one solve ([`SolveOptions::growth_limit`]): the
/// solve fails once a refinement would need more than
/// `max(at_least, factor × nodes of the guess)` nodes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrowthLimit {
    /// Largest growth over the guess's mesh \[-\] (at least 1).
    pub factor: f64,
    /// Nodes always allowed, whatever the guess's mesh (a cold start from a coarse guess
    /// legitimately refines it many times).
    pub at_least: usize,
}

impl GrowthLimit {
    /// The largest mesh a solve from a guess of `start_nodes` nodes may reach.
    pub fn nodes(&self, start_nodes: usize) -> usize {
        let grown = (self.factor * start_nodes as f64).ceil();
        // `as` saturates: a huge factor means no limit
        (grown as usize).max(self.at_least)
    }
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            tol: 1e-3,
            bc_tol: None,
            max_nodes: 10_000,
            max_mesh_iterations: 40,
            scale: ResidualScale::Relative,
            adapt: true,
            coarsen: true,
            max_jacobians_per_mesh: 4,
            max_newton_iterations_per_mesh: 8,
            newton_step_tol: None,
            factor_at_solution: false,
            linearization_params: None,
            keep_newton_matrix: false,
            verbose: 0,
            linear_solver: LinearSolverKind::Auto,
            mesh: mesh::MeshOptions::default(),
            growth_limit: None,
        }
    }
}

impl SolveOptions {
    /// Options with tolerance `tol`.
    pub fn with_tol(tol: f64) -> Self {
        SolveOptions {
            tol,
            ..Default::default()
        }
    }

    /// Options for a fixed mesh: no adaptation, Newton iterated until the correction is below
    /// `1e-12` relative.
    pub fn fixed_mesh() -> Self {
        SolveOptions {
            adapt: false,
            coarsen: false,
            max_jacobians_per_mesh: 25,
            max_newton_iterations_per_mesh: 50,
            newton_step_tol: Some(1e-12),
            ..Default::default()
        }
    }

    /// Checks the options for a problem with `n` states: `tol`, `bc_tol` and `newton_step_tol`
    /// positive and finite, `tol` and `newton_step_tol` below 1 (relative measures; `bc_tol` is
    /// absolute, in the units of the boundary residuals), `max_nodes >= 2`, the iteration and factorisation budgets at least
    /// 1, and a [`ResidualScale::PerComponent`] of `n` positive finite values. The error names
    /// the option and its value. [`Solver::solve`] calls this before any work.
    pub fn validate(&self, n: usize) -> Result<(), BvpError> {
        let positive = |name: &str, v: f64| {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(BvpError::InvalidInput(format!(
                    "SolveOptions::{name} must be positive and finite, got {v}"
                )))
            }
        };
        // relative measures: 1 or more accepts any iterate, the initial guess included
        let relative = |name: &str, v: f64| {
            positive(name, v)?;
            if v < 1.0 {
                Ok(())
            } else {
                Err(BvpError::InvalidInput(format!(
                    "SolveOptions::{name} must be below 1, got {v:e}: it bounds a relative \
                     residual, and 1 or more would accept any iterate (the initial guess \
                     included); typical values are 1e-3 to 1e-8"
                )))
            }
        };
        relative("tol", self.tol)?;
        if let Some(b) = self.bc_tol {
            positive("bc_tol", b)?;
        }
        if let Some(t) = self.newton_step_tol {
            relative("newton_step_tol", t)?;
        }
        if self.max_nodes < 2 {
            return Err(BvpError::InvalidInput(format!(
                "SolveOptions::max_nodes must be at least 2, got {}",
                self.max_nodes
            )));
        }
        for (name, v) in [
            ("max_mesh_iterations", self.max_mesh_iterations),
            ("max_jacobians_per_mesh", self.max_jacobians_per_mesh),
            (
                "max_newton_iterations_per_mesh",
                self.max_newton_iterations_per_mesh,
            ),
        ] {
            if v == 0 {
                return Err(BvpError::InvalidInput(format!(
                    "SolveOptions::{name} must be at least 1, got 0"
                )));
            }
        }
        self.mesh.validate()?;
        if let Some(g) = &self.growth_limit {
            if !(g.factor >= 1.0 && g.factor.is_finite()) || g.at_least < 2 {
                return Err(BvpError::InvalidInput(format!(
                    "SolveOptions::growth_limit must have a finite factor of at least 1 and \
                     allow at least 2 nodes, got factor {} and at_least {}; typical values are \
                     factor 16 and at_least 1000, or None for no limit",
                    g.factor, g.at_least
                )));
            }
        }
        if let Some(l) = &self.linearization_params {
            if !l.windows(2).all(|w| w[0] < w[1]) {
                return Err(BvpError::InvalidInput(format!(
                    "SolveOptions::linearization_params must be strictly increasing indices of \
                     model parameters, got {l:?}"
                )));
            }
        }
        if let ResidualScale::PerComponent(s) = &self.scale {
            if s.len() != n || s.iter().any(|v| !(*v > 0.0 && v.is_finite())) {
                return Err(BvpError::InvalidInput(format!(
                    "SolveOptions::scale: ResidualScale::PerComponent needs {n} positive finite values, got {s:?}"
                )));
            }
        }
        Ok(())
    }
}

/// Richardson's factor of the collocation (Lobatto IIIA, order 4) on a mesh with every
/// interval halved: the discretisation error of a solution `y` is `(y_half − y) · 16/15` to
/// first order, `y_half` solved on the halved mesh ([`Guess::on_halved_mesh`]), since halving
/// every interval divides the error by 16.
pub const RICHARDSON_FACTOR: f64 = 16.0 / 15.0;

/// An initial guess: mesh, states at the nodes and unknown parameters. It is also the warm-start
/// type: [`Guess::from`] a previous [`Solution`], or a predicted one such as the secant
/// predictor [`secant_guess`](crate::continuation::secant_guess), carries exactly what a solve
/// starts from, nothing of a solve that did not happen.
#[derive(Debug, Clone)]
pub struct Guess {
    /// Mesh nodes (strictly increasing; `x[0] = a`, `x[m-1] = b`).
    pub x: Vec<f64>,
    /// States at the nodes, `m × n` row-major.
    pub y: Vec<f64>,
    /// Unknown parameters (length `k`).
    pub unknowns: Vec<f64>,
}

impl Guess {
    /// The same state `y0` at every node of `x`.
    pub fn constant(x: Vec<f64>, y0: &[f64]) -> Self {
        let y = x.iter().flat_map(|_| y0.iter().copied()).collect();
        Guess {
            x,
            y,
            unknowns: Vec::new(),
        }
    }

    /// States from a function `g(x, y)` filling `y` (length `n`).
    pub fn from_fn(x: Vec<f64>, n: usize, mut g: impl FnMut(f64, &mut [f64])) -> Self {
        let mut y = vec![0.0; x.len() * n];
        for (i, &xi) in x.iter().enumerate() {
            g(xi, &mut y[i * n..(i + 1) * n]);
        }
        Guess {
            x,
            y,
            unknowns: Vec::new(),
        }
    }

    /// `s` on its mesh with every interval halved ([`mesh::halved`]): the nodes kept, the
    /// midpoints from the solution's collocation interpolant (accurate to the method's order),
    /// its unknowns. The start of a solve on a fixed mesh
    /// ([`SolveOptions::fixed_mesh`]) whose difference from `s`, times
    /// [`RICHARDSON_FACTOR`], estimates the discretisation error of `s`.
    pub fn on_halved_mesh(s: &Solution) -> Self {
        let x = mesh::halved(&s.x);
        let y = resample_regions(&s.x, &s.y, &s.yp, s.n, &x);
        Guess {
            x,
            y,
            unknowns: s.unknowns.clone(),
        }
    }

    /// Sets the unknown-parameter guess.
    pub fn with_unknowns(mut self, unknowns: &[f64]) -> Self {
        self.unknowns = unknowns.to_vec();
        self
    }
}

impl From<&Solution> for Guess {
    /// A warm start from a previous solution: its mesh, values and unknowns.
    fn from(s: &Solution) -> Self {
        Guess {
            x: s.x.clone(),
            y: s.y.clone(),
            unknowns: s.unknowns.clone(),
        }
    }
}

/// A reusable solver for one problem. It keeps its workspace (buffers, sparsity patterns and
/// symbolic factorisations of recently used mesh sizes) between solves, so repeated solves —
/// continuation, parameter sweeps, fits — do not redo that work.
pub struct Solver<'a, P: Bvp> {
    problem: &'a P,
    /// The options used by [`solve`](Self::solve).
    pub options: SolveOptions,
    ws: Workspace,
    /// Whether every solve borrows the thread's workspace (`SPARE`) instead of `ws`.
    thread_workspace: bool,
}

/// Everything a solve reuses that does not depend on the problem's type: the collocation
/// buffers, the Newton-matrix workspaces of recently used mesh sizes and the scratch of Newton
/// and the error estimate. [`solve`] borrows one per thread (`SPARE`).
struct Workspace {
    col: Collocation,
    patterns: Vec<Arc<Pattern>>,
    /// Newton-matrix workspaces of recently used mesh sizes (most recent last).
    systems: Vec<LinearSystem>,
    /// Sparsity patterns built so far (for tests of the reuse).
    patterns_built: usize,
    /// Newton-matrix workspaces created so far (for tests of the reuse).
    systems_built: usize,
    newton_work: NewtonWork,
    rms: Vec<f64>,
    buf: Vec<f64>,
    marks: Vec<u8>,
}

impl Workspace {
    fn new(n: usize, k: usize, q: usize) -> Self {
        Workspace {
            col: Collocation::new(n, k, q),
            patterns: Vec::new(),
            systems: Vec::new(),
            patterns_built: 0,
            systems_built: 0,
            newton_work: NewtonWork::default(),
            rms: Vec::new(),
            buf: Vec::new(),
            marks: Vec::new(),
        }
    }

    /// This workspace made fit for a problem with `n` states, `k` unknowns and `q` model
    /// parameters: kept as it is for the same dimensions, otherwise the dimension-bound parts
    /// (collocation buffers, patterns, Newton-matrix workspaces) are replaced.
    fn for_dims(mut self, n: usize, k: usize, q: usize) -> Self {
        if (self.col.n, self.col.k, self.col.q) != (n, k, q) {
            self.col = Collocation::new(n, k, q);
            self.patterns.clear();
            self.systems.clear();
        }
        self
    }
}

thread_local! {
    /// The workspace of the last [`solve`] on this thread, lent to the next one: repeated
    /// one-off solves (a benchmark loop, a sweep written with `solve`) reuse buffers and
    /// Newton-matrix workspaces instead of allocating (and page-faulting) fresh ones per call.
    /// A nested `solve` (from inside a right-hand side) finds it lent out and uses a fresh one.
    static SPARE: RefCell<Option<Workspace>> = const { RefCell::new(None) };
}

/// Creates the Newton-matrix workspace for a pattern: the one place where a solve makes one
/// (the choice of linear solver belongs here).
fn new_system(pattern: Arc<Pattern>, opts: &SolveOptions) -> LinearSystem {
    LinearSystem::with_kind(pattern, opts.linear_solver)
}

/// The progress line of mesh iteration `iteration` (on `m` nodes) on stderr, with the
/// largest collocation and boundary residuals and the size of the next mesh.
fn report_mesh(
    iteration: usize,
    m: usize,
    report: &NewtonReport,
    (max_res, max_bc_res): (f64, f64),
    above: usize,
    next: usize,
) {
    // a failed write to stderr must not panic
    use std::io::Write as _;
    let _ = writeln!(
        std::io::stderr(),
        "mesh {iteration:>3}: {m:>6} nodes, Newton {:>2} it ({}), max rms residual {max_res:.2e}, max bc residual {max_bc_res:.2e}, intervals above tol {above}, next mesh {next} nodes",
        report.iterations,
        if report.converged { "converged" } else { "not converged" },
    );
}

/// Newton's settings for a solve with `opts` (larger budgets on a fixed mesh).
fn newton_settings(opts: &SolveOptions) -> NewtonSettings {
    NewtonSettings {
        tol: opts.tol,
        bc_tol: opts.bc_tol.unwrap_or(opts.tol),
        max_jacobians: if opts.adapt {
            opts.max_jacobians_per_mesh
        } else {
            opts.max_jacobians_per_mesh.max(25)
        },
        max_iterations: if opts.adapt {
            opts.max_newton_iterations_per_mesh
        } else {
            opts.max_newton_iterations_per_mesh.max(50)
        },
        step_tol: opts.newton_step_tol,
        verbose: opts.verbose,
    }
}

/// The error of a mesh loop that spent its `iterations` without meeting the tolerances:
/// [`BvpError::MeshCycling`] if its mesh stopped settling, else [`BvpError::ToleranceNotMet`].
fn not_met(
    control: &MeshControl,
    opts: &SolveOptions,
    iterations: usize,
    max_residual: f64,
    max_bc_residual: f64,
) -> BvpError {
    let bc_tol = opts.bc_tol.unwrap_or(opts.tol);
    match control.cycle() {
        Some((low, high)) => BvpError::MeshCycling(Box::new(MeshCycle {
            iterations,
            low,
            high,
            switched_at: control.switched_at,
            max_residual,
            tol: opts.tol,
            max_bc_residual,
            bc_tol,
            hint: cycling_hint(opts, control.switched_at.is_some()),
        })),
        None => BvpError::ToleranceNotMet {
            iterations,
            max_residual,
            tol: opts.tol,
            max_bc_residual,
            bc_tol,
        },
    }
}

/// The options to try when the mesh cycled ([`BvpError::MeshCycling`]): those of `opts` not
/// tried yet.
fn cycling_hint(opts: &SolveOptions, switched: bool) -> String {
    let mut tries = Vec::new();
    if !switched && opts.mesh.rule != mesh::RefineRule::Scipy {
        tries.push(
            "scipy's refinement rule (SolveOptions::mesh = MeshOptions::scipy(), or MeshOptions::settle = true)"
                .to_string(),
        );
    }
    if opts.scale != ResidualScale::Auto {
        tries.push("the residual scale ResidualScale::Auto (SolveOptions::scale)".into());
    }
    tries.push(format!(
        "more mesh iterations (SolveOptions::max_mesh_iterations = {} now)",
        opts.max_mesh_iterations
    ));
    tries.join(", or ")
}

/// Solves `problem` once: a convenience around [`Solver`].
pub fn solve<P: Bvp>(
    problem: &P,
    params: &[f64],
    guess: &Guess,
    options: &SolveOptions,
) -> Result<Solution, BvpError> {
    let (n, k, q) = (problem.dim(), problem.num_unknowns(), problem.num_params());
    let spare = SPARE.try_with(|s| s.borrow_mut().take()).ok().flatten();
    let ws = match spare {
        Some(ws) => ws.for_dims(n, k, q),
        None => Workspace::new(n, k, q),
    };
    let mut solver = Solver {
        problem,
        options: options.clone(),
        ws,
        thread_workspace: false,
    };
    let result = solver.solve(params, guess);
    let ws = solver.ws;
    // during thread teardown the slot may be gone: the workspace is then dropped
    let _ = SPARE.try_with(|s| *s.borrow_mut() = Some(ws));
    result
}

impl<'a, P: Bvp> Solver<'a, P> {
    /// A solver for `problem` with `options`.
    pub fn new(problem: &'a P, options: SolveOptions) -> Self {
        let (n, k, q) = (problem.dim(), problem.num_unknowns(), problem.num_params());
        Solver {
            problem,
            options,
            ws: Workspace::new(n, k, q),
            thread_workspace: false,
        }
    }

    /// With `on`, the solver keeps no workspace of its own between solves: every solve borrows
    /// the calling thread's (as [`solve`] does) and gives it back. For many solvers alive at
    /// once — one per experiment of a joint fit, solved a few at a time on a thread pool — the
    /// memory of the Newton-matrix workspaces is then that of one solver per thread instead of
    /// one per solver; a solve on another mesh size than the thread's last ones sizes them
    /// anew. Results are the same either way.
    pub fn use_thread_workspace(&mut self, on: bool) {
        if on && !self.thread_workspace {
            let (n, k, q) = (self.ws.col.n, self.ws.col.k, self.ws.col.q);
            self.ws = Workspace::new(n, k, q);
        }
        self.thread_workspace = on;
    }

    /// The problem.
    pub fn problem(&self) -> &'a P {
        self.problem
    }

    fn pattern(&mut self, m: usize) -> Result<Arc<Pattern>, BvpError> {
        if let Some(pos) = self.ws.patterns.iter().position(|p| p.m == m) {
            let p = self.ws.patterns.remove(pos);
            self.ws.patterns.push(p.clone());
            return Ok(p);
        }
        let p = Arc::new(Pattern::new(self.ws.col.n, self.ws.col.k, m)?);
        self.ws.patterns_built += 1;
        if self.ws.patterns.len() >= 4 {
            self.ws.patterns.remove(0);
        }
        self.ws.patterns.push(p.clone());
        Ok(p)
    }

    /// The Newton-matrix workspace for `m` nodes: the cached one (its factor storage and
    /// scratch already sized), or a new one. Give it back with
    /// [`keep_system`](Self::keep_system).
    fn take_system(&mut self, m: usize, opts: &SolveOptions) -> Result<LinearSystem, BvpError> {
        if let Some(pos) = self
            .ws
            .systems
            .iter()
            .position(|s| s.pattern.m == m && s.kind() == opts.linear_solver)
        {
            return Ok(self.ws.systems.remove(pos));
        }
        let pattern = self.pattern(m)?;
        self.ws.systems_built += 1;
        Ok(new_system(pattern, opts))
    }

    /// Returns a workspace to the cache (at most 4 mesh sizes, least recently used dropped).
    fn keep_system(&mut self, lin: LinearSystem) {
        if self.ws.systems.len() >= 4 {
            self.ws.systems.remove(0);
        }
        self.ws.systems.push(lin);
    }

    fn validate(
        &self,
        params: &[f64],
        guess: &Guess,
        options: &SolveOptions,
    ) -> Result<(), BvpError> {
        let (n, k, q) = (self.ws.col.n, self.ws.col.k, self.ws.col.q);
        if n == 0 {
            return Err(BvpError::InvalidInput(
                "the problem has no states (dim() = 0)".into(),
            ));
        }
        options.validate(n)?;
        let interfaces = self.problem.interfaces();
        if interfaces.is_empty() {
            mesh::validate(&guess.x)?;
        } else {
            mesh::validate_multipoint(&guess.x, interfaces)?;
        }
        if guess.y.len() != guess.x.len() * n {
            return Err(BvpError::InvalidInput(format!(
                "the guess has {} values, expected {} nodes x {} states = {}",
                guess.y.len(),
                guess.x.len(),
                n,
                guess.x.len() * n
            )));
        }
        if let Some(i) = guess.y.iter().position(|v| !v.is_finite()) {
            return Err(BvpError::NonFinite {
                what: "initial guess",
                component: i % n,
                x: guess.x[i / n],
            });
        }
        if guess.unknowns.len() != k {
            return Err(BvpError::InvalidInput(format!(
                "the problem has {k} unknown parameters but the guess gives {}",
                guess.unknowns.len()
            )));
        }
        if params.len() != q {
            return Err(BvpError::InvalidInput(format!(
                "the problem has {q} model parameters but {} values were given",
                params.len()
            )));
        }
        if let Some(i) = guess
            .unknowns
            .iter()
            .chain(params)
            .position(|v| !v.is_finite())
        {
            return Err(BvpError::InvalidInput(format!(
                "parameter {i} of p = (unknowns, model parameters) is not finite"
            )));
        }
        if let Some(&j) = options
            .linearization_params
            .as_ref()
            .and_then(|l| l.iter().find(|&&j| j >= q))
        {
            return Err(BvpError::InvalidInput(format!(
                "SolveOptions::linearization_params names model parameter {j}, but the problem \
                 has {q} (indices 0..{q})"
            )));
        }
        if guess.x.len() > options.max_nodes {
            return Err(BvpError::InvalidInput(format!(
                "the initial mesh has {} nodes, more than max_nodes = {}",
                guess.x.len(),
                options.max_nodes
            )));
        }
        Ok(())
    }

    fn scale_for(&self, y: &[f64], scale: &ResidualScale) -> Vec<f64> {
        let n = self.ws.col.n;
        match scale {
            ResidualScale::Relative => vec![1.0; n],
            ResidualScale::PerComponent(s) => s.clone(),
            ResidualScale::Auto => {
                let mut s = vec![1.0f64; n];
                for (i, v) in y.iter().enumerate() {
                    s[i % n] = s[i % n].max(v.abs());
                }
                s
            }
        }
    }

    /// Solves the problem with model parameters `params` (length `num_params()`) from `guess`,
    /// with the solver's [`options`](Self::options).
    pub fn solve(&mut self, params: &[f64], guess: &Guess) -> Result<Solution, BvpError> {
        let opts = self.options.clone();
        self.solve_with(params, guess, &opts)
    }

    /// [`solve`](Self::solve) with `options` for this call only (the solver's own
    /// [`options`](Self::options) are neither used nor changed): a path that solves its
    /// intermediate points loosely and its last point tightly passes the two option sets per
    /// call and keeps one workspace.
    pub fn solve_with(
        &mut self,
        params: &[f64],
        guess: &Guess,
        opts: &SolveOptions,
    ) -> Result<Solution, BvpError> {
        self.solve_impl(params, guess, opts, None)
    }

    /// [`solve_with`](Self::solve_with) from a guess on the mesh of a nearby solution `near`
    /// (e.g. [`tangent_guess`](crate::sensitivity::tangent_guess) or `Guess::from(near)`),
    /// starting with simplified Newton on the factorised Newton matrix of `near` when `near`
    /// has its linearisation cached ([`Solution::factorization`]) or kept its last Newton
    /// matrix ([`SolveOptions::keep_newton_matrix`]): no Jacobian evaluation and
    /// no factorisation until the affine-invariant contraction test asks for a fresh one. The
    /// result meets the same tolerances as any solve. Without either, or on
    /// another mesh, this is `solve_with`.
    pub fn solve_near(
        &mut self,
        params: &[f64],
        guess: &Guess,
        near: &Solution,
        opts: &SolveOptions,
    ) -> Result<Solution, BvpError> {
        if guess.x != near.x {
            return self.solve_impl(params, guess, opts, None);
        }
        let initial = match (near.factorization(), &near.newton_matrix) {
            (Some(f), _) => Some(Initial::Borrowed(f)),
            (None, Some(kept)) => Some(Initial::Kept(kept)),
            (None, None) => None,
        };
        self.solve_impl(params, guess, opts, initial)
    }

    /// [`solve_inner`](Self::solve_inner) in the solver's own workspace or, with
    /// [`use_thread_workspace`](Self::use_thread_workspace), in the thread's.
    fn solve_impl(
        &mut self,
        params: &[f64],
        guess: &Guess,
        opts: &SolveOptions,
        initial: Option<Initial<'_>>,
    ) -> Result<Solution, BvpError> {
        if !self.thread_workspace {
            return self.solve_inner(params, guess, opts, initial);
        }
        let (n, k, q) = (self.ws.col.n, self.ws.col.k, self.ws.col.q);
        let spare = SPARE.try_with(|s| s.borrow_mut().take()).ok().flatten();
        let lent = match spare {
            Some(ws) => ws.for_dims(n, k, q),
            None => Workspace::new(n, k, q),
        };
        let own = std::mem::replace(&mut self.ws, lent);
        let result = self.solve_inner(params, guess, opts, initial);
        let lent = std::mem::replace(&mut self.ws, own);
        // during thread teardown the slot may be gone: the workspace is then dropped
        let _ = SPARE.try_with(|s| *s.borrow_mut() = Some(lent));
        result
    }

    fn solve_inner(
        &mut self,
        params: &[f64],
        guess: &Guess,
        opts: &SolveOptions,
        initial: Option<Initial<'_>>,
    ) -> Result<Solution, BvpError> {
        self.validate(params, guess, opts)?;
        // a kept Newton matrix carries over to this solution while no newer one is factored on
        // the guess's mesh
        let carried = initial.and_then(Initial::kept);
        let mut initial = initial.map(Initial::factorization);
        let problem = self.problem;
        let n = self.ws.col.n;
        let bc_tol = opts.bc_tol.unwrap_or(opts.tol);
        let settings = newton_settings(opts);
        let mut x = guess.x.clone();
        let mut y = guess.y.clone();
        if let Some(s) = problem.singular_term() {
            // y(0) onto the null space of S (scipy's projection): S y(0) = 0 from the start
            Singular::new(s, n, x[0])?.project(&mut y[..n]);
        }
        let mut p: Vec<f64> = guess.unknowns.iter().chain(params).copied().collect();
        let mut stats = SolveStats::default();
        self.ws.col.rhs_evals = 0;
        self.ws.col.jac_evals = 0;
        // the mesh options of this solve: the rule switches to scipy's when the mesh cycles
        let mut control = MeshControl::new(&opts.mesh);
        let mut coarsenings_left = if opts.coarsen && opts.adapt { 3 } else { 0 };
        let mut iteration = 0;
        // values interpolated onto a refined mesh rarely pass the termination test as they
        // are: their Jacobian is evaluated with their residual (one pass instead of two)
        let mut start = Start::Lazy;
        loop {
            iteration += 1;
            let m = x.len();
            let settled = self.newton_on_mesh(
                &x,
                &mut y,
                &mut p,
                opts,
                &settings,
                initial.take(),
                start,
                &mut stats,
            )?;
            let MeshPass {
                lin,
                report,
                factored,
                scale,
                max_res,
                max_bc_res,
            } = settled;

            if !opts.adapt && !report.converged {
                self.keep_system(lin);
                return Err(fixed_mesh_failure(&report, m, (max_res, max_bc_res)));
            }

            let residuals = (max_res, max_bc_res);
            let refined = opts
                .adapt
                .then(|| self.refinement(&x, &mut control, opts, iteration, &report, residuals))
                .flatten();
            stats.mesh_rule_switched_at = control.switched_at;
            if let Some(new_x) = refined {
                self.keep_system(lin);
                allowed_size(new_x.len(), guess.x.len(), max_res, opts)?;
                y = resample_regions(&x, &y, &self.ws.col.f, n, &new_x);
                x = new_x;
                stats.mesh_refinements += 1;
                start = Start::WithJacobian;
            } else if max_bc_res <= bc_tol || !opts.adapt {
                // coarsen only if the coarser mesh can still be solved and checked: the solution
                // returned must belong to the mesh it was computed on (10 % fewer nodes at least)
                let coarser =
                    (coarsenings_left > 0 && m > 8 && iteration < opts.max_mesh_iterations)
                        .then(|| coarsen_regions(&x, &self.ws.rms, opts.tol))
                        .filter(|c| (m - c.len()) * 10 >= m);
                if let Some(new_x) = coarser {
                    self.keep_system(lin);
                    coarsenings_left -= 1;
                    y = resample_regions(&x, &y, &self.ws.col.f, n, &new_x);
                    x = new_x;
                    stats.mesh_refinements += 1;
                    stats.mesh_coarsenings += 1;
                    start = Start::Lazy;
                    continue;
                }
                let kept = kept_matrix(opts, &lin, factored, x == guess.x, &carried);
                return self.finish(problem, lin, x, y, p, scale, stats, opts, kept);
            } else {
                self.keep_system(lin);
            }
            if iteration >= opts.max_mesh_iterations {
                return Err(not_met(&control, opts, iteration, max_res, max_bc_res));
            }
        }
    }

    /// The refined mesh the residuals of the pass on `x` ask for (`None`: every interval meets
    /// the tolerance), reported at `verbose >= 1`; `residuals` are the pass's largest
    /// collocation and boundary residuals.
    fn refinement(
        &mut self,
        x: &[f64],
        control: &mut MeshControl,
        opts: &SolveOptions,
        iteration: usize,
        report: &NewtonReport,
        residuals: (f64, f64),
    ) -> Option<Vec<f64>> {
        let m = x.len();
        let pass = (m, residuals.0, iteration);
        let above = control.plan(
            &self.ws.rms,
            opts.tol,
            &mut self.ws.marks,
            pass,
            opts.verbose,
        );
        let refined =
            (above > 0).then(|| refine_regions(x, &self.ws.rms, &self.ws.marks, opts, control));
        if opts.verbose >= 1 {
            let next = refined.as_ref().map_or(m, Vec::len);
            report_mesh(iteration, m, report, residuals, above, next);
        }
        refined
    }

    /// One Newton solve on the mesh `x` from `y`, `p` (both updated in place), then the scaled
    /// RMS residuals of its intervals (left in the workspace's `rms`), counted in `stats`.
    /// Errors: a Newton failure, an irregular singular solution (the system is kept).
    #[allow(clippy::too_many_arguments)]
    fn newton_on_mesh(
        &mut self,
        x: &[f64],
        y: &mut [f64],
        p: &mut [f64],
        opts: &SolveOptions,
        settings: &NewtonSettings,
        initial: Option<&Factorization>,
        start: Start,
        stats: &mut SolveStats,
    ) -> Result<MeshPass, BvpError> {
        let problem = self.problem;
        let m = x.len();
        self.ws.col.set_mesh(x);
        let mut lin = self.take_system(m, opts)?;
        let factorizations_before = lin.factorizations;
        let scale = self.scale_for(y, &opts.scale);
        let report = newton(
            problem,
            &mut self.ws.col,
            &mut lin,
            y,
            p,
            &scale,
            settings,
            &mut self.ws.newton_work,
            initial,
            start,
        );
        let report = match report {
            Ok(r) => r,
            Err(e) => {
                self.keep_system(lin);
                return Err(e);
            }
        };
        if let Err(e) = self.check_regular(report.converged, y, settings.bc_tol) {
            self.keep_system(lin);
            return Err(e);
        }
        stats.newton_iterations += report.iterations;
        stats.jacobian_factorizations += lin.factorizations - factorizations_before;
        let factored = lin.factorizations > factorizations_before;
        let max_bc_res = max_bc(&self.ws.col);
        rms_residuals(
            problem,
            &mut self.ws.col,
            y,
            p,
            &scale,
            &mut self.ws.rms,
            &mut self.ws.buf,
        );
        let max_res = self.ws.rms.iter().fold(0.0f64, |a, &v| a.max(v));
        stats.max_residual = max_res;
        stats.max_bc_residual = max_bc_res;
        Ok(MeshPass {
            lin,
            report,
            factored,
            scale,
            max_res,
            max_bc_res,
        })
    }

    /// After a converged Newton solve of a singular problem: the boundary conditions hold, so
    /// if they do not impose `S y(0) = 0` no refinement will (the solution is not smooth at 0).
    fn check_regular(&self, converged: bool, y: &[f64], bc_tol: f64) -> Result<(), BvpError> {
        match &self.ws.col.singular {
            Some(s) if converged => s.check_regular(y, bc_tol),
            _ => Ok(()),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn finish(
        &mut self,
        problem: &P,
        mut lin: LinearSystem,
        x: Vec<f64>,
        y: Vec<f64>,
        p: Vec<f64>,
        scale: Vec<f64>,
        mut stats: SolveStats,
        opts: &SolveOptions,
        newton_matrix: Option<Arc<Factorization>>,
    ) -> Result<Solution, BvpError> {
        let k = self.ws.col.k;
        if let Some(s) = &self.ws.col.singular {
            s.check_regular(&y, opts.bc_tol.unwrap_or(opts.tol))?;
        }
        // `col` holds values at the final iterate (the error estimate used them), among them the
        // midpoint states the Jacobians need
        let linearization = OnceLock::new();
        if opts.factor_at_solution {
            let lz = Linearization::compute(
                problem,
                &mut self.ws.col,
                &mut lin,
                &y,
                &p,
                opts.linearization_params.as_deref(),
            );
            stats.jacobian_factorizations += 1;
            self.keep_system(lin);
            let _ = linearization.set(Arc::new(lz?));
        } else {
            self.keep_system(lin);
        }
        stats.rhs_evaluations = self.ws.col.rhs_evals;
        stats.rhs_dual_evaluations = self.ws.col.jac_evals;
        Ok(Solution {
            n: self.ws.col.n,
            x,
            yp: self.ws.col.f.clone(),
            y,
            unknowns: p[..k].to_vec(),
            params: p[k..].to_vec(),
            rms_residuals: self.ws.rms.clone(),
            residual_scale: scale,
            stats,
            linearization,
            full_linearization: OnceLock::new(),
            newton_matrix,
        })
    }
}

/// `op(region's nodes, their range)` on every region of the (multipoint) mesh `x`, the new
/// meshes concatenated: the mesh control acts on each region alone and keeps the interfaces.
fn per_region(
    x: &[f64],
    mut op: impl FnMut(&[f64], std::ops::Range<usize>) -> Vec<f64>,
) -> Vec<f64> {
    let ranges = mesh::regions(x);
    if ranges.len() == 1 {
        return op(x, 0..x.len());
    }
    let mut out = Vec::with_capacity(x.len());
    for r in ranges {
        out.extend(op(&x[r.clone()], r));
    }
    out
}

/// [`resample`] region by region: the left limit at an interface from the region on its left,
/// the right limit from the one on its right (`xs` and `new_x` have the same interfaces).
pub(crate) fn resample_regions(
    xs: &[f64],
    ys: &[f64],
    fs: &[f64],
    n: usize,
    new_x: &[f64],
) -> Vec<f64> {
    let (old, new) = (mesh::regions(xs), mesh::regions(new_x));
    if old.len() == 1 || old.len() != new.len() {
        return resample(xs, ys, fs, n, new_x);
    }
    let mut out = Vec::with_capacity(new_x.len() * n);
    for (o, w) in old.into_iter().zip(new) {
        let nodes = o.start * n..o.end * n;
        out.extend(resample(
            &xs[o],
            &ys[nodes.clone()],
            &fs[nodes],
            n,
            &new_x[w],
        ));
    }
    out
}

/// The error of a Newton solve that did not converge on a fixed mesh of `m` nodes;
/// `residuals` are its largest collocation and boundary residuals.
fn fixed_mesh_failure(report: &NewtonReport, m: usize, residuals: (f64, f64)) -> BvpError {
    BvpError::NewtonFailed {
        iterations: report.iterations,
        nodes: m,
        reason: "no convergence on the fixed mesh".into(),
        max_residual: residuals.0,
        max_bc_residual: residuals.1,
    }
}

/// A Newton solve on one mesh, with its residuals (see `Solver::newton_on_mesh`).
struct MeshPass {
    /// The linear system (kept for the next solve, or finished with).
    lin: LinearSystem,
    report: NewtonReport,
    /// Whether a new matrix was factored on this mesh.
    factored: bool,
    /// The residual scale of this pass.
    scale: Vec<f64>,
    /// The largest scaled RMS residual of the intervals.
    max_res: f64,
    /// The largest boundary-condition residual.
    max_bc_res: f64,
}

/// The factorisation a solve nearby may start from ([`Solver::solve_near`]).
#[derive(Clone, Copy)]
pub(crate) enum Initial<'f> {
    /// The exact linearisation's factorisation at a nearby solution.
    Borrowed(&'f Factorization),
    /// A nearby solve's last Newton matrix ([`SolveOptions::keep_newton_matrix`]).
    Kept(&'f Arc<Factorization>),
}

impl<'f> Initial<'f> {
    fn factorization(self) -> &'f Factorization {
        match self {
            Initial::Borrowed(f) => f,
            Initial::Kept(k) => k,
        }
    }

    /// The kept matrix (a new reference to it), if this is one.
    fn kept(self) -> Option<Arc<Factorization>> {
        match self {
            Initial::Borrowed(_) => None,
            Initial::Kept(k) => Some(k.clone()),
        }
    }
}

/// The Newton matrix a solution keeps with [`SolveOptions::keep_newton_matrix`] (and without
/// an exact linearisation): the one its last Newton run factored, or else, on the guess's own
/// mesh, the kept matrix the solve started from (`carried`); none on another mesh.
fn kept_matrix(
    opts: &SolveOptions,
    lin: &LinearSystem,
    factored: bool,
    on_guess_mesh: bool,
    carried: &Option<Arc<Factorization>>,
) -> Option<Arc<Factorization>> {
    if !opts.keep_newton_matrix || opts.factor_at_solution {
        None
    } else if factored {
        Some(Arc::new(lin.snapshot()))
    } else if on_guess_mesh {
        carried.clone()
    } else {
        None
    }
}

/// Whether a refined mesh of `nodes` nodes may be solved: within the growth limit of a guess
/// of `start_nodes` nodes (when it is below `max_nodes`) and within `opts.max_nodes`; the error
/// says which bound it exceeds, with the largest scaled residual `max_res` reached.
fn allowed_size(
    nodes: usize,
    start_nodes: usize,
    max_res: f64,
    opts: &SolveOptions,
) -> Result<(), BvpError> {
    let limit = opts
        .growth_limit
        .map(|g| g.nodes(start_nodes))
        .filter(|&l| l < opts.max_nodes);
    if let Some(limit) = limit.filter(|&l| nodes > l) {
        return Err(BvpError::MeshGrowthLimit {
            start_nodes,
            nodes,
            limit,
            max_residual: max_res,
            tol: opts.tol,
        });
    }
    if nodes > opts.max_nodes {
        return Err(BvpError::MaxNodesExceeded {
            nodes,
            max_nodes: opts.max_nodes,
            max_residual: max_res,
            tol: opts.tol,
        });
    }
    Ok(())
}

/// The refined mesh: each region of `x` refined where its intervals' `rms` residuals exceed the
/// tolerance (`marks` from the mesh control's plan).
fn refine_regions(
    x: &[f64],
    rms: &[f64],
    marks: &[u8],
    opts: &SolveOptions,
    control: &MeshControl,
) -> Vec<f64> {
    per_region(x, |xr, r| {
        let ints = r.start..r.end - 1;
        let marks = marks.get(ints.clone()).unwrap_or(&[]);
        mesh::apply(
            xr,
            &rms[ints],
            marks,
            opts.tol,
            &control.options,
            opts.max_nodes,
        )
    })
}

/// The coarsened mesh: each region of `x` without the nodes whose intervals' residuals lie far
/// below the tolerance `tol` (a twentieth of it).
fn coarsen_regions(x: &[f64], rms: &[f64], tol: f64) -> Vec<f64> {
    per_region(x, |xr, r| {
        mesh::coarsen(xr, &rms[r.start..r.end - 1], tol / 20.0)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::linspace;
    use num_dual::DualNum;

    /// y'' = -a e^y, y(0) = 0, y(1) = 0 (Bratu, a = p[0]).
    struct Bratu;
    impl Bvp for Bratu {
        fn dim(&self) -> usize {
            2
        }
        fn num_params(&self) -> usize {
            1
        }
        fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
            f[0] = y[1];
            f[1] = -p[0] * y[0].exp();
        }
        fn bc<D: DualNum<Primitive = f64> + Copy>(
            &self,
            ya: &[D],
            yb: &[D],
            _p: &[D],
            r: &mut [D],
        ) {
            r[0] = ya[0];
            r[1] = yb[0];
        }
    }

    #[test]
    fn a_warm_re_solve_on_the_same_mesh_reuses_pattern_and_workspace() {
        let opts = SolveOptions::with_tol(1e-8);
        let mut solver = Solver::new(&Bratu, opts.clone());
        let guess = Guess::constant(linspace(0.0, 1.0, 7), &[0.1, 0.0]);
        let first = solver.solve(&[1.0], &guess).unwrap();
        let (patterns, systems) = (solver.ws.patterns_built, solver.ws.systems_built);
        assert!(patterns >= 1 && systems >= 1);
        let warm = Guess::from(&first);
        let again = solver.solve(&[1.01], &warm).unwrap();
        assert_eq!(
            again.nodes(),
            first.nodes(),
            "the warm re-solve keeps the mesh"
        );
        assert_eq!(
            solver.ws.patterns_built, patterns,
            "no new sparsity pattern"
        );
        assert_eq!(
            solver.ws.systems_built, systems,
            "no new Newton-matrix workspace"
        );
        // the reused workspace gives exactly what a fresh solver gives
        let fresh = solve(&Bratu, &[1.01], &warm, &opts).unwrap();
        assert_eq!(again.x, fresh.x);
        assert_eq!(again.y, fresh.y);
        assert_eq!(again.stats, fresh.stats);
    }

    /// y' = -y, y(0) = 1: one state, no parameters.
    struct Decay;
    impl Bvp for Decay {
        fn dim(&self) -> usize {
            1
        }
        fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
            f[0] = -y[0];
        }
        fn bc<D: DualNum<Primitive = f64> + Copy>(
            &self,
            ya: &[D],
            _yb: &[D],
            _p: &[D],
            r: &mut [D],
        ) {
            r[0] = ya[0] - 1.0;
        }
    }

    #[test]
    fn one_off_solves_lend_a_thread_workspace_without_changing_results() {
        let opts = SolveOptions::with_tol(1e-8);
        let guess = Guess::constant(linspace(0.0, 1.0, 7), &[0.1, 0.0]);
        let fresh = Solver::new(&Bratu, opts.clone())
            .solve(&[1.0], &guess)
            .unwrap();
        let first = solve(&Bratu, &[1.0], &guess, &opts).unwrap();
        assert!(
            SPARE.with(|s| s.borrow().is_some()),
            "the workspace is kept"
        );
        // a problem of other dimensions in between gets a workspace fit for it
        let decay = solve(
            &Decay,
            &[],
            &Guess::constant(linspace(0.0, 1.0, 5), &[1.0]),
            &opts,
        )
        .unwrap();
        assert!((decay.at_node(decay.nodes() - 1, 0) - (-1.0f64).exp()).abs() < 1e-7);
        let second = solve(&Bratu, &[1.0], &guess, &opts).unwrap();
        for s in [&first, &second] {
            assert_eq!(s.x, fresh.x);
            assert_eq!(s.y, fresh.y);
            assert_eq!(s.stats, fresh.stats);
        }
    }

    #[test]
    fn a_re_solve_from_a_converged_solution_takes_no_newton_step() {
        let opts = SolveOptions {
            factor_at_solution: false,
            ..SolveOptions::with_tol(1e-8)
        };
        let mut solver = Solver::new(&Bratu, opts);
        let guess = Guess::constant(linspace(0.0, 1.0, 7), &[0.1, 0.0]);
        let first = solver.solve(&[1.0], &guess).unwrap();
        let again = solver.solve(&[1.0], &Guess::from(&first)).unwrap();
        assert_eq!(again.stats.newton_iterations, 0);
        assert_eq!(again.stats.jacobian_factorizations, 0);
        assert_eq!(again.stats.rhs_dual_evaluations, 0);
        assert_eq!(again.y, first.y);
        assert!(again.stats.max_residual <= 1e-8);
        // a step criterion needs a step: the fixed-mesh options still take one
        let fixed = solver
            .solve_with(&[1.0], &Guess::from(&first), &SolveOptions::fixed_mesh())
            .unwrap();
        assert!(fixed.stats.newton_iterations >= 1);
    }

    #[test]
    fn factor_at_solution_off_computes_no_linearisation() {
        let opts = SolveOptions {
            factor_at_solution: false,
            ..SolveOptions::with_tol(1e-8)
        };
        let guess = Guess::constant(linspace(0.0, 1.0, 7), &[0.1, 0.0]);
        let lazy = solve(&Bratu, &[1.0], &guess, &opts).unwrap();
        let eager_opts = SolveOptions {
            factor_at_solution: true,
            ..SolveOptions::with_tol(1e-8)
        };
        let eager = solve(&Bratu, &[1.0], &guess, &eager_opts).unwrap();
        assert!(lazy.factorization().is_none());
        assert!(eager.factorization().is_some());
        assert_eq!(
            lazy.y, eager.y,
            "the linearisation does not change the solution"
        );
        assert_eq!(
            eager.stats.jacobian_factorizations,
            lazy.stats.jacobian_factorizations + 1
        );
        assert!(eager.stats.rhs_dual_evaluations > lazy.stats.rhs_dual_evaluations);
        assert_eq!(eager.stats.rhs_evaluations, lazy.stats.rhs_evaluations);
    }
}

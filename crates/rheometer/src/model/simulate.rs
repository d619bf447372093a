//! The user-facing simulation API: from SI inputs to SI profiles.
//!
//! ```no_run
//! use rheometer::model::{Air, Experiment, Inlet, Material, TakeUp};
//! use rheometer::model::{simulate, CarreauLike, FiberModel, Physics, SimulateOptions};
//! let exp = Experiment {
//!     name: "v0p53_p2".into(),
//!     mass_flow: 3.08e-5,
//!     inlet: Inlet::Diameter(1.134e-3),
//!     inlet_temperature: 513.15,
//!     air_temperature: 293.15,
//!     spinline_length: 0.51,
//!     take_up: Some(TakeUp::Diameter(9e-5)),
//! };
//! let model = FiberModel::new(&Material::pmma7n(), &Air::paper(), &exp, CarreauLike::new(), Physics::paper())?;
//! let sol = simulate(&model, &[0.8, 11.71], &SimulateOptions::default())?;
//! let prof = sol.profiles(&model, &[0.0, 0.25, 0.51]);
//! println!("d(L) = {} m, T(L) = {} K", prof.diameter[2], prof.temperature[2]);
//! # Ok::<(), rheometer::FiberError>(())
//! ```

use super::bvp::FiberModel;
use super::cold_start::{continuation_in_c, continuation_in_c_with_loose, PathOptions};
use super::contributions::{Balance, NusseltLaw, SiScales};
use super::material_law::ViscosityLaw;
use crate::error::FiberError;
use diffbvp::mesh::{linspace, MeshOptions};
use diffbvp::sensitivity::tangent_guess;
use diffbvp::solution::Solution;
use diffbvp::solve::{GrowthLimit, Guess, ResidualScale, SolveOptions, Solver};
use std::sync::Arc;

/// Options of [`simulate`].
#[derive(Debug, Clone)]
pub struct SimulateOptions {
    /// Tolerance on the scaled collocation residual (default 1e-6).
    pub tol: f64,
    /// Tolerance on the boundary residuals (default: `tol`).
    pub bc_tol: Option<f64>,
    /// Maximum number of mesh nodes (default 20 000).
    pub max_nodes: usize,
    /// Typical magnitudes of `(ũ, Ñ, T̃, ε̇̃)` for the residual scale (default `[1e2, 1e4, 1, 1e3]`).
    pub scale: [f64; 4],
    /// Nodes of the initial uniform mesh of a cold start (default 21).
    pub initial_nodes: usize,
    /// Continuation settings of a cold start.
    pub continuation: PathOptions,
    /// Compute the solution's linearisation (Jacobians in all parameters and the factorised
    /// Newton matrix) at the end of the solve, for sensitivities and adjoints (default `false`:
    /// the first derivative request computes it once instead; see
    /// [`SolveOptions::factor_at_solution`]).
    pub factor_at_solution: bool,
    /// Positions \[m\] added as nodes to the mesh of the final solve, e.g. output positions
    /// (default none; mesh coarsening may remove some again — the interpolant is used anyway).
    pub required_positions: Vec<f64>,
    /// Mesh adaptation of every solve (default [`MeshOptions::default`]).
    pub mesh: MeshOptions,
    /// The final solve of a cold start with [`smooth`](MeshOptions::smooth) error constants
    /// (default `true`). That solve refines the loose continuation mesh about tenfold; with the
    /// error constant held constant per old interval the prediction can miss `tol` on a few
    /// intervals and cost a second full pass, while the smooth constant reaches `tol` in one
    /// pass for a few more nodes.
    pub smooth_cold_final: bool,
    /// How far a solve may refine beyond the mesh it starts from (default `None`: up to
    /// `max_nodes`; see [`SolveOptions::growth_limit`]). The refinements of the diagnosis set it
    /// ([`ScanOptions::refine_growth_limit`](crate::diagnostics::refits::scan::ScanOptions::refine_growth_limit)):
    /// a trial point beyond the region where the fiber has a solution then fails in
    /// milliseconds instead of refining towards `max_nodes`.
    pub growth_limit: Option<GrowthLimit>,
    /// The model parameters (indices, strictly increasing) the linearisation at the solution
    /// is seeded in, with [`factor_at_solution`](Self::factor_at_solution) (default `None`: all;
    /// see [`SolveOptions::linearization_params`]). A fit's start solves set those it frees.
    pub linearization_params: Option<Arc<[usize]>>,
    /// Keep every solve's last Newton matrix for the next solve nearby (default `false`; see
    /// [`SolveOptions::keep_newton_matrix`]): a walk that needs only solutions and costs (the
    /// landscape) warm-starts simplified Newton from it.
    pub keep_newton_matrix: bool,
    /// Solve a warm start on the start's mesh with every interval halved, on that fixed mesh
    /// (no adaptation; Newton to `tol`) (default `false`):
    /// the discretisation check of a fit (`accuracy`),
    /// whose difference from the start is the start's discretisation error to first order
    /// ([`Guess::on_halved_mesh`]). Every solve of these options is then on a fixed mesh:
    /// without a start solution (a cold start) it is an error.
    pub halve_start_mesh: bool,
    /// Where a warm start fails, solve again by continuation from the stress-free fiber (a cold
    /// start; default `true`). `false`: the failed warm start is the error (a start that is not
    /// a solution of the fiber's 4 states is no warm start: it is cold-started either way). The scans' grid
    /// fits whose law is deep in the implausible range set it
    /// (`COLD_FALLBACK_MIN_N`): there
    /// the continuation towards a nearly rate-independent, strongly thinning fiber is slow and
    /// often fails at its end.
    pub cold_fallback: bool,
}

impl Default for SimulateOptions {
    fn default() -> Self {
        SimulateOptions {
            tol: 1e-6,
            bc_tol: None,
            max_nodes: 20_000,
            scale: [1e2, 1e4, 1.0, 1e3],
            initial_nodes: 21,
            continuation: PathOptions::default(),
            factor_at_solution: false,
            required_positions: Vec::new(),
            mesh: MeshOptions::default(),
            smooth_cold_final: true,
            growth_limit: None,
            linearization_params: None,
            keep_newton_matrix: false,
            halve_start_mesh: false,
            cold_fallback: true,
        }
    }
}

impl SimulateOptions {
    /// Default options with tolerance `tol`.
    pub fn with_tol(tol: f64) -> Self {
        SimulateOptions {
            tol,
            ..Default::default()
        }
    }

    /// The toolkit options of a cold start's final solve: [`solve_options`](Self::solve_options)
    /// with smooth error constants if [`smooth_cold_final`](Self::smooth_cold_final), and no
    /// [`growth_limit`](Self::growth_limit): that solve starts from the continuation path's
    /// end point at the same parameters, solved loosely, and its growth is the tolerance's
    /// (tenfold from a coarse path mesh is common), not a sign of a far start.
    pub fn cold_final_options(&self) -> SolveOptions {
        let mut o = self.solve_options();
        o.mesh.smooth |= self.smooth_cold_final;
        o.growth_limit = None;
        o
    }

    /// The toolkit options these settings translate to.
    pub fn solve_options(&self) -> SolveOptions {
        SolveOptions {
            tol: self.tol,
            bc_tol: self.bc_tol,
            max_nodes: self.max_nodes,
            scale: ResidualScale::PerComponent(self.scale.to_vec()),
            factor_at_solution: self.factor_at_solution,
            linearization_params: self.linearization_params.clone(),
            keep_newton_matrix: self.keep_newton_matrix,
            mesh: self.mesh.clone(),
            growth_limit: self.growth_limit,
            ..if self.halve_start_mesh {
                // Newton to `tol` (without `fixed_mesh`'s step test: it costs time and does not
                // change the estimated shift to the digits reported)
                SolveOptions {
                    newton_step_tol: None,
                    ..SolveOptions::fixed_mesh()
                }
            } else {
                SolveOptions::default()
            }
        }
    }
}

/// The error of a solve with [`SimulateOptions::halve_start_mesh`] but no start solution to
/// halve (a cold start).
fn no_mesh_to_halve() -> FiberError {
    FiberError::InvalidInput(
        "halve_start_mesh needs a start solution of the fiber (4 states, at least 2 nodes) to \
         halve; a cold start has none: solve without it first"
            .into(),
    )
}

/// A converged fiber solution (dimensionless states inside) with SI accessors.
#[derive(Debug, Clone)]
pub struct FiberSolution {
    /// The toolkit solution: `x = s̃`, `y = (ũ, Ñ, T̃, ε̇̃)`, `params = p`.
    pub solution: Solution,
}

/// Profiles in SI units at chosen positions.
#[derive(Debug, Clone, Default)]
pub struct Profiles {
    /// Positions `s` \[m\].
    pub position: Vec<f64>,
    /// Fiber speed `u` \[m/s\].
    pub velocity: Vec<f64>,
    /// Axial force `N` \[N\].
    pub force: Vec<f64>,
    /// Temperature `T` \[K\].
    pub temperature: Vec<f64>,
    /// Strain rate `ε̇ = u'` \[1/s\].
    pub strain_rate: Vec<f64>,
    /// Diameter `d` \[m\] the model predicts: with the mass flow its `mass_flow_scale` sets,
    /// where it has one.
    pub diameter: Vec<f64>,
    /// What the diameter gauge reads \[m\]: the diameter through the model's gauge effects
    /// (`gauge_scale`, `gauge_offset`), the quantity the fit's residuals and `compare` set
    /// against the measurements; `None` where the gauge reads the diameter itself.
    pub gauge_reading: Option<Vec<f64>>,
    /// Elongational viscosity `μ_e(T, ε̇)` \[Pa s\].
    pub viscosity: Vec<f64>,
    /// Every named term: name, balance, values in N/m (momentum) or W/m (energy).
    pub terms: Vec<(&'static str, Balance, Vec<f64>)>,
}

impl FiberSolution {
    /// Number of mesh nodes.
    pub fn nodes(&self) -> usize {
        self.solution.nodes()
    }

    /// Profiles at `positions` \[m\] through the solution's C¹ interpolant.
    pub fn profiles<L: ViscosityLaw, H: NusseltLaw>(
        &self,
        model: &FiberModel<L, H>,
        positions: &[f64],
    ) -> Profiles {
        let co = *model.coefficients();
        let SiScales {
            velocity: u_o,
            force: n_o,
            temperature: t_o,
            strain_rate: rate_o,
            diameter: d_o,
            length: l_o,
            ..
        } = co.si;
        let mu_o = model.scaling.reference.viscosity;
        let p = &self.solution.params;
        let mut out = Profiles::default();
        let mut y = [0.0; 4];
        let mut yp = [0.0; 4];
        let mut reading = Vec::with_capacity(positions.len());
        for &s in positions {
            let x = s / l_o;
            self.solution.eval_into(x, &mut y, &mut yp);
            out.position.push(s);
            out.velocity.push(y[0] * u_o);
            out.force.push(y[1] * n_o);
            out.temperature.push(y[2] * t_o);
            out.strain_rate.push(y[3] * rate_o);
            let d = model.fiber_diameter(&y, p);
            out.diameter.push(d * d_o);
            reading.push(model.observed_diameter(&y, p) * d_o);
            out.viscosity.push(model.viscosity_at(y[2], y[3], p) * mu_o);
            for (k, (name, balance, v)) in model.terms_at(x, &y, p).into_iter().enumerate() {
                let scale = match balance {
                    Balance::Momentum => co.force_per_length,
                    Balance::Energy => co.heat_per_length,
                };
                if out.terms.len() <= k {
                    out.terms
                        .push((name, balance, Vec::with_capacity(positions.len())));
                }
                out.terms[k].2.push(v * scale);
            }
        }
        if reading != out.diameter {
            out.gauge_reading = Some(reading);
        }
        out
    }

    /// Profiles at `m` uniform positions from 0 to `L`.
    pub fn uniform_profiles<L: ViscosityLaw, H: NusseltLaw>(
        &self,
        model: &FiberModel<L, H>,
        m: usize,
    ) -> Profiles {
        let positions = linspace(0.0, model.experiment.spinline_length, m.max(2));
        self.profiles(model, &positions)
    }
}

fn insert_required(x: &[f64], required: &[f64]) -> Vec<f64> {
    let mut v: Vec<f64> = x.iter().chain(required).copied().collect();
    v.sort_by(|a, b| a.total_cmp(b));
    let (a, b) = (x[0], x[x.len() - 1]);
    let span = b - a;
    let mut out: Vec<f64> = Vec::with_capacity(v.len());
    for xi in v {
        if xi < a || xi > b {
            continue;
        }
        if let Some(&last) = out.last() {
            if xi - last <= 1e-9 * span {
                continue;
            }
        }
        out.push(xi);
    }
    if let Some(l) = out.last_mut() {
        *l = b;
    }
    out
}

/// Cold start: solves the model with law parameters `law_params` (and default strengths) by
/// continuation from the stress-free fiber.
pub fn simulate<L: ViscosityLaw, H: NusseltLaw>(
    model: &FiberModel<L, H>,
    law_params: &[f64],
    options: &SimulateOptions,
) -> Result<FiberSolution, FiberError> {
    let p = model.parameters(1.0, law_params)?;
    Simulator::new(model, options.clone()).solve(&p, None)
}

/// Warm start from a previous solution (e.g. at nearby law parameters); falls back to a cold
/// start if the direct solve fails.
pub fn simulate_from<L: ViscosityLaw, H: NusseltLaw>(
    model: &FiberModel<L, H>,
    law_params: &[f64],
    start: &FiberSolution,
    options: &SimulateOptions,
) -> Result<FiberSolution, FiberError> {
    let p = model.parameters(1.0, law_params)?;
    Simulator::new(model, options.clone()).solve(&p, Some(&start.solution))
}

/// The general form: full parameter vector `p` (see [`FiberModel`] for the layout; `p[0]`, the
/// continuation parameter, is normally 1), optional warm start.
pub fn simulate_params<L: ViscosityLaw, H: NusseltLaw>(
    model: &FiberModel<L, H>,
    p: &[f64],
    start: Option<&Solution>,
    options: &SimulateOptions,
) -> Result<FiberSolution, FiberError> {
    Simulator::new(model, options.clone()).solve(p, start)
}

/// A reusable simulator for one model: keeps the toolkit [`Solver`] (workspace and symbolic
/// factorisations of recent mesh sizes) between solves, for parameter sweeps and fits.
pub struct Simulator<'a, L: ViscosityLaw, H: NusseltLaw> {
    model: &'a FiberModel<L, H>,
    solver: Solver<'a, FiberModel<L, H>>,
    options: SimulateOptions,
}

impl<'a, L: ViscosityLaw, H: NusseltLaw> Simulator<'a, L, H> {
    /// A simulator for `model` with `options`.
    pub fn new(model: &'a FiberModel<L, H>, options: SimulateOptions) -> Self {
        Simulator {
            model,
            solver: Solver::new(model, options.solve_options()),
            options,
        }
    }

    /// The model.
    pub fn model(&self) -> &'a FiberModel<L, H> {
        self.model
    }

    /// Cold start with law parameters `law_params` and default strengths.
    pub fn cold(&mut self, law_params: &[f64]) -> Result<FiberSolution, FiberError> {
        let p = self.model.parameters(1.0, law_params)?;
        self.solve(&p, None)
    }

    /// Cold start with full parameters `p` (see [`solve`](Self::solve)) that also returns the
    /// end point of the continuation path: the solution at `p` at the path's loose tolerance
    /// `max(tol, continuation.intermediate_tol)` (dimensionless collocation residual), which
    /// the final solve at `tol` started from. Returns `(final, loose)`. Options with
    /// [`required_positions`](SimulateOptions::required_positions) are refused (use
    /// [`solve`](Self::solve)).
    pub fn cold_with_loose(&mut self, p: &[f64]) -> Result<(FiberSolution, Solution), FiberError> {
        let model = self.model;
        model.check_parameters(p)?;
        if self.options.initial_nodes < 2 {
            return Err(FiberError::InvalidInput(
                "initial_nodes must be at least 2".into(),
            ));
        }
        if !self.options.required_positions.is_empty() {
            return Err(FiberError::InvalidInput(
                "cold_with_loose does not insert required positions; use solve".into(),
            ));
        }
        if self.options.halve_start_mesh {
            return Err(no_mesh_to_halve());
        }
        let guess = self.stress_free_guess(p);
        let (path_opts, final_opts) = (
            self.options.solve_options(),
            self.options.cold_final_options(),
        );
        let path = &self.options.continuation;
        let (loose, last) = continuation_in_c_with_loose(
            &mut self.solver,
            p,
            0,
            &guess,
            path,
            &path_opts,
            &final_opts,
        )?;
        Ok((FiberSolution { solution: last }, loose))
    }

    /// The stress-free fiber of `c = 0` with the process parameters of `p` on the initial
    /// uniform mesh: the start of a cold start.
    fn stress_free_guess(&self, p: &[f64]) -> Guess {
        let model = self.model;
        let x = linspace(0.0, model.length(), self.options.initial_nodes);
        let (u0, t0) = model.inlet_state(p);
        Guess::constant(x, &[u0, 0.0, t0, 0.0])
    }

    /// Warm start from `start` with law parameters `law_params` (cold start if that fails).
    pub fn warm(
        &mut self,
        law_params: &[f64],
        start: &FiberSolution,
    ) -> Result<FiberSolution, FiberError> {
        let p = self.model.parameters(1.0, law_params)?;
        self.solve(&p, Some(&start.solution))
    }

    /// Solves with full parameters `p` from `start` (warm) or by continuation in `c` (cold).
    pub fn solve(
        &mut self,
        p: &[f64],
        start: Option<&Solution>,
    ) -> Result<FiberSolution, FiberError> {
        let model = self.model;
        let options = &self.options;
        model.check_parameters(p)?;
        if options.initial_nodes < 2 {
            return Err(FiberError::InvalidInput(
                "initial_nodes must be at least 2".into(),
            ));
        }
        if options.required_positions.iter().any(|s| !s.is_finite()) {
            return Err(FiberError::InvalidInput(
                "required position is not finite".into(),
            ));
        }
        let l_si = model.experiment.spinline_length;
        let required: Vec<f64> = options
            .required_positions
            .iter()
            .map(|s| s / l_si * model.length())
            .collect();
        let solve_opts = options.solve_options();
        if options.halve_start_mesh {
            // the discretisation check's solve on the halved mesh, on that fixed mesh (no
            // fallback: a failure is the check's to report)
            return match start {
                Some(prev) if prev.n == 4 && prev.nodes() >= 2 => {
                    let guess = Guess::on_halved_mesh(prev);
                    let sol = self.solver.solve_with(p, &guess, &solve_opts)?;
                    Ok(FiberSolution { solution: sol })
                }
                _ => Err(no_mesh_to_halve()),
            };
        }
        if let Some(prev) = start {
            if prev.n == 4 && prev.nodes() >= 2 {
                // the tangent predictor when the start's linearisation is at hand (a fit computed
                // its sensitivities), and simplified Newton on the start's factorisation: two
                // iterations instead of four, and no Jacobian evaluation
                if required.is_empty() && prev.factorization().is_some() {
                    if let Ok(guess) = tangent_guess(model, prev, p) {
                        if let Ok(sol) = self.solver.solve_near(p, &guess, prev, &solve_opts) {
                            return Ok(FiberSolution { solution: sol });
                        }
                    }
                }
                let guess = if required.is_empty() {
                    Guess::from(prev)
                } else {
                    let x = insert_required(&prev.x, &required);
                    Guess::from_fn(x, 4, |x, y| prev.eval_into(x, y, &mut [0.0; 4]))
                };
                match self.solver.solve_with(p, &guess, &solve_opts) {
                    Ok(sol) => return Ok(FiberSolution { solution: sol }),
                    Err(e) if !options.cold_fallback => return Err(e.into()),
                    Err(_) => {}
                }
            }
        }
        let guess = self.stress_free_guess(p);
        let path = &options.continuation;
        let final_opts = options.cold_final_options();
        if required.is_empty() {
            let (_, sol) = continuation_in_c_with_loose(
                &mut self.solver,
                p,
                0,
                &guess,
                path,
                &solve_opts,
                &final_opts,
            )?;
            return Ok(FiberSolution { solution: sol });
        }
        // continuation without the required nodes, then a final solve on a mesh with them
        let mut loose = solve_opts.clone();
        loose.tol = solve_opts.tol.max(path.intermediate_tol);
        loose.bc_tol = None;
        let sol = continuation_in_c(&mut self.solver, p, 0, &guess, path, &loose)?;
        let x = insert_required(&sol.x, &required);
        let guess = Guess::from_fn(x, 4, |x, y| sol.eval_into(x, y, &mut [0.0; 4]));
        let sol = self.solver.solve_with(p, &guess, &final_opts)?;
        Ok(FiberSolution { solution: sol })
    }
}

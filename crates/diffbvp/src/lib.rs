//! # diffbvp — a differentiable boundary-value-problem toolkit
//!
//! Solves two-point boundary value problems
//!
//! ```text
//! y'(x) = f(x, y, p),  a <= x <= b,      g(y(a), y(b), p) = 0
//! ```
//!
//! with 3-stage Lobatto IIIa collocation (the bvp4c / scipy `solve_bvp` scheme: C1
//! piecewise-cubic solution, 4th order), damped Newton on faer's sparse LU, and
//! residual-controlled mesh adaptation with node removal. The problem is written once, generically
//! over dual numbers ([`Bvp`]); every Jacobian — with respect to the states, the unknown
//! parameters and the model parameters — is exact, from dual numbers, never from finite
//! differences. On top: homotopy [`continuation`], forward and adjoint [`sensitivity`] and bounded
//! [`least_squares`]. The crate knows nothing of any application: the melt-spinning rheometer
//! (crate `rheometer`) is one user of it, written against this public API.
//!
//! ```
//! use diffbvp::mesh::linspace;
//! use diffbvp::{solve, Bvp, DualNum, Guess, SolveOptions};
//!
//! /// Bratu's problem y'' + k e^y = 0, y(0) = y(1) = 0.
//! struct Bratu { k: f64 }
//! impl Bvp for Bratu {
//!     fn dim(&self) -> usize { 2 }
//!     fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
//!         f[0] = y[1];
//!         f[1] = -y[0].exp() * self.k;
//!     }
//!     fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
//!         r[0] = ya[0];
//!         r[1] = yb[0];
//!     }
//! }
//!
//! let options = SolveOptions::with_tol(1e-6);
//! let lower = solve(&Bratu { k: 1.0 }, &[], &Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]), &options)?;
//! let upper = solve(&Bratu { k: 1.0 }, &[], &Guess::constant(linspace(0.0, 1.0, 5), &[3.0, 0.0]), &options)?;
//! assert!((lower.eval(0.5)[0] - 0.1405392144).abs() < 1e-6);
//! assert!((upper.eval(0.5)[0] - 4.0914672462).abs() < 1e-5);
//! # Ok::<(), diffbvp::BvpError>(())
//! ```
//!
//! Modules read like the method: [`mesh`], collocation, Newton, [`solve`](mod@solve) (adaptive
//! loop), [`solution`] (interpolant), [`continuation`], [`sensitivity`], [`inspect`].
//!
//! ## Layers
//!
//! Each module imports only from its own layer's peers without cycles and from the layers below
//! it (checked by `python3 .ci/import-graph.py`, which reads this list). The toolkit, bottom to
//! top:
//!
//! 1. [`error`], [`problem`], [`mesh`], [`dense_dual`] (dual numbers with every slope stored),
//!    [`dyn_dual`], `singular` (the singular term `S y / x`);
//! 2. `dual_jacobian`, `collocation`, [`linear`] (sparse LU and block elimination),
//!    `error_control`, `newton`, `linearization`, [`solution`],
//!    `mesh_cycle` (the watch for a mesh that does not settle);
//! 3. [`solve`](mod@solve) (the adaptive loop);
//! 4. [`continuation`], [`sensitivity`], [`inspect`], `expr` (feature `expr`: problems as text);
//! 5. [`least_squares`] (the bounded driver; its [`BvpResiduals`](least_squares::BvpResiduals)
//!    adaptor solves BVPs and takes their sensitivities), `sparse` (feature `sprs`: the
//!    Jacobians as `sprs` matrices).
//!
//! ## Cargo features
//!
//! | feature | default | what it adds |
//! |---|---|---|
//! | `parallel` | no | [`least_squares::BvpResiduals`] solves its runs in parallel (rayon; faer's own rayon too) |
//! | `serde` | no | `Serialize`/`Deserialize` for the toolkit's records (options, statistics, termination) |
//! | `sprs` | no | `sparse`: the collocation, parameter, sensitivity and fit Jacobians as `sprs::CsMat<f64>` |
//! | `expr` | no | `expr::ExprBvp`: a problem given as text expressions (parsed, evaluated over dual numbers; no extra dependencies) |
//!
//! Without features the crate depends on num-dual, faer, nalgebra, num-traits and thiserror
//! only.
#![warn(missing_docs)]
// Numerical kernels index several arrays with the same loop variable, as the formulas do.
#![allow(clippy::needless_range_loop)]
mod collocation;
pub mod continuation;
pub mod dense_dual;
mod dual_jacobian;
pub mod dyn_dual;
pub mod error;
mod error_control;
#[cfg(feature = "expr")]
pub mod expr;
pub mod inspect;
pub mod least_squares;
pub mod linear;
mod linearization;
pub mod mesh;
mod mesh_cycle;
mod newton;
pub mod problem;
pub mod sensitivity;
mod singular;
pub mod solution;
pub mod solve;
#[cfg(feature = "sprs")]
pub mod sparse;
pub use error::BvpError;
pub use linear::{Factorization, LinearSolverKind};
pub use num_dual::DualNum;
pub use problem::Bvp;
pub use solution::{Solution, SolveStats};
pub use solve::{solve, GrowthLimit, Guess, ResidualScale, SolveOptions, Solver};

//! A bounded trust-region Gauss–Newton driver for nonlinear least squares,
//! `min ½‖r(p)‖²` subject to `lower ≤ p ≤ upper`, for parameter fits whose residuals come from
//! BVP solves.
//!
//! Each iteration solves the trust-region subproblem `min ‖J s + r‖²`, `‖D s‖ ≤ Δ`, exactly
//! (Levenberg–Marquardt parameter by the secular equation on the eigen-decomposition of `JᵀJ`;
//! the parameter count is small) with the Coleman–Li affine scaling `D = diag(|v|^{-1/2})`,
//! where `v_i` is the distance to the bound the negative gradient points at (unbounded
//! directions get `v_i = 1`). The step is then kept strictly inside the box (truncated at
//! 0.995 of the way to the nearest bound, then clipped to the box).
//! The trial point is accepted when the actual reduction is at least 1e-4 of the predicted one.
//! **A failed model evaluation at a trial point (a BVP that did not converge) is a rejected
//! step**: the radius shrinks and the iteration goes on. The radius is capped (`max_radius`, in
//! parameter units) so that warm starts of the BVPs from the last accepted point stay valid.
//!
//! The problem keeps its own state (warm starts): [`LeastSquaresProblem::evaluate`] is called at
//! trial points, [`LeastSquaresProblem::accept`] when a trial point is accepted.
//!
//! **Block-arrow problems.** A problem whose parameters are shared by all residuals plus
//! parameters local to one block of residuals each (one experiment's take-up factor, one run's
//! scale) declares it by returning a [`Jacobian::Blocks`] from
//! [`LeastSquaresProblem::evaluate_jacobian`] (see [`blocks`]; [`BvpResiduals::declare_blocks`]
//! for BVP runs). The driver then never forms an `N × P` or `P × P` matrix: the trust-region
//! step is the same Levenberg–Marquardt step, solved through the Schur complement of the
//! normal equations on the shared parameters (as bundle adjustment does, with the same
//! Coleman–Li scaling and bounds), and [`FitResult::standard_errors`] and
//! [`FitResult::block_covariance`] come from the same elimination: time and memory linear in
//! the number of blocks.
//!
//! For the common case — residuals of one or more BVPs at observation points, the model
//! parameters of each BVP an affine function of the fit parameters — [`BvpResiduals`] is a ready
//! [`LeastSquaresProblem`]: warm-started solvers, exact Jacobians from forward sensitivities, a
//! rejected trial point leaving the warm starts alone. [`fit_observed`] reports every iteration
//! to an [`Observer`] (progress bars, logs, early inspection); [`FitResult::history`] keeps the
//! same records.
//!
//! **Robust losses.** [`FitOptions::loss`] (default [`Loss::Linear`]) and
//! [`FitOptions::f_scale`] minimise scipy's `½ C² Σ ρ((rᵢ/C)²)` instead (soft-L1, Huber,
//! Cauchy; see [`loss`]); the iteration stays Gauss–Newton on rescaled residuals and Jacobian.
//! The covariance under a robust loss is the sandwich (see [`FitResult::covariance`]).
//!
//! **Accuracy matched to the data.** With [`FitOptions::accuracy`] = [`Accuracy::Scheduled`]
//! the driver asks the problem ([`LeastSquaresProblem::set_accuracy`]) for loose evaluations
//! while the iterate is far from the optimum: a model error (e.g. the discretisation error of
//! BVP solves) of RMS `e = η · max(σ̂, ‖J s‖/√N)` per residual is allowed (the start point is
//! evaluated at the loosest accuracy the problem offers), with `σ̂` the RMS
//! residual (the noise level at the optimum), `‖J s‖` the predicted effect of the trial step on
//! the residuals and `η` = [`AccuracySchedule::fraction`] (default 10⁻²). Once the loose
//! iteration has converged (any stopping test) or its step moves the estimate by less than
//! [`AccuracySchedule::switch_below`] standard errors (`‖J s‖/σ̂`), the current iterate is
//! re-evaluated at full accuracy and the iteration goes on there with the usual stopping tests
//! (and at least [`AccuracySchedule::final_iterations`] trial steps of budget): the
//! returned optimum, residuals and Jacobian (hence the covariance) are those of full-accuracy
//! evaluations. [`BvpResiduals::set_loose_tolerance`] turns an allowed residual error into a BVP
//! tolerance.

mod block_covariance;
pub mod blocks;
mod bvp;
mod contract;
mod driver;
mod jacobian;
mod linear_response;
pub mod loss;
mod schur;

pub use block_covariance::BlockCovariance;
pub use blocks::{BlockJacobian, BlockStructure};
pub use bvp::{BvpResiduals, BvpRun, ParamLink, ParamMap, RunError};
pub use driver::{fit, fit_observed};
pub use jacobian::Jacobian;
pub use linear_response::LinearResponse;
pub use loss::Loss;

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// A least-squares problem with exact Jacobians.
pub trait LeastSquaresProblem {
    /// Error of a failed evaluation (e.g. a BVP that did not converge).
    type Error: fmt::Display;
    /// Number of parameters.
    fn num_params(&self) -> usize;
    /// Residuals `r(p)` and Jacobian `∂r/∂p` (row-major, `len × num_params`).
    ///
    /// The contract [`fit`] checks on every result: the same number of residuals at every
    /// point, a Jacobian of exactly `len × num_params` entries (else the fit stops with
    /// [`FitError::InvalidInput`] naming the lengths), and finite values. A non-finite residual
    /// or Jacobian entry at a trial point is a failed evaluation (a rejected step, its index
    /// named in [`FitIteration::failure`]); at the start point it is a
    /// [`FitError::InvalidInput`] naming the index.
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), Self::Error>;
    /// Residuals and Jacobian in the form the driver works on: a problem with the block-arrow
    /// structure of [`blocks`] (shared parameters plus parameters local to one block of
    /// residuals) returns [`Jacobian::Blocks`], and the driver then computes its steps and the
    /// covariance through the Schur complement, linear in the number of blocks. The default
    /// returns [`evaluate`](Self::evaluate)'s dense Jacobian.
    fn evaluate_jacobian(&mut self, p: &[f64]) -> Result<(Vec<f64>, Jacobian), Self::Error> {
        let (r, j) = self.evaluate(p)?;
        Ok((r, Jacobian::Dense(j)))
    }
    /// Called when `p` (the last point passed to `evaluate`) becomes the new iterate.
    fn accept(&mut self, _p: &[f64]) {}
    /// Sets how accurate the following evaluations need to be: `Some(e)` allows a model error
    /// (e.g. the discretisation error of BVP solves) of RMS `e` per residual (residual units);
    /// `None` asks for the problem's full accuracy. Returns whether the problem evaluates
    /// loosely when allowed to; the default ignores the request and returns `false` (every
    /// evaluation at full accuracy, as [`Accuracy::Fixed`]).
    fn set_accuracy(&mut self, _rms_error: Option<f64>) -> bool {
        false
    }
}

/// How accurately a fit evaluates its model ([`FitOptions::accuracy`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Accuracy {
    /// Every evaluation at the problem's full accuracy (the default).
    #[default]
    Fixed,
    /// Loose evaluations while far from the optimum, full accuracy for the final iterations
    /// (see the [module documentation](self)).
    Scheduled(AccuracySchedule),
}

impl Accuracy {
    /// [`Accuracy::Scheduled`] with the default [`AccuracySchedule`].
    pub fn scheduled() -> Self {
        Accuracy::Scheduled(AccuracySchedule::default())
    }
}

/// Settings of [`Accuracy::Scheduled`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AccuracySchedule {
    /// `η`: allowed RMS model error per residual as a fraction of `max(σ̂, ‖J s‖/√N)`
    /// (default 10⁻²).
    pub fraction: f64,
    /// Switch to full accuracy once a trial step moves the estimate by less than this many
    /// standard errors, `‖J s‖/σ̂` (default 0.1).
    pub switch_below: f64,
    /// Trial steps allowed at full accuracy after the switch even when
    /// [`FitOptions::max_iterations`] would end the fit sooner (default 10); otherwise the
    /// full-accuracy phase runs to a stopping test or to `max_iterations`, as a fixed-accuracy
    /// fit would (a slowly converging fit is never cut short and reported as stopped by its
    /// iteration limit only because its first iterations were loose).
    pub final_iterations: usize,
    /// After the switch, a rejected trial step that moves the estimate by less than this many
    /// standard errors (`‖J s‖/σ̂`) ends the fit ([`Termination::Step`]): such a step is at the
    /// noise floor of the full-accuracy model itself, and the trust region would otherwise
    /// re-evaluate it until the radius falls below it (default 10⁻⁴).
    pub negligible_step: f64,
}

impl Default for AccuracySchedule {
    fn default() -> Self {
        AccuracySchedule {
            fraction: 1e-2,
            switch_below: 0.1,
            final_iterations: 10,
            negligible_step: 1e-4,
        }
    }
}

/// Options of [`fit`].
#[derive(Debug, Clone)]
pub struct FitOptions {
    /// Lower bounds (one per parameter; `-inf` for none).
    pub lower: Vec<f64>,
    /// Upper bounds (`+inf` for none).
    pub upper: Vec<f64>,
    /// Initial trust radius in scaled parameter units (default 0.5).
    pub initial_radius: f64,
    /// Cap on the trust radius (default 1.0); keeps warm starts valid.
    pub max_radius: f64,
    /// Stop when the scaled gradient's infinity norm is below this (default 1e-8).
    pub gtol: f64,
    /// Stop when `‖Δp‖ ≤ xtol (xtol + ‖p‖)` (default 1e-8).
    pub xtol: f64,
    /// Stop when the relative cost change of an accepted step is below this (default 1e-10).
    pub ftol: f64,
    /// Maximum iterations (accepted or rejected trial steps) (default 100).
    pub max_iterations: usize,
    /// The loss `ρ` (default [`Loss::Linear`]: ordinary least squares, results unchanged).
    pub loss: Loss,
    /// Soft margin `C` between inlier and outlier residuals, in residual units (default 1;
    /// unused by the linear loss).
    pub f_scale: f64,
    /// How accurately the model is evaluated (default [`Accuracy::Fixed`]).
    pub accuracy: Accuracy,
    /// Tolerance of the relative-offset convergence criterion of Bates and Watts (1981;
    /// default `None`: not used): the fit ends ([`Termination::RelativeOffset`]) when the
    /// Gauss–Newton step to the optimum of the linearised problem, measured in the residuals
    /// against their scatter,
    /// `(‖J s_GN‖/√P) / (‖r + J s_GN‖/√(N − P))`, is below it. The estimate is then within
    /// `tol·√P` standard errors of that optimum (`‖J s‖/σ̂` is a step's length in standard
    /// errors). Unlike `ftol` and `xtol` it is scale-free and statistical: a model evaluated
    /// with a small numerical error (a BVP solved to a tolerance) makes the cost noisy at a
    /// level `ftol` may lie below, and the trust region then spends its iterations on that
    /// noise. Bates and Watts use 10⁻³. Set, it also ends the fit when the remaining gain is
    /// within the cost's numerical noise ([`Termination::NoiseFloor`]).
    pub relative_offset: Option<f64>,
    /// Characteristic scale of each parameter, in its own unit (default empty: 1 for every
    /// parameter). The trust region is taken in the scaled variables `p_i / x_scale_i`
    /// (scipy's `x_scale`): the radii ([`initial_radius`](Self::initial_radius),
    /// [`max_radius`](Self::max_radius)) and the Coleman–Li distances to the bounds, which
    /// count as far at one scale unit, are in those units, and so is the `gtol` measure. A
    /// parameter whose useful range spans hundreds of its units (an air speed in m/s, a
    /// temperature offset in K) otherwise moves at most `max_radius` units per iteration: a fit
    /// that must travel 100 m/s spends 100 iterations on it. Empty, or one positive finite
    /// value per parameter.
    pub x_scale: Vec<f64>,
    /// A cancellation flag (default `None`): once set (by another thread, e.g. a signal
    /// handler or an interactive front end), the fit stops before its next model evaluation
    /// with [`FitError::Cancelled`].
    pub cancel: Option<Arc<AtomicBool>>,
}

impl FitOptions {
    /// Options with bounds and defaults for the rest.
    pub fn with_bounds(lower: Vec<f64>, upper: Vec<f64>) -> Self {
        FitOptions {
            lower,
            upper,
            initial_radius: 0.5,
            max_radius: 1.0,
            gtol: 1e-8,
            xtol: 1e-8,
            ftol: 1e-10,
            max_iterations: 100,
            loss: Loss::Linear,
            f_scale: 1.0,
            accuracy: Accuracy::Fixed,
            relative_offset: None,
            x_scale: Vec::new(),
            cancel: None,
        }
    }

    /// Parameter `i`'s [`x_scale`](Self::x_scale) (1 where none is given).
    pub(super) fn scale(&self, i: usize) -> f64 {
        self.x_scale.get(i).copied().unwrap_or(1.0)
    }

    /// Whether [`cancel`](Self::cancel) is set.
    pub fn cancelled(&self) -> bool {
        self.cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    }
}

/// Why the fit stopped.
#[derive(Debug, Clone, PartialEq)]
pub enum Termination {
    /// Scaled gradient below `gtol`.
    Gradient,
    /// Step below `xtol`.
    Step,
    /// Relative cost change below `ftol`.
    CostChange,
    /// The iteration budget was spent.
    MaxIterations,
    /// The trust radius collapsed (repeated failures or no decrease possible).
    RadiusCollapsed,
    /// The relative offset fell below [`FitOptions::relative_offset`].
    RelativeOffset,
    /// With [`FitOptions::relative_offset`] set: the gain the Gauss–Newton step predicts is
    /// within twice the cost's numerical noise, measured as the largest jump of the cost at a
    /// rejected trial step shorter than 1 % of every parameter's scale (a rise of more than 10
    /// times the predicted gain, which a smooth model does not make at so short a step). A model
    /// evaluated by BVP solves whose adapted mesh changes between nearby points has such jumps;
    /// the trust region would otherwise shrink towards the jump for the rest of its budget.
    /// Only where the relative offset is within 10 times its tolerance: the estimate is then
    /// within `10 · relative_offset · √P` standard errors of the optimum of the linearisation.
    NoiseFloor,
    /// With [`FitOptions::relative_offset`] set: at the pace of the last 10 trial steps (all
    /// at full accuracy), the trial steps left in the iteration budget would lower `‖r‖²` by at
    /// most 0.01 times the residual variance `σ̂² = ‖r‖²/(N − P)` (at most `f_scale²` under a
    /// robust loss). Ending there gives the result the rest of the budget would give, to within
    /// that, if the pace holds. A fit crawling along a curved valley, where the Gauss–Newton
    /// model holds only over steps far shorter than the distance to the optimum it predicts,
    /// or a trust region whose every step towards the optimum is rejected, ends here instead of
    /// at [`MaxIterations`](Self::MaxIterations). Like that, not a convergence test:
    /// [`FitResult::gauss_newton_gain`] says how much lower the linearisation at the end still
    /// places the optimum.
    Stalled,
}

impl Termination {
    /// Every reason, in declaration order.
    pub const ALL: [Termination; 8] = [
        Termination::Gradient,
        Termination::Step,
        Termination::CostChange,
        Termination::MaxIterations,
        Termination::RadiusCollapsed,
        Termination::RelativeOffset,
        Termination::NoiseFloor,
        Termination::Stalled,
    ];
}

/// The reason whose text ([`Display`](fmt::Display)) is `s`; an error listing the known texts
/// otherwise.
impl std::str::FromStr for Termination {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Termination::ALL
            .into_iter()
            .find(|t| t.to_string() == s)
            .ok_or_else(|| {
                let known: Vec<String> = Termination::ALL
                    .iter()
                    .map(|t| format!("\"{t}\""))
                    .collect();
                format!(
                    "unknown termination {s:?}: expected one of {}",
                    known.join(", ")
                )
            })
    }
}

/// Written as its text ([`Display`](fmt::Display)), so that a record reads as it prints.
#[cfg(feature = "serde")]
impl serde::Serialize for Termination {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

/// Read from its text (see [`FromStr`](std::str::FromStr)).
#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for Termination {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

impl fmt::Display for Termination {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = match self {
            Termination::Gradient => "gradient below gtol",
            Termination::Step => "step below xtol",
            Termination::CostChange => "cost change below ftol",
            Termination::MaxIterations => "maximum number of iterations reached",
            Termination::RadiusCollapsed => "trust radius collapsed",
            Termination::RelativeOffset => "relative offset below its tolerance (Bates-Watts)",
            Termination::NoiseFloor => "predicted gain within the cost's numerical noise",
            Termination::Stalled => {
                "stalled: at the pace of the last 10 steps, the rest of the budget would lower the cost by \
                 less than 0.01 of the residual variance"
            }
        };
        f.write_str(s)
    }
}

/// One iteration of the fit (one trial step): what [`Observer::observe`] receives and
/// [`FitResult::history`] keeps.
///
/// With `p_k` the iterate before the step, `s` the step and `m(s) = ½‖J s + r‖²` the
/// Gauss–Newton model, the gain ratio is `ρ = (½‖r(p_k)‖² − ½‖r(p_k + s)‖²) / (½‖r‖² − m(s))`;
/// the step is accepted when `ρ > 10⁻⁴`.
#[derive(Debug, Clone)]
pub struct FitIteration {
    /// Number of the iteration, from 1.
    pub iteration: usize,
    /// Trial point `p_k + s`.
    pub p: Vec<f64>,
    /// Cost `½‖r‖²` at the trial point (`None` if its evaluation failed).
    pub cost: Option<f64>,
    /// Cost `½‖r(p_k)‖²` of the iterate the step was taken from.
    pub previous_cost: f64,
    /// Gain ratio `ρ` (`None` if the evaluation failed).
    pub gain_ratio: Option<f64>,
    /// Euclidean norm `‖s‖` of the step (parameter units).
    pub step_norm: f64,
    /// Coleman–Li scaled gradient `max_i |v_i (Jᵀr)_i|` at `p_k` (the `gtol` measure).
    pub scaled_gradient: f64,
    /// Whether the trial point was accepted.
    pub accepted: bool,
    /// Trust radius after the iteration.
    pub radius: f64,
    /// The evaluation error, if any.
    pub failure: Option<String>,
    /// The RMS model error per residual allowed for the trial point's evaluation (`None`: full
    /// accuracy; see [`Accuracy::Scheduled`]).
    pub allowed_error: Option<f64>,
    /// Wall time since the start of the fit \[s\].
    pub elapsed_s: f64,
}

/// Watches a fit: [`fit_observed`] calls [`observe`](Self::observe) once per iteration (accepted,
/// rejected or failed trial step), after the iteration's bookkeeping and before the stopping
/// tests, in the style of argmin's observers. Any `FnMut(&FitIteration)` is an observer.
pub trait Observer {
    /// Called with the record of the iteration just done.
    fn observe(&mut self, iteration: &FitIteration);
}

impl<F: FnMut(&FitIteration)> Observer for F {
    fn observe(&mut self, iteration: &FitIteration) {
        self(iteration)
    }
}

/// Result of a least-squares fit.
#[derive(Debug, Clone)]
pub struct FitResult {
    /// Parameters found.
    pub p: Vec<f64>,
    /// Cost at `p`: `½‖r‖²`, or `½ C² Σ ρ((rᵢ/C)²)` under a robust loss.
    pub cost: f64,
    /// Residuals at `p`.
    pub residuals: Vec<f64>,
    /// Jacobian at `p` (row-major `N × P`; **empty** when the problem evaluated a block-arrow
    /// Jacobian: see [`block_jacobian`](Self::block_jacobian) and
    /// [`dense_jacobian`](Self::dense_jacobian)).
    pub jacobian: Vec<f64>,
    /// The block-arrow Jacobian at `p` when the problem evaluated one
    /// ([`Jacobian::Blocks`]; `None` for a dense fit).
    pub block_jacobian: Option<BlockJacobian>,
    /// Trial steps done (accepted + rejected).
    pub iterations: usize,
    /// Accepted steps.
    pub accepted_steps: usize,
    /// Model evaluations that failed (treated as rejected steps).
    pub failed_evaluations: usize,
    /// Why it stopped.
    pub termination: Termination,
    /// Wall time \[s\].
    pub wall_time_s: f64,
    /// Every iteration, in order (the records [`fit_observed`]'s observer saw).
    pub history: Vec<FitIteration>,
    /// The loss minimised.
    pub loss: Loss,
    /// Its soft margin `C` (residual units).
    pub f_scale: f64,
    /// Trial steps evaluated at loose accuracy ([`Accuracy::Scheduled`]; 0 for
    /// [`Accuracy::Fixed`] or a problem without loose evaluations).
    pub loose_iterations: usize,
    /// RMS difference per residual between the loose and the full-accuracy residuals at the
    /// iterate where [`Accuracy::Scheduled`] switched to full accuracy (the model error the loose
    /// phase actually had there; `None` without a switch).
    pub switch_model_error: Option<f64>,
}

/// Errors of [`fit`] itself (the model failing at the start point, bad bounds).
#[derive(Debug, Clone, thiserror::Error)]
pub enum FitError {
    /// Inconsistent input.
    #[error("invalid fit input: {0}")]
    InvalidInput(String),
    /// The model could not be evaluated at the start point.
    #[error("the model could not be evaluated at the start point {p:?}: {cause}")]
    StartFailed {
        /// Start point.
        p: Vec<f64>,
        /// Cause.
        cause: String,
    },
    /// [`Accuracy::Scheduled`]: the model could not be evaluated at full accuracy at the
    /// iterate of the loose phase.
    #[error("the model could not be evaluated at full accuracy at {p:?}: {cause}")]
    RefineFailed {
        /// The iterate.
        p: Vec<f64>,
        /// Cause.
        cause: String,
    },
    /// [`FitOptions::cancel`] was set: the fit stopped before its next model evaluation.
    #[error("the fit was cancelled (interrupted) after {iterations} iterations")]
    Cancelled {
        /// Trial steps done before the cancellation.
        iterations: usize,
    },
}

impl FitResult {
    /// Number of residuals.
    pub fn num_residuals(&self) -> usize {
        self.residuals.len()
    }

    /// Residual variance `‖r‖²/(N − p)` (the Gauss–Newton estimate of σ² for unit weights;
    /// of the raw residuals under a robust loss).
    pub fn residual_variance(&self) -> f64 {
        let cost = if self.loss.is_linear() {
            self.cost
        } else {
            cost_of(&self.residuals)
        };
        variance_of(cost, self.residuals.len(), self.p.len())
    }

    /// Number of residuals a robust loss down-weights (`|rᵢ| > f_scale`; 0 for the linear
    /// loss).
    pub fn down_weighted(&self) -> usize {
        loss::down_weighted(self.loss, self.f_scale, &self.residuals)
    }

    /// Covariance of the parameters (row-major), `None` if it cannot be inverted.
    ///
    /// Linear loss: `σ² (JᵀJ)⁻¹` with `σ²` = [`residual_variance`](Self::residual_variance).
    /// Robust loss: the sandwich (Huber–White) covariance of the M-estimator,
    /// `N/(N − p) · H⁻¹ B H⁻¹` with `H = J̃ᵀJ̃ = Σ wᵢ JᵢᵀJᵢ` the Gauss–Newton Hessian of the
    /// robust cost (the rescaled Jacobian of [`loss`]) and `B = Σ (ρ'ᵢ rᵢ)² JᵢᵀJᵢ` the spread of
    /// the per-residual gradients; it needs no noise level and stays valid when the residuals
    /// are not Gaussian.
    ///
    /// A block-arrow fit ([`block_jacobian`](Self::block_jacobian)) computes it through the
    /// Schur complement ([`block_covariance`](Self::block_covariance)) and returns the dense
    /// `P × P` matrix assembled from it; [`standard_errors`](Self::standard_errors) and
    /// [`block_covariance`](Self::block_covariance) never form it.
    pub fn covariance(&self) -> Option<Vec<f64>> {
        let np = self.p.len();
        if self.block_jacobian.is_some() {
            return Some(self.block_covariance()?.to_dense());
        }
        if !self.loss.is_linear() {
            return self.sandwich_covariance();
        }
        let j = DMatrix::from_row_slice(self.residuals.len(), np, &self.jacobian);
        let jtj = j.transpose() * &j;
        let inv = jtj.try_inverse()?;
        let s2 = self.residual_variance();
        Some((0..np * np).map(|i| inv[(i / np, i % np)] * s2).collect())
    }

    fn sandwich_covariance(&self) -> Option<Vec<f64>> {
        let np = self.p.len();
        let nr = self.residuals.len();
        let w = loss::weights(self.loss, self.f_scale, &self.residuals);
        let mut h: DMatrix<f64> = DMatrix::zeros(np, np);
        let mut b: DMatrix<f64> = DMatrix::zeros(np, np);
        for (i, ((d1, wi), ri)) in w.iter().zip(&self.residuals).enumerate() {
            let row = &self.jacobian[i * np..(i + 1) * np];
            let psi2 = (d1 * ri).powi(2);
            for a in 0..np {
                for c in 0..np {
                    let jj = row[a] * row[c];
                    h[(a, c)] += wi * jj;
                    b[(a, c)] += psi2 * jj;
                }
            }
        }
        let hi = h.try_inverse()?;
        let dof = nr.saturating_sub(np).max(1) as f64;
        let cov: DMatrix<f64> = &hi * b * &hi * (nr as f64 / dof);
        Some((0..np * np).map(|i| cov[(i / np, i % np)]).collect())
    }

    /// The covariance of a block-arrow fit in compact form (shared block, per-block local
    /// blocks and what couples them; linear in the number of blocks): `σ² (JᵀJ)⁻¹` or the
    /// sandwich as for [`covariance`](Self::covariance). `None` for a dense fit or a singular
    /// `JᵀJ`.
    pub fn block_covariance(&self) -> Option<BlockCovariance> {
        let bj = self.block_jacobian.as_ref()?;
        if self.loss.is_linear() {
            return BlockCovariance::linear(bj, self.residual_variance());
        }
        let nr = self.residuals.len();
        let w = loss::weights(self.loss, self.f_scale, &self.residuals);
        let weights: Vec<f64> = w.iter().map(|(_, wi)| *wi).collect();
        let psi: Vec<f64> = w
            .iter()
            .zip(&self.residuals)
            .map(|((d1, _), ri)| d1 * ri)
            .collect();
        let dof = nr.saturating_sub(self.p.len()).max(1) as f64;
        BlockCovariance::sandwich(bj, &weights, &psi, nr as f64 / dof)
    }

    /// The Gauss–Newton step `s = −(JᵀJ)⁺Jᵀr` from `p` with the bounds lifted (the minimum of
    /// the linearised `½‖J s + r‖²`; directions `JᵀJ` does not determine get no step): how far,
    /// to first order, the unconstrained optimum lies from an estimate the bounds stopped. The
    /// same step the driver's relative-offset test measures; a block-arrow fit solves it through
    /// the Schur complement. `None` under a robust loss (its steps are taken on rescaled
    /// residuals) or where a component is not finite.
    pub fn gauss_newton_step(&self) -> Option<Vec<f64>> {
        self.gauss_newton().map(|(s, _)| s)
    }

    /// The decrease of the cost `½‖r‖²` the linearisation predicts for the
    /// [`gauss_newton_step`](Self::gauss_newton_step), `½‖J s‖²` (bounds lifted: part of it may
    /// lie beyond them). Twice it over the [`residual_variance`](Self::residual_variance) is
    /// the `χ²` a fit that stopped short of its optimum leaves, to first order. `None` where
    /// the step is.
    pub fn gauss_newton_gain(&self) -> Option<f64> {
        self.gauss_newton().map(|(_, g)| g)
    }

    /// [`gauss_newton_step`](Self::gauss_newton_step) and its predicted gain.
    fn gauss_newton(&self) -> Option<(Vec<f64>, f64)> {
        if !self.loss.is_linear() {
            return None;
        }
        let (nr, np) = (self.residuals.len(), self.p.len());
        let lin = match &self.block_jacobian {
            Some(j) => jacobian::Linearized::Blocks {
                j,
                r: &self.residuals,
            },
            None => jacobian::Linearized::Dense {
                jm: DMatrix::from_row_slice(nr, np, &self.jacobian),
                rv: DVector::from_column_slice(&self.residuals),
            },
        };
        let s = lin.step(&vec![1.0; np], f64::INFINITY);
        let gain = lin.predicted_reduction(&s);
        (s.iter().all(|v| v.is_finite()) && gain.is_finite())
            .then(|| (s.iter().copied().collect(), gain))
    }

    /// The Jacobian at `p`, dense row-major `N × P` (a copy of [`jacobian`](Self::jacobian),
    /// or the block-arrow Jacobian expanded: `N · P` numbers).
    pub fn dense_jacobian(&self) -> Vec<f64> {
        match &self.block_jacobian {
            Some(b) => b.to_dense(),
            None => self.jacobian.clone(),
        }
    }

    /// Standard errors of the parameters (a block-arrow fit: from the compact covariance,
    /// without the `P × P` matrix).
    pub fn standard_errors(&self) -> Option<Vec<f64>> {
        let np = self.p.len();
        if self.block_jacobian.is_some() {
            let v = self.block_covariance()?.variances();
            return Some(v.into_iter().map(|x| x.max(0.0).sqrt()).collect());
        }
        let c = self.covariance()?;
        Some((0..np).map(|i| c[i * np + i].max(0.0).sqrt()).collect())
    }

    /// Correlation matrix (row-major).
    pub fn correlation(&self) -> Option<Vec<f64>> {
        let np = self.p.len();
        let c = self.covariance()?;
        Some(
            (0..np * np)
                .map(|i| {
                    let (a, b) = (i / np, i % np);
                    c[i] / (c[a * np + a] * c[b * np + b]).sqrt()
                })
                .collect(),
        )
    }
}

fn cost_of(r: &[f64]) -> f64 {
    0.5 * r.iter().map(|v| v * v).sum::<f64>()
}

/// The residual variance `2 cost/(N − P)` of `nr` residuals with least-squares cost
/// `cost = ½‖r‖²` and `np` parameters (at least one degree of freedom).
fn variance_of(cost: f64, nr: usize, np: usize) -> f64 {
    2.0 * cost / nr.saturating_sub(np).max(1) as f64
}

/// Solves `min ‖J s + r‖²` s.t. `‖D s‖ ≤ Δ` and returns the step `s`.
fn trust_region_step(j: &DMatrix<f64>, r: &DVector<f64>, d: &[f64], radius: f64) -> DVector<f64> {
    let np = j.ncols();
    // scaled variables u = D s: J s = (J D⁻¹) u
    let mut js = j.clone();
    for c in 0..np {
        let inv = 1.0 / d[c];
        for rr in 0..js.nrows() {
            js[(rr, c)] *= inv;
        }
    }
    let a = js.transpose() * &js;
    let g = js.transpose() * r;
    let eig = SymmetricEigen::new(a);
    let q = &eig.eigenvectors;
    let lam = &eig.eigenvalues;
    let gq = q.transpose() * &g;
    let lmax = lam.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let floor = 1e-14 * lmax.max(1e-300);
    let step_for = |mu: f64| -> DVector<f64> {
        let mut z = DVector::zeros(np);
        for i in 0..np {
            let den = lam[i].max(0.0) + mu;
            z[i] = if den > floor { -gq[i] / den } else { 0.0 };
        }
        q * z
    };
    let mut u = step_for(0.0);
    if u.norm() > radius {
        // ‖u(μ)‖ decreases in μ; at μ = ‖g‖/Δ + λ_max it is ≤ Δ. Geometric bisection.
        let mut hi = g.norm() / radius + lmax;
        let mut lo = hi * 1e-16;
        for _ in 0..200 {
            let mid = (lo * hi).sqrt();
            if step_for(mid).norm() > radius {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi <= lo * (1.0 + 1e-10) {
                break;
            }
        }
        u = step_for(hi);
    }
    DVector::from_iterator(np, (0..np).map(|i| u[i] / d[i]))
}

#[cfg(test)]
mod termination_tests {
    use super::Termination;

    #[test]
    fn every_termination_reads_back_from_its_text() {
        let texts: Vec<String> = Termination::ALL.iter().map(|t| t.to_string()).collect();
        for (t, s) in Termination::ALL.iter().zip(&texts) {
            assert_eq!(&s.parse::<Termination>().unwrap(), t);
            assert_eq!(texts.iter().filter(|x| *x == s).count(), 1, "{s} twice");
        }
        let e = "converged".parse::<Termination>().unwrap_err();
        assert!(
            e.contains("unknown termination \"converged\"") && e.contains("gradient below gtol")
        );
    }
}

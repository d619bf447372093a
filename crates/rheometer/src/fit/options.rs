//! Types the rheometer's modules share: the model type, the error, the options of an
//! identification, the warnings of a fit and the side of a bound an estimate sits at. Only the
//! [`estimator`](super::estimator) is below it; the layers inside the rheometer are listed in
//! the Layers section of the crate's documentation.

use super::estimator::Estimator;
use crate::data::smoothing::SmoothingError;
use crate::error::FiberError;
use crate::model::bvp::FiberModel;
use crate::model::material_law::CarreauLike;
use crate::model::simulate::SimulateOptions;
use diffbvp::least_squares::{FitError, FitIteration, Loss};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::sync::Arc;
use thiserror::Error;

/// The fiber model the rheometer identifies: Carreau-type law (a Newtonian model is `n = 1`),
/// the paper's physics plus the effects of its [`ModelSpec`](crate::model::effects::ModelSpec).
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
    /// The model could not be evaluated where the fit started or where its loose phase ended
    /// (`FitError::StartFailed`, `FitError::RefineFailed`), with that point named.
    #[error("fit: the model could not be evaluated {phase} at {at}: {cause}")]
    NotEvaluable {
        /// `"at the start point"` or `"at full accuracy"` (the loose phase's end).
        phase: &'static str,
        /// The point, named: `n = 0.09, kappa = 16.2, take-up factors 0.97 to 1.02`.
        at: String,
        /// The parameter vector of that point (the fit's order: shared, then take-up factors).
        p: Vec<f64>,
        /// Why the evaluation failed (names the experiment).
        cause: String,
    },
}

/// `v` to four significant digits, written shortest (`16.2`, `0.09123`, `1e-300`).
fn sig4(v: f64) -> String {
    match format!("{v:.3e}").parse::<f64>() {
        Ok(r) if r != 0.0 && (r.abs() >= 1e5 || r.abs() < 1e-3) => format!("{r:e}"),
        Ok(r) => r.to_string(),
        Err(_) => v.to_string(),
    }
}

/// A fit error at a point the model could not be evaluated at, with the point named by the
/// layout's parameter `names` (the rest are take-up factors); other errors unchanged.
pub(crate) fn with_named_point(e: FitError, names: &[String]) -> RheometerError {
    let (phase, p, cause) = match e {
        FitError::StartFailed { p, cause } => ("at the start point", p, cause),
        FitError::RefineFailed { p, cause } => ("at full accuracy", p, cause),
        other => return RheometerError::Fit(other),
    };
    let ns = names.len().min(p.len());
    let mut parts: Vec<String> = names
        .iter()
        .zip(&p)
        .map(|(name, v)| format!("{name} = {}", sig4(*v)))
        .collect();
    let take_up = &p[ns..];
    let lo = take_up.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = take_up.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    match take_up.len() {
        0 => {}
        1 => parts.push(format!("take-up factor {}", sig4(lo))),
        _ => parts.push(format!("take-up factors {} to {}", sig4(lo), sig4(hi))),
    }
    RheometerError::NotEvaluable {
        phase,
        at: parts.join(", "),
        p,
        cause,
    }
}

/// Options of the identification.
#[derive(Debug, Clone)]
pub struct IdentifyOptions {
    /// The cost to minimise.
    pub estimator: Estimator,
    /// Regular optimisation points per experiment for the paper's cost (`n_o`, default 20).
    pub n_opt_points: usize,
    /// BVP settings (tolerance 1e-4 by default: matched to the noise and checked, see
    /// [`max_discretisation_shift`](Self::max_discretisation_shift)).
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
    /// The loss of the least-squares fit (default [`Loss::Linear`]; a robust loss needs the
    /// principled estimator).
    pub loss: Loss,
    /// Soft margin `C` of a robust loss, in relative-residual units \[-\] (e.g. 0.02 = 2 %);
    /// `None`: the robust noise scale of the data ([`Rheometer::data_noise_scale`](super::Rheometer::data_noise_scale)).
    pub f_scale: Option<f64>,
    /// Loosest BVP tolerance \[-\] of the inner Gauss–Newton iterations (default `Some(1e-3)`):
    /// far from the optimum the BVPs are solved only as accurately as the noise and the step
    /// need ([`Accuracy::Scheduled`](diffbvp::least_squares::Accuracy::Scheduled), at most 1 % of
    /// the noise or of the step's effect on the residuals), the final iterations, the estimate
    /// and its covariance at `simulate.tol`. `None`: every solve at `simulate.tol`.
    pub loose_tolerance: Option<f64>,
    /// The largest shift of an estimate \[standard errors\] the BVPs' discretisation may cause
    /// (default `Some(0.01)`): the fit is checked at the optimum with every BVP re-solved on its
    /// mesh with every interval halved (Richardson) and refined at tighter tolerances until it
    /// holds (see
    /// `accuracy`). `None`: no check, `simulate.tol` as given.
    pub max_discretisation_shift: Option<f64>,
    /// How close \[standard errors\] to the optimum of the discretised model the fit must
    /// come (default `Some(0.01)`, the same budget as the discretisation's shift): it stops
    /// when the Gauss–Newton step to the optimum of its linearisation moves the estimate by
    /// less (the relative offset of Bates and Watts below `optimum_tolerance / √P`, with `P`
    /// fitted parameters), or when the gain that step predicts is within the cost's numerical
    /// noise ([`Termination::NoiseFloor`](diffbvp::least_squares::Termination::NoiseFloor)).
    /// `None`: only the tight tests on the cost change, the step and the gradient (1e-8–1e-10),
    /// which a cost evaluated by BVP solves can keep from ending for tens of iterations.
    /// Outside `(0, 1)`: an error.
    pub optimum_tolerance: Option<f64>,
    /// Relative noise factor of each measurement, per experiment (`σ_j / σ`, ≈ 1 on average;
    /// principled estimator): a noise that varies along the line (the take-up region noisier)
    /// weights the points by it. `None`: all points alike.
    pub noise_factors: Option<std::sync::Arc<Vec<Vec<f64>>>>,
    /// A cancellation flag (default `None`), handed to the least-squares driver
    /// ([`FitOptions::cancel`](diffbvp::least_squares::FitOptions::cancel)): once set, a running
    /// identification stops before its next model evaluation with
    /// [`diffbvp::least_squares::FitError::Cancelled`] (the Python bindings
    /// set it on Ctrl-C).
    pub cancel: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// Shared parameters held at a value instead of fitted, by name (`"n"`, `"kappa"`, an
    /// effect's name, `"effect.shape"`) with the value in model-parameter units (the profile
    /// likelihood's refits; default none).
    pub hold: Vec<(String, f64)>,
    /// Called as the identification goes on ([`FitProgress`]: the experiments simulated at the
    /// start point, then every trial step of the fit), e.g. to draw a progress bar for a large
    /// fit ([`Rheometer::plan`](super::Rheometer::plan) says beforehand how long it will take).
    /// `None` (default): nothing reported.
    pub progress: Option<ProgressHook>,
}

/// What a running identification reports to [`IdentifyOptions::progress`].
#[derive(Debug, Clone, Copy)]
pub enum FitProgress<'a> {
    /// `done` of `total` experiments simulated at the start point (cold starts, in parallel:
    /// reported from the worker threads, in completion order).
    Simulated {
        /// Experiments done so far.
        done: usize,
        /// All experiments.
        total: usize,
    },
    /// One trial step of the least-squares fit done (accepted, rejected or failed).
    Iteration(&'a FitIteration),
}

/// A callback for [`IdentifyOptions::progress`]; called from worker threads, so `Send + Sync`.
#[derive(Clone)]
pub struct ProgressHook(pub Arc<dyn Fn(&FitProgress<'_>) + Send + Sync>);

impl ProgressHook {
    /// A hook calling `f`.
    pub fn new(f: impl Fn(&FitProgress<'_>) + Send + Sync + 'static) -> Self {
        ProgressHook(Arc::new(f))
    }

    /// Reports `event`.
    pub fn report(&self, event: &FitProgress<'_>) {
        (self.0)(event)
    }
}

impl fmt::Debug for ProgressHook {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("ProgressHook(..)")
    }
}

impl Default for IdentifyOptions {
    fn default() -> Self {
        let simulate = SimulateOptions {
            factor_at_solution: true,
            tol: 1e-4,
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
            loss: Loss::Linear,
            f_scale: None,
            loose_tolerance: Some(1e-3),
            max_discretisation_shift: Some(0.01),
            optimum_tolerance: Some(0.01),
            noise_factors: None,
            cancel: None,
            hold: Vec::new(),
            progress: None,
        }
    }
}

impl IdentifyOptions {
    /// Each of experiment `k`'s `n` measurements' relative uncertainty: `sigma` times its
    /// noise factor ([`noise_factors`](Self::noise_factors); 1 where not given or not
    /// matching).
    pub fn point_sigmas(&self, k: usize, n: usize, sigma: f64) -> Vec<f64> {
        match self.noise_factors.as_ref().and_then(|f| f.get(k)) {
            Some(f) if f.len() == n => f.iter().map(|w| sigma * w).collect(),
            _ => vec![sigma; n],
        }
    }

    /// The relative offset of Bates and Watts ([`FitOptions::relative_offset`](diffbvp::least_squares::FitOptions::relative_offset))
    /// of a fit of `num_params` parameters that stops within
    /// [`optimum_tolerance`](Self::optimum_tolerance) standard errors of the optimum:
    /// `optimum_tolerance / √P`. An error naming the option where it lies outside `(0, 1)`.
    pub fn relative_offset(&self, num_params: usize) -> Result<Option<f64>, RheometerError> {
        match self.optimum_tolerance {
            Some(t) if !(t > 0.0 && t < 1.0) => Err(RheometerError::Data(format!(
                "IdentifyOptions::optimum_tolerance must lie in (0, 1) standard errors, got \
                 {t}: it is how close to the optimum the fit must come (default 0.01)"
            ))),
            t => Ok(t.map(|t| t / (num_params.max(1) as f64).sqrt())),
        }
    }

    /// Default options with the given estimator.
    pub fn with_estimator(estimator: Estimator) -> Self {
        IdentifyOptions {
            estimator,
            ..Default::default()
        }
    }
}

/// What a [`FitWarning`] is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WarningCode {
    /// An estimate at a bound of its search range (its interval is not valid).
    AtBound,
    /// RMS relative residual far above the noise level.
    Misfit,
    /// A huge standard error or an unbounded interval: the data do not determine a parameter.
    LargeUncertainty,
    /// `JᵀJ` is singular: no standard errors.
    SingularCovariance,
    /// The covariance is numerically ill-conditioned.
    IllConditioned,
    /// Measured data the model cannot describe (e.g. diameters increasing along the spin line).
    DataTrend,
    /// The systematic uncertainty from what the data cannot identify (process conditions,
    /// instrument, material data; declared or default) dominates the statistical one and
    /// leaves the law undetermined (see [`ErrorBudget::warnings`](super::ErrorBudget::warnings)).
    Systematic,
    /// A material law outside what polymer melts do (`n` near 0, an interval reaching beyond
    /// the law's range, a jump from the plain fit that the gain in fit does not pay for): the
    /// fit compensates a model error with the viscosity law; not a result.
    Implausible,
    /// An effect fixed at a strength outside its physical range (`--with radiation=2`).
    Unphysical,
    /// The fit ended without a convergence test being met (its iteration budget spent, a stall
    /// or a collapsed trust region) where its linearisation still places the optimum at least
    /// one unit of `χ²` lower: the estimates and intervals may belong to a point short of it.
    NotConverged,
    /// The estimated noise level is far below any diameter gauge's resolution: the data look
    /// noise-free (synthetic or smoothed), and intervals from them are not meaningful.
    NoiseFree,
}

impl WarningCode {
    /// The code as written in JSON (`"at_bound"`, `"misfit"`, ...).
    pub fn name(&self) -> &'static str {
        match self {
            WarningCode::AtBound => "at_bound",
            WarningCode::Misfit => "misfit",
            WarningCode::LargeUncertainty => "large_uncertainty",
            WarningCode::SingularCovariance => "singular_covariance",
            WarningCode::IllConditioned => "ill_conditioned",
            WarningCode::DataTrend => "data_trend",
            WarningCode::Systematic => "systematic",
            WarningCode::Implausible => "implausible",
            WarningCode::Unphysical => "unphysical",
            WarningCode::NotConverged => "not_converged",
            WarningCode::NoiseFree => "noise_free",
        }
    }
}

/// A warning about a fit (JSON: `{"code": "at_bound", "message": "..."}`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitWarning {
    /// What it is about.
    pub code: WarningCode,
    /// The finding in words, naming the parameter or experiment.
    pub message: String,
}

impl FitWarning {
    /// A warning with `code` and `message`.
    pub fn new(code: WarningCode, message: String) -> Self {
        FitWarning { code, message }
    }
}

impl fmt::Display for FitWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}] {}", self.code.name(), self.message)
    }
}

/// Which bound of its search range an estimate sits at.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BoundSide {
    /// The lower bound.
    Lower,
    /// The upper bound.
    Upper,
}

impl BoundSide {
    /// `"lower"` or `"upper"`.
    pub fn name(&self) -> &'static str {
        match self {
            BoundSide::Lower => "lower",
            BoundSide::Upper => "upper",
        }
    }

    pub(crate) fn flipped(self) -> Self {
        match self {
            BoundSide::Lower => BoundSide::Upper,
            BoundSide::Upper => BoundSide::Lower,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_optimum_tolerance_is_a_relative_offset_over_root_p_and_refused_outside_its_range() {
        let mut o = IdentifyOptions::default();
        // 0.01 standard errors over 16 parameters: 0.01 / 4
        assert_eq!(o.relative_offset(16).unwrap(), Some(0.0025));
        o.optimum_tolerance = None;
        assert_eq!(o.relative_offset(16).unwrap(), None);
        for bad in [0.0, -0.01, 1.0, 1.5, f64::NAN, f64::INFINITY] {
            o.optimum_tolerance = Some(bad);
            let e = o.relative_offset(16).unwrap_err().to_string();
            assert!(e.contains("IdentifyOptions::optimum_tolerance"), "{e}");
        }
        // below 1 for one parameter too: the driver's relative offset lies in (0, 1)
        o.optimum_tolerance = Some(0.5);
        assert_eq!(o.relative_offset(1).unwrap(), Some(0.5));
    }
}

#[cfg(test)]
mod named_point_tests {
    use super::*;

    /// Finding 38 of the hostile round: a point the model could not be evaluated at is named
    /// (law and effect parameters by name, take-up factors as a range), the vector kept for
    /// programs; other fit errors pass unchanged.
    #[test]
    fn a_failed_point_is_named() {
        let names = vec!["n".to_string(), "kappa".to_string()];
        let e = FitError::RefineFailed {
            p: vec![0.0912345, 16.2, 0.97, 1.02, 0.99],
            cause: "experiment v0p27_p1: the BVP did not converge".into(),
        };
        let r = with_named_point(e, &names);
        let text = r.to_string();
        assert!(
            text.starts_with(
                "fit: the model could not be evaluated at full accuracy at n = 0.09123, \
                 kappa = 16.2, take-up factors 0.97 to 1.02: experiment v0p27_p1"
            ),
            "{text}"
        );
        assert!(matches!(r, RheometerError::NotEvaluable { ref p, .. } if p.len() == 5));
        let e = FitError::StartFailed {
            p: vec![0.5, 15.0, 1.0],
            cause: "x".into(),
        };
        let text = with_named_point(e, &names).to_string();
        assert!(
            text.contains("at the start point at n = 0.5, kappa = 15, take-up factor 1: x"),
            "{text}"
        );
        let e = FitError::StartFailed {
            p: vec![1e-300, 2.5e7],
            cause: "x".into(),
        };
        let text = with_named_point(e, &names).to_string();
        assert!(text.contains("at n = 1e-300, kappa = 2.5e7: x"), "{text}");
        let e = FitError::InvalidInput("bad".into());
        assert!(matches!(
            with_named_point(e, &names),
            RheometerError::Fit(FitError::InvalidInput(_))
        ));
    }
}

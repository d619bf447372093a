//! The result of an identification as a value ([`Identification`]: the fit's summary and what
//! the next computation needs), and how a fit started from a neighbouring one differs from a
//! plain one (`WarmFit`). Produced by [`identify`](super::gauss_newton), refined by
//! [`accuracy`](super::accuracy), read by the profiles, the error budget and the diagnosis.

use crate::fit::layout::EffectSlot;
use crate::fit::summary::FitSummary;
use diffbvp::least_squares::FitResult;
use diffbvp::solution::Solution;

/// Result of an identification: its [`FitSummary`] (the outcome, as reported) and what the
/// next computation needs (the solutions, the least-squares result, the model layout).
#[derive(Debug, Clone)]
pub struct Identification {
    /// The outcome: named estimates with uncertainties, noise level, warnings.
    pub summary: FitSummary,
    /// Names of the shared fitted parameters (the first entries of `fit.p`; the take-up factors
    /// follow).
    pub names: Vec<String>,
    /// The model's effects (fixed or fitted) and where their strengths sit.
    pub effects: Vec<EffectSlot>,
    /// The fitted local model parameters `[c, n, κ, strengths..., φ = 1]`.
    pub local_params: Vec<f64>,
    /// Final fiber solutions, one per experiment.
    pub solutions: Vec<Solution>,
    /// The least-squares result (cost, Jacobian, iterations, termination).
    pub fit: FitResult,
    /// Lower bounds of `fit.p` (shared parameters in model units, then take-up factors).
    pub lower: Vec<f64>,
    /// Upper bounds of `fit.p`.
    pub upper: Vec<f64>,
    /// Per experiment: measurement positions \[m\] and relative residuals
    /// `(d_model − d_meas)/d_meas` \[-\] at the optimum.
    pub residual_profiles: Vec<(Vec<f64>, Vec<f64>)>,
}

impl Identification {
    /// `(n, κ)` of the fitted model.
    pub fn law(&self) -> [f64; 2] {
        self.summary.law_params()
    }

    /// RMS of `(d_model − d_meas)/d_meas` over all raw measurements \[-\].
    pub fn rms(&self) -> f64 {
        self.summary.rms_relative_residual
    }

    /// Take-up factors `φ_k = d_out,k / d_fit,k(L)` (all 1 for the paper's estimator).
    pub fn take_up_factors(&self) -> &[f64] {
        &self.summary.take_up_factors
    }

    /// The fitted strengths (the effects' units) and shapes by model-parameter name: the start
    /// of a fit that continues from this one
    /// ([`FitStart::strengths`](crate::fit::FitStart::strengths)).
    pub fn fitted_strengths(&self) -> Vec<(String, f64)> {
        let mut out = Vec::new();
        for slot in &self.effects {
            if slot.column.is_some() {
                out.push((
                    slot.effect.name().to_string(),
                    slot.effect.strength_of(self.local_params[slot.local]),
                ));
            }
            for sh in &slot.shapes {
                if sh.column.is_some() {
                    out.push((
                        sh.parameter.model_param.to_string(),
                        self.local_params[sh.local],
                    ));
                }
            }
        }
        out
    }
}

/// How a fit started from a neighbouring fit differs from a plain identification
/// ([`Rheometer::identify_warm`](crate::fit::Rheometer::identify_warm)).
#[derive(Debug, Clone, Default)]
pub(crate) struct WarmFit {
    /// Take-up factors to start from (principled estimator; one per experiment, clamped into
    /// [`IdentifyOptions::take_up_bounds`](crate::fit::IdentifyOptions::take_up_bounds)); any other
    /// length: 1.
    pub take_up: Vec<f64>,
    /// Stopping tolerance \[-\] of the gradient, step and cost-change tests (all three);
    /// `None`: the driver's defaults.
    pub stop_tolerance: Option<f64>,
    /// Solve the start solutions at the take-up factors `take_up` (where the warm solutions
    /// were solved at them), so that the fit's first evaluation re-solves nothing. The
    /// diagnosis' scans, refits and step fits set it, and the nested and accuracy fits (their
    /// warm starts come from the fit they continue). Off for the profile walk: on a fit at its
    /// bound (the air hotter than the melt, `n = 1`) its warm solves at the take-up factors fail
    /// more often and fall back to slow cold starts.
    pub solve_at_take_up: bool,
}

//! The Fisher information one experiment carries about the fitted shared parameters: the
//! exact sensitivities of its predicted gauge readings (forward sensitivities of the BVP,
//! dual numbers at the measurement points, as the fit's Jacobian), weighted by the relative
//! noise, with the experiment's own take-up factor profiled out.
//!
//! The measurement model is the principled estimator's: `d_meas,j = d(s_j)(1 + σ_j ε_j)` with
//! independent standard normal `ε_j`, so the information of point `j` is `g_j g_jᵀ` with
//! `g_j = ∂ ln d(s_j)/∂θ / σ_j`. The take-up factor `φ` of an experiment enters only its own
//! points; eliminating it (the Schur complement of its column) gives the information about the
//! shared parameters that the experiment adds, whatever the other experiments are.
//!
//! The fit may weight the points otherwise than the noise is: the fit the design predicts
//! weights every point alike (`τ_j`, its assumed level), while the noise model may say that the
//! take-up region is noisier (`σ_j`). The estimate's covariance is then the sandwich
//! `A⁻¹ B A⁻¹` with `A = Σ g̃_j g̃_jᵀ/τ_j²` (the information the fit's weights give) and
//! `B = Σ (σ_j/τ_j²)² g̃_j g̃_jᵀ` (the covariance of the fit's score under the real noise),
//! `g̃_j` the sensitivities with the take-up factor projected out under the fit's weights.
//! Both sum over experiments; with `σ_j = τ_j`, `B = A` and the covariance is `A⁻¹`.

use crate::error::FiberError;
use crate::fit::CarreauFiber;
use diffbvp::sensitivity::{residual_jacobian, PointFunction, Sensitivities};
use diffbvp::solution::Solution;
use diffbvp::{Bvp, DualNum};

/// `ln` of the gauge's reading of the fiber diameter as a point function of the state and the
/// full parameter vector (unknowns first): its gradient is the relative sensitivity.
struct LogReading<'a> {
    model: &'a CarreauFiber,
    unknowns: usize,
}

impl PointFunction for LogReading<'_> {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, _i: usize, _x: f64, y: &[D], p: &[D]) -> D {
        self.model.observed_diameter(y, &p[self.unknowns..]).ln()
    }
}

/// Which local model parameters an information matrix is about.
#[derive(Debug, Clone, PartialEq)]
pub struct Columns {
    /// Local indices (in the model's `p = [c, n, κ, strengths..., φ]`) of the shared fitted
    /// parameters, in fit order.
    pub shared: Vec<usize>,
    /// Local index of the experiment's take-up factor when it is fitted (profiled out), `None`
    /// when it is held.
    pub nuisance: Option<usize>,
}

/// The information about the shared parameters of one experiment (row-major `p × p`, in the
/// units of the shared parameters: `1/unit²`), and the predicted readings it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct ExperimentInformation {
    /// The matrix, nuisance profiled out: `A = Σ g̃_j g̃_jᵀ/τ_j²` with the fit's weights `τ_j`.
    pub matrix: Vec<f64>,
    /// The covariance of the fit's score under the real noise `σ_j` (row-major `p × p`,
    /// `1/unit²`): `B = Σ (σ_j/τ_j²)² g̃_j g̃_jᵀ`; equal to [`matrix`](Self::matrix) when the fit
    /// weights the points by their real noise.
    pub noise_matrix: Vec<f64>,
    /// Predicted gauge readings \[m\] at the measurement positions.
    pub readings: Vec<f64>,
    /// Relative sensitivities `∂ ln d(s_j)/∂θ_c` \[1/unit\], row-major `points × p` (shared
    /// parameters only).
    pub sensitivities: Vec<f64>,
    /// Relative sensitivities `∂ ln d(s_j)/∂φ` \[-\] to the take-up factor, one per point
    /// (empty when the take-up factor is held).
    pub nuisance_sensitivities: Vec<f64>,
}

/// The information of one experiment: `model` solved as `sol` (its parameters the fitted
/// ones), measured at `positions` \[m\] with relative noise `sigmas` \[-\] (one per position),
/// the fit weighting each point by its noise.
pub fn experiment_information(
    model: &CarreauFiber,
    sol: &Solution,
    positions: &[f64],
    sigmas: &[f64],
    columns: &Columns,
) -> Result<ExperimentInformation, FiberError> {
    experiment_information_under(model, sol, positions, (sigmas, sigmas), columns)
}

/// The information of one experiment as [`experiment_information`], for a fit that weights
/// point `j` by `1/τ_j²` while its relative noise is `σ_j` (`(fit_sigmas, noise_sigmas)` =
/// `(τ, σ)` \[-\], one each per position): [`ExperimentInformation::matrix`] is the fit's
/// information `A`, [`ExperimentInformation::noise_matrix`] its score's covariance `B` (see the
/// module docs). Errors: lengths that do not match the positions, a level that is not positive
/// and finite, a column beyond the model's parameters, a failed sensitivity solve.
pub fn experiment_information_under(
    model: &CarreauFiber,
    sol: &Solution,
    positions: &[f64],
    (fit_sigmas, noise_sigmas): (&[f64], &[f64]),
    columns: &Columns,
) -> Result<ExperimentInformation, FiberError> {
    for sigmas in [fit_sigmas, noise_sigmas] {
        if positions.len() != sigmas.len() {
            return Err(FiberError::InvalidInput(format!(
                "{} measurement positions but {} noise levels",
                positions.len(),
                sigmas.len()
            )));
        }
        if let Some(bad) = sigmas.iter().find(|s| !(**s > 0.0 && s.is_finite())) {
            return Err(FiberError::InvalidInput(format!(
                "the relative noise must be positive and finite, got {bad}"
            )));
        }
    }
    let q = sol.params.len();
    if let Some(&c) = columns
        .shared
        .iter()
        .chain(columns.nuisance.iter())
        .find(|&&c| c >= q)
    {
        return Err(FiberError::InvalidInput(format!(
            "parameter column {c} beyond the model's {q} parameters"
        )));
    }
    let sens = Sensitivities::compute(model, sol)?;
    let lo = model.scaling.reference.length;
    let xs: Vec<f64> = positions.iter().map(|s| s / lo).collect();
    let g = LogReading {
        model,
        unknowns: model.num_unknowns(),
    };
    let (values, jac) = residual_jacobian(model, sol, &sens, &xs, &g)?;
    let p = columns.shared.len();
    let m = xs.len();
    let mut sensitivities = Vec::with_capacity(m * p);
    let mut nuisance_sensitivities = Vec::new();
    for j in 0..m {
        let jr = &jac[j * q..(j + 1) * q];
        sensitivities.extend(columns.shared.iter().map(|&c| jr[c]));
        if let Some(t) = columns.nuisance {
            nuisance_sensitivities.push(jr[t]);
        }
    }
    // the take-up factor projected out under the fit's weights: g̃_j = g_j − h_j β with
    // β = Σ w g h / Σ w h² (the fit's own elimination of φ), w = 1/τ²
    let mut beta = vec![0.0; p];
    let mut nn = 0.0;
    for (j, h) in nuisance_sensitivities.iter().enumerate() {
        let w = fit_sigmas[j].powi(-2);
        for (b, g) in beta.iter_mut().zip(&sensitivities[j * p..(j + 1) * p]) {
            *b += w * g * h;
        }
        nn += w * h * h;
    }
    if nn > 0.0 {
        beta.iter_mut().for_each(|b| *b /= nn);
    } else {
        beta.iter_mut().for_each(|b| *b = 0.0);
    }
    let mut matrix = vec![0.0; p * p];
    let mut noise_matrix = vec![0.0; p * p];
    let mut row = vec![0.0; p];
    for j in 0..m {
        let h = nuisance_sensitivities.get(j).copied().unwrap_or(0.0);
        for (a, r) in row.iter_mut().enumerate() {
            *r = sensitivities[j * p + a] - h * beta[a];
        }
        let w = fit_sigmas[j].powi(-2);
        let v = (noise_sigmas[j] * w).powi(2);
        for a in 0..p {
            for b in 0..p {
                matrix[a * p + b] += w * row[a] * row[b];
                noise_matrix[a * p + b] += v * row[a] * row[b];
            }
        }
    }
    let scale = model.scaling.diameter();
    Ok(ExperimentInformation {
        matrix,
        noise_matrix,
        readings: values.iter().map(|v| v.exp() * scale).collect(),
        sensitivities,
        nuisance_sensitivities,
    })
}

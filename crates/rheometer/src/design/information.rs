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

use crate::error::FiberError;
use crate::rheometer::CarreauFiber;
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
    /// The matrix, nuisance profiled out.
    pub matrix: Vec<f64>,
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
/// ones), measured at `positions` \[m\] with relative noise `sigmas` \[-\] (one per position).
pub fn experiment_information(
    model: &CarreauFiber,
    sol: &Solution,
    positions: &[f64],
    sigmas: &[f64],
    columns: &Columns,
) -> Result<ExperimentInformation, FiberError> {
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
    let mut matrix = vec![0.0; p * p];
    let mut cross = vec![0.0; p];
    let mut nn = 0.0;
    let mut sensitivities = Vec::with_capacity(xs.len() * p);
    let mut nuisance_sensitivities = Vec::new();
    let mut row = vec![0.0; p];
    for (j, sigma) in sigmas.iter().enumerate() {
        let jr = &jac[j * q..(j + 1) * q];
        for (r, &c) in row.iter_mut().zip(&columns.shared) {
            *r = jr[c];
        }
        sensitivities.extend_from_slice(&row);
        let w = 1.0 / (sigma * sigma);
        for a in 0..p {
            for b in 0..p {
                matrix[a * p + b] += w * row[a] * row[b];
            }
        }
        if let Some(t) = columns.nuisance {
            nuisance_sensitivities.push(jr[t]);
            for a in 0..p {
                cross[a] += w * row[a] * jr[t];
            }
            nn += w * jr[t] * jr[t];
        }
    }
    if nn > 0.0 {
        for a in 0..p {
            for b in 0..p {
                matrix[a * p + b] -= cross[a] * cross[b] / nn;
            }
        }
    }
    let scale = model.scaling.diameter();
    Ok(ExperimentInformation {
        matrix,
        readings: values.iter().map(|v| v.exp() * scale).collect(),
        sensitivities,
        nuisance_sensitivities,
    })
}

//! The trial step of an iteration: the trust-region step from the iterate kept inside the
//! box, and its length in standard errors for the accuracy schedule.

use super::super::jacobian::Linearized;
#[cfg(doc)]
use super::super::Accuracy;
use super::super::{FitOptions, Termination};
use super::Driver;
use nalgebra::DVector;

/// A trial step from the iterate, kept strictly inside the box.
pub(super) struct Proposal {
    /// The trial point `p + s`.
    pub(super) trial: Vec<f64>,
    /// The step `s` actually taken (after truncation and clipping to the box).
    pub(super) step: DVector<f64>,
    /// The Coleman–Li scaling `D` of the step.
    pub(super) d: Vec<f64>,
    /// The reduction of the Gauss–Newton model's cost the step predicts.
    pub(super) predicted: f64,
    /// The scaled gradient at the iterate (the `gtol` measure).
    pub(super) scaled_gradient: f64,
}

/// Under [`Accuracy::Scheduled`], a step's length in standard errors is `effect / sigma`
/// (`NaN` without a schedule).
#[derive(Clone, Copy)]
pub(super) struct StepSize {
    /// `σ̂`, the RMS residual (at most the soft margin under a robust loss).
    pub(super) sigma: f64,
    /// `‖J s‖`.
    pub(super) effect: f64,
}

impl Driver<'_> {
    /// The trust-region step from the iterate, kept strictly inside the box; `Err` with the
    /// stopping test the iterate meets instead (gradient, iteration budget, radius).
    pub(super) fn propose(&self) -> Result<Proposal, Termination> {
        let (np, nr, o) = (self.np, self.nr, self.options);
        let (r_gn, jac_gn) = match &self.scaled {
            Some((rs, js)) => (rs.as_slice(), js),
            None => (self.r.as_slice(), &self.jac),
        };
        let lin = Linearized::new(jac_gn, r_gn, nr, np);
        let g = lin.gradient();
        // the Coleman–Li distances in the scaled variables p_i / x_scale_i
        let v = cl_scaling(&self.p, g.as_slice(), o);
        let scaled_gradient = (0..np)
            .map(|i| (g[i] * o.scale(i) * v[i]).abs())
            .fold(0.0, f64::max);
        if scaled_gradient <= o.gtol {
            return Err(Termination::Gradient);
        }
        let d: Vec<f64> = (0..np).map(|i| 1.0 / (v[i].sqrt() * o.scale(i))).collect();
        // at the optimum to within the tolerance, whatever numerical noise the cost carries
        // (not in the loose phase of a schedule: its evaluations are not yet the final model);
        // the Gauss–Newton step it measures is also the trust-region step when it lies inside
        // the radius, so it is computed once
        let gauss_newton = o
            .relative_offset
            .filter(|_| !self.loose)
            .map(|tol| (tol, lin.step(&d, f64::INFINITY)));
        if let Some((tol, s_gn)) = &gauss_newton {
            let offset = lin.relative_offset(s_gn, nr, np);
            if offset <= *tol {
                return Err(Termination::RelativeOffset);
            }
            if self.noise_floor > 0.0
                && offset <= super::NOISE_FLOOR_OFFSET_FACTOR * tol
                && lin.predicted_reduction(s_gn) <= super::NOISE_FLOOR_FACTOR * self.noise_floor
            {
                return Err(Termination::NoiseFloor);
            }
        }
        if o.relative_offset.is_some() && !self.loose && self.stalled() {
            return Err(Termination::Stalled);
        }
        if self.iterations >= self.tight_limit.unwrap_or(o.max_iterations) {
            return Err(Termination::MaxIterations);
        }
        if self.radius < 1e-12 {
            return Err(Termination::RadiusCollapsed);
        }
        let s = match gauss_newton {
            Some((_, s_gn)) if scaled_norm(&s_gn, &d) <= self.radius => s_gn,
            _ => lin.step(&d, self.radius),
        };
        let trial = inside_box(&self.p, &s, &o.lower, &o.upper);
        let step: Vec<f64> = (0..np).map(|i| trial[i] - self.p[i]).collect();
        let step = DVector::from_column_slice(&step);
        Ok(Proposal {
            predicted: lin.predicted_reduction(&step),
            trial,
            step,
            d,
            scaled_gradient,
        })
    }

    /// Accuracy::Scheduled: the step's length in standard errors, ‖J s‖/σ̂, with σ̂ the
    /// [`residual_variance`](Self::residual_variance)'s root.
    pub(super) fn step_size(&self, step: &DVector<f64>) -> StepSize {
        let (np, nr) = (self.np, self.nr);
        match self.schedule {
            Some(_) => {
                let sigma = self.residual_variance().sqrt();
                let effect = self.jac.effect(step, nr, np);
                StepSize { sigma, effect }
            }
            None => StepSize {
                sigma: f64::NAN,
                effect: f64::NAN,
            },
        }
    }
}

/// `‖D s‖`, the length of the step `s` in the trust region's scaled variables.
pub(super) fn scaled_norm(s: &DVector<f64>, d: &[f64]) -> f64 {
    s.iter()
        .zip(d)
        .map(|(x, di)| (x * di) * (x * di))
        .sum::<f64>()
        .sqrt()
}

/// The trial point `p + s` kept strictly inside the box `[lo, hi]`: a step that would leave it
/// is truncated at 0.995 of the way to the nearest bound, then clipped to the box.
fn inside_box(p: &[f64], s: &DVector<f64>, lo: &[f64], hi: &[f64]) -> Vec<f64> {
    let np = p.len();
    let mut t_max = 1.0f64;
    for i in 0..np {
        if s[i] > 0.0 && hi[i].is_finite() {
            t_max = t_max.min((hi[i] - p[i]) / s[i]);
        } else if s[i] < 0.0 && lo[i].is_finite() {
            t_max = t_max.min((lo[i] - p[i]) / s[i]);
        }
    }
    let theta = 0.995;
    let mut trial: Vec<f64> = if t_max < 1.0 {
        (0..np).map(|i| p[i] + theta * t_max * s[i]).collect()
    } else {
        (0..np).map(|i| p[i] + s[i]).collect()
    };
    for i in 0..np {
        trial[i] = trial[i].clamp(lo[i], hi[i]);
    }
    trial
}

/// Coleman–Li scaling vector: distance to the bound the negative gradient points at, in units
/// of the parameter's scale ([`FitOptions::scale`]) and at most 1.
fn cl_scaling(p: &[f64], g: &[f64], o: &FitOptions) -> Vec<f64> {
    p.iter()
        .zip(g)
        .zip(o.lower.iter().zip(&o.upper))
        .enumerate()
        .map(|(i, ((&x, &gi), (&l, &u)))| {
            let scale = o.scale(i);
            let v = if gi < 0.0 && u.is_finite() {
                u - x
            } else if gi > 0.0 && l.is_finite() {
                x - l
            } else {
                scale
            };
            (v / scale).abs().clamp(1e-12, 1.0)
        })
        .collect()
}

//! The strain rates the data cover ([`StrainRateCoverage`]): the model's strain rates at the
//! measurement positions where the fiber still draws, from the fitted solutions, and the same
//! rates shifted to one reference temperature by the VFT factor (time–temperature
//! superposition). A fit's summary holds them; the flow curve marks where it extrapolates.

use crate::data::statistics::median;
use crate::fit::data::Rheometer;
use diffbvp::solution::Solution;
use serde::{Deserialize, Serialize};

/// A measurement position counts towards the strain rates the data cover where the model's
/// strain rate exceeds this fraction of its largest value along that experiment's line: where
/// the fiber still draws. Downstream the fiber has frozen; its diameter no longer depends on
/// the law, while its reduced rate `a_T ε̇` (tiny rate, huge shift factor) would claim
/// coverage up to 1e12 1/s.
pub const DRAWING_FRACTION: f64 = 0.01;

/// The strain rates \[1/s\] of a fit's model at the measurement positions where the fiber
/// draws (`DRAWING_FRACTION`) (JSON: `strain_rates` of a fit).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StrainRateCoverage {
    /// Temperature the reduced rates refer to \[K\]: the median die (inlet) temperature.
    pub reference_temperature_k: f64,
    /// Smallest, median and largest model strain rate at the measurement positions where the
    /// fiber draws \[1/s\], as they occur on the spin line.
    pub measured_per_s: [f64; 3],
    /// The same rates shifted to `reference_temperature_k` by the VFT factor
    /// `η₀(T)/η₀(T_ref)` \[1/s\]: the part of the flow curve at `T_ref` the data probe.
    pub reduced_per_s: [f64; 3],
    /// Coldest and hottest melt temperature at those positions \[K\].
    pub temperature_k: [f64; 2],
    /// How much the fitted law thins at the largest reduced rate and `reference_temperature_k`,
    /// `1 − η_E(ε̇_max)/η_E0` \[-\] (in memory only, for judging a law in the diagnosis;
    /// `NaN` when read from JSON).
    #[serde(skip, default = "crate::report::serde_nan::nan")]
    pub thinning_at_max: f64,
}

/// Equal as written to JSON (`thinning_at_max`, in memory only, left out).
impl PartialEq for StrainRateCoverage {
    fn eq(&self, other: &Self) -> bool {
        self.reference_temperature_k == other.reference_temperature_k
            && self.measured_per_s == other.measured_per_s
            && self.reduced_per_s == other.reduced_per_s
            && self.temperature_k == other.temperature_k
    }
}

impl Rheometer {
    /// The strain rates the data cover, from the fitted `solutions` (one per experiment) at the
    /// measurement positions where the fiber draws (`None` without a positive rate).
    pub fn strain_rate_coverage(&self, solutions: &[Solution]) -> Option<StrainRateCoverage> {
        let mut inlet: Vec<f64> = self
            .experiments
            .iter()
            .map(|e| e.inlet_temperature)
            .collect();
        let t_ref = median(&mut inlet);
        let (mut raw, mut reduced) = (Vec::new(), Vec::new());
        let (mut t_lo, mut t_hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let thinning = |rate: f64| -> f64 {
            let (Some(model), Some(sol)) = (self.models.first(), solutions.first()) else {
                return f64::NAN;
            };
            let sc = &model.scaling;
            let t = t_ref / sc.reference.temperature;
            let eta = |r: f64| model.viscosity_at(t, r / sc.strain_rate(), &sol.params);
            1.0 - eta(rate) / eta(0.0)
        };
        let mut y = [0.0; 4];
        let mut yp = [0.0; 4];
        for (k, sol) in solutions.iter().enumerate() {
            let (Some(model), Some(m)) = (self.models.get(k), self.measurements.get(k)) else {
                continue;
            };
            let sc = &model.scaling;
            let (lo, t_o) = (sc.reference.length, sc.reference.temperature);
            let eta0_ref = model.viscosity_at(t_ref / t_o, 0.0, &sol.params);
            let states: Vec<(f64, f64, f64)> = m
                .positions
                .iter()
                .map(|&s| {
                    sol.eval_into(s / lo, &mut y, &mut yp);
                    (y[2], y[3] * sc.strain_rate(), y[2] * t_o)
                })
                .collect();
            let peak = states.iter().map(|s| s.1).fold(0.0, f64::max);
            for &(t_nd, rate, t) in &states {
                if !(rate > DRAWING_FRACTION * peak && rate.is_finite() && t.is_finite()) {
                    continue;
                }
                let a_t = model.viscosity_at(t_nd, 0.0, &sol.params) / eta0_ref;
                raw.push(rate);
                reduced.push(rate * a_t);
                t_lo = t_lo.min(t);
                t_hi = t_hi.max(t);
            }
        }
        let three = |v: &mut Vec<f64>| -> Option<[f64; 3]> {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            (lo.is_finite() && hi.is_finite()).then(|| [lo, median(v), hi])
        };
        let reduced_per_s = three(&mut reduced)?;
        Some(StrainRateCoverage {
            reference_temperature_k: t_ref,
            measured_per_s: three(&mut raw)?,
            reduced_per_s,
            temperature_k: [t_lo, t_hi],
            thinning_at_max: thinning(reduced_per_s[2]),
        })
    }
}

//! The look-elsewhere calibration of a diagnosis as a value ([`Calibration`]): the null
//! distribution of the best `ΔBIC` over all candidates and shapes on effect-free data like the
//! user's, and the false-alarm probability it gives a `ΔBIC`. Computed by the bootstrap of
//! [`calibrate`](super::diagnose::linear::calibrate); the
//! [`Diagnosis`](super::diagnosis::Diagnosis) holds it.

use serde::{Deserialize, Serialize};

/// The null distribution of the best `ΔBIC` over all candidates and shapes on effect-free data
/// like the user's.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Calibration {
    /// Replicates drawn.
    pub replicates: usize,
    /// Columns searched (candidates × shapes).
    pub columns: usize,
    /// The best `ΔBIC` of each replicate, increasing.
    #[serde(skip)]
    pub best: Vec<f64>,
    /// Its 5 % quantile: a `ΔBIC` below it is a false alarm in fewer than 5 % of effect-free
    /// data sets like these.
    pub quantile_5: f64,
    /// Its median.
    pub median: f64,
}

impl Calibration {
    /// The fraction of replicates whose best `ΔBIC` is at or below `delta_bic` (`NaN` without
    /// replicates).
    pub fn false_alarm(&self, delta_bic: f64) -> f64 {
        if self.best.is_empty() || !delta_bic.is_finite() {
            return f64::NAN;
        }
        let below = self.best.partition_point(|&b| b <= delta_bic);
        below as f64 / self.best.len() as f64
    }
}

//! Data sets for the design tests: clean diameters of the independent model with relative
//! Gaussian noise, on the library's types (the independent model itself knows none of them).

use crate::independent::rng::Rng;
use crate::independent::scenarios::NOISE_SD;
use rheometer::model::{Experiment, ExperimentSet, Measurements};

/// `template`'s set with `experiments`, their clean diameters `clean` \[m\] at `positions`
/// \[m\] multiplied by `1 + σ ξ` (`σ` = [`NOISE_SD`], `ξ` standard normal from `rng`).
pub fn noisy_set(
    template: &ExperimentSet,
    experiments: Vec<Experiment>,
    clean: &[Vec<f64>],
    positions: &[Vec<f64>],
    rng: &mut Rng,
) -> ExperimentSet {
    ExperimentSet {
        experiments,
        measurements: clean
            .iter()
            .zip(positions)
            .map(|(d, s)| {
                Some(Measurements {
                    positions: s.clone(),
                    diameters: d
                        .iter()
                        .map(|v| v * (1.0 + NOISE_SD * rng.normal()))
                        .collect(),
                })
            })
            .collect(),
        ..template.clone()
    }
}

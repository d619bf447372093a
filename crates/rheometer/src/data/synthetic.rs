//! Synthetic measurements: reproducible multiplicative noise on simulated diameters, for
//! testing an identification or a diagnosis on data whose truth is known.
//!
//! The noise model is the one of the shipped data sets (`data/*/TRUTH.md`):
//!
//! `d_meas(s) = d_true(s) (1 + σ ξ₁ + σ_extra(s) ξ₂)`,
//! `σ_extra(s) = a ((s − s₀)/w)²` for `s > s₀` (a disturbance growing towards the take-up,
//! e.g. from the aspirator), else 0,
//!
//! with `ξ₁, ξ₂` standard normal from a seeded SplitMix64 generator (Box–Muller, one normal per
//! pair of uniforms). Per experiment all `ξ₁` are drawn first, then all `ξ₂`, so a data set is
//! reproduced exactly from its seed and the order of its experiments.
//!
//! ```
//! use rheometer::data::synthetic::{SplitMix64, SyntheticNoise};
//! let s = [0.0, 0.2, 0.4, 0.5];
//! let clean = [1e-3, 3e-4, 1.1e-4, 1e-4];
//! let noise = SyntheticNoise::pmma7n_synthetic();
//! let mut rng = SplitMix64::new(20_250_611);
//! let measured = noise.apply(&s, &clean, &mut rng)?;
//! assert!(measured.iter().zip(&clean).all(|(m, c)| (m / c - 1.0).abs() < 0.1));
//! # Ok::<(), String>(())
//! ```

/// SplitMix64 (Steele, Lea and Flood 2014): a small, well-mixed, seeded 64-bit generator.
#[derive(Debug, Clone)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator started from `seed`.
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in the open interval (0, 1).
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// Standard normal (Box–Muller, one value from two uniforms).
    pub fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

/// Relative measurement noise: white noise everywhere plus a disturbance growing
/// quadratically beyond a position (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SyntheticNoise {
    /// Relative standard deviation `σ` of every measurement \[-\].
    pub relative_sd: f64,
    /// Position `s₀` where the extra disturbance starts \[m\].
    pub disturbance_start: f64,
    /// Length `w` over which the disturbance reaches its amplitude \[m\].
    pub disturbance_width: f64,
    /// Amplitude `a` of the disturbance's relative standard deviation at `s₀ + w` \[-\].
    pub disturbance_amplitude: f64,
}

impl SyntheticNoise {
    /// The noise of `data/pmma7n_synthetic` and `data/hidden_radiation`: 1.5% everywhere,
    /// plus `0.04 ((s − 0.35 m)/0.16 m)²` beyond 0.35 m.
    pub fn pmma7n_synthetic() -> Self {
        SyntheticNoise {
            relative_sd: 0.015,
            disturbance_start: 0.35,
            disturbance_width: 0.16,
            disturbance_amplitude: 0.04,
        }
    }

    /// White noise only, relative standard deviation `relative_sd` \[-\].
    pub fn white(relative_sd: f64) -> Self {
        SyntheticNoise {
            relative_sd,
            disturbance_start: f64::INFINITY,
            disturbance_width: 1.0,
            disturbance_amplitude: 0.0,
        }
    }

    /// Relative standard deviation of the disturbance at `s` \[m\].
    pub fn disturbance_sd(&self, s: f64) -> f64 {
        if s > self.disturbance_start {
            self.disturbance_amplitude
                * ((s - self.disturbance_start) / self.disturbance_width).powi(2)
        } else {
            0.0
        }
    }

    /// RMS relative noise level over `positions` \[m\]: `√(mean(σ² + σ_extra(s)²))`.
    pub fn rms_level(&self, positions: &[f64]) -> f64 {
        if positions.is_empty() {
            return self.relative_sd;
        }
        let sum: f64 = positions
            .iter()
            .map(|&s| self.relative_sd.powi(2) + self.disturbance_sd(s).powi(2))
            .sum();
        (sum / positions.len() as f64).sqrt()
    }

    /// Noisy measurements of the diameters `clean` \[m\] at `positions` \[m\], drawing first
    /// one `ξ₁` per position, then one `ξ₂` per position from `rng`. Errors if the lengths
    /// differ or a noisy diameter is not positive.
    pub fn apply(
        &self,
        positions: &[f64],
        clean: &[f64],
        rng: &mut SplitMix64,
    ) -> Result<Vec<f64>, String> {
        if positions.len() != clean.len() {
            return Err(format!(
                "{} positions but {} diameters",
                positions.len(),
                clean.len()
            ));
        }
        let xi1: Vec<f64> = positions.iter().map(|_| rng.normal()).collect();
        let xi2: Vec<f64> = positions.iter().map(|_| rng.normal()).collect();
        positions
            .iter()
            .zip(clean)
            .enumerate()
            .map(|(i, (&s, &d))| {
                let noisy = d * (1.0 + self.relative_sd * xi1[i] + self.disturbance_sd(s) * xi2[i]);
                if noisy > 0.0 {
                    Ok(noisy)
                } else {
                    Err(format!(
                        "non-positive noisy diameter {noisy:e} m at s = {s} m"
                    ))
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_have_unit_variance() {
        let mut rng = SplitMix64::new(1);
        let v: Vec<f64> = (0..20_000).map(|_| rng.normal()).collect();
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64;
        // standard errors: 0.007 for the mean, 0.01 for the variance
        assert!(mean.abs() < 0.03, "mean {mean}");
        assert!((var - 1.0).abs() < 0.04, "variance {var}");
    }

    #[test]
    fn noise_is_reproducible_and_grows_at_the_take_up() {
        let s: Vec<f64> = (0..26).map(|i| 0.02 * f64::from(i)).collect();
        let clean = vec![1e-4; s.len()];
        let m = SyntheticNoise::pmma7n_synthetic();
        let a = m.apply(&s, &clean, &mut SplitMix64::new(7)).unwrap();
        let b = m.apply(&s, &clean, &mut SplitMix64::new(7)).unwrap();
        assert_eq!(a, b);
        assert_eq!(m.disturbance_sd(0.35), 0.0);
        assert!((m.disturbance_sd(0.51) - 0.04).abs() < 1e-15);
        assert!(m.rms_level(&s) > 0.015 && m.rms_level(&s) < 0.02);
        assert!(m.apply(&s[..3], &clean, &mut SplitMix64::new(7)).is_err());
    }
}

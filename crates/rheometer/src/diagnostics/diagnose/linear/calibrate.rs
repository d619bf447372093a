//! Stage 7: calibrated evidence. Trying many candidates and shapes and naming the best is a
//! look-elsewhere problem: on effect-free data the *best* `ΔBIC` over all of them falls below a
//! fixed threshold far more often than any single one would. This stage measures how often, on
//! data like the user's, by a parametric bootstrap of the linearised search:
//!
//! 1. effect-free residuals like the user's: `e = σ ⊙ z`, `z` standard normal, `σ` each
//!    point's noise level from the user's fit's noise model (in the fit's residual units), with
//!    the fitted parameters refitted: `r* = (I − P_X) e` (`X` the fit's Jacobian). Where the
//!    noise model finds the noise correlated along the line, `z` is AR(1) with its
//!    correlation within each experiment (unit variance), so the evidence of effect-free
//!    correlated noise, which a smooth signature picks up more often, is measured too;
//! 2. every candidate column — each candidate at its default shape and at every shape the
//!    global search scans (the sensitivity at strength 0 depends on the shape) — orthogonalised
//!    against `X`: `c⊥`; its score `(c⊥·e)²/‖c⊥‖²` is the cost it removes from `r*` to first
//!    order, and `ΔBIC = N ln(1 − score/J*) + k ln N` with `J* = ‖r*‖²`;
//! 3. the best (lowest) `ΔBIC` over all columns, per replicate.
//!
//! The false-alarm probability of a candidate with `ΔBIC` `b` is the fraction of replicates
//! whose best `ΔBIC` is at or below `b`: how often effect-free data like these would produce an
//! effect at least that convincing somewhere among the candidates. The linearisation leaves out
//! what a nonlinear refit adds (continuous shapes, large strengths); the false-alarm rate of the
//! whole diagnosis on effect-free data is measured separately (see the book and the closing
//! figures of `tests/diagnose_calibration.rs`).

use super::linearise::Linearisation;
use crate::data::synthetic::SplitMix64;
pub use crate::diagnostics::calibration::Calibration;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// Replicates of the bootstrap (default of
/// [`DiagnoseOptions`](crate::diagnostics::diagnose::DiagnoseOptions)).
pub const DEFAULT_REPLICATES: usize = 2000;

/// The orthonormal basis of the columns of the `n × q` row-major `x` (singular values above
/// `1e-12` of the largest).
fn basis(x: &[f64], n: usize, q: usize) -> DMatrix<f64> {
    if n == 0 || q == 0 {
        return DMatrix::zeros(n, 0);
    }
    let m = DMatrix::from_row_slice(n, q, x);
    let svd = m.svd(true, false);
    let Some(u) = svd.u else {
        return DMatrix::zeros(n, 0);
    };
    let smax = svd.singular_values.iter().copied().fold(0.0, f64::max);
    let keep: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&i| svd.singular_values[i] > 1e-12 * smax)
        .collect();
    DMatrix::from_fn(n, keep.len(), |r, c| u[(r, keep[c])])
}

/// The noise of the bootstrap: each residual's noise level and the along-line correlation.
pub(crate) struct NullNoise<'a> {
    /// Each residual's noise level in the fit's residual units.
    pub sd: &'a [f64],
    /// The lag-1 autocorrelation of the noise within an experiment \[-\] (0: white).
    pub correlation: f64,
    /// The number of residuals of each experiment, in order (the AR(1) chains restart).
    pub segments: &'a [usize],
}

impl NullNoise<'_> {
    /// Fills `e` with one draw: `sd ⊙ z`, `z` AR(1) of unit variance in each segment.
    fn draw(&self, rng: &mut SplitMix64, e: &mut DVector<f64>) {
        let r = self.correlation;
        let innovation = (1.0 - r * r).sqrt();
        let mut i = 0;
        for &len in self.segments {
            let mut z = 0.0;
            for j in 0..len {
                let w = rng.normal();
                z = if j == 0 { w } else { r * z + innovation * w };
                e[i] = self.sd[i] * z;
                i += 1;
            }
        }
    }
}

/// The bootstrap: `columns` are `(extra parameters k, column)` per candidate and shape (the
/// residuals' derivative per unit strength), `noise` the effect-free noise to draw.
pub(crate) fn calibrate(
    lin: &Linearisation,
    columns: &[(usize, Vec<f64>)],
    noise: &NullNoise<'_>,
    replicates: usize,
    seed: u64,
) -> Calibration {
    let n = lin.residuals();
    if n == 0
        || noise.sd.len() != n
        || noise.segments.iter().sum::<usize>() != n
        || !(0.0..1.0).contains(&noise.correlation)
        || replicates == 0
    {
        return Calibration::default();
    }
    let u = basis(&lin.x, n, lin.q);
    let ortho: Vec<(f64, DVector<f64>, f64)> = columns
        .iter()
        .filter(|(_, c)| c.len() == n)
        .filter_map(|(k, c)| {
            let c = DVector::from_column_slice(c);
            let perp = &c - &u * (u.transpose() * &c);
            let norm2 = perp.norm_squared();
            (norm2 > 1e-30 * c.norm_squared().max(1e-300)).then_some((*k as f64, perp, norm2))
        })
        .collect();
    let ln_n = (n as f64).ln();
    let chunks = 16;
    let per = replicates.div_ceil(chunks);
    let mut best: Vec<f64> = (0..chunks)
        .into_par_iter()
        .flat_map_iter(|ch| {
            let mut rng = SplitMix64::new(seed ^ (0x9E37_79B9 * (ch as u64 + 1)));
            let count = per.min(replicates.saturating_sub(ch * per));
            let mut e = DVector::zeros(n);
            let mut out = Vec::with_capacity(count);
            for _ in 0..count {
                noise.draw(&mut rng, &mut e);
                let ue = u.transpose() * &e;
                let j_star = (e.norm_squared() - ue.norm_squared()).max(1e-300);
                let b = ortho
                    .iter()
                    .map(|(k, perp, norm2)| {
                        let d = perp.dot(&e);
                        let frac = (d * d / norm2 / j_star).min(1.0 - 1e-15);
                        n as f64 * (1.0 - frac).ln() + k * ln_n
                    })
                    .fold(f64::INFINITY, f64::min);
                out.push(b);
            }
            out
        })
        .collect();
    best.sort_by(f64::total_cmp);
    let q = |p: f64| {
        best.get(((p * best.len() as f64) as usize).min(best.len().saturating_sub(1)))
            .copied()
            .unwrap_or(f64::NAN)
    };
    Calibration {
        replicates: best.len(),
        columns: ortho.len(),
        quantile_5: q(0.05),
        median: q(0.5),
        best,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a problem with one fitted parameter and one candidate column, the bootstrap's
    /// distribution of the best ΔBIC follows from the χ²₁ score: `score/σ² ~ χ²₁`, so
    /// P(ΔBIC ≤ N ln(1 − t σ²/J) + ln N) ≈ P(χ²₁ ≥ t); at t = 3.84 that is 5 %.
    #[test]
    fn one_column_follows_chi_square() {
        let n = 400;
        let x: Vec<f64> = vec![1.0; n];
        let lin = Linearisation {
            r: vec![0.0; n],
            x,
            q: 1,
            cols: Vec::new(),
            scores: Vec::new(),
            cost_before: 1.0,
            positions: vec![0.0; n],
        };
        let col: Vec<f64> = (0..n).map(|i| i as f64 / n as f64 - 0.5).collect();
        let sd = vec![0.5; n];
        let white = NullNoise {
            sd: &sd,
            correlation: 0.0,
            segments: &[n],
        };
        let cal = calibrate(&lin, &[(1, col)], &white, 20_000, 7);
        // J* ≈ (n − 1) σ²: the ΔBIC at which χ²₁ = 3.84
        let j = (n - 1) as f64 * 0.25;
        let b = n as f64 * (1.0 - 3.84 * 0.25 / j).ln() + (n as f64).ln();
        let p = cal.false_alarm(b);
        assert!((p - 0.05).abs() < 0.01, "p = {p}");
        assert_eq!(cal.columns, 1);
        // more columns: the best of several is more often extreme
        let col2: Vec<f64> = (0..n).map(|i| ((i * 7919) % 13) as f64 - 6.0).collect();
        let col1: Vec<f64> = (0..n).map(|i| i as f64 / n as f64 - 0.5).collect();
        let two = calibrate(&lin, &[(1, col1.clone()), (1, col2)], &white, 20_000, 7);
        assert!(two.false_alarm(b) > 0.08, "{}", two.false_alarm(b));
        // correlated noise: a smooth column's score has variance σ² (1 + ρ)/(1 − ρ) for
        // ρ = 0.5, three times white noise's, so the same ΔBIC is reached far more often
        let correlated = NullNoise {
            correlation: 0.5,
            ..white
        };
        let c = calibrate(&lin, &[(1, col1)], &correlated, 20_000, 7);
        let p = c.false_alarm(b);
        // P(3 χ²₁ ≥ 3.84) = P(χ²₁ ≥ 1.28) ≈ 0.26
        assert!((p - 0.26).abs() < 0.03, "p = {p}");
    }
}

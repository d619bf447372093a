//! Smoothing of measured diameters with the velocity ansatz of Bier et al. (paper eq. 5).
//!
//! The inverse squared diameter behaves like a velocity. The ansatz
//!
//! ```text
//! u_f(s; b, c, v, u0) = u0 v E / ((E - 1) u0 + v),   E = exp((s/c)^b),
//! ```
//!
//! runs from `u_f(0) = u0` to the plateau `v`; equivalently `d_fit² = 1/v + (1/u0 - 1/v) e^{-(s/c)^b}`
//! (a stretched-exponential decay of `d²`). With `u0 = d_meas(0)^{-2}` fixed, `(b, c, v)` are
//! fitted by nonlinear least squares on the relative deviation `u_f(s_i) d_i² - 1` with the
//! bounded trust-region Gauss–Newton driver and exact (dual-number) derivatives. The initial
//! guess needs no user input: `v` from the smallest measured diameters, then `b` and `c` from a
//! straight-line fit of `ln(-ln y)` against `ln s`, `y = (d² - 1/v)/(d0² - 1/v)`.

use diffbvp::least_squares::{fit, FitOptions, LeastSquaresProblem, Termination};
use num_dual::{DualNum, DualSVec64};
use thiserror::Error;

/// Parameters of a fitted ansatz.
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothFit {
    /// Shape exponent `b` \[-\].
    pub b: f64,
    /// Length scale `c` \[m\].
    pub c: f64,
    /// Plateau `v` of `1/d²` \[1/m²\].
    pub v: f64,
    /// Start value `u0 = d_meas(0)^{-2}` \[1/m²\].
    pub u0: f64,
    /// RMS of the relative deviations `u_f(s_i) d_i² - 1` \[-\].
    pub rms: f64,
    /// Gauss–Newton iterations.
    pub iterations: usize,
    /// Why the fit stopped.
    pub termination: Termination,
}

/// Smoothing failed.
#[derive(Debug, Clone, Error)]
pub enum SmoothingError {
    /// Too few or invalid points.
    #[error("cannot smooth: {0}")]
    InvalidData(String),
    /// The least-squares fit failed.
    #[error("ansatz fit failed: {0}")]
    FitFailed(String),
}

/// `u_f / u0` with `w = v/u0` (scale-free form used in the fit).
fn ansatz_ratio<D: DualNum<Primitive = f64> + Copy>(s: f64, b: D, c: D, w: D) -> D {
    if s <= 0.0 {
        return D::one();
    }
    // E = exp((s/c)^b) computed as exp(exp(b ln(s/c)))
    let e = ((c.recip() * s).ln() * b).exp().exp();
    w * e / (e - 1.0 + w)
}

impl SmoothFit {
    /// `u_f(s)` \[1/m²\].
    pub fn velocity_like(&self, s: f64) -> f64 {
        self.u0 * ansatz_ratio(s, self.b, self.c, self.v / self.u0)
    }

    /// Smoothed diameter `d_fit(s) = u_f(s)^{-1/2}` \[m\] at position `s` \[m\].
    pub fn diameter(&self, s: f64) -> f64 {
        self.velocity_like(s).sqrt().recip()
    }
}

struct AnsatzProblem<'a> {
    s: &'a [f64],
    /// `(d_i/d_0)²`.
    d2: Vec<f64>,
}

impl LeastSquaresProblem for AnsatzProblem<'_> {
    type Error = SmoothingError;
    fn num_params(&self) -> usize {
        3
    }
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), SmoothingError> {
        let b = DualSVec64::<3>::from_re(p[0]).derivative(0);
        let c = DualSVec64::<3>::from_re(p[1]).derivative(1);
        let w = DualSVec64::<3>::from_re(p[2]).derivative(2);
        let mut r = Vec::with_capacity(self.s.len());
        let mut jac = Vec::with_capacity(3 * self.s.len());
        for (&s, &d2) in self.s.iter().zip(&self.d2) {
            let v = ansatz_ratio(s, b, c, w) * d2 - 1.0;
            if !v.re.is_finite() {
                return Err(SmoothingError::FitFailed(format!(
                    "non-finite ansatz value at s = {s} m for (b, c, v/u0) = {p:?}"
                )));
            }
            r.push(v.re);
            match &v.eps.0 {
                Some(g) => jac.extend((0..3).map(|i| g[i])),
                None => jac.extend([0.0; 3]),
            }
        }
        Ok((r, jac))
    }
}

/// Fits the ansatz to positions `s` \[m\] and diameters `d` \[m\] (first point at or near the
/// nozzle: `u0 = d[0]^{-2}`).
pub fn smooth(s: &[f64], d: &[f64]) -> Result<SmoothFit, SmoothingError> {
    if s.len() != d.len() {
        return Err(SmoothingError::InvalidData(format!(
            "{} positions but {} diameters",
            s.len(),
            d.len()
        )));
    }
    if s.len() < 4 {
        return Err(SmoothingError::InvalidData(format!(
            "{} points; the ansatz has 3 parameters and needs at least 4",
            s.len()
        )));
    }
    if d.iter().any(|&x| !(x > 0.0 && x.is_finite())) {
        return Err(SmoothingError::InvalidData(
            "diameters must be positive and finite".into(),
        ));
    }
    let u0 = 1.0 / (d[0] * d[0]);
    let d2: Vec<f64> = d.iter().map(|x| x * x).collect();
    let (b0, c0, w0) = initial_guess(s, &d2);
    let length = s[s.len() - 1].max(1e-9);
    let opts = FitOptions {
        initial_radius: 1.0,
        max_radius: 10.0,
        max_iterations: 200,
        ..FitOptions::with_bounds(
            vec![0.05, 1e-6 * length, 1.0 + 1e-9],
            vec![20.0, 100.0 * length, 1e6],
        )
    };
    // residual u_f d² - 1 = (u_f/u0) (d/d0)² - 1
    let ratio2: Vec<f64> = d2.iter().map(|x| x * u0).collect();
    let mut prob = AnsatzProblem { s, d2: ratio2 };
    let res = fit(&mut prob, &[b0, c0, w0], &opts)
        .map_err(|e| SmoothingError::FitFailed(e.to_string()))?;
    let rms = (2.0 * res.cost / s.len() as f64).sqrt();
    Ok(SmoothFit {
        b: res.p[0],
        c: res.p[1],
        v: res.p[2] * u0,
        u0,
        rms,
        iterations: res.iterations,
        termination: res.termination,
    })
}

/// `(b, c, v/u0)` from the data alone.
fn initial_guess(s: &[f64], d2: &[f64]) -> (f64, f64, f64) {
    let d0 = d2[0];
    let tail = d2.len().saturating_sub(3).max(1);
    let dmin = d2[tail..]
        .iter()
        .cloned()
        .fold(f64::INFINITY, f64::min)
        .min(d0 * 0.999);
    // plateau slightly below the smallest measured d² (noise)
    let dv = 0.9 * dmin;
    let w = (d0 / dv).max(1.0 + 1e-6);
    let (mut sx, mut sy, mut sxx, mut sxy, mut cnt) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (&si, &di) in s.iter().zip(d2) {
        let y = (di - dv) / (d0 - dv);
        if si > 0.0 && y > 0.02 && y < 0.98 {
            let (lx, ly) = (si.ln(), (-y.ln()).ln());
            sx += lx;
            sy += ly;
            sxx += lx * lx;
            sxy += lx * ly;
            cnt += 1.0;
        }
    }
    let length = s[s.len() - 1].max(1e-9);
    if cnt >= 2.0 && (cnt * sxx - sx * sx).abs() > 1e-12 {
        let b = ((cnt * sxy - sx * sy) / (cnt * sxx - sx * sx)).clamp(0.1, 10.0);
        let a = (sy - b * sx) / cnt; // ln(-ln y) = b ln s - b ln c
        let c = (-a / b).exp().clamp(1e-4 * length, 10.0 * length);
        (b, c, w)
    } else {
        (1.0, 0.1 * length, w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_ansatz_parameters_from_clean_ansatz_data() {
        let truth = SmoothFit {
            b: 0.8,
            c: 0.03,
            v: 1.0 / (60e-6f64).powi(2),
            u0: 1.0 / (1.1e-3f64).powi(2),
            rms: 0.0,
            iterations: 0,
            termination: Termination::Gradient,
        };
        let s: Vec<f64> = (0..26).map(|i| i as f64 * 0.02).collect();
        let d: Vec<f64> = s.iter().map(|&x| truth.diameter(x)).collect();
        let f = smooth(&s, &d).unwrap();
        assert!((f.b - truth.b).abs() < 1e-6 * truth.b, "{f:?}");
        assert!((f.c - truth.c).abs() < 1e-6 * truth.c, "{f:?}");
        assert!((f.v - truth.v).abs() < 1e-6 * truth.v, "{f:?}");
        assert!(f.rms < 1e-10);
        for &x in &[0.005, 0.1, 0.51] {
            assert!((f.diameter(x) - truth.diameter(x)).abs() < 1e-8 * truth.diameter(x));
        }
    }

    #[test]
    fn rejects_bad_input() {
        assert!(smooth(&[0.0, 0.1, 0.2], &[1e-3, 5e-4, 2e-4]).is_err());
        assert!(smooth(&[0.0, 0.1, 0.2, 0.3], &[1e-3, -5e-4, 2e-4, 1e-4]).is_err());
        assert!(smooth(&[0.0, 0.1], &[1e-3]).is_err());
    }
}

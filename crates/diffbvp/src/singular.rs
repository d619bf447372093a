//! The singular term `S y / x` of [`Bvp::singular_term`](crate::Bvp::singular_term), treated as
//! bvp4c (Shampine, Kierzenka & Reichelt) and scipy's `solve_bvp(S=...)` treat it.
//!
//! On `0 < x <= b` the right-hand side is `S y / x + f(x, y, p)`. A smooth solution has
//! `S y(0) = 0`, and then `y'(0) = S y'(0) + f(0, y(0), p)` (l'Hôpital), so at `x = 0` the
//! right-hand side is `D f(0, y(0), p)` with `D = (I − S)⁻¹`. The guess's `y(0)` is projected
//! with `B = I − S⁺ S` onto the null space of `S` (scipy projects the same way); the boundary
//! conditions must impose `S y(0) = 0`, checked at the solution. The term is linear in `y`, so
//! evaluating it with dual numbers gives its exact Jacobian `S / x` (and `D ∂f/∂(y, p)` at 0).

use crate::error::BvpError;
use nalgebra::DMatrix;
use num_dual::DualNum;

/// `S`, `D = (I − S)⁻¹` and the projector `B = I − S⁺ S` of one problem, `n × n` row-major.
#[derive(Debug, Clone)]
pub(crate) struct Singular {
    n: usize,
    s: Vec<f64>,
    d: Vec<f64>,
    b: Vec<f64>,
}

/// Largest `n` whose `D f` product at `x = 0` uses a stack buffer (larger systems allocate
/// once per pass, at the one node `x = 0`).
const STACK_DIM: usize = 16;

impl Singular {
    /// Checks `S` (size `n × n`, finite, `I − S` nonsingular) and the interval's start `a = 0`,
    /// and precomputes `D` and `B`.
    pub(crate) fn new(s: Vec<f64>, n: usize, a: f64) -> Result<Self, BvpError> {
        if s.len() != n * n {
            return Err(BvpError::InvalidInput(format!(
                "Bvp::singular_term returned {} entries; S must be the n x n = {n} x {n} matrix \
                 (row-major, {} entries) of y' = S y / x + f(x, y, p)",
                s.len(),
                n * n
            )));
        }
        if let Some(i) = s.iter().position(|v| !v.is_finite()) {
            return Err(BvpError::InvalidInput(format!(
                "entry ({}, {}) of the singular term S (Bvp::singular_term) is not finite",
                i / n,
                i % n
            )));
        }
        Self::check_start(a)?;
        let sm = DMatrix::from_row_slice(n, n, &s);
        let ims = DMatrix::identity(n, n) - &sm;
        // I − S must be safely invertible: y'(0) = (I − S)⁻¹ f(0, y(0), p)
        let sv = ims.singular_values();
        let (smax, smin) = sv.iter().fold((0.0f64, f64::INFINITY), |(hi, lo), &v| {
            (hi.max(v), lo.min(v))
        });
        if smin.is_nan() || smin <= 1e-12 * smax.max(1.0) {
            return Err(BvpError::InvalidInput(format!(
                "I - S is singular (smallest singular value {smin:.3e}, largest {smax:.3e}) for \
                 the singular term S of Bvp::singular_term: the slope y'(0) = (I - S)^-1 f(0, y(0), \
                 p) is not defined; an eigenvalue of S equal to 1 has no smooth solution of this \
                 form"
            )));
        }
        let d = ims.try_inverse().ok_or_else(|| {
            BvpError::InvalidInput(
                "I - S could not be inverted for the singular term S of Bvp::singular_term".into(),
            )
        })?;
        let pinv = sm
            .clone()
            .pseudo_inverse(1e-12 * sm.norm().max(1.0))
            .map_err(|e| {
                BvpError::InvalidInput(format!(
                    "the pseudo-inverse of the singular term S (Bvp::singular_term) failed: {e}"
                ))
            })?;
        let b = DMatrix::identity(n, n) - pinv * &sm;
        let row_major = |m: &DMatrix<f64>| -> Vec<f64> {
            (0..n)
                .flat_map(|r| (0..n).map(move |c| (r, c)))
                .map(|(r, c)| m[(r, c)])
                .collect()
        };
        Ok(Singular {
            n,
            s,
            d: row_major(&d),
            b: row_major(&b),
        })
    }

    /// The interval of a singular problem must start at `a = 0`.
    pub(crate) fn check_start(a: f64) -> Result<(), BvpError> {
        if a != 0.0 {
            return Err(BvpError::InvalidInput(format!(
                "the problem has a singular term S y / x (Bvp::singular_term), which needs the \
                 interval to start at a = 0, but the mesh starts at {a}; shift x so that the \
                 singular point is 0"
            )));
        }
        Ok(())
    }

    /// Whether this is the term of the matrix `s`.
    pub(crate) fn is_of(&self, s: &[f64]) -> bool {
        self.s == s
    }

    /// Adds the singular term to the right-hand side `f = f(x, y, p)` at `x >= 0`: `f += S y / x`
    /// for `x > 0`, `f = D f` at `x = 0`.
    #[inline]
    pub(crate) fn apply<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], f: &mut [D]) {
        let n = self.n;
        if x != 0.0 {
            let inv = 1.0 / x;
            for (r, fr) in f[..n].iter_mut().enumerate() {
                let row = &self.s[r * n..(r + 1) * n];
                for (&s, &yc) in row.iter().zip(y) {
                    if s != 0.0 {
                        *fr += yc * (s * inv);
                    }
                }
            }
            return;
        }
        if n <= STACK_DIM {
            let mut buf = [D::zero(); STACK_DIM];
            self.times_d(f, &mut buf[..n]);
            f[..n].copy_from_slice(&buf[..n]);
        } else {
            let mut buf = vec![D::zero(); n];
            self.times_d(f, &mut buf);
            f[..n].copy_from_slice(&buf);
        }
    }

    /// `out = D f`.
    fn times_d<D: DualNum<Primitive = f64> + Copy>(&self, f: &[D], out: &mut [D]) {
        let n = self.n;
        for (r, o) in out.iter_mut().enumerate() {
            let mut acc = D::zero();
            for (&d, &fc) in self.d[r * n..(r + 1) * n].iter().zip(f) {
                acc += fc * d;
            }
            *o = acc;
        }
    }

    /// Projects `y0 = y(0)` onto the null space of `S`: `y0 = B y0` (scipy's treatment of the
    /// guess).
    pub(crate) fn project(&self, y0: &mut [f64]) {
        let n = self.n;
        let old: Vec<f64> = y0[..n].to_vec();
        for (r, v) in y0[..n].iter_mut().enumerate() {
            *v = self.b[r * n..(r + 1) * n]
                .iter()
                .zip(&old)
                .map(|(b, y)| b * y)
                .sum();
        }
    }

    /// Checks the regularity condition `S y(0) = 0` at a solution: `|S y(0)|∞` may not exceed
    /// `10 tol (1 + ‖S‖∞ ‖y(0)‖∞)` (`tol` the boundary tolerance).
    pub(crate) fn check_regular(&self, y0: &[f64], tol: f64) -> Result<(), BvpError> {
        let n = self.n;
        let y_norm = y0[..n].iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let s_norm = (0..n)
            .map(|r| {
                self.s[r * n..(r + 1) * n]
                    .iter()
                    .map(|v| v.abs())
                    .sum::<f64>()
            })
            .fold(0.0f64, f64::max);
        let bound = 10.0 * tol * (1.0 + s_norm * y_norm);
        for r in 0..n {
            let v: f64 = self.s[r * n..(r + 1) * n]
                .iter()
                .zip(&y0[..n])
                .map(|(s, y)| s * y)
                .sum();
            if v.is_nan() || v.abs() > bound {
                return Err(BvpError::InvalidInput(format!(
                    "the regularity condition S y(0) = 0 of the singular term \
                     (Bvp::singular_term) is violated at the solution: component {r} of S y(0) \
                     is {v:.3e} (allowed {bound:.1e}); the boundary conditions must impose it \
                     (e.g. y'(0) = 0 for a (2/x) y' term)"
                )));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks_name_the_violated_condition() {
        let e = Singular::new(vec![0.0; 3], 2, 0.0).unwrap_err().to_string();
        assert!(e.contains("n x n = 2 x 2"), "{e}");
        let e = Singular::new(vec![0.0; 4], 2, 0.5).unwrap_err().to_string();
        assert!(e.contains("a = 0"), "{e}");
        let e = Singular::new(vec![1.0, 0.0, 0.0, -2.0], 2, 0.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("I - S is singular"), "{e}");
        let e = Singular::new(vec![f64::NAN, 0.0, 0.0, 0.0], 2, 0.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("(0, 0)"), "{e}");
    }

    #[test]
    fn projection_and_slope_at_zero_follow_scipy() {
        let s = Singular::new(vec![0.0, 0.0, 0.0, -2.0], 2, 0.0).unwrap();
        // B = diag(1, 0), D = diag(1, 1/3)
        let mut y0 = [2.0, 5.0];
        s.project(&mut y0);
        assert_eq!(y0, [2.0, 0.0]);
        let mut f = [1.0, 3.0];
        s.apply(0.0, &[2.0, 0.0], &mut f);
        assert!((f[0] - 1.0f64).abs() < 1e-15 && (f[1] - 1.0f64).abs() < 1e-15);
        let mut f = [1.0, 3.0];
        s.apply(0.5, &[2.0, 1.0], &mut f);
        assert_eq!(f, [1.0, 3.0 - 4.0]);
        assert!(s.check_regular(&[2.0, 0.0], 1e-8).is_ok());
        let e = s.check_regular(&[2.0, 0.1], 1e-8).unwrap_err().to_string();
        assert!(e.contains("S y(0) = 0"), "{e}");
    }
}

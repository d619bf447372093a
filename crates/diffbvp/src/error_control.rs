//! Residual-based error estimate of Kierzenka & Shampine (bvp4c), as in scipy's `solve_bvp`.
//!
//! The C1 cubic interpolant `S(x)` satisfies the ODE exactly at the nodes. Its residual
//! `r(x) = S'(x) - f(x, S(x), p)`, scaled componentwise by `s_c + |f_c|`, is integrated over each
//! interval with 5-point Lobatto quadrature (end points contribute zero): the midpoint residual is
//! `1.5 r_i / h_i` in terms of the collocation residual `r_i`, and two more points lie at
//! `x_mid ± h/2 √(3/7)`. The estimate is the RMS over the interval of the Euclidean norm of the
//! scaled residual.

use crate::collocation::Collocation;
use crate::problem::Bvp;
use crate::solution::hermite_weights;

/// Scaled RMS residual per interval, written into `rms` (length `m - 1`). Uses the node and
/// midpoint values stored in `col` by the last residual evaluation at `y`.
pub(crate) fn rms_residuals<P: Bvp>(
    problem: &P,
    col: &mut Collocation,
    y: &[f64],
    p: &[f64],
    scale: &[f64],
    rms: &mut Vec<f64>,
    buf: &mut Vec<f64>,
) {
    let (n, m) = (col.n, col.m());
    rms.clear();
    buf.resize(4 * n, 0.0);
    let (s1, rest) = buf.split_at_mut(n);
    let (d1, rest) = rest.split_at_mut(n);
    let (f1, _) = rest.split_at_mut(n);
    let off = 0.5 * (3.0f64 / 7.0).sqrt();
    // the Hermite weights at the two quadrature points for h = 1 (those of `hermite_weights`,
    // which scales them by h and 1/h the same way)
    let weights = [0.5 - off, 0.5 + off].map(|t| (t, hermite_weights(t, 1.0)));
    for i in 0..m - 1 {
        let h = col.h[i];
        if h == 0.0 {
            // an interface: no collocation polynomial to check
            rms.push(0.0);
            continue;
        }
        let mut r_mid = 0.0;
        let res_i = &col.res[i * n..(i + 1) * n];
        let fm_i = &col.f_mid[i * n..(i + 1) * n];
        for ((r, fm), sc) in res_i.iter().zip(fm_i).zip(scale) {
            let s = 1.5 * r / h / (sc + fm.abs());
            r_mid += s * s;
        }
        let (yi, yj) = (&y[i * n..(i + 1) * n], &y[(i + 1) * n..(i + 2) * n]);
        let (fi, fj) = (&col.f[i * n..(i + 1) * n], &col.f[(i + 1) * n..(i + 2) * n]);
        let mut r_12 = 0.0;
        for &(t, (v1, d1w)) in &weights {
            let v = [v1[0], h * v1[1], v1[2], h * v1[3]];
            let d = [d1w[0] / h, d1w[1], d1w[2] / h, d1w[3]];
            for c in 0..n {
                s1[c] = v[0] * yi[c] + v[1] * fi[c] + v[2] * yj[c] + v[3] * fj[c];
                d1[c] = d[0] * yi[c] + d[1] * fi[c] + d[2] * yj[c] + d[3] * fj[c];
            }
            problem.rhs_in_region(col.region[i], col.x[i] + t * h, s1, p, f1);
            if let Some(s) = &col.singular {
                s.apply(col.x[i] + t * h, s1, f1);
            }
            for ((d, f), sc) in d1.iter().zip(f1.iter()).zip(scale) {
                let s = (d - f) / (sc + f.abs());
                r_12 += s * s;
            }
        }
        col.rhs_evals += 2;
        let v = (0.5 * (32.0 / 45.0 * r_mid + 49.0 / 90.0 * r_12)).sqrt();
        rms.push(if v.is_finite() { v } else { f64::INFINITY });
    }
}

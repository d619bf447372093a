//! Exact Jacobians of small vector functions with forward-mode dual numbers.
//!
//! A function `out = F(input)` written generically over [`DualNum`] is evaluated with static
//! vector duals (`DualSVec64<W>`) that carry `W` directional derivatives at once. Derivatives
//! with respect to the first `n_seeds` inputs are computed in `ceil(n_seeds / W)` passes; the
//! remaining inputs are constants. The width `W ∈ {1, 2, 4, 8}` is chosen from `n_seeds`, so a
//! 4-state right-hand side needs one pass. Buffers are kept between calls: no allocation once
//! warmed up.

use crate::problem::Bvp;
use nalgebra::{Const, U1};
use num_dual::{Derivative, DualNum, DualSVec64};

/// A vector function of a slice of inputs, generic over the number type.
pub(crate) trait DualFn {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, input: &[D], out: &mut [D]);
}

/// `f(x, y, p)` with input `[y, p]`.
pub(crate) struct RhsFn<'a, P> {
    pub problem: &'a P,
    pub x: f64,
    pub n: usize,
}

impl<P: Bvp> DualFn for RhsFn<'_, P> {
    #[inline]
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, input: &[D], out: &mut [D]) {
        let (y, p) = input.split_at(self.n);
        self.problem.rhs(self.x, y, p, out);
    }
}

/// `g(ya, yb, p)` with input `[ya, yb, p]`.
pub(crate) struct BcFn<'a, P> {
    pub problem: &'a P,
    pub n: usize,
}

impl<P: Bvp> DualFn for BcFn<'_, P> {
    #[inline]
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, input: &[D], out: &mut [D]) {
        let (ya, rest) = input.split_at(self.n);
        let (yb, p) = rest.split_at(self.n);
        self.problem.bc(ya, yb, p, out);
    }
}

#[derive(Default)]
struct Buffers<const W: usize> {
    input: Vec<DualSVec64<W>>,
    out: Vec<DualSVec64<W>>,
    /// `(n_seeds, input length)` for which `input` holds the seeds of a single pass: the next
    /// call with the same shape only replaces the values.
    seeded_for: Option<(usize, usize)>,
}

impl<const W: usize> Buffers<W> {
    fn jacobian<F: DualFn>(
        &mut self,
        f: &F,
        input: &[f64],
        n_seeds: usize,
        out: &mut [f64],
        jac: &mut [f64],
    ) {
        let n_out = out.len();
        let single = n_seeds <= W;
        let seeded = single && self.seeded_for == Some((n_seeds, input.len()));
        if seeded {
            for (v, &x) in self.input.iter_mut().zip(input) {
                v.re = x;
            }
        } else {
            self.input.clear();
            self.input
                .extend(input.iter().map(|&v| DualSVec64::<W>::from_re(v)));
        }
        self.seeded_for = None;
        self.out.clear();
        self.out.resize(n_out, DualSVec64::<W>::from_re(0.0));
        let mut start = 0;
        while start < n_seeds.max(1) {
            let end = (start + W).min(n_seeds);
            if !seeded {
                for (j, v) in self.input.iter_mut().enumerate() {
                    v.eps = if j >= start && j < end {
                        Derivative::derivative_generic(Const::<W>, U1, j - start)
                    } else {
                        Derivative::none()
                    };
                }
            }
            for o in self.out.iter_mut() {
                *o = DualSVec64::<W>::from_re(0.0);
            }
            f.eval(&self.input, &mut self.out);
            for (i, o) in self.out.iter().enumerate() {
                if start == 0 {
                    out[i] = o.re;
                }
                let row = &mut jac[i * n_seeds..(i + 1) * n_seeds];
                match &o.eps.0 {
                    Some(d) => {
                        for j in start..end {
                            row[j] = d[j - start];
                        }
                    }
                    None => {
                        for v in &mut row[start..end] {
                            *v = 0.0;
                        }
                    }
                }
            }
            if n_seeds == 0 {
                break;
            }
            start = end;
        }
        if single {
            self.seeded_for = Some((n_seeds, input.len()));
        }
    }
}

/// Reusable workspace for dual-number Jacobians.
#[derive(Default)]
pub(crate) struct DualJacobian {
    w1: Buffers<1>,
    w2: Buffers<2>,
    w4: Buffers<4>,
    w8: Buffers<8>,
}

impl DualJacobian {
    /// Evaluates `out = F(input)` and the row-major Jacobian `jac[i * n_seeds + j] =
    /// ∂out_i/∂input_j` for the first `n_seeds` inputs.
    pub(crate) fn jacobian<F: DualFn>(
        &mut self,
        f: &F,
        input: &[f64],
        n_seeds: usize,
        out: &mut [f64],
        jac: &mut [f64],
    ) {
        debug_assert!(n_seeds <= input.len());
        debug_assert!(jac.len() >= out.len() * n_seeds);
        match n_seeds {
            0 | 1 => self.w1.jacobian(f, input, n_seeds, out, jac),
            2 => self.w2.jacobian(f, input, n_seeds, out, jac),
            3 | 4 => self.w4.jacobian(f, input, n_seeds, out, jac),
            _ => self.w8.jacobian(f, input, n_seeds, out, jac),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Poly;
    impl DualFn for Poly {
        fn eval<D: DualNum<Primitive = f64> + Copy>(&self, x: &[D], out: &mut [D]) {
            // out_i = sum_j (j+1) x_j^2 * x_i + sin(x_0) for a wide input
            let s: D = x
                .iter()
                .enumerate()
                .map(|(j, &v)| v * v * (j as f64 + 1.0))
                .sum();
            for (i, o) in out.iter_mut().enumerate() {
                *o = s * x[i] + x[0].sin();
            }
        }
    }

    #[test]
    fn chunked_jacobian_matches_analytic_for_all_widths() {
        for n in [1usize, 2, 3, 4, 5, 8, 9, 13] {
            let x: Vec<f64> = (0..n).map(|i| 0.3 + 0.1 * i as f64).collect();
            let mut out = vec![0.0; n];
            let mut jac = vec![0.0; n * n];
            let mut engine = DualJacobian::default();
            engine.jacobian(&Poly, &x, n, &mut out, &mut jac);
            let s: f64 = x
                .iter()
                .enumerate()
                .map(|(j, v)| v * v * (j as f64 + 1.0))
                .sum();
            for i in 0..n {
                assert!((out[i] - (s * x[i] + x[0].sin())).abs() < 1e-14);
                for j in 0..n {
                    let mut exact = 2.0 * (j as f64 + 1.0) * x[j] * x[i];
                    if i == j {
                        exact += s;
                    }
                    if j == 0 {
                        exact += x[0].cos();
                    }
                    assert!((jac[i * n + j] - exact).abs() < 1e-13, "n={n} i={i} j={j}");
                }
            }
        }
    }

    #[test]
    fn partial_seeding_leaves_constants() {
        let x = [0.5, 0.7, 0.9];
        let mut out = [0.0; 3];
        let mut jac = [0.0; 3];
        DualJacobian::default().jacobian(&Poly, &x, 1, &mut out, &mut jac);
        let s: f64 = 0.25 + 2.0 * 0.49 + 3.0 * 0.81;
        assert!((jac[0] - (s + 2.0 * 0.25 + 0.5f64.cos())).abs() < 1e-14);
        assert!((jac[1] - (2.0 * 0.5 * 0.7 + 0.5f64.cos())).abs() < 1e-14);
    }
}

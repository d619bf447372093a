//! Exact Jacobians of small vector functions with forward-mode dual numbers.
//!
//! A function `out = F(input)` written generically over [`DualNum`] is evaluated with static
//! vector duals ([`DenseDual64<W>`]) that carry `W` directional derivatives at once, always
//! stored (num-dual's `DualSVec64<W>`, whose slopes are optional, made the fiber model's 4-wide
//! pass 2.0× and its 8-wide pass 1.8× slower). Derivatives with respect to the seeded inputs
//! ([`Seeds`]: the first `n_seeds`, or a list) are computed in `ceil(n_seeds / W)` passes; the
//! remaining inputs are constants. The width `W ∈ {1, 2, 4, 8}` is chosen from `n_seeds`, so a
//! 4-state right-hand side needs one pass. Buffers are kept between calls: no allocation once
//! warmed up.

use crate::dense_dual::DenseDual64;
use crate::problem::Bvp;
use crate::singular::Singular;
use num_dual::DualNum;

/// A vector function of a slice of inputs, generic over the number type.
pub(crate) trait DualFn {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, input: &[D], out: &mut [D]);
}

/// `f(x, y, p)` with input `[y, p]`.
pub(crate) struct RhsFn<'a, P> {
    pub problem: &'a P,
    pub x: f64,
    pub n: usize,
    /// The problem's singular term, added to `f` (exact: it is linear in `y`).
    pub singular: Option<&'a Singular>,
    /// The region of a multipoint problem ([`Bvp::rhs_in_region`]).
    pub region: usize,
}

impl<P: Bvp> DualFn for RhsFn<'_, P> {
    #[inline]
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, input: &[D], out: &mut [D]) {
        let (y, p) = input.split_at(self.n);
        self.problem.rhs_in_region(self.region, self.x, y, p, out);
        if let Some(s) = self.singular {
            s.apply(self.x, y, out);
        }
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

/// The interface conditions `h_j(left, right, p)` with input `[left, right, p]` (the layout
/// of [`BcFn`]'s input).
pub(crate) struct InterfaceFn<'a, P> {
    pub problem: &'a P,
    pub index: usize,
    pub n: usize,
}

impl<P: Bvp> DualFn for InterfaceFn<'_, P> {
    #[inline]
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, input: &[D], out: &mut [D]) {
        let (left, rest) = input.split_at(self.n);
        let (right, p) = rest.split_at(self.n);
        self.problem
            .interface_conditions(self.index, left, right, p, out);
    }
}

/// The inputs a Jacobian is taken in: its columns, in order.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Seeds<'a> {
    /// The first `n` inputs.
    First(usize),
    /// The inputs at these indices (strictly increasing).
    These(&'a [usize]),
}

impl Seeds<'_> {
    /// Number of seeded inputs (= Jacobian columns).
    #[inline]
    pub(crate) fn len(&self) -> usize {
        match self {
            Seeds::First(n) => *n,
            Seeds::These(l) => l.len(),
        }
    }

    /// Input index of column `j`.
    #[inline]
    fn input(&self, j: usize) -> usize {
        match self {
            Seeds::First(_) => j,
            Seeds::These(l) => l[j],
        }
    }

    /// Whether these seeds are those recorded in `first`/`list` by [`Seeds::record`].
    fn same_as(&self, first: usize, list: &[usize]) -> bool {
        match self {
            Seeds::First(n) => list.is_empty() && *n == first,
            Seeds::These(l) => first == usize::MAX && *l == list,
        }
    }

    /// Records these seeds (for [`Seeds::same_as`]).
    fn record(&self, first: &mut usize, list: &mut Vec<usize>) {
        list.clear();
        match self {
            Seeds::First(n) => *first = *n,
            Seeds::These(l) => {
                *first = usize::MAX;
                list.extend_from_slice(l);
            }
        }
    }
}

#[derive(Default)]
struct Buffers<const W: usize> {
    input: Vec<DenseDual64<W>>,
    out: Vec<DenseDual64<W>>,
    /// Input length for which `input` holds the seeds of a single pass (those recorded in
    /// `seeded_first` and `seeded_list`): the next call with the same seeds only replaces the
    /// values.
    seeded_for: Option<usize>,
    seeded_first: usize,
    seeded_list: Vec<usize>,
}

impl<const W: usize> Buffers<W> {
    fn jacobian<F: DualFn>(
        &mut self,
        f: &F,
        input: &[f64],
        seeds: Seeds<'_>,
        out: &mut [f64],
        jac: &mut [f64],
    ) {
        let n_seeds = seeds.len();
        let n_out = out.len();
        let single = n_seeds <= W;
        let seeded = single
            && self.seeded_for == Some(input.len())
            && seeds.same_as(self.seeded_first, &self.seeded_list);
        if seeded {
            for (v, &x) in self.input.iter_mut().zip(input) {
                v.re = x;
            }
        } else {
            self.input.clear();
            self.input
                .extend(input.iter().map(|&v| DenseDual64::<W>::from_re(v)));
        }
        self.seeded_for = None;
        self.out.clear();
        self.out.resize(n_out, DenseDual64::<W>::from_re(0.0));
        let mut start = 0;
        while start < n_seeds.max(1) {
            let end = (start + W).min(n_seeds);
            if !seeded {
                for v in self.input.iter_mut() {
                    *v = DenseDual64::<W>::from_re(v.re);
                }
                for j in start..end {
                    let v = &mut self.input[seeds.input(j)];
                    *v = v.derivative(j - start);
                }
            }
            for o in self.out.iter_mut() {
                *o = DenseDual64::<W>::from_re(0.0);
            }
            f.eval(&self.input, &mut self.out);
            for (i, o) in self.out.iter().enumerate() {
                if start == 0 {
                    out[i] = o.re;
                }
                let row = &mut jac[i * n_seeds..(i + 1) * n_seeds];
                for j in start..end {
                    row[j] = o.eps.0[j - start];
                }
            }
            if n_seeds == 0 {
                break;
            }
            start = end;
        }
        if single {
            self.seeded_for = Some(input.len());
            seeds.record(&mut self.seeded_first, &mut self.seeded_list);
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
        self.jacobian_in(f, input, Seeds::First(n_seeds), out, jac)
    }

    /// Evaluates `out = F(input)` and the row-major Jacobian `jac[i * s + j] =
    /// ∂out_i/∂input_{seed j}` for the `s = seeds.len()` seeded inputs.
    pub(crate) fn jacobian_in<F: DualFn>(
        &mut self,
        f: &F,
        input: &[f64],
        seeds: Seeds<'_>,
        out: &mut [f64],
        jac: &mut [f64],
    ) {
        let n_seeds = seeds.len();
        debug_assert!(n_seeds == 0 || seeds.input(n_seeds - 1) < input.len());
        debug_assert!(jac.len() >= out.len() * n_seeds);
        match n_seeds {
            0 | 1 => self.w1.jacobian(f, input, seeds, out, jac),
            2 => self.w2.jacobian(f, input, seeds, out, jac),
            3 | 4 => self.w4.jacobian(f, input, seeds, out, jac),
            _ => self.w8.jacobian(f, input, seeds, out, jac),
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
    fn listed_seeds_are_the_columns_of_the_full_jacobian() {
        let x: Vec<f64> = (0..13).map(|i| 0.2 + 0.07 * i as f64).collect();
        let mut full = vec![0.0; 13 * 13];
        let mut out = vec![0.0; 13];
        let mut engine = DualJacobian::default();
        engine.jacobian(&Poly, &x, 13, &mut out, &mut full);
        // one pass (4 seeds), two passes (9 seeds); the same list twice (cached seeds), then a
        // prefix of the same length (the cache must not mistake one for the other)
        for list in [
            vec![0, 3, 7, 12],
            vec![0, 1, 2, 3, 5, 6, 9, 11, 12],
            vec![0, 3, 7, 12],
        ] {
            let s = list.len();
            let mut jac = vec![0.0; 13 * s];
            let mut o = vec![0.0; 13];
            engine.jacobian_in(&Poly, &x, Seeds::These(&list), &mut o, &mut jac);
            assert_eq!(o, out);
            for i in 0..13 {
                for (j, &c) in list.iter().enumerate() {
                    assert_eq!(jac[i * s + j], full[i * 13 + c], "row {i}, input {c}");
                }
            }
        }
        let mut jac = vec![0.0; 13 * 4];
        engine.jacobian(&Poly, &x, 4, &mut out, &mut jac);
        for i in 0..13 {
            for c in 0..4 {
                assert_eq!(
                    jac[i * 4 + c],
                    full[i * 13 + c],
                    "prefix row {i}, input {c}"
                );
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

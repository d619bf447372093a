//! Exact Jacobians of small vector functions with forward-mode dual numbers.
//!
//! A function `out = F(input)` written generically over [`DualNum`] is evaluated with static
//! vector duals ([`DenseDual64<W>`]) that carry `W` directional derivatives at once, always
//! stored (num-dual's `DualSVec64<W>`, whose slopes are optional, branches on every operation;
//! the measured cost is in `benches/README.md`). Derivatives with respect to the seeded inputs
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

impl<const W: usize> Buffers<W> {
    /// The Jacobian in the seeded inputs by column compression: the columns of one colour of
    /// `coloring` share a dual direction, and each row reads back only the columns its pattern
    /// lists (the others are zero).
    fn jacobian_colored<F: DualFn>(
        &mut self,
        f: &F,
        input: &[f64],
        seeds: Seeds<'_>,
        coloring: &Coloring,
        out: &mut [f64],
        jac: &mut [f64],
    ) {
        let n_seeds = seeds.len();
        let n_out = out.len();
        self.seeded_for = None;
        self.input.clear();
        self.input
            .extend(input.iter().map(|&v| DenseDual64::<W>::from_re(v)));
        self.out.clear();
        self.out.resize(n_out, DenseDual64::<W>::from_re(0.0));
        jac[..n_out * n_seeds].fill(0.0);
        let mut start = 0;
        while start < coloring.colors.max(1) {
            let end = (start + W).min(coloring.colors);
            for v in self.input.iter_mut() {
                *v = DenseDual64::<W>::from_re(v.re);
            }
            for (j, &c) in coloring.color.iter().enumerate() {
                if (start..end).contains(&c) {
                    let v = &mut self.input[seeds.input(j)];
                    v.eps.0[c - start] = 1.0;
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
                for &j in coloring.row(i) {
                    let c = coloring.color[j];
                    if (start..end).contains(&c) {
                        row[j] = o.eps.0[c - start];
                    }
                }
            }
            if coloring.colors == 0 {
                break;
            }
            start = end;
        }
    }
}

/// A colouring of the seeded columns of a sparse Jacobian ([`Bvp::rhs_sparsity`]): columns
/// that share no row get the same colour, so one dual direction carries them all (Curtis,
/// Powell and Reid's compression, greedy in column order). Its buffers are kept between builds.
#[derive(Default, Debug)]
pub(crate) struct Coloring {
    /// Colour of each seeded column.
    color: Vec<usize>,
    /// Number of colours.
    colors: usize,
    /// The seeded columns of row `i` (ascending): `cols[row_start[i]..row_start[i + 1]]`.
    row_start: Vec<usize>,
    cols: Vec<usize>,
    /// Seeded column of each input (`usize::MAX` where not seeded).
    column_of: Vec<usize>,
    /// The rows of each column (`col_rows[col_start[j]..col_start[j + 1]]`).
    col_start: Vec<usize>,
    col_rows: Vec<usize>,
    /// Per colour, the last column that found it taken.
    taken: Vec<usize>,
    /// Scratch: the next free slot of every column in `col_rows`.
    fill: Vec<usize>,
}

impl Coloring {
    /// Colours the columns `seeds` of a Jacobian whose row `i` depends on the inputs
    /// `pattern[i]` (indices below `n_inputs`). Returns whether compression saves dual passes
    /// (fewer colours than seeded columns).
    pub(crate) fn build(
        &mut self,
        pattern: &[Vec<usize>],
        seeds: Seeds<'_>,
        n_inputs: usize,
    ) -> bool {
        let s = seeds.len();
        self.column_of.clear();
        self.column_of.resize(n_inputs, usize::MAX);
        for j in 0..s {
            self.column_of[seeds.input(j)] = j;
        }
        self.row_start.clear();
        self.cols.clear();
        self.row_start.push(0);
        for deps in pattern {
            let first = self.cols.len();
            self.cols.extend(
                deps.iter()
                    .filter_map(|&d| self.column_of.get(d).copied())
                    .filter(|&j| j != usize::MAX),
            );
            self.cols[first..].sort_unstable();
            let mut w = first;
            for r in first..self.cols.len() {
                if r == first || self.cols[r] != self.cols[w - 1] {
                    self.cols[w] = self.cols[r];
                    w += 1;
                }
            }
            self.cols.truncate(w);
            self.row_start.push(self.cols.len());
        }
        // the rows of every column (counting sort of the row lists)
        self.col_start.clear();
        self.col_start.resize(s + 1, 0);
        for &j in &self.cols {
            self.col_start[j + 1] += 1;
        }
        for j in 0..s {
            self.col_start[j + 1] += self.col_start[j];
        }
        self.col_rows.clear();
        self.col_rows.resize(self.cols.len(), 0);
        self.fill.clear();
        self.fill.extend_from_slice(&self.col_start[..s]);
        for i in 0..pattern.len() {
            for &j in &self.cols[self.row_start[i]..self.row_start[i + 1]] {
                self.col_rows[self.fill[j]] = i;
                self.fill[j] += 1;
            }
        }
        self.color.clear();
        self.color.resize(s, usize::MAX);
        self.taken.clear();
        self.colors = 0;
        for j in 0..s {
            for &i in &self.col_rows[self.col_start[j]..self.col_start[j + 1]] {
                for &other in &self.cols[self.row_start[i]..self.row_start[i + 1]] {
                    let c = self.color[other];
                    if c != usize::MAX {
                        self.taken[c] = j;
                    }
                }
            }
            let c = (0..self.colors)
                .find(|&c| self.taken[c] != j)
                .unwrap_or(self.colors);
            if c == self.colors {
                self.colors += 1;
                self.taken.push(usize::MAX);
            }
            self.color[j] = c;
        }
        self.colors < s
    }

    /// The seeded columns row `i` depends on.
    fn row(&self, i: usize) -> &[usize] {
        &self.cols[self.row_start[i]..self.row_start[i + 1]]
    }

    /// Dual passes of a compressed Jacobian (at most 8 directions each).
    pub(crate) fn passes(&self) -> usize {
        self.colors.div_ceil(8).max(1)
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

impl DualJacobian {
    /// [`jacobian_in`](Self::jacobian_in) by column compression with `coloring` (built for
    /// `seeds` by [`Coloring::build`]): the same derivatives in `ceil(colours / W)` passes.
    pub(crate) fn jacobian_colored<F: DualFn>(
        &mut self,
        f: &F,
        input: &[f64],
        seeds: Seeds<'_>,
        coloring: &Coloring,
        out: &mut [f64],
        jac: &mut [f64],
    ) {
        debug_assert_eq!(coloring.color.len(), seeds.len());
        debug_assert_eq!(coloring.row_start.len(), out.len() + 1);
        match coloring.colors {
            0 | 1 => self
                .w1
                .jacobian_colored(f, input, seeds, coloring, out, jac),
            2 => self
                .w2
                .jacobian_colored(f, input, seeds, coloring, out, jac),
            3 | 4 => self
                .w4
                .jacobian_colored(f, input, seeds, coloring, out, jac),
            _ => self
                .w8
                .jacobian_colored(f, input, seeds, coloring, out, jac),
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

    /// `out_i = x_i x_{(i+3) mod n} + sin(x_n)` for `n` outputs of `n + 1` inputs: a banded
    /// part and one input every row reads.
    struct Banded(usize);
    impl DualFn for Banded {
        fn eval<D: DualNum<Primitive = f64> + Copy>(&self, x: &[D], out: &mut [D]) {
            let n = self.0;
            for (i, o) in out.iter_mut().enumerate() {
                *o = x[i] * x[(i + 3) % n] + x[n].sin();
            }
        }
    }

    #[test]
    fn colored_jacobian_equals_the_dense_one() {
        for n in [3usize, 5, 8, 13, 40] {
            let x: Vec<f64> = (0..=n).map(|i| 0.2 + 0.05 * i as f64).collect();
            let pattern: Vec<Vec<usize>> = (0..n).map(|i| vec![i, (i + 3) % n, n]).collect();
            let f = Banded(n);
            let mut engine = DualJacobian::default();
            let mut out = vec![0.0; n];
            let mut full = vec![0.0; n * (n + 1)];
            engine.jacobian(&f, &x, n + 1, &mut out, &mut full);
            // all columns, the states only, and a list that skips some
            let lists: [Vec<usize>; 3] = [
                (0..=n).collect(),
                (0..n).collect(),
                (0..=n).filter(|j| j % 3 != 1).collect(),
            ];
            for list in &lists {
                let s = list.len();
                let mut coloring = Coloring::default();
                let saves = coloring.build(&pattern, Seeds::These(list), n + 1);
                // a band of width 2 and one dense column: at most 4 colours
                assert!(coloring.colors <= 4, "n = {n}: {} colours", coloring.colors);
                assert_eq!(saves, coloring.colors < s);
                let mut jac = vec![f64::NAN; n * s];
                let mut o = vec![0.0; n];
                engine.jacobian_colored(&f, &x, Seeds::These(list), &coloring, &mut o, &mut jac);
                assert_eq!(o, out);
                for i in 0..n {
                    for (j, &c) in list.iter().enumerate() {
                        assert_eq!(
                            jac[i * s + j],
                            full[i * (n + 1) + c],
                            "n {n} row {i} in {c}"
                        );
                    }
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

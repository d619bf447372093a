//! Block-arrow least-squares problems: parameters shared by every residual plus parameters local
//! to one block of residuals (one experiment's take-up factor, one camera's pose in bundle
//! adjustment). The Jacobian then has the block-arrow pattern
//!
//! ```text
//!          shared   local 0   local 1  …  local M−1
//! rows 0 [  J_s0  |  J_l0   |    0    |     0     ]
//! rows 1 [  J_s1  |    0    |  J_l1   |     0     ]
//!   …
//! ```
//!
//! and its normal matrix `JᵀJ` the arrow `[[A, B], [Bᵀ, C]]` with `C` block diagonal. A
//! [`BlockStructure`] declares it; a [`BlockJacobian`] stores only the nonzero blocks
//! (`N (n_s + n_l)` numbers instead of `N · P`); the trust-region step and the covariance are
//! then computed through the Schur complement `S = A − Σ_k B_k C_k⁻¹ B_kᵀ` (`n_s × n_s`), in time
//! and memory linear in the number of blocks.
//!
//! Ordering: the parameter vector is `[shared…, locals of block 0…, locals of block 1…, …]`, the
//! residual vector `[rows of block 0…, rows of block 1…, …]`.

use nalgebra::{DMatrix, DVector};
use std::ops::Range;
use std::sync::Arc;

/// The block-arrow structure of a least-squares problem (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BlockStructure {
    num_shared: usize,
    // per block: first row, first local parameter (global index), and one past the last of each
    rows: Vec<usize>,
    locals: Vec<usize>,
}

impl BlockStructure {
    /// `num_shared` shared parameters and blocks of `(residuals, local parameters)`, in order.
    pub fn new(num_shared: usize, blocks: impl IntoIterator<Item = (usize, usize)>) -> Self {
        let (mut rows, mut locals) = (vec![0], vec![num_shared]);
        for (nr, nl) in blocks {
            rows.push(rows[rows.len() - 1] + nr);
            locals.push(locals[locals.len() - 1] + nl);
        }
        BlockStructure {
            num_shared,
            rows,
            locals,
        }
    }

    /// Number of shared parameters `n_s`.
    pub fn num_shared(&self) -> usize {
        self.num_shared
    }

    /// Number of blocks `M`.
    pub fn num_blocks(&self) -> usize {
        self.rows.len() - 1
    }

    /// Number of parameters `P = n_s + Σ n_l,k`.
    pub fn num_params(&self) -> usize {
        self.locals[self.locals.len() - 1]
    }

    /// Number of residuals `N`.
    pub fn num_residuals(&self) -> usize {
        self.rows[self.rows.len() - 1]
    }

    /// Total number of local parameters.
    pub fn num_local(&self) -> usize {
        self.num_params() - self.num_shared
    }

    /// The residual rows of block `k`.
    pub fn rows(&self, k: usize) -> Range<usize> {
        self.rows[k]..self.rows[k + 1]
    }

    /// The local parameters of block `k` (indices into the parameter vector).
    pub fn locals(&self, k: usize) -> Range<usize> {
        self.locals[k]..self.locals[k + 1]
    }

    /// The block whose local parameters include parameter `p` and `p`'s position among them
    /// (`None` for a shared parameter or `p ≥ P`).
    pub fn block_of_param(&self, p: usize) -> Option<(usize, usize)> {
        if p < self.num_shared || p >= self.num_params() {
            return None;
        }
        let k = self.locals.partition_point(|&l| l <= p) - 1;
        Some((k, p - self.locals[k]))
    }

    /// The block that residual `i` belongs to (`None` for `i ≥ N`).
    pub fn block_of_row(&self, i: usize) -> Option<usize> {
        (i < self.num_residuals()).then(|| self.rows.partition_point(|&r| r <= i) - 1)
    }

    /// Offset of block `k`'s local Jacobian in [`BlockJacobian::local`].
    fn local_offset(&self, k: usize) -> usize {
        (0..k)
            .map(|j| self.rows(j).len() * self.locals(j).len())
            .sum()
    }

    /// Number of stored Jacobian entries, `N n_s + Σ_k N_k n_l,k`.
    pub fn jacobian_len(&self) -> usize {
        self.num_residuals() * self.num_shared
            + (0..self.num_blocks())
                .map(|k| self.rows(k).len() * self.locals(k).len())
                .sum::<usize>()
    }

    /// Bytes the fit driver holds per evaluation of this structure: residuals, Jacobian, its
    /// robustly rescaled copy and the step's per-block factors (an estimate for planning a
    /// large fit; the problem's own state comes on top).
    pub fn driver_bytes(&self) -> usize {
        let n = self.num_residuals() + self.jacobian_len();
        let per_block: usize = (0..self.num_blocks())
            .map(|k| {
                let nl = self.locals(k).len();
                nl * nl + nl * (self.num_shared + 2)
            })
            .sum();
        8 * (3 * n + 2 * per_block + 4 * self.num_params())
    }
}

/// A Jacobian in block-arrow form: for every residual its row in the shared columns, and for
/// every block the rows of its residuals in its own local columns (both row-major).
#[derive(Debug, Clone, PartialEq)]
pub struct BlockJacobian {
    structure: Arc<BlockStructure>,
    shared: Vec<f64>,
    local: Vec<f64>,
    // offsets of the blocks' local Jacobians in `local` (length M + 1)
    offsets: Arc<Vec<usize>>,
}

impl BlockJacobian {
    /// A zero Jacobian of `structure`.
    pub fn zeros(structure: Arc<BlockStructure>) -> Self {
        let m = structure.num_blocks();
        let offsets: Vec<usize> = (0..=m).map(|k| structure.local_offset(k)).collect();
        BlockJacobian {
            shared: vec![0.0; structure.num_residuals() * structure.num_shared()],
            local: vec![0.0; offsets[m]],
            offsets: Arc::new(offsets),
            structure,
        }
    }

    /// A zero Jacobian with the same structure as `self` (no recomputation of offsets).
    pub fn zeros_like(&self) -> Self {
        BlockJacobian {
            structure: self.structure.clone(),
            shared: vec![0.0; self.shared.len()],
            local: vec![0.0; self.local.len()],
            offsets: self.offsets.clone(),
        }
    }

    /// Reads the blocks from a dense row-major `N × P` Jacobian; `None` if an entry outside
    /// the declared blocks is nonzero or the size is wrong.
    pub fn from_dense(structure: Arc<BlockStructure>, dense: &[f64]) -> Option<Self> {
        let (nr, np) = (structure.num_residuals(), structure.num_params());
        if dense.len() != nr * np {
            return None;
        }
        let mut j = BlockJacobian::zeros(structure.clone());
        let ns = structure.num_shared();
        for k in 0..structure.num_blocks() {
            let cols = structure.locals(k);
            for i in structure.rows(k) {
                let row = &dense[i * np..(i + 1) * np];
                j.shared[i * ns..(i + 1) * ns].copy_from_slice(&row[..ns]);
                let outside = row[ns..]
                    .iter()
                    .enumerate()
                    .any(|(c, v)| *v != 0.0 && !cols.contains(&(ns + c)));
                if outside {
                    return None;
                }
                let nl = cols.len();
                let off = j.offsets[k] + (i - structure.rows[k]) * nl;
                j.local[off..off + nl].copy_from_slice(&row[cols.clone()]);
            }
        }
        Some(j)
    }

    /// The structure.
    pub fn structure(&self) -> &Arc<BlockStructure> {
        &self.structure
    }

    /// The shared columns, row-major `N × n_s`.
    pub fn shared(&self) -> &[f64] {
        &self.shared
    }

    /// The shared columns, mutable.
    pub fn shared_mut(&mut self) -> &mut [f64] {
        &mut self.shared
    }

    /// Block `k`'s local columns at its rows, row-major `N_k × n_l,k`.
    pub fn local(&self, k: usize) -> &[f64] {
        &self.local[self.offsets[k]..self.offsets[k + 1]]
    }

    /// Block `k`'s rows: its shared columns (`N_k × n_s`) and its local columns
    /// (`N_k × n_l,k`), mutable (e.g. to fill them from a parallel evaluation).
    pub fn block_mut(&mut self, k: usize) -> (&mut [f64], &mut [f64]) {
        let ns = self.structure.num_shared();
        let rows = self.structure.rows(k);
        (
            &mut self.shared[rows.start * ns..rows.end * ns],
            &mut self.local[self.offsets[k]..self.offsets[k + 1]],
        )
    }

    /// Every block's rows, mutable, in block order (see [`block_mut`](Self::block_mut)).
    pub fn blocks_mut(&mut self) -> Vec<(&mut [f64], &mut [f64])> {
        let ns = self.structure.num_shared();
        let mut out = Vec::with_capacity(self.structure.num_blocks());
        let (mut shared, mut local) = (&mut self.shared[..], &mut self.local[..]);
        for k in 0..self.structure.num_blocks() {
            let (s, rest) = shared.split_at_mut(self.structure.rows(k).len() * ns);
            let (l, lrest) = local.split_at_mut(self.offsets[k + 1] - self.offsets[k]);
            out.push((s, l));
            shared = rest;
            local = lrest;
        }
        out
    }

    /// Whether every entry is finite.
    pub fn is_finite(&self) -> bool {
        self.shared.iter().chain(&self.local).all(|v| v.is_finite())
    }

    /// Entry `(i, j)` (0 outside the blocks).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let s = &self.structure;
        let ns = s.num_shared();
        if j < ns {
            return self.shared[i * ns + j];
        }
        let Some(k) = s.block_of_row(i) else {
            return 0.0;
        };
        let cols = s.locals(k);
        if !cols.contains(&j) {
            return 0.0;
        }
        self.local[self.offsets[k] + (i - s.rows[k]) * cols.len() + (j - cols.start)]
    }

    /// The dense row-major `N × P` Jacobian (`N · P` numbers: for small problems and checks).
    pub fn to_dense(&self) -> Vec<f64> {
        let s = &self.structure;
        let (ns, np) = (s.num_shared(), s.num_params());
        let mut d = vec![0.0; s.num_residuals() * np];
        for k in 0..s.num_blocks() {
            let cols = s.locals(k);
            let nl = cols.len();
            let loc = self.local(k);
            for (a, i) in s.rows(k).enumerate() {
                let row = &mut d[i * np..(i + 1) * np];
                row[..ns].copy_from_slice(&self.shared[i * ns..(i + 1) * ns]);
                row[cols.clone()].copy_from_slice(&loc[a * nl..(a + 1) * nl]);
            }
        }
        d
    }

    /// `J x` (length `N`).
    pub fn mul_vec(&self, x: &[f64]) -> Vec<f64> {
        let s = &self.structure;
        let ns = s.num_shared();
        let mut y = vec![0.0; s.num_residuals()];
        for k in 0..s.num_blocks() {
            let cols = s.locals(k);
            let nl = cols.len();
            let loc = self.local(k);
            for (a, i) in s.rows(k).enumerate() {
                let sh = &self.shared[i * ns..(i + 1) * ns];
                let mut v: f64 = sh.iter().zip(&x[..ns]).map(|(a, b)| a * b).sum();
                v += loc[a * nl..(a + 1) * nl]
                    .iter()
                    .zip(&x[cols.clone()])
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
                y[i] = v;
            }
        }
        y
    }

    /// `Jᵀ r` (length `P`).
    pub fn tr_mul_vec(&self, r: &[f64]) -> Vec<f64> {
        let s = &self.structure;
        let ns = s.num_shared();
        let mut g = vec![0.0; s.num_params()];
        for k in 0..s.num_blocks() {
            let cols = s.locals(k);
            let nl = cols.len();
            let loc = self.local(k);
            for (a, i) in s.rows(k).enumerate() {
                let ri = r[i];
                for (gj, v) in g[..ns].iter_mut().zip(&self.shared[i * ns..(i + 1) * ns]) {
                    *gj += v * ri;
                }
                for (gj, v) in g[cols.clone()].iter_mut().zip(&loc[a * nl..(a + 1) * nl]) {
                    *gj += v * ri;
                }
            }
        }
        g
    }

    /// Multiplies row `i` by `f[i]` (the robust losses' rescaling).
    pub fn scale_rows(&mut self, f: &[f64]) {
        let s = self.structure.clone();
        let ns = s.num_shared();
        for k in 0..s.num_blocks() {
            let nl = s.locals(k).len();
            let (sh, loc) = self.block_mut(k);
            for (a, i) in s.rows(k).enumerate() {
                let fi = f[i];
                for v in &mut sh[a * ns..(a + 1) * ns] {
                    *v *= fi;
                }
                for v in &mut loc[a * nl..(a + 1) * nl] {
                    *v *= fi;
                }
            }
        }
    }

    /// The normal equations' blocks of `Jᵀ W J` with row weights `w` (all 1 if `None`), the
    /// columns scaled by `1/d` (`d` per parameter; all 1 if `None`): the shared block `A`
    /// (`n_s × n_s`) and per block `B_k` (`n_s × n_l,k`) and `C_k` (`n_l,k × n_l,k`).
    pub(crate) fn normal_blocks(&self, w: Option<&[f64]>, d: Option<&[f64]>) -> NormalBlocks {
        let s = &self.structure;
        let ns = s.num_shared();
        let inv = |j: usize| d.map_or(1.0, |d| 1.0 / d[j]);
        let mut a = DMatrix::zeros(ns, ns);
        let mut b = Vec::with_capacity(s.num_blocks());
        let mut c = Vec::with_capacity(s.num_blocks());
        let mut sh = vec![0.0; ns];
        let mut lo = Vec::new();
        for k in 0..s.num_blocks() {
            let cols = s.locals(k);
            let nl = cols.len();
            let loc = self.local(k);
            let mut bk = DMatrix::zeros(ns, nl);
            let mut ck = DMatrix::zeros(nl, nl);
            for (r, i) in s.rows(k).enumerate() {
                let wi = w.map_or(1.0, |w| w[i]);
                for (j, v) in sh.iter_mut().enumerate() {
                    *v = self.shared[i * ns + j] * inv(j);
                }
                lo.clear();
                lo.extend((0..nl).map(|j| loc[r * nl + j] * inv(cols.start + j)));
                for p in 0..ns {
                    let wp = wi * sh[p];
                    if wp == 0.0 {
                        continue;
                    }
                    for q in p..ns {
                        a[(p, q)] += wp * sh[q];
                    }
                    for (q, l) in lo.iter().enumerate() {
                        bk[(p, q)] += wp * l;
                    }
                }
                for p in 0..nl {
                    let wp = wi * lo[p];
                    for q in p..nl {
                        ck[(p, q)] += wp * lo[q];
                    }
                }
            }
            for p in 0..nl {
                for q in 0..p {
                    ck[(p, q)] = ck[(q, p)];
                }
            }
            b.push(bk);
            c.push(ck);
        }
        for p in 0..ns {
            for q in 0..p {
                a[(p, q)] = a[(q, p)];
            }
        }
        NormalBlocks { a, b, c }
    }

    /// `(Jᵀ r)` split into its shared part and per block its local part, columns scaled by
    /// `1/d`.
    pub(crate) fn scaled_gradient(
        &self,
        r: &[f64],
        d: &[f64],
    ) -> (DVector<f64>, Vec<DVector<f64>>) {
        let g = self.tr_mul_vec(r);
        let s = &self.structure;
        let ns = s.num_shared();
        let gs = DVector::from_iterator(ns, (0..ns).map(|j| g[j] / d[j]));
        let gl = (0..s.num_blocks())
            .map(|k| {
                let cols = s.locals(k);
                DVector::from_iterator(cols.len(), cols.map(|j| g[j] / d[j]))
            })
            .collect();
        (gs, gl)
    }
}

/// The blocks of a block-arrow normal matrix `[[A, B], [Bᵀ, C]]`.
pub(crate) struct NormalBlocks {
    pub a: DMatrix<f64>,
    pub b: Vec<DMatrix<f64>>,
    pub c: Vec<DMatrix<f64>>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> BlockJacobian {
        // 2 shared, blocks (2 rows, 1 local), (3 rows, 2 locals), (1 row, 0 locals)
        let s = Arc::new(BlockStructure::new(2, [(2, 1), (3, 2), (1, 0)]));
        let mut j = BlockJacobian::zeros(s);
        let mut v = 0.5;
        for (sh, lo) in j.blocks_mut() {
            for x in sh.iter_mut().chain(lo.iter_mut()) {
                v = (v * 3.7 + 0.3) % 2.0 - 1.0;
                *x = v;
            }
        }
        j
    }

    #[test]
    fn structure_counts_and_ranges() {
        let j = example();
        let s = j.structure();
        assert_eq!(
            (s.num_params(), s.num_residuals(), s.num_blocks()),
            (5, 6, 3)
        );
        assert_eq!((s.rows(1), s.locals(1)), (2..5, 3..5));
        assert_eq!(s.locals(2), 5..5);
        assert_eq!(s.jacobian_len(), 6 * 2 + 2 + 6);
    }

    #[test]
    fn dense_round_trip_and_products() {
        let j = example();
        let d = j.to_dense();
        let back = BlockJacobian::from_dense(j.structure().clone(), &d).unwrap();
        assert_eq!(back, j);
        for i in 0..6 {
            for c in 0..5 {
                assert_eq!(j.get(i, c), d[i * 5 + c]);
            }
        }
        // an entry outside the blocks is refused
        let mut bad = d.clone();
        bad[2] = 1.0; // row 0, column 2 (block 0's local) is inside; column 3 is not
        assert!(BlockJacobian::from_dense(j.structure().clone(), &bad).is_some());
        bad[3] = 1.0;
        assert!(BlockJacobian::from_dense(j.structure().clone(), &bad).is_none());
        let x = [0.3, -1.1, 2.0, 0.7, -0.4];
        let r = [1.0, -2.0, 0.5, 0.25, 3.0, -1.5];
        let jx = j.mul_vec(&x);
        let jtr = j.tr_mul_vec(&r);
        for i in 0..6 {
            let e: f64 = (0..5).map(|c| d[i * 5 + c] * x[c]).sum();
            assert!((jx[i] - e).abs() < 1e-14);
        }
        for c in 0..5 {
            let e: f64 = (0..6).map(|i| d[i * 5 + c] * r[i]).sum();
            assert!((jtr[c] - e).abs() < 1e-14);
        }
    }

    #[test]
    fn normal_blocks_are_those_of_the_dense_normal_matrix() {
        let j = example();
        let dense = DMatrix::from_row_slice(6, 5, &j.to_dense());
        let w: [f64; 6] = [1.0, 0.5, 2.0, 0.1, 1.0, 3.0];
        let d = [1.0, 2.0, 0.5, 4.0, 1.5];
        let mut scaled = dense.clone();
        for i in 0..6 {
            for c in 0..5 {
                scaled[(i, c)] *= w[i].sqrt() / d[c];
            }
        }
        let n = scaled.transpose() * &scaled;
        let nb = j.normal_blocks(Some(&w), Some(&d));
        for p in 0..2 {
            for q in 0..2 {
                assert!((nb.a[(p, q)] - n[(p, q)]).abs() < 1e-13);
            }
        }
        for (k, off) in [(0usize, 2usize), (1, 3)] {
            let s = j.structure();
            let nl = s.locals(k).len();
            for p in 0..nl {
                for q in 0..2 {
                    assert!((nb.b[k][(q, p)] - n[(q, off + p)]).abs() < 1e-13);
                }
                for q in 0..nl {
                    assert!((nb.c[k][(p, q)] - n[(off + p, off + q)]).abs() < 1e-13);
                }
            }
        }
        assert_eq!(nb.c[2].nrows(), 0);
    }
}

//! The general fallback: the Newton matrix's sparsity pattern (built once per mesh from index
//! arithmetic), assembly from the collocation blocks, and faer's sparse LU. Used for
//! non-separated boundary conditions, many unknown parameters, or on request
//! ([`LinearSolverKind::SparseLu`](super::LinearSolverKind::SparseLu)).
//!
//! The factorisation is faer's simplicial (left-looking, Gilbert–Peierls) sparse LU with partial
//! pivoting, applied in the natural block order of the unknowns. That order is already a good
//! elimination order for this block-bidiagonal matrix (fill stays within the bandwidth plus the
//! `n + k` boundary rows and the parameter columns), so no fill-reducing analysis (COLAMD) is run:
//! it would cost a sizeable share of a solve and reduce no fill. The pattern and the
//! (identity) column permutation are built once per mesh (on first use) and reused for every numeric
//! factorisation; the factor storage and scratch are reused across Newton iterations.
//!
//! Rows: `(m-1) n` collocation rows (interval by interval), then `n + k` boundary rows.
//! Columns: `m n` state columns (node by node), then `k` dense unknown-parameter columns.
//! Collocation rows of interval `i` touch the state blocks of nodes `i` and `i+1`; boundary rows
//! touch nodes `0` and `m-1`.

use crate::collocation::Collocation;
use crate::error::BvpError;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::lu::simplicial::{
    factorize_simplicial_numeric_lu, factorize_simplicial_numeric_lu_scratch,
    solve_in_place_scratch, SimplicialLu,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par};
use std::sync::{Arc, OnceLock};

/// Dimensions of the collocation Jacobian for one `(n, k, m)`, with its sparsity pattern and
/// column order for the sparse LU (built on first use: the structured elimination needs
/// neither).
pub(crate) struct Pattern {
    pub n: usize,
    pub k: usize,
    pub m: usize,
    sparse: OnceLock<SparseStructure>,
}

struct SparseStructure {
    symbolic: SymbolicSparseColMat<usize>,
    /// Identity column permutation (natural block order).
    identity: Vec<usize>,
}

impl Pattern {
    pub(crate) fn new(n: usize, k: usize, m: usize) -> Result<Self, BvpError> {
        if m < 2 || n == 0 {
            return Err(BvpError::InvalidInput(format!(
                "a collocation system needs at least 1 state and 2 nodes (got {n} states, {m} \
                 nodes)"
            )));
        }
        Ok(Pattern {
            n,
            k,
            m,
            sparse: OnceLock::new(),
        })
    }

    fn structure(&self) -> &SparseStructure {
        self.sparse.get_or_init(|| {
            let (n, k, m) = (self.n, self.k, self.m);
            let size = m * n + k;
            let nb = n + k;
            let mut col_ptr = Vec::with_capacity(size + 1);
            let mut row_idx = Vec::new();
            col_ptr.push(0usize);
            for i in 0..m {
                for _c in 0..n {
                    if i >= 1 {
                        row_idx.extend((i - 1) * n..i * n);
                    }
                    if i + 1 < m {
                        row_idx.extend(i * n..(i + 1) * n);
                    }
                    if i == 0 || i == m - 1 {
                        row_idx.extend((m - 1) * n..(m - 1) * n + nb);
                    }
                    col_ptr.push(row_idx.len());
                }
            }
            for _l in 0..k {
                row_idx.extend(0..size);
                col_ptr.push(row_idx.len());
            }
            SparseStructure {
                symbolic: SymbolicSparseColMat::new_checked(size, size, col_ptr, None, row_idx),
                identity: (0..size).collect(),
            }
        })
    }

    /// The sparsity pattern (column-compressed), built on first use.
    pub(crate) fn symbolic(&self) -> &SymbolicSparseColMat<usize> {
        &self.structure().symbolic
    }

    pub(crate) fn size(&self) -> usize {
        self.m * self.n + self.k
    }

    fn col_perm(&self) -> PermRef<'_, usize> {
        let id = &self.structure().identity;
        PermRef::new_checked(id, id, self.size())
    }

    /// Number of stored entries.
    pub(crate) fn nnz(&self) -> usize {
        self.symbolic().row_idx().len()
    }

    /// Writes the Jacobian of the collocation system into `values` (in the pattern's order).
    pub(crate) fn assemble(&self, col: &Collocation, values: &mut Vec<f64>, work: &mut Vec<f64>) {
        let (n, k, m) = (self.n, self.k, self.m);
        let size = m * n + k;
        values.resize(self.nnz(), 0.0);
        let cp = self.symbolic().col_ptr();
        work.resize(2 * n * n + size, 0.0);
        let (ab, pcol) = work.split_at_mut(2 * n * n);
        for i in 0..m - 1 {
            col.interval_rows(i, ab, 2 * n);
            let a_off = if i >= 1 { n } else { 0 };
            for c in 0..n {
                let base_a = cp[i * n + c] + a_off;
                let base_b = cp[(i + 1) * n + c];
                for r in 0..n {
                    values[base_a + r] = ab[r * 2 * n + c];
                    values[base_b + r] = ab[r * 2 * n + n + c];
                }
            }
        }
        for c in 0..n {
            let base0 = cp[c] + n;
            let base1 = cp[(m - 1) * n + c] + n;
            for r in 0..n + k {
                values[base0 + r] = col.bc_state(r, 0, c);
                values[base1 + r] = col.bc_state(r, 1, c);
            }
        }
        for l in 0..k {
            col.param_column(l, &mut pcol[..size]);
            let base = cp[m * n + l];
            values[base..base + size].copy_from_slice(&pcol[..size]);
        }
    }
}

/// A numeric sparse LU factorisation with everything needed to solve with it or its transpose.
#[derive(Clone)]
pub(crate) struct SparseFactor {
    pub pattern: Arc<Pattern>,
    lu: SimplicialLu<usize, f64>,
    row_perm: Vec<usize>,
    row_perm_inv: Vec<usize>,
}

impl SparseFactor {
    /// Solves `J x = b` or `Jᵀ x = b` in place (`b` column-major, `size × ncols`, checked by the
    /// caller).
    pub(crate) fn solve(&self, b: &mut [f64], ncols: usize, transpose: bool) {
        let size = self.pattern.size();
        let mut buf = MemBuffer::new(solve_in_place_scratch::<usize, f64>(size, ncols, Par::Seq));
        let stack = MemStack::new(&mut buf);
        let rp = PermRef::new_checked(&self.row_perm, &self.row_perm_inv, size);
        let cp = self.pattern.col_perm();
        let rhs = MatMut::from_column_major_slice_mut(b, size, ncols);
        if transpose {
            self.lu
                .solve_transpose_in_place_with_conj(rp, cp, Conj::No, rhs, Par::Seq, stack);
        } else {
            self.lu
                .solve_in_place_with_conj(rp, cp, Conj::No, rhs, Par::Seq, stack);
        }
    }
}

/// Sparse-LU workspace for one mesh: values, numeric LU and scratch, reused across iterations.
pub(crate) struct SparseLu {
    pattern: Arc<Pattern>,
    values: Vec<f64>,
    work: Vec<f64>,
    lu: SimplicialLu<usize, f64>,
    row_perm: Vec<usize>,
    row_perm_inv: Vec<usize>,
    factor_buf: MemBuffer,
    solve_buf: MemBuffer,
}

impl SparseLu {
    pub(crate) fn new(pattern: Arc<Pattern>) -> Self {
        let size = pattern.size();
        let factor_buf = MemBuffer::new(factorize_simplicial_numeric_lu_scratch::<usize, f64>(
            size, size,
        ));
        let solve_buf = MemBuffer::new(solve_in_place_scratch::<usize, f64>(size, 1, Par::Seq));
        SparseLu {
            pattern,
            values: Vec::new(),
            work: Vec::new(),
            lu: SimplicialLu::new(),
            row_perm: vec![0; size],
            row_perm_inv: vec![0; size],
            factor_buf,
            solve_buf,
        }
    }

    /// Assembles and factors the Jacobian held in `col`.
    pub(crate) fn factor(&mut self, col: &Collocation) -> Result<(), BvpError> {
        self.pattern.assemble(col, &mut self.values, &mut self.work);
        let a = SparseColMatRef::new(self.pattern.symbolic().as_ref(), &self.values);
        let stack = MemStack::new(&mut self.factor_buf);
        factorize_simplicial_numeric_lu(
            &mut self.row_perm,
            &mut self.row_perm_inv,
            &mut self.lu,
            a,
            self.pattern.col_perm(),
            stack,
        )
        .map_err(|e| BvpError::SingularJacobian {
            detail: format!("sparse LU found no pivot ({e:?})"),
        })
    }

    /// Solves `J x = b` in place with the current factorisation (one column).
    pub(crate) fn solve(&mut self, b: &mut [f64]) {
        let size = b.len();
        let stack = MemStack::new(&mut self.solve_buf);
        let rp = PermRef::new_checked(&self.row_perm, &self.row_perm_inv, size);
        self.lu.solve_in_place_with_conj(
            rp,
            self.pattern.col_perm(),
            Conj::No,
            MatMut::from_column_major_slice_mut(b, size, 1),
            Par::Seq,
            stack,
        );
    }

    /// A copy of the current factorisation for later solves.
    pub(crate) fn snapshot(&self) -> SparseFactor {
        SparseFactor {
            pattern: self.pattern.clone(),
            lu: self.lu.clone(),
            row_perm: self.row_perm.clone(),
            row_perm_inv: self.row_perm_inv.clone(),
        }
    }
}

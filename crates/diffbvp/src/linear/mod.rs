//! The global Newton matrix of the collocation system and its factorisation.
//!
//! Rows: `(m-1) n` collocation rows (interval by interval), then `n + k` boundary rows.
//! Columns: `m n` state columns (node by node), then `k` dense unknown-parameter columns.
//! Collocation rows of interval `i` touch the state blocks of nodes `i` and `i+1` and the
//! parameter columns; boundary rows touch nodes `0` and `m-1` and the parameter columns.
//!
//! Two factorisations, chosen per factorisation by [`LinearSolverKind`]:
//!
//! * `block_elimination`: structured Gaussian elimination with partial pivoting for the
//!   almost-block-diagonal form that *separated* boundary conditions give (SOLVEBLOK / COLROW
//!   style, bordered by the parameter columns). Dense small blocks, no index structures, no
//!   allocation per factorisation or solve.
//! * `sparse_lu`: faer's general simplicial sparse LU, the fallback for boundary conditions
//!   that couple both ends (periodic and the like) and for many unknown parameters.
//!
//! [`LinearSolverKind::Auto`] (the default) uses the structured elimination when every boundary
//! row touches only one end and `k <= n`, otherwise the sparse LU. Why `k <= n`: the bordered
//! elimination carries the `k` parameter columns densely through every interval block, so each
//! step costs `O(n (n + nL)(2n + k))` with up to `nL = n + k` carried rows and stores that many
//! numbers per interval; once the border is wider than the state blocks it dominates the work
//! and the storage, and the general sparse LU is the safer choice.

pub(crate) mod block_elimination;
pub(crate) mod sparse_lu;

use crate::collocation::Collocation;
use crate::error::BvpError;
use block_elimination::{BlockError, BlockLu, BlockSource, Dims};
pub(crate) use sparse_lu::Pattern;
use sparse_lu::{SparseFactor, SparseLu};
use std::sync::Arc;

/// Which linear solver factors the collocation Newton matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinearSolverKind {
    /// Structured elimination when the boundary conditions are separated and the number of
    /// unknown parameters `k` is at most the number of states `n`; otherwise the sparse LU
    /// (decided per factorisation from the numeric boundary Jacobian).
    #[default]
    Auto,
    /// Always the structured (almost-block-diagonal) elimination; a factorisation with
    /// boundary conditions that couple both ends is an [`BvpError::InvalidInput`].
    Structured,
    /// Always faer's general sparse LU.
    SparseLu,
}

#[derive(Clone)]
enum Inner {
    Sparse(SparseFactor),
    Structured(BlockLu),
}

/// A numeric LU factorisation of the collocation Jacobian, with everything needed to solve with
/// it or its transpose again later (sensitivities, adjoints).
#[derive(Clone)]
pub struct Factorization {
    size: usize,
    inner: Inner,
}

impl std::fmt::Debug for Factorization {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Factorization {{ size: {}, kind: {:?} }}",
            self.size,
            self.kind()
        )
    }
}

impl Factorization {
    /// Bytes of the factors on the heap: exact for the structured elimination; for the sparse LU
    /// an estimate (three numbers per nonzero of the Newton matrix).
    pub(crate) fn heap_bytes(&self) -> usize {
        match &self.inner {
            Inner::Structured(b) => b.heap_bytes(),
            Inner::Sparse(s) => {
                let (n, k, m) = (s.pattern.n, s.pattern.k, s.pattern.m);
                let nnz = (m - 1) * n * (2 * n + k) + (n + k) * (2 * n + k);
                3 * 8 * nnz + 2 * std::mem::size_of::<usize>() * self.size
            }
        }
    }

    /// Dimension of the factored system.
    pub fn size(&self) -> usize {
        self.size
    }

    /// Which solver produced this factorisation: [`LinearSolverKind::Structured`] or
    /// [`LinearSolverKind::SparseLu`] (never `Auto`).
    pub fn kind(&self) -> LinearSolverKind {
        match self.inner {
            Inner::Sparse(_) => LinearSolverKind::SparseLu,
            Inner::Structured(_) => LinearSolverKind::Structured,
        }
    }

    /// Solves `J x = b` in place for the columns of `b` (column-major, `size × ncols`).
    /// Errors if `b` does not hold `size × ncols` values.
    pub fn solve_in_place(&self, b: &mut [f64], ncols: usize) -> Result<(), BvpError> {
        self.solve_impl(b, ncols, false)
    }

    /// Solves `Jᵀ x = b` in place (adjoints). Errors if `b` does not hold `size × ncols`
    /// values.
    pub fn solve_transpose_in_place(&self, b: &mut [f64], ncols: usize) -> Result<(), BvpError> {
        self.solve_impl(b, ncols, true)
    }

    fn solve_impl(&self, b: &mut [f64], ncols: usize, transpose: bool) -> Result<(), BvpError> {
        self.solve_with_scratch(b, ncols, transpose, &mut Vec::new())
    }

    /// [`solve_in_place`](Self::solve_in_place) (or the transposed solve) with the structured
    /// path's scratch kept by the caller: repeated solves (simplified Newton, refinement) grow it
    /// once instead of allocating per call.
    pub(crate) fn solve_with_scratch(
        &self,
        b: &mut [f64],
        ncols: usize,
        transpose: bool,
        scratch: &mut Vec<f64>,
    ) -> Result<(), BvpError> {
        let size = self.size;
        if Some(b.len()) != size.checked_mul(ncols) {
            return Err(BvpError::InvalidInput(format!(
                "right-hand side of {} values for a {size} × {size} system with {ncols} column(s) \
                 (expected {})",
                b.len(),
                size.saturating_mul(ncols)
            )));
        }
        match &self.inner {
            Inner::Sparse(s) => s.solve(b, ncols, transpose),
            Inner::Structured(s) => {
                if scratch.len() < s.scratch_len() {
                    scratch.resize(s.scratch_len(), 0.0);
                }
                s.solve(b, ncols, transpose, scratch);
            }
        }
        Ok(())
    }
}

/// The collocation Jacobian seen block by block.
struct CollocationBlocks<'a> {
    col: &'a Collocation,
    /// The `k` parameter columns, each of length `size`.
    pcols: &'a [f64],
    size: usize,
}

impl BlockSource for CollocationBlocks<'_> {
    fn fill_interval(&mut self, i: usize, out: &mut [f64], w: usize) {
        let (n, k) = (self.col.n, self.col.k);
        self.col.interval_rows(i, out, w);
        for (r, row) in out.chunks_exact_mut(w).take(n).enumerate() {
            for l in 0..k {
                row[2 * n + l] = self.pcols[l * self.size + i * n + r];
            }
        }
    }

    fn fill_boundary(&mut self, out: &mut [f64], w: usize) {
        let (n, k, m) = (self.col.n, self.col.k, self.col.m());
        for (r, row) in out.chunks_exact_mut(w).take(n + k).enumerate() {
            for c in 0..n {
                row[c] = self.col.bc_state(r, 0, c);
                row[n + c] = self.col.bc_state(r, 1, c);
            }
            for l in 0..k {
                row[2 * n + l] = self.pcols[l * self.size + (m - 1) * n + r];
            }
        }
    }

    fn node_x(&self, i: usize) -> f64 {
        self.col.x.get(i).copied().unwrap_or(f64::NAN)
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Active {
    None,
    Sparse,
    Structured,
}

/// Newton-matrix workspace for one mesh: the chosen factorisation and its scratch, reused
/// across iterations.
pub(crate) struct LinearSystem {
    pub pattern: Arc<Pattern>,
    kind: LinearSolverKind,
    sparse: Option<SparseLu>,
    block: BlockLu,
    /// Factor scratch of the structured path: the parameter columns.
    pcols: Vec<f64>,
    /// Solve scratch of the structured path.
    scratch: Vec<f64>,
    active: Active,
    /// Number of numeric factorisations done.
    pub factorizations: usize,
    /// Of those, the number done by the structured elimination.
    pub structured_factorizations: usize,
}

impl LinearSystem {
    /// A workspace choosing the solver automatically ([`LinearSolverKind::Auto`]).
    pub(crate) fn new(pattern: Arc<Pattern>) -> Self {
        Self::with_kind(pattern, LinearSolverKind::Auto)
    }

    /// A workspace using the solver `kind`.
    pub(crate) fn with_kind(pattern: Arc<Pattern>, kind: LinearSolverKind) -> Self {
        LinearSystem {
            pattern,
            kind,
            sparse: None,
            block: BlockLu::default(),
            pcols: Vec::new(),
            scratch: Vec::new(),
            active: Active::None,
            factorizations: 0,
            structured_factorizations: 0,
        }
    }

    /// The solver kind this workspace was built for (as requested, possibly `Auto`).
    pub(crate) fn kind(&self) -> LinearSolverKind {
        self.kind
    }

    /// Which solver holds the current factorisation (`None` before the first).
    #[allow(dead_code)]
    pub(crate) fn active_kind(&self) -> Option<LinearSolverKind> {
        match self.active {
            Active::None => None,
            Active::Sparse => Some(LinearSolverKind::SparseLu),
            Active::Structured => Some(LinearSolverKind::Structured),
        }
    }

    /// Assembles and factors the Jacobian held in `col`.
    pub(crate) fn factor(&mut self, col: &Collocation) -> Result<(), BvpError> {
        self.factorizations += 1;
        self.active = Active::None;
        let (n, k, m) = (self.pattern.n, self.pattern.k, self.pattern.m);
        if col.n != n || col.k != k || col.m() != m {
            return Err(BvpError::InvalidInput(format!(
                "the collocation system ({} states, {} unknowns, {} nodes) does not match the \
                 linear system ({n}, {k}, {m})",
                col.n,
                col.k,
                col.m()
            )));
        }
        let try_structured = match self.kind {
            LinearSolverKind::SparseLu => false,
            LinearSolverKind::Structured => true,
            LinearSolverKind::Auto => k <= n,
        };
        if try_structured {
            match self.factor_structured(col) {
                Ok(()) => {
                    self.active = Active::Structured;
                    self.structured_factorizations += 1;
                    return Ok(());
                }
                Err(BlockError::Singular { detail }) => {
                    return Err(BvpError::SingularJacobian { detail })
                }
                Err(BlockError::NotSeparated { row }) => {
                    if self.kind == LinearSolverKind::Structured {
                        return Err(BvpError::InvalidInput(format!(
                            "LinearSolverKind::Structured needs separated boundary conditions, \
                             but boundary condition {row} depends on both y(a) and y(b); use \
                             LinearSolverKind::Auto or SparseLu"
                        )));
                    }
                }
            }
        }
        let pattern = &self.pattern;
        let sparse = self
            .sparse
            .get_or_insert_with(|| SparseLu::new(pattern.clone()));
        sparse.factor(col)?;
        self.active = Active::Sparse;
        Ok(())
    }

    fn factor_structured(&mut self, col: &Collocation) -> Result<(), BlockError> {
        let (n, k, m) = (self.pattern.n, self.pattern.k, self.pattern.m);
        let size = self.pattern.size();
        self.pcols.resize(k * size, 0.0);
        for l in 0..k {
            col.param_column(l, &mut self.pcols[l * size..(l + 1) * size]);
        }
        let mut src = CollocationBlocks {
            col,
            pcols: &self.pcols,
            size,
        };
        self.block.factor(Dims { n, k, m }, &mut src)?;
        let need = self.block.scratch_len();
        if self.scratch.len() < need {
            self.scratch.resize(need, 0.0);
        }
        Ok(())
    }

    /// Solves `J x = b` in place with the current factorisation (no-op without one).
    pub(crate) fn solve(&mut self, b: &mut [f64]) {
        match self.active {
            Active::Structured => self.block.solve(b, 1, false, &mut self.scratch),
            Active::Sparse => {
                if let Some(s) = self.sparse.as_mut() {
                    s.solve(b);
                }
            }
            Active::None => {}
        }
    }

    /// A copy of the current factorisation for later solves.
    pub(crate) fn snapshot(&self) -> Factorization {
        let size = self.pattern.size();
        let inner = match (self.active, self.sparse.as_ref()) {
            (Active::Sparse, Some(s)) => Inner::Sparse(s.snapshot()),
            _ => Inner::Structured(self.block.clone()),
        };
        Factorization { size, inner }
    }
}

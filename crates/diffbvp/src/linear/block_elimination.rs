//! Structured (almost-block-diagonal) Gaussian elimination for the collocation Newton matrix.
//!
//! # The matrix
//!
//! Unknowns `Y = (y_0, …, y_{m-1}, p)`: `m` nodes × `n` states, then `k` unknown parameters.
//! Rows: interval `i` (`n` collocation rows) touches `y_i` through `A_i`, `y_{i+1}` through
//! `B_i` and all `k` parameter columns through `P_i`; the `n + k` boundary rows `g(ya, yb, p)`
//! touch `y_0` (`C_a`), `y_{m-1}` (`C_b`) and `p` (`C_p`):
//!
//! ```text
//!            y_0  y_1  y_2  …  y_{m-1}  p
//! left bc  [ Ca_L                       Cp_L ]
//! int 0    [ A_0  B_0                   P_0  ]
//! int 1    [      A_1  B_1              P_1  ]
//!   …                  …    …
//! int m-2  [           A_{m-2} B_{m-2}  P_{m-2} ]
//! right bc [                   Cb_R     Cp_R ]
//! ```
//!
//! With *separated* boundary conditions (every boundary row touches `ya` or `yb`, not both) and
//! the boundary rows split into the `nL` left rows (nonzeros in `ya`, none in `yb`) and the
//! `n + k - nL` right rows (the rest), the rows ordered as above form an almost-block-diagonal
//! (ABD) matrix with a dense border of `k` parameter columns: the structure that de Boor & Weiss'
//! SOLVEBLOK (ACM TOMS 6, 1980) and Diaz, Fairweather & Keast's COLROW (ACM TOMS 9, 1983)
//! exploit in COLSYS/COLNEW (Ascher, Mattheij & Russell, *Numerical Solution of Boundary Value
//! Problems for ODEs*, SIAM 1995, §7.3; the bordered form for unknown parameters in §7.3.3).
//!
//! # Elimination
//!
//! Step `i = 0, …, m-2` works on an `(nL + n) × (2n + k)` block with columns `(y_i, y_{i+1}, p)`:
//! its first `nL` rows are the rows *carried* from step `i - 1` (at step 0 the left boundary
//! rows), which have no entries in `y_{i+1}`, then the `n` rows of interval `i`. Gaussian
//! elimination with partial (row) pivoting eliminates the `n` columns `y_i` inside the block. No
//! row outside the block touches `y_i`, so this is *exactly* Gaussian elimination with partial
//! pivoting of the whole matrix in this row order — the same stability. The `n` pivot rows keep
//! their `U11` (in `y_i`) and `U12` (in `y_{i+1}`, `p`) parts; the `nL` remaining rows become
//! the Schur complement over `(y_{i+1}, p)`, carried to step `i + 1`. The number of carried rows
//! therefore stays `nL` throughout. The last step is a dense `(n+k) × (n+k)` LU with partial
//! pivoting over `(y_{m-1}, p)` of the carried rows followed by the right boundary rows.
//! The parameter columns ride along every step as a dense border (the bordered variant).
//!
//! Work per interval `O(n (n + nL)(2n + k))`, storage `(n + nL)(2n + k)` numbers per interval, in
//! one flat vector sized once per mesh (it only grows); nothing is allocated per factorisation
//! or per solve once the sizes are reached.
//!
//! # Solves
//!
//! Write `T J = Ũ` with `T = M_{m-2} ⋯ M_0 Π`, where `Π` is the row order above and
//! `M_i = L̂_i⁻¹ P_i` the row swaps and unit-lower multipliers of step `i` (acting on the `nL + n`
//! rows of its block); `Ũ` is block upper triangular with the `U11_i`, `U12_i` rows and the final
//! dense block `F`.
//!
//! * `J x = b`: forward elimination `T b` block by block, the dense solve with `F` for
//!   `(x_{m-1}, p)`, then back substitution `U11_i x_i = z_i − U12_i (x_{i+1}, p)`.
//! * `Jᵀ x = c` (adjoints): `Jᵀ = Ũᵀ T⁻ᵀ`, so first `Ũᵀ u = c` (a forward sweep:
//!   `U11_iᵀ u_i = c_{y_i} − U12_{i-1, y}ᵀ u_{i-1}`, the `p` part accumulating
//!   `− Σ U12_{i, p}ᵀ u_i`, then `Fᵀ u_F = …`), then `x = Πᵀ M_0ᵀ ⋯ M_{m-2}ᵀ u` in reverse step
//!   order, `M_iᵀ = P_iᵀ L̂_i⁻ᵀ`.
//!
//! Both handle several right-hand sides (column-major), in place.

/// Number of states, unknown parameters and nodes of a block system.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Dims {
    pub n: usize,
    pub k: usize,
    pub m: usize,
}

impl Dims {
    fn size(&self) -> usize {
        self.m * self.n + self.k
    }
}

/// Where the numbers of the matrix come from (the collocation Jacobian, or a test matrix).
pub(crate) trait BlockSource {
    /// Writes the `n` rows of interval `i` into `out` (row `r` at `out[r * w..]`, `w = 2n + k`):
    /// `A_i` in columns `0..n`, `B_i` in `n..2n`, `P_i` in `2n..2n + k`.
    fn fill_interval(&mut self, i: usize, out: &mut [f64], w: usize);
    /// Writes the `n + k` boundary rows into `out` (row `r` at `out[r * w..]`): `∂g/∂ya` in
    /// columns `0..n`, `∂g/∂yb` in `n..2n`, `∂g/∂p` in `2n..2n + k`.
    fn fill_boundary(&mut self, out: &mut [f64], w: usize);
    /// Position of node `i` (for error messages).
    fn node_x(&self, i: usize) -> f64;
}

/// Why a structured factorisation failed.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum BlockError {
    /// Boundary row `row` has nonzeros at both ends: the conditions are not separated.
    NotSeparated { row: usize },
    /// No nonzero pivot in a column: the matrix is singular. `detail` says where.
    Singular { detail: String },
}

/// The numeric structured LU factorisation (see the module documentation).
#[derive(Clone, Debug, Default)]
pub(crate) struct BlockLu {
    dims: Option<Dims>,
    /// Boundary rows (indices into `g`) eliminated first, in order.
    left: Vec<usize>,
    /// Boundary rows appended to the last block, in order.
    right: Vec<usize>,
    /// Per interval: the `(nL + n) × (2n + k)` block after elimination (row-major).
    blocks: Vec<f64>,
    /// Per interval: the pivot row (within the block) chosen for each of the `n` columns.
    piv: Vec<usize>,
    /// Per interval: the reciprocals of the `n` pivots `U11[r][r]` (back substitution
    /// multiplies instead of dividing: off the solve's serial dependency chain).
    dinv: Vec<f64>,
    /// The final `(n+k) × (n+k)` block's LU (row-major).
    last: Vec<f64>,
    /// Its pivot rows.
    last_piv: Vec<usize>,
    /// Boundary rows as read from the source, `(n+k) × (2n+k)` (factor scratch).
    bc: Vec<f64>,
}

fn swap_rows(a: &mut [f64], w: usize, r1: usize, r2: usize) {
    if r1 != r2 {
        let (lo, hi) = (r1.min(r2), r1.max(r2));
        let (head, tail) = a.split_at_mut(hi * w);
        head[lo * w..lo * w + w].swap_with_slice(&mut tail[..w]);
    }
}

/// Partial-pivoting elimination of columns `0..ncols` of the `rows × w` row-major block `a`.
/// Returns the first column without a nonzero pivot as `Err(column)`. Small widths run with
/// the width known at compile time (the same operations in the same order).
fn eliminate(
    a: &mut [f64],
    rows: usize,
    w: usize,
    ncols: usize,
    piv: &mut [usize],
) -> Result<(), usize> {
    // the interval steps (`ncols = n`, `w = 2n + k`) of small systems with both known at
    // compile time: the column loop unrolls
    match (ncols, w) {
        (1, 2) => return eliminate_nw::<1, 2>(a, rows, piv),
        (1, 3) => return eliminate_nw::<1, 3>(a, rows, piv),
        (2, 4) => return eliminate_nw::<2, 4>(a, rows, piv),
        (2, 5) => return eliminate_nw::<2, 5>(a, rows, piv),
        (3, 6) => return eliminate_nw::<3, 6>(a, rows, piv),
        (3, 7) => return eliminate_nw::<3, 7>(a, rows, piv),
        (4, 8) => return eliminate_nw::<4, 8>(a, rows, piv),
        (4, 9) => return eliminate_nw::<4, 9>(a, rows, piv),
        _ => {}
    }
    match w {
        2 => eliminate_w::<2>(a, rows, w, ncols, piv),
        3 => eliminate_w::<3>(a, rows, w, ncols, piv),
        4 => eliminate_w::<4>(a, rows, w, ncols, piv),
        5 => eliminate_w::<5>(a, rows, w, ncols, piv),
        6 => eliminate_w::<6>(a, rows, w, ncols, piv),
        7 => eliminate_w::<7>(a, rows, w, ncols, piv),
        8 => eliminate_w::<8>(a, rows, w, ncols, piv),
        9 => eliminate_w::<9>(a, rows, w, ncols, piv),
        10 => eliminate_w::<10>(a, rows, w, ncols, piv),
        _ => eliminate_w::<0>(a, rows, w, ncols, piv),
    }
}

/// [`eliminate`] with `ncols = N` and the width `W` fixed at compile time (the same operations
/// in the same order as [`eliminate_w`]: bit-identical).
fn eliminate_nw<const N: usize, const W: usize>(
    a: &mut [f64],
    rows: usize,
    piv: &mut [usize],
) -> Result<(), usize> {
    let a = &mut a[..rows * W];
    // each column step inlined with its index a constant (N <= 4 here)
    for j in 0..N.min(4) {
        match j {
            0 => eliminate_column::<W>(a, rows, 0, piv)?,
            1 => eliminate_column::<W>(a, rows, 1, piv)?,
            2 => eliminate_column::<W>(a, rows, 2, piv)?,
            _ => eliminate_column::<W>(a, rows, 3, piv)?,
        }
    }
    for j in 4..N {
        eliminate_column::<W>(a, rows, j, piv)?;
    }
    Ok(())
}

/// Step `j` of [`eliminate_nw`]: pivot search, row swap and update of the rows below.
#[inline(always)]
fn eliminate_column<const W: usize>(
    a: &mut [f64],
    rows: usize,
    j: usize,
    piv: &mut [usize],
) -> Result<(), usize> {
    let mut p = j;
    let mut best = a[j * W + j].abs();
    for r in j + 1..rows {
        let v = a[r * W + j].abs();
        if v > best {
            best = v;
            p = r;
        }
    }
    if best.is_nan() || best <= 0.0 {
        return Err(j);
    }
    piv[j] = p;
    swap_rows(a, W, j, p);
    let (top, below) = a.split_at_mut((j + 1) * W);
    let prow: &[f64; W] = match top[j * W..].try_into() {
        Ok(r) => r,
        Err(_) => return Err(j),
    };
    let inv = 1.0 / prow[j];
    for row in below.chunks_exact_mut(W) {
        let row: &mut [f64; W] = match row.try_into() {
            Ok(r) => r,
            Err(_) => return Err(j),
        };
        let l = row[j] * inv;
        row[j] = l;
        if l != 0.0 {
            for (x, u) in row[j + 1..].iter_mut().zip(&prow[j + 1..]) {
                *x -= l * u;
            }
        }
    }
    Ok(())
}

/// [`eliminate`] with the width `W` fixed at compile time (`W = 0`: the run-time `w_rt`).
fn eliminate_w<const W: usize>(
    a: &mut [f64],
    rows: usize,
    w_rt: usize,
    ncols: usize,
    piv: &mut [usize],
) -> Result<(), usize> {
    let w = if W > 0 { W } else { w_rt };
    for j in 0..ncols {
        let mut p = j;
        let mut best = a[j * w + j].abs();
        for r in j + 1..rows {
            let v = a[r * w + j].abs();
            if v > best {
                best = v;
                p = r;
            }
        }
        if best.is_nan() || best <= 0.0 {
            return Err(j);
        }
        piv[j] = p;
        swap_rows(a, w, j, p);
        let (top, below) = a.split_at_mut((j + 1) * w);
        let prow = &top[j * w..(j + 1) * w];
        let inv = 1.0 / prow[j];
        for row in below.chunks_exact_mut(w).take(rows - j - 1) {
            let l = row[j] * inv;
            row[j] = l;
            if l != 0.0 {
                for (x, u) in row[j + 1..].iter_mut().zip(&prow[j + 1..]) {
                    *x -= l * u;
                }
            }
        }
    }
    Ok(())
}

impl BlockLu {
    /// Bytes of the factors on the heap.
    pub(crate) fn heap_bytes(&self) -> usize {
        let f = self.blocks.len() + self.dinv.len() + self.last.len() + self.bc.len();
        let u = self.piv.len() + self.last_piv.len() + self.left.len() + self.right.len();
        8 * f + std::mem::size_of::<usize>() * u
    }

    /// Number of carried (left boundary) rows `nL` of the current factorisation.
    #[cfg(test)]
    pub(crate) fn carried_rows(&self) -> usize {
        self.left.len()
    }

    /// Factors the matrix given by `src` with dimensions `dims` (`m >= 2`).
    pub(crate) fn factor(
        &mut self,
        dims: Dims,
        src: &mut impl BlockSource,
    ) -> Result<(), BlockError> {
        let Dims { n, k, m } = dims;
        self.dims = None;
        if m < 2 || n == 0 {
            return Err(BlockError::Singular {
                detail: format!("a block system needs n >= 1 and m >= 2 (n = {n}, m = {m})"),
            });
        }
        let nb = n + k;
        let w = 2 * n + k;
        self.bc.resize(nb * w, 0.0);
        src.fill_boundary(&mut self.bc, w);
        self.left.clear();
        self.right.clear();
        for r in 0..nb {
            let row = &self.bc[r * w..(r + 1) * w];
            let at_a = row[..n].iter().any(|v| *v != 0.0);
            let at_b = row[n..2 * n].iter().any(|v| *v != 0.0);
            match (at_a, at_b) {
                (true, true) => return Err(BlockError::NotSeparated { row: r }),
                (true, false) => self.left.push(r),
                _ => self.right.push(r),
            }
        }
        let nl = self.left.len();
        let rows = nl + n;
        let bsize = rows * w;
        if self.blocks.len() < (m - 1) * bsize {
            self.blocks.resize((m - 1) * bsize, 0.0);
        }
        if self.piv.len() < (m - 1) * n {
            self.piv.resize((m - 1) * n, 0);
        }
        if self.dinv.len() < (m - 1) * n {
            self.dinv.resize((m - 1) * n, 0.0);
        }
        for i in 0..m - 1 {
            let (done, rest) = self.blocks.split_at_mut(i * bsize);
            let blk = &mut rest[..bsize];
            // carried rows: columns y_i and p; nothing in y_{i+1}
            for (t, out) in blk.chunks_exact_mut(w).take(nl).enumerate() {
                let src_row: &[f64] = if i == 0 {
                    &self.bc[self.left[t] * w..(self.left[t] + 1) * w]
                } else {
                    let prev = &done[(i - 1) * bsize..];
                    &prev[(n + t) * w..(n + t + 1) * w]
                };
                if i == 0 {
                    out[..n].copy_from_slice(&src_row[..n]);
                } else {
                    out[..n].copy_from_slice(&src_row[n..2 * n]);
                }
                out[n..2 * n].fill(0.0);
                out[2 * n..].copy_from_slice(&src_row[2 * n..]);
            }
            src.fill_interval(i, &mut blk[nl * w..], w);
            eliminate(blk, rows, w, n, &mut self.piv[i * n..(i + 1) * n]).map_err(|c| {
                BlockError::Singular {
                    detail: format!(
                        "structured elimination found no nonzero pivot for state component {c} \
                         at node {i} of {m} (x = {:e})",
                        src.node_x(i)
                    ),
                }
            })?;
            for (r, d) in self.dinv[i * n..(i + 1) * n].iter_mut().enumerate() {
                *d = 1.0 / blk[r * w + r];
            }
        }
        self.last.resize(nb * nb, 0.0);
        self.last_piv.resize(nb, 0);
        let lastblk = &self.blocks[(m - 2) * bsize..(m - 1) * bsize];
        for t in 0..nl {
            let s = &lastblk[(n + t) * w..(n + t + 1) * w];
            let out = &mut self.last[t * nb..(t + 1) * nb];
            out[..n].copy_from_slice(&s[n..2 * n]);
            out[n..].copy_from_slice(&s[2 * n..]);
        }
        for (t, &r) in self.right.iter().enumerate() {
            let s = &self.bc[r * w..(r + 1) * w];
            let out = &mut self.last[(nl + t) * nb..(nl + t + 1) * nb];
            out[..n].copy_from_slice(&s[n..2 * n]);
            out[n..].copy_from_slice(&s[2 * n..]);
        }
        eliminate(&mut self.last, nb, nb, nb, &mut self.last_piv).map_err(|c| {
            BlockError::Singular {
                detail: if c < n {
                    format!(
                        "structured elimination found no nonzero pivot for state component {c} \
                         at the last node {} (x = {:e}); check that the boundary conditions fix \
                         every state component",
                        m - 1,
                        src.node_x(m - 1)
                    )
                } else {
                    format!(
                        "structured elimination found no nonzero pivot for unknown parameter {}; \
                         check that the boundary conditions determine it",
                        c - n
                    )
                },
            }
        })?;
        self.dims = Some(dims);
        Ok(())
    }

    /// Scratch length the solves need.
    pub(crate) fn scratch_len(&self) -> usize {
        self.dims.map_or(0, |d| 4 * (2 * d.n + d.k))
    }

    /// Solves `J x = b` (`transpose = false`) or `Jᵀ x = b` in place for the `ncols` columns of
    /// `b` (column-major, `size × ncols`). `scratch` holds at least
    /// [`scratch_len`](Self::scratch_len) values. Does nothing before a successful factorisation.
    pub(crate) fn solve(&self, b: &mut [f64], ncols: usize, transpose: bool, scratch: &mut [f64]) {
        let Some(d) = self.dims else { return };
        let size = d.size();
        for col in b.chunks_exact_mut(size).take(ncols) {
            if transpose {
                self.solve_transpose_one(d, col, scratch);
            } else {
                // small systems with the sizes known at compile time (the same operations)
                match (d.n, 2 * d.n + d.k) {
                    (1, 2) => self.solve_one::<1, 2>(d, col, scratch),
                    (1, 3) => self.solve_one::<1, 3>(d, col, scratch),
                    (2, 4) => self.solve_one::<2, 4>(d, col, scratch),
                    (2, 5) => self.solve_one::<2, 5>(d, col, scratch),
                    (3, 6) => self.solve_one::<3, 6>(d, col, scratch),
                    (3, 7) => self.solve_one::<3, 7>(d, col, scratch),
                    (4, 8) => self.solve_one::<4, 8>(d, col, scratch),
                    (4, 9) => self.solve_one::<4, 9>(d, col, scratch),
                    _ => self.solve_one::<0, 0>(d, col, scratch),
                }
            }
        }
    }

    /// One solve `J x = b`; `N`, `W` are `n` and `2n + k` fixed at compile time (`0`: those of
    /// `d` at run time).
    fn solve_one<const N: usize, const W: usize>(
        &self,
        d: Dims,
        x: &mut [f64],
        scratch: &mut [f64],
    ) {
        let Dims { n, k, m } = d;
        let n = if N > 0 { N } else { n };
        let nl = self.left.len();
        let nb = n + k;
        let w = if W > 0 { W } else { 2 * n + k };
        let rows = nl + n;
        let bsize = rows * w;
        let off = (m - 1) * n;
        let (v, rest) = scratch.split_at_mut(w);
        let (bcv, rest) = rest.split_at_mut(nb);
        let f = &mut rest[..nb];
        bcv.copy_from_slice(&x[off..off + nb]);
        for (t, &r) in self.left.iter().enumerate() {
            v[t] = bcv[r];
        }
        // forward elimination, block by block; the carried part lives in v[0..nl]
        for i in 0..m - 1 {
            let blk = &self.blocks[i * bsize..(i + 1) * bsize];
            let piv = &self.piv[i * n..(i + 1) * n];
            v[nl..rows].copy_from_slice(&x[i * n..(i + 1) * n]);
            for (j, &p) in piv.iter().enumerate() {
                v.swap(j, p);
            }
            for j in 0..n {
                let vj = v[j];
                if vj != 0.0 {
                    for r in j + 1..rows {
                        v[r] -= blk[r * w + j] * vj;
                    }
                }
            }
            x[i * n..(i + 1) * n].copy_from_slice(&v[..n]);
            v.copy_within(n..rows, 0);
        }
        f[..nl].copy_from_slice(&v[..nl]);
        for (t, &r) in self.right.iter().enumerate() {
            f[nl + t] = bcv[r];
        }
        dense_solve(&self.last, &self.last_piv, nb, f);
        x[off..off + nb].copy_from_slice(f);
        // back substitution
        let (head, p_part) = x.split_at_mut(m * n);
        for i in (0..m - 1).rev() {
            let blk = &self.blocks[i * bsize..(i + 1) * bsize];
            let (xi_all, xnext_all) = head.split_at_mut((i + 1) * n);
            let xi = &mut xi_all[i * n..];
            let xnext = &xnext_all[..n];
            let dinv = &self.dinv[i * n..(i + 1) * n];
            // the parts in (x_{i+1}, p) first: independent of each other, so only the
            // triangular part within the block is a serial chain
            for (r, xr) in xi.iter_mut().enumerate() {
                let row = &blk[r * w..(r + 1) * w];
                let mut s = *xr;
                for (u, xv) in row[n..2 * n].iter().zip(xnext) {
                    s -= u * xv;
                }
                for (u, pv) in row[2 * n..].iter().zip(p_part.iter()) {
                    s -= u * pv;
                }
                *xr = s;
            }
            for r in (0..n).rev() {
                let row = &blk[r * w..(r + 1) * w];
                let mut s = xi[r];
                for c in r + 1..n {
                    s -= row[c] * xi[c];
                }
                xi[r] = s * dinv[r];
            }
        }
    }

    fn solve_transpose_one(&self, d: Dims, x: &mut [f64], scratch: &mut [f64]) {
        let Dims { n, k, m } = d;
        let nl = self.left.len();
        let nb = n + k;
        let w = 2 * n + k;
        let rows = nl + n;
        let bsize = rows * w;
        let off = (m - 1) * n;
        // Ũᵀ u = c, forward: u_i overwrites the y_i slot
        {
            let (head, p_part) = x.split_at_mut(m * n);
            for i in 0..m - 1 {
                let blk = &self.blocks[i * bsize..(i + 1) * bsize];
                let (ui_all, next_all) = head.split_at_mut((i + 1) * n);
                let ui = &mut ui_all[i * n..];
                for r in 0..n {
                    let mut s = ui[r];
                    for c in 0..r {
                        s -= blk[c * w + r] * ui[c];
                    }
                    ui[r] = s / blk[r * w + r];
                }
                let next = &mut next_all[..n];
                for (r, &u) in ui.iter().enumerate() {
                    if u != 0.0 {
                        let row = &blk[r * w..(r + 1) * w];
                        for (t, a) in next.iter_mut().zip(&row[n..2 * n]) {
                            *t -= a * u;
                        }
                        for (t, a) in p_part.iter_mut().zip(&row[2 * n..]) {
                            *t -= a * u;
                        }
                    }
                }
            }
        }
        let (v, rest) = scratch.split_at_mut(w);
        let (bcv, rest) = rest.split_at_mut(nb);
        let f = &mut rest[..nb];
        f.copy_from_slice(&x[off..off + nb]);
        dense_solve_transpose(&self.last, &self.last_piv, nb, f);
        for (t, &r) in self.right.iter().enumerate() {
            bcv[r] = f[nl + t];
        }
        // x = Πᵀ M_0ᵀ ⋯ M_{m-2}ᵀ u, in reverse step order; carried part in v[n..rows]
        v[n..rows].copy_from_slice(&f[..nl]);
        for i in (0..m - 1).rev() {
            let blk = &self.blocks[i * bsize..(i + 1) * bsize];
            let piv = &self.piv[i * n..(i + 1) * n];
            v[..n].copy_from_slice(&x[i * n..(i + 1) * n]);
            for j in (0..n).rev() {
                let mut s = v[j];
                for r in j + 1..rows {
                    s -= blk[r * w + j] * v[r];
                }
                v[j] = s;
            }
            for (j, &p) in piv.iter().enumerate().rev() {
                v.swap(j, p);
            }
            x[i * n..(i + 1) * n].copy_from_slice(&v[nl..rows]);
            v.copy_within(0..nl, n);
        }
        for (t, &r) in self.left.iter().enumerate() {
            bcv[r] = v[n + t];
        }
        x[off..off + nb].copy_from_slice(bcv);
    }
}

/// Solves `F x = b` with the row-major LU of `F` from [`eliminate`].
fn dense_solve(lu: &[f64], piv: &[usize], nb: usize, b: &mut [f64]) {
    for (j, &p) in piv.iter().enumerate() {
        b.swap(j, p);
    }
    for r in 0..nb {
        let mut s = b[r];
        for c in 0..r {
            s -= lu[r * nb + c] * b[c];
        }
        b[r] = s;
    }
    for r in (0..nb).rev() {
        let mut s = b[r];
        for c in r + 1..nb {
            s -= lu[r * nb + c] * b[c];
        }
        b[r] = s / lu[r * nb + r];
    }
}

/// Solves `Fᵀ x = b` with the row-major LU of `F` (`P F = L U`, so `Fᵀ = Uᵀ Lᵀ P`).
fn dense_solve_transpose(lu: &[f64], piv: &[usize], nb: usize, b: &mut [f64]) {
    for r in 0..nb {
        let mut s = b[r];
        for c in 0..r {
            s -= lu[c * nb + r] * b[c];
        }
        b[r] = s / lu[r * nb + r];
    }
    for r in (0..nb).rev() {
        let mut s = b[r];
        for c in r + 1..nb {
            s -= lu[c * nb + r] * b[c];
        }
        b[r] = s;
    }
    for (j, &p) in piv.iter().enumerate().rev() {
        b.swap(j, p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Small deterministic generator (tests only).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        }
    }

    /// A dense matrix in the collocation layout (interval rows, then boundary rows).
    struct Dense {
        d: Dims,
        a: Vec<f64>,
    }

    impl Dense {
        fn at(&self, r: usize, c: usize) -> f64 {
            self.a[r * self.d.size() + c]
        }

        /// A random well-conditioned block system with `nl` left boundary rows (at random
        /// positions among the boundary rows).
        fn random(d: Dims, nl: usize, rng: &mut Lcg) -> Self {
            let Dims { n, k, m } = d;
            let size = d.size();
            let mut a = vec![0.0; size * size];
            for i in 0..m - 1 {
                for r in 0..n {
                    let row = i * n + r;
                    for c in 0..n {
                        let id = if r == c { 1.0 } else { 0.0 };
                        a[row * size + i * n + c] = -id + 0.3 * rng.next();
                        a[row * size + (i + 1) * n + c] = id + 0.3 * rng.next();
                    }
                    for l in 0..k {
                        a[row * size + m * n + l] = 0.3 * rng.next() / m as f64;
                    }
                }
            }
            // which boundary rows are left rows: a rotation of 0..n+k
            let nb = n + k;
            let shift = ((rng.next() + 1.0) * nb as f64) as usize % nb;
            for t in 0..nb {
                let r = (t + shift) % nb;
                let row = (m - 1) * n + r;
                let left = t < nl;
                let base = if left { 0 } else { (m - 1) * n };
                for c in 0..n {
                    a[row * size + base + c] = rng.next() + if c == t % n { 2.0 } else { 0.0 };
                }
                for l in 0..k {
                    a[row * size + m * n + l] =
                        rng.next() + if t >= n && l == t - n { 2.0 } else { 0.0 };
                }
            }
            Dense { d, a }
        }

        fn transposed(&self) -> Vec<f64> {
            let s = self.d.size();
            let mut t = vec![0.0; s * s];
            for r in 0..s {
                for c in 0..s {
                    t[c * s + r] = self.a[r * s + c];
                }
            }
            t
        }
    }

    impl BlockSource for Dense {
        fn fill_interval(&mut self, i: usize, out: &mut [f64], w: usize) {
            let Dims { n, k, m } = self.d;
            for r in 0..n {
                for c in 0..2 * n {
                    out[r * w + c] = self.at(i * n + r, i * n + c);
                }
                for l in 0..k {
                    out[r * w + 2 * n + l] = self.at(i * n + r, m * n + l);
                }
            }
        }
        fn fill_boundary(&mut self, out: &mut [f64], w: usize) {
            let Dims { n, k, m } = self.d;
            for r in 0..n + k {
                let row = (m - 1) * n + r;
                for c in 0..n {
                    out[r * w + c] = self.at(row, c);
                    out[r * w + n + c] = self.at(row, (m - 1) * n + c);
                }
                for l in 0..k {
                    out[r * w + 2 * n + l] = self.at(row, m * n + l);
                }
            }
        }
        fn node_x(&self, i: usize) -> f64 {
            i as f64
        }
    }

    /// Dense Gaussian elimination with partial pivoting: solves `a x = b` (row-major `a`).
    fn dense_reference(a: &[f64], s: usize, b: &[f64]) -> Vec<f64> {
        let mut lu = a.to_vec();
        let mut piv = vec![0; s];
        eliminate(&mut lu, s, s, s, &mut piv).expect("reference matrix is regular");
        let mut x = b.to_vec();
        dense_solve(&lu, &piv, s, &mut x);
        x
    }

    fn max_rel_diff(a: &[f64], b: &[f64]) -> f64 {
        let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            / scale
    }

    #[test]
    fn agrees_with_dense_elimination_forward_transpose_and_multiple_rhs() {
        let mut rng = Lcg(12345);
        let mut lu = BlockLu::default();
        let mut cases = 0;
        for n in 1..=5 {
            for k in 0..=3 {
                for nl in 0..=n + k {
                    for m in [2, 3, 7, 20] {
                        let d = Dims { n, k, m };
                        let s = d.size();
                        let mut dense = Dense::random(d, nl, &mut rng);
                        // the same workspace is reused across sizes (it only grows)
                        lu.factor(d, &mut dense).expect("regular test matrix");
                        assert_eq!(lu.carried_rows(), nl);
                        let ncols = 3;
                        let b: Vec<f64> = (0..s * ncols).map(|_| rng.next()).collect();
                        let mut scratch = vec![0.0; lu.scratch_len()];
                        let at = dense.transposed();
                        for transpose in [false, true] {
                            let mut x = b.clone();
                            lu.solve(&mut x, ncols, transpose, &mut scratch);
                            for c in 0..ncols {
                                let mat = if transpose { &at } else { &dense.a };
                                let r = dense_reference(mat, s, &b[c * s..(c + 1) * s]);
                                let e = max_rel_diff(&x[c * s..(c + 1) * s], &r);
                                assert!(
                                    e < 1e-12,
                                    "n={n} k={k} nl={nl} m={m} transpose={transpose} col {c}: \
                                     relative difference {e:e}"
                                );
                            }
                        }
                        cases += 1;
                    }
                }
            }
        }
        assert_eq!(
            cases,
            4 * (2 + 3 + 4 + 5 + 3 + 4 + 5 + 6 + 4 + 5 + 6 + 7 + 5 + 6 + 7 + 8 + 6 + 7 + 8 + 9)
        );
    }

    #[test]
    fn coupled_boundary_rows_are_reported() {
        let mut rng = Lcg(7);
        let d = Dims { n: 2, k: 0, m: 4 };
        let mut dense = Dense::random(d, 1, &mut rng);
        let s = d.size();
        // boundary row 1 also gets an entry at the left end
        let row = (d.m - 1) * d.n + 1;
        dense.a[row * s] = 0.5;
        dense.a[row * s + (d.m - 1) * d.n] = 0.5;
        let mut lu = BlockLu::default();
        assert_eq!(
            lu.factor(d, &mut dense),
            Err(BlockError::NotSeparated { row: 1 })
        );
    }

    #[test]
    fn a_zero_pivot_column_names_the_node() {
        let mut rng = Lcg(99);
        let d = Dims { n: 2, k: 1, m: 5 };
        let mut dense = Dense::random(d, 1, &mut rng);
        let s = d.size();
        // state component 1 of node 2 appears in no row
        for r in 0..s {
            dense.a[r * s + 2 * d.n + 1] = 0.0;
        }
        let mut lu = BlockLu::default();
        match lu.factor(d, &mut dense) {
            Err(BlockError::Singular { detail }) => {
                assert!(detail.contains("state component 1 at node 2"), "{detail}")
            }
            other => panic!("expected a singular matrix, got {other:?}"),
        }
        // an unknown parameter no row depends on
        let mut dense = Dense::random(d, 1, &mut rng);
        for r in 0..s {
            dense.a[r * s + d.m * d.n] = 0.0;
        }
        match lu.factor(d, &mut dense) {
            Err(BlockError::Singular { detail }) => {
                assert!(detail.contains("unknown parameter 0"), "{detail}")
            }
            other => panic!("expected a singular matrix, got {other:?}"),
        }
    }
}

//! The covariance of a block-arrow fit without the dense `P × P` matrix.
//!
//! With `H = Jᵀ W J = [[A, B], [Bᵀ, C]]` (`W` the robust weights, or 1), `G_k = C_k⁻¹ B_kᵀ` and
//! the Schur complement `S = A − Σ_k B_k G_k`, the columns of `H⁻¹` follow block by block, and
//! every covariance of the fit is a sum `c Σᵢ ψᵢ² zᵢ zᵢᵀ` with `zᵢ = H⁻¹ Jᵢᵀ` (the sandwich) or
//! `σ² H⁻¹` (the linear loss). Both are held as
//!
//! ```text
//! cov(shared, shared)  = Y                                                   (n_s × n_s)
//! cov(shared, local_l) = −F_lᵀ,            F_l = G_l Y − E_l                 (n_s × n_l)
//! cov(local_l, local_m) = δ_lm A_l + F_l G_mᵀ − G_l E_mᵀ                      (n_l × n_l)
//! ```
//!
//! with, for the linear loss, `Y = σ² S⁻¹`, `A_l = σ² C_l⁻¹`, `E_l = 0`, and for the sandwich
//! (residual `i` in block `k`, `tᵢ = J_s,i − G_kᵀ J_l,i`, `yᵢ = S⁻¹ tᵢ`, `aᵢ = C_k⁻¹ J_l,i`)
//! `Y = c Σᵢ ψᵢ² yᵢ yᵢᵀ`, `A_l = c Σ_{i∈l} ψᵢ² aᵢ aᵢᵀ`, `E_l = c Σ_{i∈l} ψᵢ² aᵢ yᵢᵀ`.
//! Storage and work are linear in the number of blocks; any entry, the variances or the dense
//! matrix can be read from it.

use super::blocks::{BlockJacobian, BlockStructure};
use nalgebra::{DMatrix, DVector};
use std::sync::Arc;

/// The covariance of a block-arrow fit in compact form (see the module docs of `least_squares::block_covariance`).
#[derive(Debug, Clone)]
pub struct BlockCovariance {
    structure: Arc<BlockStructure>,
    y: DMatrix<f64>,
    a: Vec<DMatrix<f64>>,
    e: Vec<DMatrix<f64>>,
    g: Vec<DMatrix<f64>>,
    // F_l = G_l Y − E_l
    f: Vec<DMatrix<f64>>,
}

/// `(S⁻¹, [C_k⁻¹], [G_k])` of the block elimination.
type BlockInverse = (DMatrix<f64>, Vec<DMatrix<f64>>, Vec<DMatrix<f64>>);

/// `C_k⁻¹`, `G_k = C_k⁻¹ B_kᵀ` and `S⁻¹` of `H = Jᵀ W J`; `None` if `H` is singular.
fn factors(j: &BlockJacobian, w: Option<&[f64]>) -> Option<BlockInverse> {
    let nb = j.normal_blocks(w, None);
    let mut s = nb.a;
    let mut c_inv = Vec::with_capacity(nb.c.len());
    let mut g = Vec::with_capacity(nb.c.len());
    for (c, b) in nb.c.into_iter().zip(&nb.b) {
        let ci = if c.nrows() == 0 { c } else { c.try_inverse()? };
        let gk = &ci * b.transpose();
        s -= b * &gk;
        c_inv.push(ci);
        g.push(gk);
    }
    let s_inv = if s.nrows() == 0 { s } else { s.try_inverse()? };
    Some((s_inv, c_inv, g))
}

impl BlockCovariance {
    /// `σ² (JᵀJ)⁻¹`; `None` if `JᵀJ` is singular.
    pub(crate) fn linear(j: &BlockJacobian, s2: f64) -> Option<Self> {
        let (s_inv, c_inv, g) = factors(j, None)?;
        let ns = j.structure().num_shared();
        let e: Vec<DMatrix<f64>> = g.iter().map(|gk| DMatrix::zeros(gk.nrows(), ns)).collect();
        let a = c_inv.into_iter().map(|c| c * s2).collect();
        Some(Self::assemble(j.structure().clone(), s_inv * s2, a, e, g))
    }

    /// The sandwich `c H⁻¹ (Σᵢ ψᵢ² JᵢᵀJᵢ) H⁻¹`, `H = Σᵢ wᵢ JᵢᵀJᵢ`; `None` if `H` is singular.
    pub(crate) fn sandwich(j: &BlockJacobian, w: &[f64], psi: &[f64], c: f64) -> Option<Self> {
        let (s_inv, c_inv, g) = factors(j, Some(w))?;
        let st = j.structure().clone();
        let ns = st.num_shared();
        let mut t_sum = DMatrix::zeros(ns, ns);
        let mut a = Vec::with_capacity(st.num_blocks());
        let mut e = Vec::with_capacity(st.num_blocks());
        let mut t = DVector::zeros(ns);
        for k in 0..st.num_blocks() {
            let nl = st.locals(k).len();
            let loc = j.local(k);
            let (mut ak, mut ek) = (DMatrix::zeros(nl, nl), DMatrix::zeros(nl, ns));
            for (r, i) in st.rows(k).enumerate() {
                let p2 = c * psi[i] * psi[i];
                let jl = DVector::from_column_slice(&loc[r * nl..(r + 1) * nl]);
                let ai = &c_inv[k] * &jl;
                t.copy_from_slice(&j.shared()[i * ns..(i + 1) * ns]);
                t -= g[k].transpose() * &jl;
                let yi = &s_inv * &t;
                t_sum += &t * t.transpose() * p2;
                ak += &ai * ai.transpose() * p2;
                ek += &ai * yi.transpose() * p2;
            }
            a.push(ak);
            e.push(ek);
        }
        let y = &s_inv * t_sum * &s_inv;
        Some(Self::assemble(st, y, a, e, g))
    }

    fn assemble(
        structure: Arc<BlockStructure>,
        y: DMatrix<f64>,
        a: Vec<DMatrix<f64>>,
        e: Vec<DMatrix<f64>>,
        g: Vec<DMatrix<f64>>,
    ) -> Self {
        let f = g.iter().zip(&e).map(|(gl, el)| gl * &y - el).collect();
        BlockCovariance {
            structure,
            y,
            a,
            e,
            g,
            f,
        }
    }

    /// The structure of the fit.
    pub fn structure(&self) -> &Arc<BlockStructure> {
        &self.structure
    }

    /// Covariance of the shared parameters (row-major `n_s × n_s`).
    pub fn shared(&self) -> Vec<f64> {
        let ns = self.y.nrows();
        (0..ns * ns).map(|i| self.y[(i / ns, i % ns)]).collect()
    }

    /// Covariance of block `k`'s local parameters (row-major `n_l × n_l`).
    pub fn local(&self, k: usize) -> Vec<f64> {
        let m = self.local_block(k, k);
        let nl = m.nrows();
        (0..nl * nl).map(|i| m[(i / nl, i % nl)]).collect()
    }

    /// `cov(local_l, local_m)`.
    fn local_block(&self, l: usize, m: usize) -> DMatrix<f64> {
        let mut c = &self.f[l] * self.g[m].transpose() - &self.g[l] * self.e[m].transpose();
        if l == m {
            c += &self.a[l];
        }
        c
    }

    /// Variances of all parameters (length `P`), without forming the `P × P` matrix.
    pub fn variances(&self) -> Vec<f64> {
        let mut v: Vec<f64> = (0..self.y.nrows()).map(|i| self.y[(i, i)]).collect();
        for k in 0..self.structure.num_blocks() {
            let (fk, gk, ek, ak) = (&self.f[k], &self.g[k], &self.e[k], &self.a[k]);
            for a in 0..ak.nrows() {
                let fg = fk.row(a).dot(&gk.row(a));
                let ge = gk.row(a).dot(&ek.row(a));
                v.push(ak[(a, a)] + fg - ge);
            }
        }
        v
    }

    /// Entry `(i, j)` of the covariance.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let st = &self.structure;
        match (st.block_of_param(i), st.block_of_param(j)) {
            (None, None) => self.y[(i, j)],
            (None, Some((k, b))) => -self.f[k][(b, i)],
            (Some((k, a)), None) => -self.f[k][(a, j)],
            (Some((l, a)), Some((m, b))) => self.local_entry(l, a, m, b),
        }
    }

    /// `cov(local_l[a], local_m[b])`.
    fn local_entry(&self, l: usize, a: usize, m: usize, b: usize) -> f64 {
        let mut v =
            self.f[l].row(a).dot(&self.g[m].row(b)) - self.g[l].row(a).dot(&self.e[m].row(b));
        if l == m {
            v += self.a[l][(a, b)];
        }
        v
    }

    /// The product `cov · v` (length `P`) without the `P × P` matrix: linear in the number of
    /// blocks. With `cov = (JᵀJ)⁻¹` (unit variance) and `v = Jᵀ d` it is the least-squares
    /// response of the parameters to a residual change `d`.
    pub fn mul_vec(&self, v: &[f64]) -> Vec<f64> {
        let st = &self.structure;
        let ns = st.num_shared();
        let vs = DVector::from_column_slice(&v[..ns]);
        // Σ_m G_mᵀ v_m and Σ_m E_mᵀ v_m
        let mut gv = DVector::zeros(ns);
        let mut ev = DVector::zeros(ns);
        let mut xs = &self.y * &vs;
        for k in 0..st.num_blocks() {
            let vk = DVector::from_column_slice(&v[st.locals(k)]);
            gv += self.g[k].transpose() * &vk;
            ev += self.e[k].transpose() * &vk;
            xs -= self.f[k].transpose() * &vk;
        }
        let mut x = Vec::with_capacity(st.num_params());
        x.extend(xs.iter());
        for k in 0..st.num_blocks() {
            let vk = DVector::from_column_slice(&v[st.locals(k)]);
            let xk = &self.a[k] * &vk - &self.f[k] * &vs + &self.f[k] * &gv - &self.g[k] * &ev;
            x.extend(xk.iter());
        }
        x
    }

    /// The shared rows of `cov · v` (length `n_s`): `Y v_s − Σ_l F_lᵀ v_l`, skipping the blocks
    /// where `v` is zero (a change confined to one experiment costs `O(n_s²)` per block it
    /// touches).
    pub fn mul_vec_shared(&self, v: &[f64]) -> Vec<f64> {
        let st = &self.structure;
        let ns = st.num_shared();
        let mut x: Vec<f64> = (0..ns)
            .map(|i| (0..ns).map(|j| self.y[(i, j)] * v[j]).sum())
            .collect();
        for k in 0..st.num_blocks() {
            let vk = &v[st.locals(k)];
            if vk.iter().all(|&a| a == 0.0) {
                continue;
            }
            let f = &self.f[k];
            for (i, xi) in x.iter_mut().enumerate() {
                *xi -= vk
                    .iter()
                    .enumerate()
                    .map(|(a, va)| f[(a, i)] * va)
                    .sum::<f64>();
            }
        }
        x
    }

    /// The dense covariance (row-major `P × P`: `P²` numbers; for small fits and reports).
    pub fn to_dense(&self) -> Vec<f64> {
        let st = &self.structure;
        let (ns, np) = (st.num_shared(), st.num_params());
        let mut c = vec![0.0; np * np];
        for i in 0..ns {
            for j in 0..ns {
                c[i * np + j] = self.y[(i, j)];
            }
        }
        for l in 0..st.num_blocks() {
            for (a, pi) in st.locals(l).enumerate() {
                for j in 0..ns {
                    let v = -self.f[l][(a, j)];
                    c[pi * np + j] = v;
                    c[j * np + pi] = v;
                }
                for m in 0..st.num_blocks() {
                    for (b, pj) in st.locals(m).enumerate() {
                        c[pi * np + pj] = self.local_entry(l, a, m, b);
                    }
                }
            }
        }
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::least_squares::loss::{self, Loss};

    fn jacobian() -> BlockJacobian {
        let s = Arc::new(BlockStructure::new(2, [(4, 1), (5, 2), (3, 0), (6, 1)]));
        let mut j = BlockJacobian::zeros(s);
        let mut v = 0.61;
        for (sh, lo) in j.blocks_mut() {
            for x in sh.iter_mut().chain(lo.iter_mut()) {
                v = (v * 5.77 + 0.29) % 2.0 - 1.0;
                *x = v;
            }
        }
        j
    }

    fn assert_close(a: &[f64], b: &[f64]) {
        let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (i, (x, y)) in a.iter().zip(b).enumerate() {
            assert!((x - y).abs() <= 1e-10 * scale, "entry {i}: {x} vs {y}");
        }
    }

    #[test]
    fn products_equal_the_dense_matrix_times_the_vector() {
        let j = jacobian();
        let np = 6;
        let psi: Vec<f64> = (0..18).map(|i| 0.3 + 0.05 * i as f64).collect();
        let w: Vec<f64> = (0..18).map(|i| 1.0 - 0.02 * i as f64).collect();
        let v: Vec<f64> = (0..np).map(|i| (i as f64 * 1.3).sin()).collect();
        for c in [
            BlockCovariance::linear(&j, 0.7).unwrap(),
            BlockCovariance::sandwich(&j, &w, &psi, 1.1).unwrap(),
        ] {
            let d = c.to_dense();
            let dense: Vec<f64> = (0..np)
                .map(|i| (0..np).map(|k| d[i * np + k] * v[k]).sum())
                .collect();
            assert_close(&c.mul_vec(&v), &dense);
            assert_close(&c.mul_vec_shared(&v), &dense[..2]);
        }
    }

    #[test]
    fn linear_covariance_is_the_inverse_normal_matrix() {
        let j = jacobian();
        let (nr, np) = (18, 6);
        let jm = DMatrix::from_row_slice(nr, np, &j.to_dense());
        let inv = (jm.transpose() * &jm).try_inverse().unwrap() * 0.7;
        let dense: Vec<f64> = (0..np * np).map(|i| inv[(i / np, i % np)]).collect();
        let c = BlockCovariance::linear(&j, 0.7).unwrap();
        assert_close(&c.to_dense(), &dense);
        let diag: Vec<f64> = (0..np).map(|i| dense[i * np + i]).collect();
        assert_close(&c.variances(), &diag);
        for (i, k) in [(0, 1), (3, 5), (4, 2), (5, 5), (2, 4)] {
            assert_close(&[c.get(i, k)], &[dense[i * np + k]]);
        }
        assert_close(&c.shared(), &[dense[0], dense[1], dense[np], dense[np + 1]]);
        assert_close(
            &c.local(1),
            &[
                dense[3 * np + 3],
                dense[3 * np + 4],
                dense[4 * np + 3],
                dense[4 * np + 4],
            ],
        );
    }

    #[test]
    fn sandwich_is_the_dense_sandwich() {
        let j = jacobian();
        let (nr, np) = (18, 6);
        let r: Vec<f64> = (0..nr).map(|i| ((i * 7 % 5) as f64 - 2.0) * 0.8).collect();
        let w = loss::weights(Loss::SoftL1, 0.5, &r);
        let (wt, psi): (Vec<f64>, Vec<f64>) = w
            .iter()
            .zip(&r)
            .map(|((d1, wi), ri)| (*wi, d1 * ri))
            .unzip();
        let jd = j.to_dense();
        let (mut h, mut b) = (DMatrix::zeros(np, np), DMatrix::zeros(np, np));
        for i in 0..nr {
            let row = DVector::from_column_slice(&jd[i * np..(i + 1) * np]);
            h += &row * row.transpose() * wt[i];
            b += &row * row.transpose() * psi[i] * psi[i];
        }
        let hi = h.try_inverse().unwrap();
        let cov = &hi * b * &hi * 1.5;
        let dense: Vec<f64> = (0..np * np).map(|i| cov[(i / np, i % np)]).collect();
        let c = BlockCovariance::sandwich(&j, &wt, &psi, 1.5).unwrap();
        assert_close(&c.to_dense(), &dense);
        let diag: Vec<f64> = (0..np).map(|i| dense[i * np + i]).collect();
        assert_close(&c.variances(), &diag);
    }

    #[test]
    fn a_singular_normal_matrix_has_no_covariance() {
        let mut j = jacobian();
        // block 3's local column zero
        for v in j.blocks_mut().pop().unwrap().1.iter_mut() {
            *v = 0.0;
        }
        assert!(BlockCovariance::linear(&j, 1.0).is_none());
    }
}

//! The trust-region step of a block-arrow problem through the Schur complement of its normal
//! equations (as bundle adjustment solves them).
//!
//! In the scaled variables `u = D s` the step solves `(ĴᵀĴ + μ I) u = −Ĵᵀr`, `Ĵ = J D⁻¹`, with
//! the smallest `μ ≥ 0` that keeps `‖u‖ ≤ Δ` (the same Levenberg–Marquardt parameter the dense
//! path finds from the eigen-decomposition of `ĴᵀĴ`). With `ĴᵀĴ = [[A, B], [Bᵀ, C]]`, `C`
//! block diagonal, each block's `C_k` is diagonalised once per step (`C_k = Q_k Λ_k Q_kᵀ`, tiny),
//! and for every trial `μ`
//!
//! ```text
//! S(μ)  = A + μ I − Σ_k B̃_k (Λ_k + μ)⁻¹ B̃_kᵀ            (n_s × n_s, B̃_k = B_k Q_k)
//! u_s   = S(μ)⁺ (−g_s + Σ_k B̃_k (Λ_k + μ)⁻¹ g̃_k)           (g̃_k = Q_kᵀ g_k)
//! ũ_k   = (Λ_k + μ)⁻¹ (−g̃_k − B̃_kᵀ u_s),   u_k = Q_k ũ_k
//! ```
//!
//! costs `O(M n_l n_s²)`: linear in the number of blocks `M`. Eigenvalues below `10⁻¹⁴ λ̄`
//! (`λ̄ = 2 max(λ_max(A), max_k λ_max(C_k)) ≥ λ_max(ĴᵀĴ)`) count as zero, as in the dense path's
//! pseudo-inverse.

use super::blocks::BlockJacobian;
use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// A block's local system in the eigenbasis of its `C_k`.
struct LocalBlock {
    /// Eigenvectors `Q_k` (`n_l × n_l`).
    q: DMatrix<f64>,
    /// Eigenvalues `Λ_k` (clipped at 0).
    lam: Vec<f64>,
    /// `B̃_k = B_k Q_k` (`n_s × n_l`).
    b: DMatrix<f64>,
    /// `g̃_k = Q_kᵀ g_k`.
    g: Vec<f64>,
}

/// `min ‖J s + r‖²` subject to `‖D s‖ ≤ Δ` for a block-arrow `J`; returns `s`.
pub(super) fn block_trust_region_step(
    j: &BlockJacobian,
    r: &[f64],
    d: &[f64],
    radius: f64,
) -> Vec<f64> {
    let structure = j.structure().clone();
    let ns = structure.num_shared();
    let nb = j.normal_blocks(None, Some(d));
    let (gs, gl) = j.scaled_gradient(r, d);
    let mut lmax = if ns > 0 {
        SymmetricEigen::new(nb.a.clone())
            .eigenvalues
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
    } else {
        0.0
    };
    let mut blocks = Vec::with_capacity(nb.c.len());
    let mut lmax_local = 0.0f64;
    for ((c, b), g) in nb.c.into_iter().zip(nb.b).zip(gl) {
        if c.nrows() == 0 {
            blocks.push(LocalBlock {
                q: c,
                lam: Vec::new(),
                b,
                g: Vec::new(),
            });
            continue;
        }
        let eig = SymmetricEigen::new(c);
        lmax_local = eig
            .eigenvalues
            .iter()
            .fold(lmax_local, |m, v| m.max(v.abs()));
        let bt = &b * &eig.eigenvectors;
        let gt = eig.eigenvectors.transpose() * g;
        blocks.push(LocalBlock {
            lam: eig.eigenvalues.iter().map(|v| v.max(0.0)).collect(),
            q: eig.eigenvectors,
            b: bt,
            g: gt.iter().copied().collect(),
        });
    }
    if lmax_local > 0.0 {
        // ĴᵀĴ ≤ 2 diag(A, C): an upper bound within a factor 2 of λ_max
        lmax = 2.0 * lmax.max(lmax_local);
    }
    let floor = 1e-14 * lmax.max(1e-300);
    let gnorm = (gs.norm_squared()
        + blocks
            .iter()
            .map(|b| b.g.iter().map(|v| v * v).sum::<f64>())
            .sum::<f64>())
    .sqrt();
    let mut local = vec![0.0; structure.num_local()];
    let mut u_s = solve_at(0.0, &nb.a, &gs, &blocks, floor, &mut local);
    let norm = |u_s: &DVector<f64>, local: &[f64]| {
        (u_s.norm_squared() + local.iter().map(|v| v * v).sum::<f64>()).sqrt()
    };
    if norm(&u_s, &local) > radius {
        // ‖u(μ)‖ decreases in μ; at μ = ‖g‖/Δ + λ̄ it is ≤ Δ. Geometric bisection.
        let mut hi = gnorm / radius + lmax;
        let mut lo = hi * 1e-16;
        for _ in 0..200 {
            let mid = (lo * hi).sqrt();
            let us = solve_at(mid, &nb.a, &gs, &blocks, floor, &mut local);
            if norm(&us, &local) > radius {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi <= lo * (1.0 + 1e-10) {
                break;
            }
        }
        u_s = solve_at(hi, &nb.a, &gs, &blocks, floor, &mut local);
    }
    // back to the parameters: u_k = Q_k ũ_k, s = D⁻¹ u
    let mut s = vec![0.0; structure.num_params()];
    for i in 0..ns {
        s[i] = u_s[i] / d[i];
    }
    let mut off = 0;
    for (k, b) in blocks.iter().enumerate() {
        let cols = structure.locals(k);
        let nl = cols.len();
        let ut = &local[off..off + nl];
        for (a, c) in cols.enumerate() {
            let v: f64 = (0..nl).map(|m| b.q[(a, m)] * ut[m]).sum();
            s[c] = v / d[c];
        }
        off += nl;
    }
    s
}

/// The shared part `u_s` of the step at `μ`; writes the rotated local parts `ũ_k` (block after
/// block) into `local`.
fn solve_at(
    mu: f64,
    a: &DMatrix<f64>,
    gs: &DVector<f64>,
    blocks: &[LocalBlock],
    floor: f64,
    local: &mut [f64],
) -> DVector<f64> {
    let ns = gs.len();
    let mut s = a.clone();
    for i in 0..ns {
        s[(i, i)] += mu;
    }
    let mut rhs = -gs;
    for b in blocks {
        for (m, &l) in b.lam.iter().enumerate() {
            let den = l + mu;
            if den <= floor {
                continue;
            }
            let col = b.b.column(m);
            for p in 0..ns {
                let cp = col[p] / den;
                if cp == 0.0 {
                    continue;
                }
                rhs[p] += cp * b.g[m];
                for q in 0..ns {
                    s[(p, q)] -= cp * col[q];
                }
            }
        }
    }
    let u_s = if ns > 0 {
        let eig = SymmetricEigen::new(s);
        let gq = eig.eigenvectors.transpose() * &rhs;
        let z = DVector::from_iterator(
            ns,
            (0..ns).map(|i| {
                let den = eig.eigenvalues[i].max(0.0);
                if den > floor {
                    gq[i] / den
                } else {
                    0.0
                }
            }),
        );
        eig.eigenvectors * z
    } else {
        DVector::zeros(0)
    };
    let mut off = 0;
    for b in blocks {
        for (m, &l) in b.lam.iter().enumerate() {
            let den = l + mu;
            local[off + m] = if den > floor {
                let bu: f64 = b.b.column(m).dot(&u_s);
                (-b.g[m] - bu) / den
            } else {
                0.0
            };
        }
        off += b.lam.len();
    }
    u_s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::least_squares::blocks::BlockStructure;
    use crate::least_squares::trust_region_step;
    use std::sync::Arc;

    /// A pseudo-random block-arrow Jacobian (2 shared; blocks with 0, 1 and 2 locals).
    fn jacobian(zero_local: bool) -> BlockJacobian {
        let s = Arc::new(BlockStructure::new(2, [(4, 1), (5, 2), (3, 0), (6, 1)]));
        let mut j = BlockJacobian::zeros(s);
        let mut v = 0.37;
        for (k, (sh, lo)) in j.blocks_mut().into_iter().enumerate() {
            for x in sh.iter_mut() {
                v = (v * 7.31 + 0.17) % 2.0 - 1.0;
                *x = v;
            }
            for x in lo.iter_mut() {
                v = (v * 7.31 + 0.17) % 2.0 - 1.0;
                // block 3's local column is zero: a parameter the data do not see
                *x = if zero_local && k == 3 { 0.0 } else { 3.0 * v };
            }
        }
        j
    }

    fn dense_step(j: &BlockJacobian, r: &[f64], d: &[f64], radius: f64) -> Vec<f64> {
        let s = j.structure();
        let jm = DMatrix::from_row_slice(s.num_residuals(), s.num_params(), &j.to_dense());
        let rv = DVector::from_column_slice(r);
        trust_region_step(&jm, &rv, d, radius)
            .iter()
            .copied()
            .collect()
    }

    #[test]
    fn schur_step_is_the_dense_step() {
        for zero_local in [false, true] {
            let j = jacobian(zero_local);
            let nr = j.structure().num_residuals();
            let r: Vec<f64> = (0..nr)
                .map(|i| ((i * 37 % 11) as f64 - 5.0) * 0.1)
                .collect();
            let d = [1.0, 0.5, 2.0, 1.3, 0.7, 1.0];
            for radius in [1e3, 1.0, 0.3, 1e-3] {
                let a = block_trust_region_step(&j, &r, &d, radius);
                let b = dense_step(&j, &r, &d, radius);
                let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for (x, y) in a.iter().zip(&b) {
                    assert!(
                        (x - y).abs() <= 1e-9 * scale,
                        "zero_local {zero_local}, radius {radius}: {a:?} vs {b:?}"
                    );
                }
                // the trust region holds
                let norm: f64 = a.iter().zip(&d).map(|(s, d)| (s * d).powi(2)).sum();
                assert!(norm.sqrt() <= radius * (1.0 + 1e-8), "{radius}");
            }
        }
    }
}

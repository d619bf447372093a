//! Mesh operations: validation, uniform meshes, refinement (equal subdivision, as in scipy's
//! `solve_bvp`) and coarsening (removing nodes where the residual is far below tolerance, in the
//! spirit of bvp4c's redistribution).

use crate::error::BvpError;

/// `m` equally spaced nodes on `[a, b]`, the last one exactly `b`. `m = 0` gives an empty
/// vector and `m = 1` gives `[a]` (as numpy's `linspace`); neither is a valid mesh
/// ([`validate`] needs two nodes).
pub fn linspace(a: f64, b: f64, m: usize) -> Vec<f64> {
    match m {
        0 => return Vec::new(),
        1 => return vec![a],
        _ => {}
    }
    let h = (b - a) / (m - 1) as f64;
    (0..m)
        .map(|i| if i == m - 1 { b } else { a + h * i as f64 })
        .collect()
}

/// Checks that a mesh has at least two finite, strictly increasing nodes.
pub fn validate(x: &[f64]) -> Result<(), BvpError> {
    if x.len() < 2 {
        return Err(BvpError::InvalidInput(format!(
            "the mesh needs at least 2 nodes, got {}",
            x.len()
        )));
    }
    for (i, w) in x.windows(2).enumerate() {
        if !w[0].is_finite() || !w[1].is_finite() {
            return Err(BvpError::InvalidInput(format!(
                "mesh node {} is not finite",
                if w[0].is_finite() { i + 1 } else { i }
            )));
        }
        if w[1] <= w[0] {
            return Err(BvpError::InvalidInput(format!(
                "mesh nodes must be strictly increasing: x[{}] = {} >= x[{}] = {}",
                i,
                w[0],
                i + 1,
                w[1]
            )));
        }
    }
    Ok(())
}

/// Inserts one node into each interval of `insert_1` and two nodes (equal subdivision) into each
/// interval of `insert_2`. Interval `i` is `[x[i], x[i+1]]`; both lists are sorted.
/// A mesh of fewer than two nodes is returned unchanged.
///
/// # Panics
///
/// Panics if `nodes_per_interval` has fewer than `x.len() - 1` entries.
pub fn refine(x: &[f64], nodes_per_interval: &[u8]) -> Vec<f64> {
    if x.len() < 2 {
        return x.to_vec();
    }
    let mut out = Vec::with_capacity(
        x.len()
            + nodes_per_interval
                .iter()
                .map(|&k| k as usize)
                .sum::<usize>(),
    );
    for i in 0..x.len() - 1 {
        out.push(x[i]);
        let k = nodes_per_interval[i] as usize;
        let h = (x[i + 1] - x[i]) / (k + 1) as f64;
        for j in 1..=k {
            out.push(x[i] + h * j as f64);
        }
    }
    out.push(x[x.len() - 1]);
    out
}

/// Marks intervals for refinement: 1 node where `tol < r < 100 tol`, 2 nodes where `r >= 100 tol`
/// (scipy's rule). Returns the number of nodes to add.
pub fn mark_refinement(rms: &[f64], tol: f64, marks: &mut Vec<u8>) -> usize {
    marks.clear();
    let mut added = 0;
    for &r in rms {
        let k = if r.is_nan() || r >= 100.0 * tol {
            2
        } else if r > tol {
            1
        } else {
            0
        };
        added += k as usize;
        marks.push(k);
    }
    added
}

/// Removes interior nodes shared by two neighbouring intervals whose residuals are both below
/// `threshold` (pairs taken left to right without overlap). Merging two intervals doubles `h`,
/// and the residual of the 4th-order Lobatto IIIa solution scales like `h^3`, so a threshold of
/// `tol / 20` keeps the merged interval below about `0.4 tol`. Returns the coarser mesh; a mesh
/// of fewer than two nodes is returned unchanged, and a NaN residual never counts as below the
/// threshold.
///
/// # Panics
///
/// Panics if `rms` has more than `x.len() - 1` entries.
pub fn coarsen(x: &[f64], rms: &[f64], threshold: f64) -> Vec<f64> {
    if x.len() < 2 {
        return x.to_vec();
    }
    let mut out = Vec::with_capacity(x.len());
    out.push(x[0]);
    let mut i = 0;
    let n_int = rms.len();
    while i < n_int {
        if i + 1 < n_int && rms[i] < threshold && rms[i + 1] < threshold {
            // drop node i+1
            out.push(x[i + 2]);
            i += 2;
        } else {
            out.push(x[i + 1]);
            i += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refine_lists(x: &[f64], one: &[usize], two: &[usize]) -> Vec<f64> {
        let mut marks = vec![0u8; x.len() - 1];
        for &i in one {
            marks[i] = 1;
        }
        for &i in two {
            marks[i] = 2;
        }
        refine(x, &marks)
    }

    #[test]
    fn refinement_matches_scipy_modify_mesh() {
        assert_eq!(
            refine_lists(&[0.0, 1.0, 3.0, 9.0], &[0], &[2]),
            vec![0.0, 0.5, 1.0, 3.0, 5.0, 7.0, 9.0]
        );
        assert_eq!(
            refine_lists(&[-6.0, -3.0, 0.0, 3.0, 6.0], &[1], &[0, 2, 3]),
            vec![-6.0, -5.0, -4.0, -3.0, -1.5, 0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
        );
    }

    #[test]
    fn marks_follow_scipy_thresholds() {
        let mut marks = Vec::new();
        let added = mark_refinement(&[0.5, 2.0, 150.0, f64::NAN], 1.0, &mut marks);
        assert_eq!(marks, vec![0, 1, 2, 2]);
        assert_eq!(added, 5);
    }

    #[test]
    fn coarsening_merges_quiet_pairs_only() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let rms = [0.0, 0.0, 1.0, 0.0, 0.0];
        assert_eq!(coarsen(&x, &rms, 0.1), vec![0.0, 2.0, 3.0, 5.0]);
    }

    #[test]
    fn validation_names_the_problem() {
        assert!(validate(&[0.0]).is_err());
        let e = validate(&[0.0, 1.0, 1.0]).unwrap_err().to_string();
        assert!(e.contains("strictly increasing"), "{e}");
        assert!(validate(&[0.0, f64::NAN]).is_err());
        assert_eq!(linspace(0.0, 1.0, 5), vec![0.0, 0.25, 0.5, 0.75, 1.0]);
        assert_eq!(linspace(0.0, 1.0, 0), Vec::<f64>::new());
        assert_eq!(linspace(2.0, 1.0, 1), vec![2.0]);
    }
}

//! The cost landscape `J(n, κ)` on a grid (paper Fig. 4).
//!
//! Rows are computed in parallel. Each κ-row is walked from the Newtonian end (largest `n`) towards smaller `n`, every point
//! warm-started from its neighbour; the row starts from the Newtonian solution (`n = 1` does not
//! depend on κ). Where a point fails, one intermediate step is tried; if that fails too, the
//! rest of the row (smaller `n`, i.e. stronger strain thinning) is marked `NaN`: there the BVP
//! has no solution, the strain rate explodes at the take-up, as the paper notes. The BVPs are
//! solved at the tolerance of `options.simulate` without keeping factorisations.

use super::identify::{IdentifyOptions, Rheometer, RheometerError};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// A computed landscape.
#[derive(Debug, Clone)]
pub struct Landscape {
    /// Grid values of `n`.
    pub n: Vec<f64>,
    /// Grid values of `κ`.
    pub kappa: Vec<f64>,
    /// `J(n_i, κ_j)` at index `j * n.len() + i` (`NaN` where the simulation failed).
    pub cost: Vec<f64>,
}

impl Landscape {
    /// The grid point with the smallest cost `(n, κ, J)`.
    pub fn minimum(&self) -> Option<(f64, f64, f64)> {
        let mut best: Option<(f64, f64, f64)> = None;
        for (j, &k) in self.kappa.iter().enumerate() {
            for (i, &n) in self.n.iter().enumerate() {
                let c = self.cost[j * self.n.len() + i];
                if c.is_finite() && best.is_none_or(|b| c < b.2) {
                    best = Some((n, k, c));
                }
            }
        }
        best
    }
}

impl Rheometer {
    /// Computes `J(n, κ)` of `options.estimator` (take-up factors 1) on the grid `ns × kappas`,
    /// solving the BVPs at `options.simulate.tol` (the CLI uses 1e-4 for landscapes: a picture,
    /// not a fit).
    /// `progress` is called after every point with the number of points done.
    pub fn landscape(
        &self,
        ns: &[f64],
        kappas: &[f64],
        options: &IdentifyOptions,
        mut progress: impl FnMut(usize) + Send,
    ) -> Result<Landscape, RheometerError> {
        if ns.is_empty() || kappas.is_empty() {
            return Err(RheometerError::Data("the landscape grid is empty".into()));
        }
        let mut opts = options.clone();
        opts.simulate.factor_at_solution = false;
        // a solve that diverges must fail fast, not refine towards 20 000 nodes
        opts.simulate.max_nodes = opts.simulate.max_nodes.min(3000);
        let mut order: Vec<usize> = (0..ns.len()).collect();
        order.sort_by(|&a, &b| ns[b].total_cmp(&ns[a]));
        let newtonian = self.objective([1.0, kappas[0]], &opts)?.solutions();
        let done = AtomicUsize::new(0);
        let progress = Mutex::new(&mut progress);
        // rows are independent: each starts from the Newtonian solution; one objective (solver
        // workspace) per worker
        let rows: Vec<Vec<f64>> = kappas
            .par_iter()
            .map_init(
                || self.objective([1.0, kappas[0]], &opts).ok(),
                |obj, &k| {
                    let mut row = vec![f64::NAN; ns.len()];
                    if let Some(obj) = obj.as_mut() {
                        obj.set_solutions(&newtonian);
                        let mut prev_n = 1.0;
                        for &i in &order {
                            let n = ns[i];
                            let r = obj.try_cost_at(n, k).or_else(|_| {
                                obj.try_cost_at(0.5 * (n + prev_n), k)?;
                                obj.try_cost_at(n, k)
                            });
                            match r {
                                Ok(c) => {
                                    row[i] = c;
                                    prev_n = n;
                                }
                                Err(_) => break,
                            }
                        }
                    }
                    let d = done.fetch_add(ns.len(), Ordering::Relaxed) + ns.len();
                    if let Ok(mut p) = progress.lock() {
                        (*p)(d);
                    }
                    row
                },
            )
            .collect();
        let cost: Vec<f64> = rows.into_iter().flatten().collect();
        Ok(Landscape {
            n: ns.to_vec(),
            kappa: kappas.to_vec(),
            cost,
        })
    }
}

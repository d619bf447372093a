//! The cost landscape `J(n, κ)` on a grid (paper Fig. 4).
//!
//! Rows are computed in parallel. Each κ-row is walked from the Newtonian end (largest `n`)
//! towards smaller `n`; the row starts from the Newtonian solution (`n = 1` does not depend on
//! κ). Every point is warm-started from the toolkit's secant predictor
//! ([`secant_guess`]): the last two solutions of the row, extrapolated linearly in `n` onto the
//! newest mesh (about a third fewer Newton iterations than starting from the neighbour itself).
//! Only costs are evaluated (no sensitivities); every solve keeps its last Newton matrix
//! ([`SolveOptions::keep_newton_matrix`](crate::SolveOptions::keep_newton_matrix)) and the next
//! point on the same mesh starts simplified Newton from it (on the shipped data's 41×41 grid,
//! 1.0 factorisations per solve instead of 1.5 and 178 dual-number evaluations instead of 226;
//! the 101×101 landscape takes 0.86 of the time, its costs move by at most 8e-6 relative,
//! within the solves' tolerance).
//!
//! Where a point fails, the step from the last good point is halved recursively
//! ([`bisect_step`]; once on fine grids, up to three times on coarse ones); if that fails too,
//! the rest of the row
//! (smaller `n`, i.e. stronger strain thinning) is marked `NaN`: there the BVP has no solution,
//! the strain rate explodes at the take-up, as the paper notes. Approaching that edge the
//! meshes grow quickly and a failing solve refines until it exceeds its node budget, so the
//! landscape caps the mesh at [`LANDSCAPE_MAX_NODES`] nodes and each solve's growth over the
//! mesh it starts from at [`LANDSCAPE_GROWTH_LIMIT`]: a failure costs a few milliseconds
//! instead of tens, and points that would need more nodes are marked missing.
//!
//! [`Rheometer::landscape_with`] can be stopped early (a cancellation flag, checked before
//! every grid point) and says for every point whether it was computed, failed, or not reached
//! ([`PointStatus`]).

use super::data::Rheometer;
use super::options::{IdentifyOptions, RheometerError};
use crate::continuation::{bisect_step, secant_guess};
use crate::solution::Solution;
use crate::solve::{GrowthLimit, Guess};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// Largest mesh of a landscape solve (at the CLI's tolerance 1e-4 the solutions need 60–300
/// nodes except right at the edge of the region where the BVP has a solution).
pub const LANDSCAPE_MAX_NODES: usize = 1000;

/// How far a landscape solve may refine beyond the mesh it starts from (a neighbour's solution,
/// or its secant prediction): 8 times its nodes, always 300. A step of the grid changes the
/// solution's mesh by a few tens of percent except at the edge of the region where the BVP has a
/// solution, where a failing solve otherwise refines to [`LANDSCAPE_MAX_NODES`] before it fails,
/// once per row and again in each bisection of the step. On the shipped data's 101×101 grid the
/// landscape takes 0.90 of the time (9.89 s against 10.95 s, medians of 3), on 61×61 grids
/// 0.77 (shipped data and `data/two_effects`); 3 of the 10 201 points (at n ≤ 0.03, `J` 32–37
/// times the minimum's) are marked failed instead of computed, 3 of 3721 on each 61×61 grid
/// (one of them on `data/two_effects`, whose user fit sits at n = 0.18, at 1.07 times the
/// minimum's `J`), and the other costs move by at most 2.3e-6 relative. 4 times and 200 nodes
/// took 0.78 of the time on the 101×101 grid but marked 15–19 points failed per grid. The
/// Newtonian solutions the rows start from are solved without it; options that set a growth
/// limit of their own keep it.
pub const LANDSCAPE_GROWTH_LIMIT: GrowthLimit = GrowthLimit {
    factor: 8.0,
    at_least: 300,
};

/// How often a failed step `Δn` is halved before the rest of the row is marked missing: until
/// the sub-steps are below 0.02 (fine grids lose nothing by it, and halving steps of 0.01 at
/// the edge of the solvable region only adds failing solves), at least once, at most 3 times.
fn retry_bisections(step: f64) -> u32 {
    let mut depth = 1;
    while depth < 3 && step.abs() / f64::from(1u32 << depth) >= 0.02 {
        depth += 1;
    }
    depth
}

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

/// What happened at one grid point of a landscape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PointStatus {
    /// The cost was computed.
    Computed,
    /// The simulation failed, or an earlier point of the row (larger `n`) failed so the point
    /// lies beyond the edge of the solvable region: cost `NaN`.
    Failed,
    /// Not computed because the landscape was cancelled: cost `NaN`.
    NotReached,
}

/// A landscape that may be incomplete: the costs and, per point, what happened.
#[derive(Debug, Clone)]
pub struct LandscapeRun {
    /// The grid and the costs (`NaN` where failed or not reached).
    pub landscape: Landscape,
    /// Status of `cost[j * n.len() + i]`, same indexing.
    pub status: Vec<PointStatus>,
    /// Whether the run was cancelled before every point was reached.
    pub cancelled: bool,
}

impl LandscapeRun {
    /// Number of grid points with the given status.
    pub fn count(&self, status: PointStatus) -> usize {
        self.status.iter().filter(|&&s| s == status).count()
    }

    /// Number of failed grid points ([`PointStatus::Failed`]).
    pub fn failed(&self) -> usize {
        self.count(PointStatus::Failed)
    }

    /// Number of grid points not reached before cancellation ([`PointStatus::NotReached`]).
    pub fn not_reached(&self) -> usize {
        self.count(PointStatus::NotReached)
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
        progress: impl FnMut(usize) + Send,
    ) -> Result<Landscape, RheometerError> {
        let never = AtomicBool::new(false);
        Ok(self
            .landscape_with(ns, kappas, options, progress, &never)?
            .landscape)
    }

    /// [`Rheometer::landscape`] that stops early once `cancel` is set (checked before every
    /// grid point, so within one point's solve, typically milliseconds) and returns what it
    /// has, with the status of every point. `progress` is called after every finished row with
    /// the number of points done.
    pub fn landscape_with(
        &self,
        ns: &[f64],
        kappas: &[f64],
        options: &IdentifyOptions,
        progress: impl FnMut(usize) + Send,
        cancel: &AtomicBool,
    ) -> Result<LandscapeRun, RheometerError> {
        let walk = RowWalk::new(self, ns, kappas, options, None)?;
        Ok(self.walk_rows(&walk, kappas, vec![None; kappas.len()], progress, cancel))
    }

    /// Walks a few rows of the landscape `ns × kappas` (the smallest, middle and largest `κ`:
    /// the smallest has the largest region without solution, where failing solves cost most)
    /// exactly as [`Rheometer::landscape_with`] does, in parallel, and times them: the
    /// estimate of the whole run ([`LandscapeSample::remaining_s`]) comes from the real
    /// computation, and [`Rheometer::landscape_from`] continues from these rows instead of
    /// computing them again.
    pub fn landscape_sample(
        &self,
        ns: &[f64],
        kappas: &[f64],
        options: &IdentifyOptions,
        cancel: &AtomicBool,
    ) -> Result<LandscapeSample, RheometerError> {
        let walk = RowWalk::new(self, ns, kappas, options, None)?;
        let mut picked = vec![0, kappas.len() / 2, kappas.len() - 1];
        picked.dedup();
        let rows: Vec<SampledRow> = picked
            .par_iter()
            .map_init(
                || walk.objective(self),
                |obj, &j| {
                    let t0 = Instant::now();
                    let (cost, status) = walk.row(obj.as_mut(), kappas[j], cancel);
                    SampledRow {
                        kappa_index: j,
                        cost,
                        status,
                        seconds: t0.elapsed().as_secs_f64(),
                    }
                },
            )
            .collect();
        Ok(LandscapeSample {
            n: ns.to_vec(),
            kappa: kappas.to_vec(),
            options: options.clone(),
            newtonian: walk.newtonian,
            rows,
        })
    }

    /// The whole landscape of `sample` (from [`Rheometer::landscape_sample`] of this
    /// rheometer: its grid, options and Newtonian solutions), keeping the sample's rows
    /// instead of computing them again; otherwise as [`Rheometer::landscape_with`], with
    /// `progress` counting the sample's rows as done from the start.
    pub fn landscape_from(
        &self,
        sample: LandscapeSample,
        mut progress: impl FnMut(usize) + Send,
        cancel: &AtomicBool,
    ) -> Result<LandscapeRun, RheometerError> {
        let LandscapeSample {
            n,
            kappa,
            options,
            newtonian,
            rows,
        } = sample;
        let mut kept: Vec<Option<(Vec<f64>, Vec<PointStatus>)>> = vec![None; kappa.len()];
        for r in rows {
            kept[r.kappa_index] = Some((r.cost, r.status));
        }
        let already = kept.iter().flatten().count() * n.len();
        if already > 0 {
            progress(already);
        }
        let walk = RowWalk::new(self, &n, &kappa, &options, Some(newtonian))?;
        Ok(self.walk_rows(&walk, &kappa, kept, progress, cancel))
    }

    /// Every row of `kappas` not in `kept` walked in parallel (one objective, i.e. solver
    /// workspace, per worker; rows are independent, each starts from the Newtonian solution),
    /// the kept ones as they are; `progress` after every computed row with the points done.
    fn walk_rows(
        &self,
        walk: &RowWalk<'_>,
        kappas: &[f64],
        kept: Vec<Option<(Vec<f64>, Vec<PointStatus>)>>,
        mut progress: impl FnMut(usize) + Send,
        cancel: &AtomicBool,
    ) -> LandscapeRun {
        let ns = walk.ns;
        let done = AtomicUsize::new(kept.iter().flatten().count() * ns.len());
        let progress = Mutex::new(&mut progress);
        let rows: Vec<(Vec<f64>, Vec<PointStatus>)> = kappas
            .par_iter()
            .zip(kept)
            .map_init(
                || walk.objective(self),
                |obj, (&k, kept)| {
                    if let Some(row) = kept {
                        return row;
                    }
                    let row = walk.row(obj.as_mut(), k, cancel);
                    let d = done.fetch_add(ns.len(), Ordering::Relaxed) + ns.len();
                    if let Ok(mut p) = progress.lock() {
                        (*p)(d);
                    }
                    row
                },
            )
            .collect();
        let mut cost = Vec::with_capacity(ns.len() * kappas.len());
        let mut status = Vec::with_capacity(ns.len() * kappas.len());
        for (r, st) in rows {
            cost.extend(r);
            status.extend(st);
        }
        let cancelled = status.contains(&PointStatus::NotReached);
        LandscapeRun {
            landscape: Landscape {
                n: ns.to_vec(),
                kappa: kappas.to_vec(),
                cost,
            },
            status,
            cancelled,
        }
    }
}

/// Rows of a landscape computed ahead of the rest ([`Rheometer::landscape_sample`]), with the
/// time each took, and the grid, options and Newtonian solutions the rest continues from
/// ([`Rheometer::landscape_from`]): the estimate of the run, and rows the run keeps.
#[derive(Debug, Clone)]
pub struct LandscapeSample {
    n: Vec<f64>,
    kappa: Vec<f64>,
    options: IdentifyOptions,
    newtonian: Vec<Solution>,
    rows: Vec<SampledRow>,
}

/// One row of a [`LandscapeSample`].
#[derive(Debug, Clone)]
struct SampledRow {
    kappa_index: usize,
    cost: Vec<f64>,
    status: Vec<PointStatus>,
    seconds: f64,
}

impl LandscapeSample {
    /// Rows computed.
    pub fn rows(&self) -> usize {
        self.rows.len()
    }

    /// Mean wall time of a sampled row \[s\] (the rows ran side by side on the worker threads,
    /// as the run's rows do).
    pub fn row_s(&self) -> f64 {
        self.rows.iter().map(|r| r.seconds).sum::<f64>() / self.rows.len().max(1) as f64
    }

    /// Estimated wall time \[s\] of the rows not yet computed, spread over `threads` workers.
    pub fn remaining_s(&self, threads: usize) -> f64 {
        let left = self.kappa.len().saturating_sub(self.rows.len());
        self.row_s() * left.div_ceil(threads.max(1)) as f64
    }
}

/// What every row of one landscape shares: the options of its solves, the order of its `n`
/// values (Newtonian end first) and the Newtonian solutions it starts from (`n = 1` does not
/// depend on κ; given, e.g. a sample's, or solved at the first κ).
struct RowWalk<'a> {
    ns: &'a [f64],
    opts: IdentifyOptions,
    order: Vec<usize>,
    newtonian: Vec<Solution>,
    kappa0: f64,
}

impl<'a> RowWalk<'a> {
    fn new(
        rh: &Rheometer,
        ns: &'a [f64],
        kappas: &[f64],
        options: &IdentifyOptions,
        newtonian: Option<Vec<Solution>>,
    ) -> Result<Self, RheometerError> {
        if ns.is_empty() || kappas.is_empty() {
            return Err(RheometerError::Data("the landscape grid is empty".into()));
        }
        let mut opts = options.clone();
        opts.simulate.factor_at_solution = false;
        // every point starts simplified Newton from its neighbour's last Newton matrix
        opts.simulate.keep_newton_matrix = true;
        // a solve that diverges must fail fast, not refine towards 20 000 nodes
        opts.simulate.max_nodes = opts.simulate.max_nodes.min(LANDSCAPE_MAX_NODES);
        let mut order: Vec<usize> = (0..ns.len()).collect();
        order.sort_by(|&a, &b| ns[b].total_cmp(&ns[a]));
        let newtonian = match newtonian {
            Some(s) => s,
            None => rh.objective([1.0, kappas[0]], &opts)?.solutions(),
        };
        // a solve at the edge of the solvable region fails at 8 times its start's mesh
        opts.simulate.growth_limit = opts.simulate.growth_limit.or(Some(LANDSCAPE_GROWTH_LIMIT));
        Ok(RowWalk {
            ns,
            opts,
            order,
            newtonian,
            kappa0: kappas[0],
        })
    }

    /// A worker's objective (its solver workspace); `None` if it cannot be built (its rows
    /// are then marked failed).
    fn objective<'r>(&self, rh: &'r Rheometer) -> Option<super::objective::Objective<'r>> {
        rh.objective([1.0, self.kappa0], &self.opts).ok()
    }

    /// The row at `k`: walked from the Newtonian end towards smaller `n`, each point
    /// warm-started from the secant predictor of the last two, a failed step bisected, and the
    /// rest of the row marked failed after a failure that bisection does not mend.
    fn row(
        &self,
        obj: Option<&mut super::objective::Objective<'_>>,
        k: f64,
        cancel: &AtomicBool,
    ) -> (Vec<f64>, Vec<PointStatus>) {
        let ns = self.ns;
        let order = &self.order;
        let mut row = vec![f64::NAN; ns.len()];
        let mut status = vec![PointStatus::Failed; ns.len()];
        if cancel.load(Ordering::Relaxed) {
            status.fill(PointStatus::NotReached);
            return (row, status);
        }
        let Some(obj) = obj else {
            return (row, status);
        };
        obj.set_solutions(&self.newtonian);
        // the last two accepted points of the row: (n, solutions)
        let mut last: (f64, Vec<Solution>) = (1.0, self.newtonian.clone());
        let mut before: Option<(f64, Vec<Solution>)> = None;
        for (pos, &i) in order.iter().enumerate() {
            if cancel.load(Ordering::Relaxed) {
                for &rest in &order[pos..] {
                    status[rest] = PointStatus::NotReached;
                }
                break;
            }
            let n = ns[i];
            let predicted: Option<Vec<Guess>> = before.as_ref().and_then(|(nb, sb)| {
                let t = (n - last.0) / (last.0 - nb);
                (t.is_finite() && t.abs() <= 2.0).then(|| {
                    last.1
                        .iter()
                        .zip(sb)
                        .map(|(a, b)| secant_guess(a, b, t))
                        .collect()
                })
            });
            let first = match &predicted {
                Some(guesses) => obj.try_cost_from(n, k, guesses),
                None => obj.try_cost_at(n, k),
            };
            // on failure the warm starts are still the neighbour's solutions: retry from
            // them, bisecting the step (giving up early once `cancel` is set)
            let r = first.or_else(|_| {
                bisect_step(
                    last.0,
                    n,
                    retry_bisections(n - last.0),
                    &mut |to| obj.try_cost_at(to, k),
                    &|| {
                        cancel
                            .load(Ordering::Relaxed)
                            .then(|| RheometerError::Data("the landscape was cancelled".into()))
                    },
                )
            });
            match r {
                Ok(c) => {
                    row[i] = c;
                    status[i] = PointStatus::Computed;
                    let sols = obj.solutions();
                    before = Some(std::mem::replace(&mut last, (n, sols)));
                }
                Err(_) => {
                    // a retry given up because of the cancellation: the point and the rest
                    // of the row were not reached, not failed
                    if cancel.load(Ordering::Relaxed) {
                        for &rest in &order[pos..] {
                            status[rest] = PointStatus::NotReached;
                        }
                    }
                    break;
                }
            }
        }
        (row, status)
    }
}

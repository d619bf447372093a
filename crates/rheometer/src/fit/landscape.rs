//! The cost landscape `J(n, κ)` on a grid (paper Fig. 4).
//!
//! Rows are computed in parallel. Each κ-row is walked from the Newtonian end (largest `n`)
//! towards smaller `n`; the row starts from the Newtonian solution (`n = 1` does not depend on
//! κ). Every point is warm-started from the toolkit's secant predictor
//! ([`secant_guess`]): the last two solutions of the row, extrapolated linearly in `n` onto the
//! newest mesh (it needs fewer Newton iterations than a start from the neighbour itself).
//! Only costs are evaluated (no sensitivities); every solve keeps its last Newton matrix
//! ([`SolveOptions::keep_newton_matrix`](diffbvp::SolveOptions::keep_newton_matrix)) and the next
//! point on the same mesh starts simplified Newton from it: that saves factorisations and
//! dual-number evaluations and moves the costs only within the solves' tolerance.
//!
//! Where a point fails, the step from the last good point is halved recursively
//! ([`bisect_step`]; once on fine grids, up to three times on coarse ones), starting with the
//! first half, not with a retry of the point itself from its neighbour's solution: the halved
//! step rescues more failed points, and a retry would cost every row's final failure one more
//! failing solve; if that fails too, the rest
//! of the row
//! (smaller `n`, i.e. stronger strain thinning) is marked `NaN`: there the BVP has no solution,
//! the strain rate explodes at the take-up, as the paper notes. Approaching that edge the
//! meshes grow quickly and a failing solve refines until it exceeds its node budget, so the
//! landscape caps the mesh at [`LANDSCAPE_MAX_NODES`] nodes and each solve's growth over the
//! mesh it starts from: a point's first attempt at [`LANDSCAPE_FIRST_GROWTH_LIMIT`], the
//! halved steps at [`LANDSCAPE_GROWTH_LIMIT`]. A failure costs a few milliseconds instead of
//! tens, and points that would need more nodes are marked missing.
//!
//! **Accuracy matched to the picture** ([`FarRule`]): a point whose row neighbour's cost is more
//! than twice the lowest cost of its row so far is solved at ten times the tolerance (at most
//! 1e-3): its cost moves by a few 1e-4 relative, while the minimum and every cost near it are
//! computed at the landscape's tolerance. Each point's tolerance is in [`LandscapeRun::tol`].
//! Most of a landscape's work lies at those far points, near the edge of the region where the
//! BVP has a solution, where `J` is many times its minimum, so that is where the looser
//! tolerance saves time.
//!
//! [`Rheometer::landscape_with`] can be stopped early (a cancellation flag, checked before
//! every grid point) and says for every point whether it was computed, failed, or not reached
//! ([`PointStatus`]).

use super::data::Rheometer;
use super::options::{IdentifyOptions, RheometerError};
use diffbvp::continuation::{bisect_step, secant_guess};
use diffbvp::solution::Solution;
use diffbvp::solve::{GrowthLimit, Guess};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// Largest mesh of a landscape solve (at the CLI's tolerance 1e-4 the solutions need 60–300
/// nodes except right at the edge of the region where the BVP has a solution).
pub const LANDSCAPE_MAX_NODES: usize = 1000;

/// How far a landscape solve may refine beyond the mesh it starts from when a point is retried
/// by halving its step (from the neighbour's solution; a point's first attempt, from the secant
/// prediction, has [`LANDSCAPE_FIRST_GROWTH_LIMIT`]): 8 times its nodes, always 300. A step of
/// the grid changes the solution's mesh by a few tens of percent except at the edge of the
/// region where the BVP has a solution, where a failing solve otherwise refines to
/// [`LANDSCAPE_MAX_NODES`] before it fails, once per row and again in each bisection of the
/// step. The limit makes such a solve fail early, at the price of a few points near the edge
/// marked failed instead of computed, and leaves the other costs well within the solves'
/// tolerance; a tighter limit would mark many more points failed. The
/// Newtonian solutions the rows start from are solved without it; options that set a growth
/// limit of their own keep it.
pub const LANDSCAPE_GROWTH_LIMIT: GrowthLimit = GrowthLimit {
    factor: 8.0,
    at_least: 300,
};

/// How far a landscape solve may refine at a point's first attempt (from the secant
/// prediction): 3 times the nodes it starts from, always 300. Where the first attempt fails (at
/// the edge of the region where the BVP has a solution), the step is halved and solved with
/// [`LANDSCAPE_GROWTH_LIMIT`]; a first attempt that would have needed more than 3 times its
/// nodes is rare away from the edge, and at the edge it usually fails anyway, after refining
/// 8 times as far, so the tighter first limit saves that refinement. At the edge, which points
/// a walk reaches depends on its path, so a row may end a grid step earlier or later than with
/// other limits.
pub const LANDSCAPE_FIRST_GROWTH_LIMIT: GrowthLimit = GrowthLimit {
    factor: 3.0,
    at_least: 300,
};

/// A point is far from its row's minimum when the cost of the point before it in its row is
/// more than this multiple of the lowest cost of the row so far \[-\] ([`FarRule::for_tol`]).
pub const LANDSCAPE_FAR_COST: f64 = 2.0;

/// Far points are solved at this multiple of the landscape's tolerance \[-\]
/// ([`FarRule::for_tol`]), at most [`LANDSCAPE_FAR_TOL_MAX`].
pub const LANDSCAPE_FAR_TOL_FACTOR: f64 = 10.0;

/// The loosest tolerance of far points \[-\]: it keeps their costs to a few 1e-4 relative,
/// which is all the picture needs.
pub const LANDSCAPE_FAR_TOL_MAX: f64 = 1e-3;

/// The accuracy of a landscape's far points: where the picture needs its costs to a few 1e-4
/// relative, not to the noise's 0.01 standard errors.
///
/// A point is far when the cost of the point before it in its row (the row walks from `n = 1`
/// down) exceeds `cost_factor` times the lowest cost of the row so far; it is solved at `tol`.
/// The rest, among them the row's minimum and every point whose cost is within `cost_factor`
/// of it, are solved at the landscape's own tolerance. The decision depends only on the row,
/// so a landscape is the same however its rows are spread over threads.
///
/// Why far points need less: a 95 % confidence region of `(n, κ)` ends where `J` has grown by
/// about 6 `σ²` over its minimum `J_min ≈ dof · σ²`, a relative growth of 6/dof (a few percent
/// for the shipped data's 234 points). A point at twice `J_min` lies about √dof standard
/// errors away, and a relative error `ε` of its cost moves its contour by about
/// `ε · J / (2 √dof σ²)`: at `ε = 3e-4`, 0.005 standard errors, and more only at the edge,
/// hundreds of standard errors from the minimum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FarRule {
    /// A point is far when the cost of the point before it in its row exceeds this multiple of
    /// the row's lowest cost so far \[-\] (`INFINITY`: no point is far).
    pub cost_factor: f64,
    /// BVP tolerance of far points \[-\].
    pub tol: f64,
}

impl FarRule {
    /// The landscape's default for the tolerance `tol`: far beyond
    /// `LANDSCAPE_FAR_COST` times the row's minimum, solved at
    /// `LANDSCAPE_FAR_TOL_FACTOR`` · tol`, at most `LANDSCAPE_FAR_TOL_MAX` (and never
    /// tighter than `tol`: at `tol >= 1e-3` every point is solved at `tol`).
    pub fn for_tol(tol: f64) -> Self {
        let far = (LANDSCAPE_FAR_TOL_FACTOR * tol).min(LANDSCAPE_FAR_TOL_MAX);
        // to 12 digits, so that ten times 1e-6 is 1e-5 (not 9.999999999999999e-6) in the CSV
        let far = format!("{far:.11e}").parse().unwrap_or(far);
        FarRule {
            cost_factor: LANDSCAPE_FAR_COST,
            tol: f64::max(far, tol),
        }
    }

    /// Every point at the landscape's own tolerance (no point is far; `tol` is unused, NaN).
    pub fn uniform() -> Self {
        FarRule {
            cost_factor: f64::INFINITY,
            tol: f64::NAN,
        }
    }

    /// The tolerance of the next point of a row: `tight` unless `last` (the cost of the point
    /// before it) exceeds `cost_factor` times `row_min`.
    fn tol_after(&self, last: f64, row_min: f64, tight: f64) -> f64 {
        if last > self.cost_factor * row_min {
            self.tol
        } else {
            tight
        }
    }
}

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
    /// The BVP tolerance each cost was computed at \[-\] (the landscape's own, or a far
    /// point's, see [`FarRule`]), same indexing; `NaN` where no cost was computed.
    pub tol: Vec<f64>,
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
    /// not a fit) and the points far from their row's minimum at [`FarRule::for_tol`].
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
    /// has, with the status and tolerance of every point. `progress` is called after every
    /// finished row with the number of points done.
    pub fn landscape_with(
        &self,
        ns: &[f64],
        kappas: &[f64],
        options: &IdentifyOptions,
        progress: impl FnMut(usize) + Send,
        cancel: &AtomicBool,
    ) -> Result<LandscapeRun, RheometerError> {
        let far = FarRule::for_tol(options.simulate.tol);
        self.landscape_ruled(ns, kappas, options, far, progress, cancel)
    }

    /// [`Rheometer::landscape_with`] with the accuracy of far points given (e.g.
    /// [`FarRule::uniform`]: every point at `options.simulate.tol`).
    pub fn landscape_ruled(
        &self,
        ns: &[f64],
        kappas: &[f64],
        options: &IdentifyOptions,
        far: FarRule,
        progress: impl FnMut(usize) + Send,
        cancel: &AtomicBool,
    ) -> Result<LandscapeRun, RheometerError> {
        let walk = RowWalk::new(self, ns, kappas, options, far, None)?;
        Ok(self.walk_rows(&walk, kappas, vec![None; kappas.len()], progress, cancel))
    }

    /// Walks a few rows of the landscape `ns × kappas` (the smallest, middle and largest `κ`:
    /// the smallest has the largest region without solution, where failing solves cost most)
    /// exactly as [`Rheometer::landscape_with`] does, in parallel, and times them: the
    /// estimate of the whole run ([`LandscapeSample::remaining_s`]) comes from the real
    /// computation, and [`Rheometer::landscape_from`] continues from these rows instead of
    /// computing them again. `far` is the accuracy of far points of the sample and of the
    /// run that continues from it ([`FarRule::for_tol`]`(options.simulate.tol)` as
    /// [`Rheometer::landscape_with`], or [`FarRule::uniform`]).
    pub fn landscape_sample(
        &self,
        ns: &[f64],
        kappas: &[f64],
        options: &IdentifyOptions,
        far: FarRule,
        cancel: &AtomicBool,
    ) -> Result<LandscapeSample, RheometerError> {
        let walk = RowWalk::new(self, ns, kappas, options, far, None)?;
        let mut picked = vec![0, kappas.len() / 2, kappas.len() - 1];
        picked.dedup();
        let rows: Vec<SampledRow> = picked
            .par_iter()
            .map_init(
                || walk.objective(self),
                |obj, &j| {
                    let t0 = Instant::now();
                    let row = walk.row(obj.as_mut(), kappas[j], cancel);
                    SampledRow {
                        kappa_index: j,
                        row,
                        seconds: t0.elapsed().as_secs_f64(),
                    }
                },
            )
            .collect();
        Ok(LandscapeSample {
            n: ns.to_vec(),
            kappa: kappas.to_vec(),
            options: options.clone(),
            far,
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
            far,
            newtonian,
            rows,
        } = sample;
        let mut kept: Vec<Option<Row>> = vec![None; kappa.len()];
        for r in rows {
            kept[r.kappa_index] = Some(r.row);
        }
        let already = kept.iter().flatten().count() * n.len();
        if already > 0 {
            progress(already);
        }
        let walk = RowWalk::new(self, &n, &kappa, &options, far, Some(newtonian))?;
        Ok(self.walk_rows(&walk, &kappa, kept, progress, cancel))
    }

    /// Every row of `kappas` not in `kept` walked in parallel (one objective, i.e. solver
    /// workspace, per worker; rows are independent, each starts from the Newtonian solution),
    /// the kept ones as they are; `progress` after every computed row with the points done.
    fn walk_rows(
        &self,
        walk: &RowWalk<'_>,
        kappas: &[f64],
        kept: Vec<Option<Row>>,
        mut progress: impl FnMut(usize) + Send,
        cancel: &AtomicBool,
    ) -> LandscapeRun {
        let ns = walk.ns;
        let done = AtomicUsize::new(kept.iter().flatten().count() * ns.len());
        let progress = Mutex::new(&mut progress);
        let rows: Vec<Row> = kappas
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
        let points = ns.len() * kappas.len();
        let mut cost = Vec::with_capacity(points);
        let mut status = Vec::with_capacity(points);
        let mut tol = Vec::with_capacity(points);
        for r in rows {
            cost.extend(r.cost);
            status.extend(r.status);
            tol.extend(r.tol);
        }
        let cancelled = status.contains(&PointStatus::NotReached);
        LandscapeRun {
            landscape: Landscape {
                n: ns.to_vec(),
                kappa: kappas.to_vec(),
                cost,
            },
            status,
            tol,
            cancelled,
        }
    }
}

/// One row of a landscape (one `κ`): per `n` value, the cost, what happened and the tolerance
/// of the solves.
#[derive(Debug, Clone)]
struct Row {
    cost: Vec<f64>,
    status: Vec<PointStatus>,
    tol: Vec<f64>,
}

impl Row {
    /// A row of `len` points not (yet) computed: failed unless marked otherwise.
    fn failed(len: usize) -> Self {
        Row {
            cost: vec![f64::NAN; len],
            status: vec![PointStatus::Failed; len],
            tol: vec![f64::NAN; len],
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
    far: FarRule,
    newtonian: Vec<Solution>,
    rows: Vec<SampledRow>,
}

/// One row of a [`LandscapeSample`].
#[derive(Debug, Clone)]
struct SampledRow {
    kappa_index: usize,
    row: Row,
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
/// values (Newtonian end first), the Newtonian solutions it starts from (`n = 1` does not
/// depend on κ; given, e.g. a sample's, or solved at the first κ), the accuracy of far points
/// and the growth limits of a point's first attempt and of its halved steps.
struct RowWalk<'a> {
    ns: &'a [f64],
    opts: IdentifyOptions,
    order: Vec<usize>,
    newtonian: Vec<Solution>,
    kappa0: f64,
    far: FarRule,
    first_growth: Option<GrowthLimit>,
    retry_growth: Option<GrowthLimit>,
}

impl<'a> RowWalk<'a> {
    fn new(
        rh: &Rheometer,
        ns: &'a [f64],
        kappas: &[f64],
        options: &IdentifyOptions,
        far: FarRule,
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
        // a solve at the edge of the solvable region fails at 3 (first attempt) or 8 (halved
        // steps) times its start's mesh; options with a growth limit of their own keep it
        let own = opts.simulate.growth_limit;
        Ok(RowWalk {
            ns,
            order,
            newtonian,
            kappa0: kappas[0],
            far,
            first_growth: own.or(Some(LANDSCAPE_FIRST_GROWTH_LIMIT)),
            retry_growth: own.or(Some(LANDSCAPE_GROWTH_LIMIT)),
            opts,
        })
    }

    /// A worker's objective (its solver workspace); `None` if it cannot be built (its rows
    /// are then marked failed).
    fn objective<'r>(&self, rh: &'r Rheometer) -> Option<super::objective::Objective<'r>> {
        rh.objective([1.0, self.kappa0], &self.opts).ok()
    }

    /// The row at `k`: walked from the Newtonian end towards smaller `n`, each point
    /// warm-started from the secant predictor of the last two at its tolerance ([`FarRule`]),
    /// a failed point retried by halving the step, and the rest of the row marked failed after
    /// a failure that the halving does not mend.
    fn row(
        &self,
        obj: Option<&mut super::objective::Objective<'_>>,
        k: f64,
        cancel: &AtomicBool,
    ) -> Row {
        let ns = self.ns;
        let order = &self.order;
        let mut out = Row::failed(ns.len());
        if cancel.load(Ordering::Relaxed) {
            out.status.fill(PointStatus::NotReached);
            return out;
        }
        let Some(obj) = obj else {
            return out;
        };
        obj.set_solutions(&self.newtonian);
        let tight = self.opts.simulate.tol;
        // the last two accepted points of the row: (n, solutions), and the costs so far
        let mut last: (f64, Vec<Solution>) = (1.0, self.newtonian.clone());
        let mut before: Option<(f64, Vec<Solution>)> = None;
        let (mut last_cost, mut row_min) = (f64::NAN, f64::INFINITY);
        let stop = || {
            cancel
                .load(Ordering::Relaxed)
                .then(|| RheometerError::Data("the landscape was cancelled".into()))
        };
        for (pos, &i) in order.iter().enumerate() {
            if cancel.load(Ordering::Relaxed) {
                for &rest in &order[pos..] {
                    out.status[rest] = PointStatus::NotReached;
                }
                break;
            }
            let n = ns[i];
            let tol = self.far.tol_after(last_cost, row_min, tight);
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
            obj.set_solve_accuracy(tol, self.first_growth);
            let first = match &predicted {
                Some(guesses) => obj.try_cost_from(n, k, guesses),
                None => obj.try_cost_at(n, k),
            };
            // on failure the warm starts are still the neighbour's solutions: from them, the
            // step halved (its first half, then the rest), with the full growth limit (giving
            // up early once `cancel` is set)
            let r = first.or_else(|_| {
                obj.set_solve_accuracy(tol, self.retry_growth);
                let depth = retry_bisections(n - last.0) - 1;
                let mid = 0.5 * (last.0 + n);
                let mut solve_at = |to| obj.try_cost_at(to, k);
                bisect_step(last.0, mid, depth, &mut solve_at, &stop)?;
                bisect_step(mid, n, depth, &mut solve_at, &stop)
            });
            match r {
                Ok(c) => {
                    out.cost[i] = c;
                    out.status[i] = PointStatus::Computed;
                    out.tol[i] = tol;
                    (last_cost, row_min) = (c, row_min.min(c));
                    let sols = obj.solutions();
                    before = Some(std::mem::replace(&mut last, (n, sols)));
                }
                Err(_) => {
                    // a retry given up because of the cancellation: the point and the rest
                    // of the row were not reached, not failed
                    if cancel.load(Ordering::Relaxed) {
                        for &rest in &order[pos..] {
                            out.status[rest] = PointStatus::NotReached;
                        }
                    }
                    break;
                }
            }
        }
        out
    }
}

//! Mesh operations: validation, uniform meshes, refinement (equal subdivision, as in scipy's
//! `solve_bvp`) and coarsening (removing nodes where the residual is far below tolerance, in the
//! spirit of bvp4c's redistribution).

use crate::error::BvpError;

/// `m` equally spaced nodes on `[a, b]`, the last one exactly `b`. `m = 0` gives an empty
/// vector and `m = 1` gives `[a]` (as numpy's `linspace`); neither is a valid mesh
/// ([`validate`] needs two nodes).
///
/// Finite ends whose distance `b - a` overflows `f64` (e.g. `-f64::MAX` and `f64::MAX`) still
/// give finite, equally spaced nodes. A non-finite end (NaN or `±inf`) gives non-finite nodes,
/// as the arithmetic does (numpy alike); [`try_linspace`] refuses such ends with an error
/// instead.
///
/// # Panics
///
/// Panics if `m` nodes cannot be allocated (as `Vec::with_capacity` does); [`try_linspace`]
/// returns an error instead.
pub fn linspace(a: f64, b: f64, m: usize) -> Vec<f64> {
    match m {
        0 => return Vec::new(),
        1 => return vec![a],
        _ => {}
    }
    let mut out = Vec::with_capacity(m);
    fill_linspace(a, b, m, &mut out);
    out
}

/// [`linspace`] with checked input: both ends finite and the `m` nodes allocatable, else a
/// [`BvpError::InvalidInput`] that names the offending end (or the node count). The nodes are
/// those of [`linspace`], bit for bit.
pub fn try_linspace(a: f64, b: f64, m: usize) -> Result<Vec<f64>, BvpError> {
    for (name, v) in [("start a", a), ("end b", b)] {
        if !v.is_finite() {
            return Err(BvpError::InvalidInput(format!(
                "linspace: the {name} = {v} is not finite; both ends of a mesh must be finite numbers"
            )));
        }
    }
    let mut out = Vec::new();
    out.try_reserve_exact(m).map_err(|_| {
        BvpError::InvalidInput(format!(
            "linspace: cannot allocate {m} nodes; ask for fewer"
        ))
    })?;
    match m {
        0 => {}
        1 => out.push(a),
        _ => fill_linspace(a, b, m, &mut out),
    }
    Ok(out)
}

/// Pushes the `m >= 2` nodes of [`linspace`] onto `out`.
fn fill_linspace(a: f64, b: f64, m: usize, out: &mut Vec<f64>) {
    let den = (m - 1) as f64;
    let h = (b - a) / den;
    if h.is_finite() || !a.is_finite() || !b.is_finite() {
        out.extend((0..m).map(|i| if i == m - 1 { b } else { a + h * i as f64 }));
    } else {
        // finite ends whose distance overflows: weights of the ends (no overflow on the way)
        out.extend((0..m).map(|i| {
            if i == m - 1 {
                b
            } else {
                let t = i as f64 / den;
                a * (1.0 - t) + b * t
            }
        }));
    }
}

/// Checks that a mesh has at least two finite, strictly increasing nodes and is not degenerate:
/// every interval's width `h = x[i+1] - x[i]` must be finite (not overflowing `f64`), a normal
/// number whose reciprocal is finite, and wide enough that the collocation and quadrature
/// points inside it (at `x[i] + h/2` and `x[i] + (1/2 ± √(3/28)) h`) are distinct from its
/// ends, which needs `h >= 64 ε max(|x[i]|, |x[i+1]|)` (ε = `f64::EPSILON`). The error names
/// the node or interval and says what to change.
pub fn validate(x: &[f64]) -> Result<(), BvpError> {
    if x.len() < 2 {
        return Err(BvpError::InvalidInput(format!(
            "the mesh needs at least 2 nodes, got {}",
            x.len()
        )));
    }
    for (i, w) in x.windows(2).enumerate() {
        if !w[0].is_finite() || !w[1].is_finite() {
            let j = if w[0].is_finite() { i + 1 } else { i };
            return Err(BvpError::InvalidInput(format!(
                "mesh node {j} is not finite (x[{j}] = {})",
                x[j]
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
        degenerate_interval(i, w[0], w[1])?;
    }
    Ok(())
}

/// The error of [`validate`] for interval `i = [a, b]` (`a < b`, both finite) when it is
/// degenerate.
fn degenerate_interval(i: usize, a: f64, b: f64) -> Result<(), BvpError> {
    let h = b - a;
    if !h.is_finite() {
        return Err(BvpError::InvalidInput(format!(
            "the mesh is degenerate: the width of interval {i}, x[{}] - x[{i}] = {b:e} - ({a:e}), \
             overflows f64; rescale the independent variable (e.g. x' = x / {:e}) so that the \
             interval widths stay below about 1e308",
            i + 1,
            b.abs().max(a.abs())
        )));
    }
    let resolvable = 64.0 * f64::EPSILON * a.abs().max(b.abs());
    if !h.is_normal() || !(1.0 / h).is_finite() || h < resolvable {
        return Err(BvpError::InvalidInput(format!(
            "the mesh is degenerate: interval {i}, [x[{i}], x[{}]] = [{a:e}, {b:e}], has the width \
             {h:e}, too small to place the collocation points inside it in f64 (at least \
             {:e} is needed here); rescale the independent variable or remove node {}",
            i + 1,
            resolvable.max(f64::MIN_POSITIVE),
            i + 1
        )));
    }
    Ok(())
}

/// Inserts one node into each interval of `insert_1` and two nodes (equal subdivision) into each
/// interval of `insert_2`. Interval `i` is `[x[i], x[i+1]]`; both lists are sorted.
/// A mesh of fewer than two nodes is returned unchanged.
///
/// # Panics
///
/// Panics if `nodes_per_interval` has fewer than `x.len() - 1` entries; [`try_refine`]
/// returns an error instead.
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

/// [`refine`] with the lengths checked: a [`BvpError::InvalidInput`] naming both lengths when
/// `nodes_per_interval` has fewer than `x.len() - 1` entries.
pub fn try_refine(x: &[f64], nodes_per_interval: &[u8]) -> Result<Vec<f64>, BvpError> {
    check_per_interval(
        "nodes_per_interval",
        nodes_per_interval.len(),
        x.len(),
        false,
    )?;
    Ok(refine(x, nodes_per_interval))
}

/// Checks that a per-interval list `name` of `len` entries fits a mesh of `nodes` nodes: at
/// least (`exact`: exactly) one entry per interval.
fn check_per_interval(name: &str, len: usize, nodes: usize, exact: bool) -> Result<(), BvpError> {
    let intervals = nodes.saturating_sub(1);
    let fits = if exact {
        len == intervals || nodes < 2
    } else {
        len >= intervals
    };
    if fits {
        Ok(())
    } else {
        Err(BvpError::InvalidInput(format!(
            "{name} has {len} entries, but the mesh of {nodes} nodes has {intervals} intervals \
             (one entry per interval expected)"
        )))
    }
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

/// How [`plan`] and [`apply`] refine a mesh on which some interval is above tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RefineRule {
    /// scipy's `solve_bvp`: 1 node into each interval with `tol < r < 100 tol`, 2 where
    /// `r >= 100 tol` ([`mark_refinement`]); the other intervals are kept.
    Scipy,
    /// Equidistribution (the default): every interval `i` of length `h_i` gets the density
    /// `w_i = (r_i / (θ tol))^(1/p)` pieces, the number that brings each piece to `θ tol` if the
    /// residual scales like `h^p`, clamped to `[1 / max_growth, max_pieces]`; the whole mesh is
    /// redistributed so that each new interval holds `Σ w / ⌈Σ w⌉ <= 1` of it. Intervals below
    /// tolerance take part (they may grow by up to `max_growth`), so the mesh follows the
    /// residual instead of accumulating scipy's halvings.
    #[default]
    Equidistribute,
}

/// Options of the mesh adaptation ([`plan`], [`apply`]). The defaults (equidistribution, order 3,
/// target `0.5 tol`, at most 16 pieces, growth at most 1.5) were chosen on the shock layer
/// ε = 1e-3, the coupled Troesch problem μ = 5 and Bratu at tol 1e-6 (tests/mesh_passes.rs):
/// less than half of scipy's mesh passes and fewer final nodes on all three. The target of half
/// the tolerance leaves room for the solution to move between passes (a larger one saves nodes
/// but adds nearly-empty final passes) and keeps the global error close to that of scipy's
/// rule, whose halvings leave most intervals well below `tol`.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshOptions {
    /// Refinement rule.
    pub rule: RefineRule,
    /// Order `p` of the per-interval RMS residual in the interval length, `r ~ h^p` (3 for the
    /// C1 cubic interpolant of the 4th-order collocation; measured on the test problems).
    pub order: f64,
    /// Fraction `θ` of `tol` that each new interval is predicted to reach (`0 < θ <= 1`; smaller
    /// is safer and costs nodes).
    pub target: f64,
    /// Largest number of pieces one interval is cut into in one pass (>= 2): far from the
    /// asymptotic range the `h^p` prediction is not trusted beyond this.
    pub max_pieces: u8,
    /// Largest factor by which an interval may grow in one pass (>= 1). Far from where the error
    /// is made, the residual of a stiff problem reflects the global error rather than the local
    /// `h`, so growth is predicted less reliably than subdivision.
    pub max_growth: f64,
    /// Equidistribution only: interpolate the error constant `c_i = r_i / h_i^p` log-linearly
    /// between interval midpoints instead of holding it constant over each old interval
    /// (default `false`). When one pass cuts intervals into many pieces, the residual of the new
    /// pieces follows the error constant's variation inside the old interval, which a constant
    /// misses, and an interval whose new residual exceeds the constant prediction forces a
    /// second full pass.
    pub smooth: bool,
    /// Switch to scipy's rule ([`RefineRule::Scipy`]) for the rest of a solve when the
    /// equidistributed mesh does not settle (default `true`): over three refinement passes the
    /// mesh grew by at most 10 % and the largest residual did not halve, as happens on
    /// solutions with tens of oscillations, where the mesh follows the phase of the computed
    /// solution and the phase follows the mesh. scipy's rule only adds nodes, so it cannot
    /// cycle. The pass of the switch is
    /// [`SolveStats::mesh_rule_switched_at`](crate::SolveStats::mesh_rule_switched_at); with
    /// `false` a cycling mesh ends in
    /// [`BvpError::MeshCycling`] once `max_mesh_iterations` are spent.
    pub settle: bool,
}

impl Default for MeshOptions {
    fn default() -> Self {
        MeshOptions {
            rule: RefineRule::Equidistribute,
            order: 3.0,
            target: 0.5,
            max_pieces: 16,
            max_growth: 1.5,
            smooth: false,
            settle: true,
        }
    }
}

impl MeshOptions {
    /// Checks the options: `order` positive and finite, `0 < target <= 1`, `max_pieces >= 2`,
    /// `max_growth >= 1` and finite. The error names the field and its value.
    pub fn validate(&self) -> Result<(), BvpError> {
        let bad = |what: &str, v: f64| {
            Err(BvpError::InvalidInput(format!(
                "MeshOptions::{what}, got {v}"
            )))
        };
        if !(self.order > 0.0 && self.order.is_finite()) {
            return bad("order must be positive and finite", self.order);
        }
        if !(self.target > 0.0 && self.target <= 1.0) {
            return bad("target must be in (0, 1]", self.target);
        }
        if self.max_pieces < 2 {
            return bad("max_pieces must be at least 2", f64::from(self.max_pieces));
        }
        if !(self.max_growth >= 1.0 && self.max_growth.is_finite()) {
            return bad("max_growth must be at least 1 and finite", self.max_growth);
        }
        Ok(())
    }

    /// scipy's `solve_bvp` refinement ([`RefineRule::Scipy`]).
    pub fn scipy() -> Self {
        MeshOptions {
            rule: RefineRule::Scipy,
            ..Default::default()
        }
    }
}

/// Counts the intervals whose residual `rms` is above `tol` (a NaN counts as above); `0` means
/// the mesh is final. For [`RefineRule::Scipy`] it also writes the nodes to insert per interval
/// into `marks` ([`mark_refinement`]); the equidistribution needs no marks and clears them.
pub fn plan(rms: &[f64], tol: f64, opts: &MeshOptions, marks: &mut Vec<u8>) -> usize {
    let above = rms.iter().filter(|&&r| r.is_nan() || r > tol).count();
    marks.clear();
    if above > 0 && opts.rule == RefineRule::Scipy {
        mark_refinement(rms, tol, marks);
    }
    above
}

/// The refined mesh after [`plan`] found intervals above `tol`: scipy's subdivision of the marked
/// intervals ([`refine`]) or the equidistributed mesh of the residuals `rms` (see
/// [`RefineRule::Equidistribute`]; a NaN or infinite residual counts as `max_pieces`). The end
/// points are kept exactly; a mesh of fewer than two nodes is returned unchanged.
///
/// An equidistributed mesh that would exceed `max_nodes` while `x` has fewer is redistributed on
/// `max_nodes` nodes instead (the best mesh of the allowed size, which may still meet `tol`);
/// from a mesh of `max_nodes` or more, the wanted mesh is returned as it is, so the caller can
/// report how many nodes were needed.
///
/// # Panics
///
/// Panics if `rms` (or, for the scipy rule, `marks`) has fewer than `x.len() - 1` entries;
/// [`try_apply`] returns an error instead.
pub fn apply(
    x: &[f64],
    rms: &[f64],
    marks: &[u8],
    tol: f64,
    opts: &MeshOptions,
    max_nodes: usize,
) -> Vec<f64> {
    if x.len() < 2 {
        return x.to_vec();
    }
    match opts.rule {
        RefineRule::Scipy => refine(x, marks),
        RefineRule::Equidistribute => {
            let cap = if x.len() < max_nodes {
                max_nodes.max(2) - 1
            } else {
                usize::MAX
            };
            equidistribute(x, rms, tol, opts, cap)
        }
    }
}

/// [`apply`] with the lengths checked: a [`BvpError::InvalidInput`] naming the list and both
/// lengths when `rms` (or, for the scipy rule, `marks`) has fewer than `x.len() - 1` entries.
pub fn try_apply(
    x: &[f64],
    rms: &[f64],
    marks: &[u8],
    tol: f64,
    opts: &MeshOptions,
    max_nodes: usize,
) -> Result<Vec<f64>, BvpError> {
    check_per_interval("rms", rms.len(), x.len(), false)?;
    if opts.rule == RefineRule::Scipy {
        check_per_interval("marks", marks.len(), x.len(), false)?;
    }
    Ok(apply(x, rms, marks, tol, opts, max_nodes))
}

/// Redistributes the nodes of `x` (at least two) so that each new interval holds at most one
/// predicted piece of the density `w_i = clamp((r_i / (θ tol))^(1/p), 1/max_growth, max_pieces)`
/// per old interval `i` (a NaN or infinite residual counts as `max_pieces`). The density is
/// constant within an old interval, so the new nodes follow its cumulative integral linearly.
/// At most `max_intervals` intervals are made.
fn equidistribute(
    x: &[f64],
    rms: &[f64],
    tol: f64,
    opts: &MeshOptions,
    max_intervals: usize,
) -> Vec<f64> {
    let n_int = x.len() - 1;
    let max_pieces = f64::from(opts.max_pieces.max(2));
    let lo = 1.0 / opts.max_growth.max(1.0);
    let pieces_of = |r: f64| {
        let v = (r / (opts.target * tol)).powf(1.0 / opts.order);
        if v.is_finite() {
            v.clamp(lo, max_pieces)
        } else {
            max_pieces
        }
    };
    if !opts.smooth || n_int < 2 {
        let w: Vec<f64> = rms[..n_int].iter().map(|&r| pieces_of(r)).collect();
        return distribute(x, &w, max_intervals);
    }
    // log error constants at the interval midpoints (None: not finite or zero)
    let log_c: Vec<Option<f64>> = (0..n_int)
        .map(|i| {
            let c = rms[i].ln() - opts.order * (x[i + 1] - x[i]).ln();
            c.is_finite().then_some(c)
        })
        .collect();
    let mid = |i: usize| 0.5 * (x[i] + x[i + 1]);
    // every old interval in SUB cells, the density of each from the interpolated constant
    const SUB: usize = 8;
    let mut xs = Vec::with_capacity(n_int * SUB + 1);
    let mut ws = Vec::with_capacity(n_int * SUB);
    xs.push(x[0]);
    for i in 0..n_int {
        let (a, h) = (x[i], x[i + 1] - x[i]);
        for j in 0..SUB {
            let xc = a + (j as f64 + 0.5) / SUB as f64 * h;
            // the neighbour on the side of the cell centre (the interval itself at the ends)
            let nb = if xc < mid(i) {
                i.checked_sub(1)
            } else {
                Some(i + 1)
            }
            .filter(|&k| k < n_int);
            let w = match (log_c[i], nb.and_then(|k| log_c[k].map(|c| (k, c)))) {
                (Some(ci), Some((k, ck))) => {
                    let t = (xc - mid(i)) / (mid(k) - mid(i));
                    let lc = ci + t * (ck - ci);
                    // pieces of the whole old interval at this density
                    let r = (lc + opts.order * h.ln()).exp();
                    pieces_of(r)
                }
                _ => pieces_of(rms[i]),
            };
            ws.push(w / SUB as f64);
            xs.push(if j + 1 == SUB {
                x[i + 1]
            } else {
                a + (j + 1) as f64 / SUB as f64 * h
            });
        }
    }
    distribute(&xs, &ws, max_intervals)
}

/// The mesh of at most `max_intervals` intervals on which every interval holds the same share
/// `Σ w / ⌈Σ w⌉` of the piecewise constant density whose integral over `[x_i, x_{i+1}]` is
/// `w_i` (all positive).
fn distribute(x: &[f64], w: &[f64], max_intervals: usize) -> Vec<f64> {
    let n_int = x.len() - 1;
    let total: f64 = w.iter().sum();
    let pieces = (total.ceil() as usize).clamp(1, max_intervals.max(1));
    let per = total / pieces as f64;
    let mut out = Vec::with_capacity(pieces + 1);
    out.push(x[0]);
    let (mut i, mut acc) = (0usize, 0.0f64); // acc: integral of w up to x[i]
    for j in 1..pieces {
        let target = per * j as f64;
        while i + 1 < n_int && acc + w[i] < target {
            acc += w[i];
            i += 1;
        }
        let t = ((target - acc) / w[i]).clamp(0.0, 1.0);
        let xn = x[i] + t * (x[i + 1] - x[i]);
        if xn > *out.last().unwrap_or(&x[0]) && xn < x[n_int] {
            out.push(xn);
        }
    }
    out.push(x[n_int]);
    out
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
/// Panics if `rms` has more than `x.len() - 1` entries; [`try_coarsen`] returns an error
/// instead.
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

/// [`coarsen`] with the lengths checked: a [`BvpError::InvalidInput`] naming both lengths when
/// `rms` has more than `x.len() - 1` entries.
pub fn try_coarsen(x: &[f64], rms: &[f64], threshold: f64) -> Result<Vec<f64>, BvpError> {
    if rms.len() > x.len().saturating_sub(1) {
        check_per_interval("rms", rms.len(), x.len(), true)?;
    }
    Ok(coarsen(x, rms, threshold))
}

/// The mesh `x` with every interval halved: `2 m - 1` nodes for `m` (the same nodes and the
/// midpoint of every interval; a multipoint mesh's interfaces, held twice, stay as they are).
pub fn halved(x: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(2 * x.len());
    for w in x.windows(2) {
        out.push(w[0]);
        if w[1] != w[0] {
            out.push(0.5 * (w[0] + w[1]));
        }
    }
    out.extend(x.last());
    out
}

/// A multipoint mesh ([`Bvp::interfaces`](crate::Bvp::interfaces)) on the points
/// `x_0 < x_1 < … < x_R`: `nodes_per_region` equally spaced nodes (at least 2) on every region
/// `[x_{r-1}, x_r]`, each interior point held twice (the left and the right limit).
pub fn multipoint_linspace(points: &[f64], nodes_per_region: usize) -> Vec<f64> {
    let mut out = Vec::new();
    for w in points.windows(2) {
        out.extend(linspace(w[0], w[1], nodes_per_region.max(2)));
    }
    out
}

/// The node ranges of the regions of a mesh (a multipoint mesh holds each interface twice:
/// a region ends at a node whose successor has the same `x`); one range for an ordinary mesh.
pub fn regions(x: &[f64]) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    for i in 0..x.len().saturating_sub(1) {
        if x[i + 1] == x[i] {
            out.push(start..i + 1);
            start = i + 1;
        }
    }
    out.push(start..x.len());
    out
}

/// [`validate`] for a multipoint mesh with the interfaces `interfaces`: each region's mesh
/// must be valid and the repeated nodes must be exactly the interfaces, in order.
pub fn validate_multipoint(x: &[f64], interfaces: &[f64]) -> Result<(), BvpError> {
    let ranges = regions(x);
    let found: Vec<f64> = ranges[1..].iter().map(|r| x[r.start]).collect();
    if found != interfaces {
        return Err(BvpError::InvalidInput(format!(
            "the mesh holds the points {found:?} twice but the problem's interfaces              (Bvp::interfaces) are {interfaces:?}: a multipoint mesh holds every interface              twice (left and right limit) and no other point (mesh::multipoint_linspace builds              one)"
        )));
    }
    for (r, range) in ranges.iter().enumerate() {
        validate(&x[range.clone()]).map_err(|e| match e {
            BvpError::InvalidInput(m) => BvpError::InvalidInput(format!(
                "region {r} (nodes {}..{}) of the multipoint mesh: {m}",
                range.start, range.end
            )),
            other => other,
        })?;
    }
    Ok(())
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

    /// A residual that follows the model `r = c(x_mid) h^3` exactly, with a layer of width
    /// `1e-2` at `x = 0.3` in `c`.
    fn model_rms(x: &[f64]) -> Vec<f64> {
        x.windows(2)
            .map(|w| {
                let (h, xm) = (w[1] - w[0], 0.5 * (w[0] + w[1]));
                let c = 1.0 + 1e6 / (1.0 + ((xm - 0.3) / 1e-2).powi(2)).powi(2);
                c * h * h * h
            })
            .collect()
    }

    fn assert_mesh(x: &[f64], a: f64, b: f64) {
        assert_eq!(x[0], a);
        assert_eq!(*x.last().unwrap(), b);
        assert!(x.windows(2).all(|w| w[1] > w[0]), "{x:?}");
    }

    #[test]
    fn options_are_checked() {
        assert!(MeshOptions::default().validate().is_ok());
        assert!(MeshOptions::scipy().validate().is_ok());
        for o in [
            MeshOptions {
                order: 0.0,
                ..Default::default()
            },
            MeshOptions {
                target: 1.5,
                ..Default::default()
            },
            MeshOptions {
                target: f64::NAN,
                ..Default::default()
            },
            MeshOptions {
                max_pieces: 1,
                ..Default::default()
            },
            MeshOptions {
                max_growth: 0.5,
                ..Default::default()
            },
        ] {
            let e = o.validate().unwrap_err().to_string();
            assert!(e.contains("MeshOptions::"), "{e}");
        }
    }

    #[test]
    fn plan_never_refines_a_mesh_within_tolerance() {
        let mut marks = vec![7];
        for opts in [MeshOptions::default(), MeshOptions::scipy()] {
            assert_eq!(plan(&[0.5, 1.0, 0.0], 1.0, &opts, &mut marks), 0);
            assert!(marks.is_empty());
            assert_eq!(plan(&[0.5, 1.5, f64::NAN], 1.0, &opts, &mut marks), 2);
        }
        assert_eq!(marks, vec![0, 1, 2]);
    }

    #[test]
    fn equidistribution_predicts_the_node_count_of_a_uniform_residual() {
        // r = 27 θ tol everywhere: 3 pieces per interval, the same uniform spacing
        let opts = MeshOptions::default();
        let x = linspace(0.0, 2.0, 5);
        let tol = 1e-6;
        let rms = vec![27.0 * opts.target * tol; 4];
        let new = apply(&x, &rms, &[], tol, &opts, usize::MAX);
        assert_eq!(new.len(), 13);
        for (a, b) in new.iter().zip(linspace(0.0, 2.0, 13)) {
            assert!((a - b).abs() < 1e-12, "{new:?}");
        }
        // growth is limited to max_growth, subdivision to max_pieces, NaN counts as max_pieces
        let new = apply(&x, &[0.0; 4], &[], tol, &opts, usize::MAX);
        assert_eq!(new.len(), (4.0 / opts.max_growth).ceil() as usize + 1);
        let new = apply(&x, &[1.0, f64::NAN, 0.0, 0.0], &[], tol, &opts, usize::MAX);
        assert_eq!(
            new.len(),
            (2.0 * f64::from(opts.max_pieces) + 2.0 / opts.max_growth).ceil() as usize + 1
        );
        assert_mesh(&new, 0.0, 2.0);
        // a node budget: redistributed on max_nodes nodes, unless the mesh is already that big
        let capped = apply(&x, &rms, &[], tol, &opts, 7);
        assert_eq!(capped.len(), 7);
        assert_mesh(&capped, 0.0, 2.0);
        assert_eq!(apply(&x, &rms, &[], tol, &opts, 5).len(), 13);
    }

    #[test]
    fn equidistribution_meets_a_model_residual_in_few_passes_and_fewer_nodes_than_scipy() {
        let tol = 1e-6;
        let run = |opts: &MeshOptions| {
            let mut x = linspace(0.0, 1.0, 5);
            let mut marks = Vec::new();
            for pass in 1..40 {
                let rms = model_rms(&x);
                if plan(&rms, tol, opts, &mut marks) == 0 {
                    return (pass, x);
                }
                x = apply(&x, &rms, &marks, tol, opts, usize::MAX);
                assert_mesh(&x, 0.0, 1.0);
            }
            panic!("no convergence");
        };
        let (passes, x) = run(&MeshOptions::default());
        let (scipy_passes, scipy_x) = run(&MeshOptions::scipy());
        assert!(model_rms(&x).iter().all(|&r| r <= tol));
        assert!(passes * 2 <= scipy_passes, "{passes} vs {scipy_passes}");
        assert!(x.len() < scipy_x.len(), "{} vs {}", x.len(), scipy_x.len());
        // the fewest nodes meeting tol: ∫ (c / tol)^(1/3) dx, estimated on a fine mesh
        let fine = linspace(0.0, 1.0, 100_001);
        let optimum: f64 = model_rms(&fine).iter().map(|r| (r / tol).cbrt()).sum();
        let bound = optimum / MeshOptions::default().target.cbrt() * 1.1 + 2.0;
        assert!(
            (x.len() as f64) < bound,
            "{} nodes, optimum {optimum}",
            x.len()
        );
    }

    #[test]
    fn smooth_error_constants_predict_a_graded_layer_better() {
        let tol = 1e-6;
        let smooth = MeshOptions {
            smooth: true,
            ..Default::default()
        };
        // a constant error constant: the same mesh as the piecewise-constant rule
        let x = linspace(0.0, 2.0, 5);
        let rms = vec![27.0 * smooth.target * tol; 4];
        let a = apply(&x, &rms, &[], tol, &smooth, usize::MAX);
        let b = apply(&x, &rms, &[], tol, &MeshOptions::default(), usize::MAX);
        assert_eq!(a.len(), b.len());
        for (u, v) in a.iter().zip(&b) {
            assert!((u - v).abs() < 1e-12, "{a:?} vs {b:?}");
        }
        // one pass from a coarse mesh of the layer model: the largest new residual, relative to
        // the target, is smaller with the interpolated constant
        let x = linspace(0.0, 1.0, 12);
        let rms = model_rms(&x);
        let worst = |opts: &MeshOptions| {
            let new = apply(&x, &rms, &[], tol, opts, usize::MAX);
            assert_mesh(&new, 0.0, 1.0);
            let r = model_rms(&new);
            (r.iter().fold(0.0f64, |m, &v| m.max(v)), new.len())
        };
        let (w_smooth, n_smooth) = worst(&smooth);
        let (w_const, n_const) = worst(&MeshOptions::default());
        assert!(w_smooth < w_const, "{w_smooth:e} vs {w_const:e}");
        assert!(
            (n_smooth as f64) < 1.5 * n_const as f64,
            "{n_smooth} vs {n_const}"
        );
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

    #[test]
    fn halving_keeps_the_nodes_and_adds_every_midpoint() {
        assert_eq!(halved(&[0.0, 1.0, 3.0]), vec![0.0, 0.5, 1.0, 2.0, 3.0]);
        assert_eq!(halved(&[2.0]), vec![2.0]);
        assert!(halved(&[]).is_empty());
    }
}

//! Watching the adaptive loop for a mesh that does not settle.
//!
//! Equidistribution moves every node on every pass. On solutions with many oscillations the
//! error constant of an interval depends on where it sits in the period, and that moves with
//! the phase of the computed solution, which moves with the mesh: the mesh can then wander
//! around one size with a few intervals above tolerance on every pass (seen on
//! `ε² y'' + y = 0` with ε = 0.01–0.04: 16–4 periods, about 380 nodes at tol 1e-3 and 3610 at
//! 1e-6, 40 passes without convergence). [`CycleWatch`] sees this in the refinement passes: over
//! the last [`WINDOW`] of them the mesh grew by at most a factor [`GROWTH`] (last node count
//! against the first) and the largest residual did not fall below [`DROP`] times the smaller of
//! the two before. A converging run either grows
//! its mesh or cuts its residual by much more on every pass (the benchmark problems: at least a
//! factor 100 per refinement), so the watch stays silent there.

use crate::mesh::{self, MeshOptions, RefineRule};

/// The mesh options of one solve and the watch over its passes: the rule switches to scipy's
/// when the mesh does not settle ([`MeshOptions::settle`]).
#[derive(Debug, Clone)]
pub(crate) struct MeshControl {
    /// The options in force (the caller's, with the rule switched after a cycle).
    pub(crate) options: MeshOptions,
    /// The watch over the refinement passes.
    watch: CycleWatch,
    /// The mesh iteration after which the rule switched to scipy's.
    pub(crate) switched_at: Option<usize>,
}

impl MeshControl {
    /// The control of a solve with the caller's mesh options.
    pub(crate) fn new(options: &MeshOptions) -> Self {
        MeshControl {
            options: options.clone(),
            watch: CycleWatch::default(),
            switched_at: None,
        }
    }

    /// [`mesh::plan`] for the mesh iteration `pass.2` on a mesh of `pass.0` nodes whose largest
    /// residual is `pass.1`; a pass with intervals above `tol` is recorded, and when it shows
    /// a cycle (and [`MeshOptions::settle`] is on) the rule switches to scipy's before planning
    /// (said on stderr with `verbose >= 1`).
    pub(crate) fn plan(
        &mut self,
        rms: &[f64],
        tol: f64,
        marks: &mut Vec<u8>,
        pass: (usize, f64, usize),
        verbose: u8,
    ) -> usize {
        let (nodes, max_residual, iteration) = pass;
        let above = mesh::plan(rms, tol, &self.options, marks);
        if above == 0 || !self.watch.stalled(nodes, max_residual) {
            return above;
        }
        if !self.options.settle || self.options.rule == RefineRule::Scipy {
            return above;
        }
        self.options.rule = RefineRule::Scipy;
        self.switched_at = Some(iteration);
        if verbose >= 1 {
            // a failed write to stderr must not panic
            use std::io::Write as _;
            let (lo, hi) = self.watch.cycle().unwrap_or((nodes, nodes));
            let _ = writeln!(
                std::io::stderr(),
                "mesh {iteration:>3}: the mesh does not settle ({lo} to {hi} nodes over the last \
                 passes, residual not falling): switching to scipy's refinement rule"
            );
        }
        mesh::plan(rms, tol, &self.options, marks)
    }

    /// The smallest and largest node counts of the passes that showed a cycle, if any did.
    pub(crate) fn cycle(&self) -> Option<(usize, usize)> {
        self.watch.cycle()
    }
}

/// Refinement passes the watch looks back over.
pub(crate) const WINDOW: usize = 3;
/// Largest mesh growth over the window (a ratio of node counts) that counts as "not growing".
pub(crate) const GROWTH: f64 = 1.1;
/// The residual of the last pass must fall below this fraction of the smaller of the two
/// before it to count as progress.
pub(crate) const DROP: f64 = 0.5;

/// The node counts and largest residuals of the last refinement passes of one solve.
#[derive(Debug, Clone, Default)]
pub(crate) struct CycleWatch {
    /// `(nodes, largest scaled RMS residual)` of the last passes, oldest first.
    recent: [(usize, f64); WINDOW],
    /// Passes recorded (all of them, not only the window).
    passes: usize,
    /// Smallest and largest node counts of the window in which a cycle was first seen.
    cycle: Option<(usize, usize)>,
}

impl CycleWatch {
    /// Records a refinement pass on a mesh of `nodes` nodes whose largest scaled RMS residual is
    /// `max_residual`; returns `true` the first time the window shows a mesh that neither grows
    /// nor improves (see the module documentation). A NaN residual is no progress.
    pub(crate) fn stalled(&mut self, nodes: usize, max_residual: f64) -> bool {
        self.recent.rotate_left(1);
        self.recent[WINDOW - 1] = (nodes, max_residual);
        self.passes += 1;
        if self.passes < WINDOW || self.cycle.is_some() {
            return false;
        }
        let lo = self.recent.iter().map(|r| r.0).min().unwrap_or(nodes);
        let hi = self.recent.iter().map(|r| r.0).max().unwrap_or(nodes);
        let not_growing = nodes as f64 <= GROWTH * self.recent[0].0 as f64;
        let before = self.recent[..WINDOW - 1]
            .iter()
            .map(|r| r.1)
            .fold(f64::INFINITY, f64::min);
        let improving = max_residual < DROP * before;
        if not_growing && !improving {
            self.cycle = Some((lo, hi));
            true
        } else {
            false
        }
    }

    /// The smallest and largest node counts of the passes in which the cycle was seen, if one
    /// was.
    pub(crate) fn cycle(&self) -> Option<(usize, usize)> {
        self.cycle
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mesh_that_grows_or_improves_is_not_a_cycle() {
        let mut w = CycleWatch::default();
        // the shock layer at tol 1e-6: 5, 65, 462 nodes, residual falling by 10-100
        for (m, r) in [(5, 1.36), (65, 1.3e-1), (462, 7.8e-4)] {
            assert!(!w.stalled(m, r));
        }
        // a stagnant size, but the residual halves on every pass
        let mut w = CycleWatch::default();
        for (m, r) in [(400, 1e-1), (402, 4e-2), (401, 1.9e-2), (400, 9e-3)] {
            assert!(!w.stalled(m, r));
        }
        assert_eq!(w.cycle(), None);
    }

    #[test]
    fn a_wandering_mesh_is_a_cycle_with_its_node_counts() {
        // ε = 0.01, tol 1e-3 on the default rule (examples/oscillatory_mesh.rs)
        let mut w = CycleWatch::default();
        let passes = [
            (332, 2.3e-1),
            (398, 2.82e-1),
            (402, 3.57e-2),
            (389, 1.88e-2),
        ];
        let seen: Vec<bool> = passes.iter().map(|&(m, r)| w.stalled(m, r)).collect();
        assert_eq!(seen, vec![false, false, false, true]);
        assert_eq!(w.cycle(), Some((389, 402)));
        // reported once
        assert!(!w.stalled(384, 2.26e-2));
        // repeating counts with a NaN residual
        let mut w = CycleWatch::default();
        assert!(!w.stalled(100, 1.0));
        assert!(!w.stalled(120, 1.0));
        assert!(w.stalled(100, f64::NAN));
        assert_eq!(w.cycle(), Some((100, 120)));
    }
}

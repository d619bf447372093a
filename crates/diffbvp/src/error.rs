//! Why a solve failed, with the numbers that show it.

use thiserror::Error;

/// A failed solve. Every variant names the reason and the figures reached; nothing panics.
#[derive(Debug, Clone, Error)]
pub enum BvpError {
    /// The input (mesh, guess, parameters or options) is invalid.
    #[error("invalid input: {0}")]
    InvalidInput(String),

    /// Refinement would need more nodes than allowed.
    #[error(
        "maximum number of mesh nodes exceeded: {nodes} nodes needed more than max_nodes = {max_nodes}; \
         the largest scaled RMS residual reached was {max_residual:.3e} (tol {tol:.1e})"
    )]
    MaxNodesExceeded {
        /// Nodes the next mesh would have had.
        nodes: usize,
        /// The limit.
        max_nodes: usize,
        /// Largest RMS collocation residual on the last mesh.
        max_residual: f64,
        /// Requested tolerance.
        tol: f64,
    },

    /// Refinement would grow the mesh beyond [`SolveOptions::growth_limit`](crate::solve::SolveOptions::growth_limit)
    /// allows for the mesh the solve started from: the start is far from a solution at these
    /// parameters (or there is none), and the caller should take a shorter step.
    #[error(
        "the mesh would grow from the start's {start_nodes} nodes to {nodes}, beyond the growth \
         limit of {limit} nodes (SolveOptions::growth_limit): the start is far from a solution at \
         these parameters, or there is none; take a shorter step or start closer (the largest \
         scaled RMS residual reached was {max_residual:.3e}, tol {tol:.1e})"
    )]
    MeshGrowthLimit {
        /// Nodes of the start's mesh.
        start_nodes: usize,
        /// Nodes the next mesh would have had.
        nodes: usize,
        /// The limit the growth limit set for this solve.
        limit: usize,
        /// Largest RMS collocation residual on the last mesh.
        max_residual: f64,
        /// Requested tolerance.
        tol: f64,
    },

    /// The Newton matrix is singular.
    #[error("singular Jacobian: {detail}")]
    SingularJacobian {
        /// Where the singularity shows (components, positions, parameters).
        detail: String,
    },

    /// Newton's method did not converge on a mesh.
    #[error(
        "Newton's method did not converge after {iterations} iterations on a mesh of {nodes} nodes: \
         {reason} (largest scaled collocation residual {max_residual:.3e}, largest boundary residual {max_bc_residual:.3e})"
    )]
    NewtonFailed {
        /// Newton iterations done.
        iterations: usize,
        /// Mesh size.
        nodes: usize,
        /// What went wrong.
        reason: String,
        /// Largest scaled collocation residual at the last iterate.
        max_residual: f64,
        /// Largest boundary-condition residual at the last iterate.
        max_bc_residual: f64,
    },

    /// The mesh loop ended without meeting the tolerances.
    #[error(
        "tolerance not met after {iterations} mesh iterations: largest RMS residual {max_residual:.3e} (tol {tol:.1e}), \
         largest boundary residual {max_bc_residual:.3e} (bc_tol {bc_tol:.1e})"
    )]
    ToleranceNotMet {
        /// Mesh iterations done.
        iterations: usize,
        /// Largest RMS collocation residual.
        max_residual: f64,
        /// Requested tolerance.
        tol: f64,
        /// Largest boundary residual.
        max_bc_residual: f64,
        /// Requested boundary tolerance.
        bc_tol: f64,
    },

    /// The mesh loop ended without meeting the tolerances after its mesh had stopped settling
    /// (the figures boxed: they would double the size of every `BvpError`).
    #[error("{0}")]
    MeshCycling(Box<MeshCycle>),

    /// The right-hand side or the boundary residual returned a non-finite value.
    #[error("non-finite value in {what}: component {component} at x = {x:e}")]
    NonFinite {
        /// `"right-hand side"`, `"boundary residual"`, `"Jacobian"`, `"initial guess"`, ...
        what: &'static str,
        /// Offending component index.
        component: usize,
        /// Position (for boundary residuals: the left end point `a`).
        x: f64,
    },

    /// A path-following method (continuation) could not proceed.
    #[error("continuation stopped at c = {reached} (target {target}): step {step:.3e} below the minimum {min_step:.1e}; last failure: {last_error}")]
    ContinuationStalled {
        /// Continuation parameter value reached.
        reached: f64,
        /// Target value.
        target: f64,
        /// Step size when it gave up.
        step: f64,
        /// Minimum step size.
        min_step: f64,
        /// The last solver failure.
        last_error: Box<BvpError>,
    },
}

/// The figures of a mesh loop that ended without meeting the tolerances after its mesh had
/// stopped settling ([`BvpError::MeshCycling`]): over several refinement passes the node count
/// stayed between `low` and `high` while the residual did not fall.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshCycle {
    /// Mesh iterations done.
    pub iterations: usize,
    /// Smallest node count of the passes that showed the cycle.
    pub low: usize,
    /// Largest node count of the passes that showed the cycle.
    pub high: usize,
    /// The mesh iteration after which the refinement switched to scipy's rule (`None`:
    /// [`MeshOptions::settle`](crate::mesh::MeshOptions::settle) was off).
    pub switched_at: Option<usize>,
    /// Largest RMS collocation residual on the last mesh.
    pub max_residual: f64,
    /// Requested tolerance.
    pub tol: f64,
    /// Largest boundary residual.
    pub max_bc_residual: f64,
    /// Requested boundary tolerance.
    pub bc_tol: f64,
    /// Which options to try.
    pub hint: String,
}

impl std::fmt::Display for MeshCycle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "tolerance not met after {} mesh iterations: the mesh did not settle, it cycled \
             between {} and {} nodes",
            self.iterations, self.low, self.high
        )?;
        if let Some(k) = self.switched_at {
            write!(
                f,
                ", and scipy's refinement rule, switched to after mesh iteration {k}, did not \
                 converge either"
            )?;
        }
        write!(
            f,
            " (largest RMS residual {:.3e}, tol {:.1e}; largest boundary residual {:.3e}, bc_tol \
             {:.1e}); try {}",
            self.max_residual, self.tol, self.max_bc_residual, self.bc_tol, self.hint
        )
    }
}

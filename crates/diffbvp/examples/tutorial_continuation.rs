//! Book, tutorial 3: a problem that needs continuation.
//!
//! Troesch's problem y'' = μ sinh(μ y), y(0) = 0, y(1) = 1 at μ = 10 has a boundary layer at
//! x = 1 that Newton's method does not find from a linear guess. Written as a family in a model
//! parameter c (μ = 1 + 9c), it is easy at c = 0 and is followed to c = 1 with the paper's
//! Adapter step control.
//!
//! Run with `cargo run --release --example tutorial_continuation`.

// `tests/book_examples.rs` includes this file as a module and checks `run()`'s numbers.
#![allow(dead_code)]

use diffbvp::continuation::{continuation, ContinuationOptions};
use diffbvp::mesh::linspace;
use diffbvp::{Bvp, BvpError, DualNum, Guess, SolveOptions, Solver};

// ANCHOR: problem
/// Troesch's problem with μ = 1 + 9c; c is model parameter 0.
struct Troesch;

impl Bvp for Troesch {
    fn dim(&self) -> usize {
        2
    }
    fn num_params(&self) -> usize {
        1 // c, supplied by the caller
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        let mu = p[0] * 9.0 + 1.0;
        f[0] = y[1];
        f[1] = (y[0] * mu).sinh() * mu;
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0] - 1.0;
    }
}
// ANCHOR_END: problem

/// The numbers the tutorial prints (checked by `tests/book_examples.rs`).
pub struct ContinuationSummary {
    /// Whether the direct solve at μ = 10 from the linear guess failed.
    pub direct_failed: bool,
    /// y'(0) at μ = 10 after continuation.
    pub slope_at_zero: f64,
    /// Accepted and rejected continuation steps.
    pub steps: (usize, usize),
    /// Nodes of the final mesh.
    pub nodes: usize,
}

/// Runs the tutorial and prints the path.
pub fn run() -> Result<ContinuationSummary, BvpError> {
    // ANCHOR: direct
    let linear = Guess::from_fn(linspace(0.0, 1.0, 11), 2, |x, y| {
        y[0] = x;
        y[1] = 1.0;
    });
    let mut solver = Solver::new(&Troesch, SolveOptions::with_tol(1e-6));
    let direct = solver.solve(&[1.0], &linear);
    match &direct {
        Ok(s) => println!(
            "direct solve at μ = 10 converged: y'(0) = {:e}",
            s.at_node(0, 1)
        ),
        Err(e) => println!("direct solve at μ = 10 failed: {e}"),
    }
    // ANCHOR_END: direct

    // ANCHOR: continuation
    let start = solver.solve(&[0.0], &linear)?; // μ = 1: easy
    let path = continuation(&mut solver, &start, 0, 1.0, &ContinuationOptions::default())?;
    let s = &path.solution;
    println!(
        "continuation to μ = 10: y'(0) = {:.8e}, {} nodes, {} steps accepted, {} rejected, {} f evaluations",
        s.at_node(0, 1),
        s.nodes(),
        path.steps_accepted,
        path.steps_rejected,
        path.total_rhs_evaluations
    );
    // ANCHOR_END: continuation
    println!("literature: y'(0) = 3.5833778e-4");
    println!(
        "\n{:>8} {:>8} {:>8} {:>9} {:>6} {:>8}",
        "from", "step", "reached", "accepted", "full", "halves"
    );
    for r in &path.history {
        let cost = |c: Option<usize>| c.map_or("-".to_string(), |v| v.to_string());
        println!(
            "{:>8.4} {:>8.4} {:>8.4} {:>9} {:>6} {:>8}",
            r.from,
            r.step,
            r.reached,
            r.accepted,
            cost(r.cost_full),
            cost(r.cost_halves)
        );
    }
    Ok(ContinuationSummary {
        direct_failed: direct.is_err(),
        slope_at_zero: s.at_node(0, 1),
        steps: (path.steps_accepted, path.steps_rejected),
        nodes: s.nodes(),
    })
}

fn main() -> Result<(), BvpError> {
    run().map(|_| ())
}

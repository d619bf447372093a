//! Bratu's problem y'' + k e^y = 0, y(0) = y(1) = 0: both solution branches from two initial
//! guesses, with the solution statistics.
//!
//! Run with `cargo run --release --example bratu`.

// ANCHOR: problem
use diffbvp::mesh::linspace;
use diffbvp::{solve, Bvp, DualNum, Guess, SolveOptions};

/// Bratu's problem with parameter k.
struct Bratu {
    k: f64,
}

impl Bvp for Bratu {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = -y[0].exp() * self.k;
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0];
    }
}
// ANCHOR_END: problem

fn main() -> Result<(), diffbvp::BvpError> {
    // ANCHOR: solve
    let problem = Bratu { k: 1.0 };
    let options = SolveOptions::with_tol(1e-6);
    let mesh = linspace(0.0, 1.0, 5);
    let lower = solve(
        &problem,
        &[],
        &Guess::constant(mesh.clone(), &[0.0, 0.0]),
        &options,
    )?;
    let upper = solve(&problem, &[], &Guess::constant(mesh, &[3.0, 0.0]), &options)?;
    // ANCHOR_END: solve
    // ANCHOR: report
    for (name, s) in [("lower", &lower), ("upper", &upper)] {
        println!(
            "{name} branch: y(1/2) = {:.10}, y'(0) = {:.10}",
            s.eval(0.5)[0],
            s.at_node(0, 1)
        );
        println!(
            "  {} nodes, {} Newton iterations, {} factorisations, {} f evaluations (+{} dual), {} mesh changes, max RMS residual {:.2e}",
            s.nodes(),
            s.stats.newton_iterations,
            s.stats.jacobian_factorizations,
            s.stats.rhs_evaluations,
            s.stats.rhs_dual_evaluations,
            s.stats.mesh_refinements,
            s.stats.max_residual
        );
    }
    // ANCHOR_END: report
    println!("exact: y(1/2) = 0.1405392144 (lower), 4.0914672462 (upper)");
    Ok(())
}

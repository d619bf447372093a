//! Book, tutorial 4: sensitivities, adjoints, and fitting BVP parameters to data.
//!
//! The problem y'' = −a e^y, y(0) = b, y(1) = 0 has two model parameters p = (a, b). We compute
//! dy/dp by forward sensitivities, the gradient of a functional by one adjoint solve, and then
//! fit (a, b) to noisy samples of y with the bounded trust-region Gauss–Newton driver.
//!
//! Run with `cargo run --release --example tutorial_fit`.

// `tests/book_examples.rs` includes this file as a module and checks `run()`'s numbers.
#![allow(dead_code)]

use diffbvp::least_squares::{
    fit_observed, BvpResiduals, BvpRun, FitIteration, FitOptions, ParamMap,
};
use diffbvp::mesh::linspace;
use diffbvp::sensitivity::{adjoint_gradient, PointFunction, Sensitivities};
use diffbvp::{Bvp, DualNum, Guess, SolveOptions, Solver};

// ANCHOR: problem
/// y'' = −a e^y, y(0) = b, y(1) = 0 with model parameters p = (a, b).
struct BratuAB;

impl Bvp for BratuAB {
    fn dim(&self) -> usize {
        2
    }
    fn num_params(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = -p[0] * y[0].exp();
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        r[0] = ya[0] - p[1];
        r[1] = yb[0];
    }
}
// ANCHOR_END: problem

// ANCHOR: functional
/// g_j = y(x_j)²: the summand of the functional G = Σ_j w_j y(x_j)².
struct Square;

impl PointFunction for Square {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, _j: usize, _x: f64, y: &[D], _p: &[D]) -> D {
        y[0] * y[0]
    }
}
// ANCHOR_END: functional

// ANCHOR: misfit
/// The residual r_j = y(x_j) − data_j.
struct Misfit {
    data: Vec<f64>,
}

impl PointFunction for Misfit {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, j: usize, _x: f64, y: &[D], _p: &[D]) -> D {
        y[0] - self.data[j]
    }
}
// ANCHOR_END: misfit

/// The numbers the tutorial prints (checked by `tests/book_examples.rs`).
pub struct FitSummary {
    /// dy/da and dy/db at x = 1/2 (forward sensitivities).
    pub dy_dp_half: [f64; 2],
    /// The same from central differences of re-solved problems (for comparison only).
    pub dy_dp_half_differences: [f64; 2],
    /// dG/dp from the adjoint solve.
    pub adjoint: [f64; 2],
    /// dG/dp assembled from the forward sensitivities.
    pub forward: [f64; 2],
    /// Fitted (a, b).
    pub fitted: [f64; 2],
    /// Standard errors of (a, b).
    pub standard_errors: [f64; 2],
    /// Trial steps of the fit.
    pub iterations: usize,
}

/// Deterministic "measurement noise" of amplitude 0.002 (no random-number crate needed).
fn noise(j: usize) -> f64 {
    0.002 * (37.0 * j as f64).sin()
}

/// Runs the tutorial.
pub fn run() -> Result<FitSummary, Box<dyn std::error::Error>> {
    let opts = SolveOptions::with_tol(1e-8);
    let guess = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);

    // ANCHOR: sensitivities
    let p = [1.7, 0.4];
    let sol = diffbvp::solve(&BratuAB, &p, &guess, &opts)?;
    let sens = Sensitivities::compute(&BratuAB, &sol)?; // one linear solve, 2 right-hand sides
    let dy = sens.at(0.5); // layout: dy[c * q + j] = ∂y_c/∂p_j
    println!("y(1/2) = {:.10}", sol.eval(0.5)[0]);
    println!("dy(1/2)/da = {:.10}, dy(1/2)/db = {:.10}", dy[0], dy[1]);
    // ANCHOR_END: sensitivities

    // Only to show agreement: central differences of two re-solves per parameter.
    let mut fd = [0.0; 2];
    for (j, v) in fd.iter_mut().enumerate() {
        let h = 1e-5;
        let (mut pp, mut pm) = (p, p);
        pp[j] += h;
        pm[j] -= h;
        let warm = Guess::from(&sol);
        let yp = diffbvp::solve(&BratuAB, &pp, &warm, &opts)?.eval(0.5)[0];
        let ym = diffbvp::solve(&BratuAB, &pm, &warm, &opts)?.eval(0.5)[0];
        *v = (yp - ym) / (2.0 * h);
    }
    println!(
        "central differences of re-solves: {:.10}, {:.10}",
        fd[0], fd[1]
    );

    // ANCHOR: adjoint
    let xs: Vec<f64> = (1..20).map(|i| i as f64 / 20.0).collect();
    let weights = vec![1.0 / 19.0; xs.len()];
    let (g, grad) = adjoint_gradient(&BratuAB, &sol, &xs, &weights, &Square)?;
    println!(
        "G = {g:.10}, dG/dp by one adjoint solve = ({:.10}, {:.10})",
        grad[0], grad[1]
    );
    // ANCHOR_END: adjoint
    let mut forward = [0.0; 2];
    for (x, w) in xs.iter().zip(&weights) {
        let (y, d) = (sol.eval(*x)[0], sens.at(*x));
        for j in 0..2 {
            forward[j] += w * 2.0 * y * d[j];
        }
    }
    println!(
        "dG/dp from forward sensitivities  = ({:.10}, {:.10})",
        forward[0], forward[1]
    );

    // ANCHOR: fit
    // Data: y at 19 points for the truth (a, b) = (1.7, 0.4), plus noise.
    let mut solver = Solver::new(&BratuAB, opts);
    let truth = solver.solve(&[1.7, 0.4], &guess)?;
    let data: Vec<f64> = (xs.iter().enumerate())
        .map(|(j, &x)| truth.eval(x)[0] + noise(j))
        .collect();
    let start = [0.5, 0.0];
    let accepted = solver.solve(&start, &guess)?; // the first warm start
                                                  // the model parameters (a, b) are the fit parameters (p₀, p₁)
    let map = ParamMap::new(vec![0.0; 2]).link(0, 0).link(1, 1);
    let run = BvpRun::new(solver, accepted, xs.clone(), Misfit { data }, map)?;
    let mut problem = BvpResiduals::new(2).with_run(run)?;
    let bounds = FitOptions::with_bounds(vec![0.0, -1.0], vec![3.0, 1.0]);
    let mut progress = |it: &FitIteration| {
        let cost = it.cost.map_or("failed".into(), |c| format!("{c:.3e}"));
        let verdict = if it.accepted { "accepted" } else { "rejected" };
        println!(
            "  step {:>2}: cost {cost}, {verdict}, radius {:.3}",
            it.iteration, it.radius
        );
    };
    println!("\nfit from (0.5, 0):");
    let result = fit_observed(&mut problem, &start, &bounds, &mut progress)?;
    let se = result
        .standard_errors()
        .ok_or("singular Jacobian at the optimum")?;
    println!(
        "a = {:.5} ± {:.5}, b = {:.5} ± {:.5}",
        result.p[0], se[0], result.p[1], se[1]
    );
    println!(
        "{} trial steps ({} accepted), cost ½‖r‖² = {:.3e}, stopped: {}",
        result.iterations, result.accepted_steps, result.cost, result.termination
    );
    // ANCHOR_END: fit
    println!("truth: a = 1.7, b = 0.4");
    Ok(FitSummary {
        dy_dp_half: [dy[0], dy[1]],
        dy_dp_half_differences: fd,
        adjoint: [grad[0], grad[1]],
        forward,
        fitted: [result.p[0], result.p[1]],
        standard_errors: [se[0], se[1]],
        iterations: result.iterations,
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    run().map(|_| ())
}

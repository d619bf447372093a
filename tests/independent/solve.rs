//! Solving a [`Line`] by continuation in its homotopy parameter `c` (0 → 1) with the crate's
//! generic collocation solver and continuation (tested separately), and its profiles.

use super::model::{AirFlow, Line};
use diffbvp::continuation::{solve_by_continuation, PathOptions};
use diffbvp::{Guess, ResidualScale, Solution, SolveOptions, Solver};

/// Collocation tolerance of the final solve (scaled RMS residual) [-].
pub const TOLERANCE: f64 = 1e-8;

/// Profiles along the line (SI).
#[derive(Debug, Clone)]
pub struct Profile {
    /// s [m]
    pub position: Vec<f64>,
    /// u [m/s]
    pub velocity: Vec<f64>,
    /// N [N]
    pub force: Vec<f64>,
    /// T [K]
    pub temperature: Vec<f64>,
    /// ε̇ [1/s]
    pub strain_rate: Vec<f64>,
    /// d [m]
    pub diameter: Vec<f64>,
}

/// Solves `line` at c = 1 in still air, then (if it has an air flow) continues the air speed
/// from 0 to its full value (tolerance [`TOLERANCE`]).
pub fn solve_line(line: &Line) -> Result<Solution, String> {
    let x: Vec<f64> = (0..=40).map(|i| i as f64 / 40.0).collect();
    let guess = Guess::from_fn(x, 3, |x, y| line.guess_state(x, y));
    let mut options = SolveOptions::with_tol(TOLERANCE);
    options.scale = ResidualScale::Auto;
    options.factor_at_solution = false;
    options.max_nodes = 50_000;
    let mut solver = Solver::new(line, options.clone());
    let err = |e| format!("independent model: {e}");
    let still = solve_by_continuation(
        &mut solver,
        &[0.0, 0.0],
        0,
        1.0,
        &guess,
        &PathOptions::default(),
        &options,
    )
    .map_err(err)?;
    if matches!(line.air_flow, AirFlow::Still) {
        return Ok(still);
    }
    solve_by_continuation(
        &mut solver,
        &[1.0, 0.0],
        1,
        1.0,
        &Guess::from(&still),
        &PathOptions::default(),
        &options,
    )
    .map_err(err)
}

/// Profiles of a solution at positions `s` [m].
pub fn profile(line: &Line, sol: &Solution, s: &[f64]) -> Profile {
    let mut p = Profile {
        position: s.to_vec(),
        velocity: vec![],
        force: vec![],
        temperature: vec![],
        strain_rate: vec![],
        diameter: vec![],
    };
    for &si in s {
        let y = sol.eval((si / line.length).clamp(0.0, 1.0));
        let (u, n, t) = line.physical(&y);
        p.velocity.push(u);
        p.force.push(n);
        p.temperature.push(t);
        p.strain_rate.push(line.strain_rate(&y));
        p.diameter.push(line.diameter(&y));
    }
    p
}

/// Diameters [m] at positions `s` [m].
pub fn diameters(line: &Line, s: &[f64]) -> Result<Vec<f64>, String> {
    let sol = solve_line(line)?;
    Ok(profile(line, &sol, s).diameter)
}

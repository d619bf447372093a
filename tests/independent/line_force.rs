//! A hidden axial force concentrated at one place of the line (a thread guide rubbing on the
//! fiber, an air knife): the force per length `F/(w √(2π)) exp(−(s − s_c)²/(2 w²))` \[N/m\]
//! along the spinning direction (negative `F`: against the motion, as a guide's friction), added
//! to the momentum balance of a [`Line`] as an external force like gravity. Written here, apart
//! from the crate's `FiberTerm`s; nothing here calls `rheometer`.

use super::model::Line;
use super::solve::TOLERANCE;
use diffbvp::continuation::{solve_by_continuation, PathOptions};
use diffbvp::{Bvp, DualNum, Guess, ResidualScale, Solution, SolveOptions, Solver};
use std::f64::consts::PI;

/// A Gaussian line force.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineForce {
    /// Total force `F` \[N\] along the spinning direction (negative: against the motion).
    pub force: f64,
    /// Centre `s_c` \[m\].
    pub centre: f64,
    /// Width `w` \[m\] (standard deviation of the Gaussian).
    pub width: f64,
}

impl LineForce {
    /// Force per length \[N/m\] at `s` \[m\].
    pub fn per_length(&self, s: f64) -> f64 {
        let z = (s - self.centre) / self.width;
        self.force * (-0.5 * z * z).exp() / (self.width * (2.0 * PI).sqrt())
    }
}

/// A line with a [`LineForce`]; the homotopy parameter `c` of the line multiplies it too.
#[derive(Debug, Clone)]
pub struct ForcedLine {
    /// The line.
    pub line: Line,
    /// The hidden force.
    pub force: LineForce,
}

impl ForcedLine {
    /// Tension scale of the line's second state \[N\] (its state is `N/N_ref`).
    fn tension_scale(&self) -> f64 {
        self.line.physical(&[0.0, 1.0, 0.0]).1
    }
}

impl Bvp for ForcedLine {
    fn dim(&self) -> usize {
        3
    }
    fn num_params(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D], f: &mut [D]) {
        self.line.rhs(x, y, p, f);
        // N' = Q u' − c (Σ external forces along the spinning direction), per unit of x = s/L
        let l = self.line.length;
        let extra = self.force.per_length(x * l) * (l / self.tension_scale());
        f[1] -= p[0] * extra;
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        self.line.bc(ya, yb, p, r);
    }
}

/// Solves a forced line in still air by continuation in `c` from 0 to 1 (the line's own start).
pub fn solve_forced(forced: &ForcedLine) -> Result<Solution, String> {
    let line = &forced.line;
    let x: Vec<f64> = (0..=40).map(|i| i as f64 / 40.0).collect();
    let guess = Guess::from_fn(x, 3, |x, y| line.guess_state(x, y));
    let mut options = SolveOptions::with_tol(TOLERANCE);
    options.scale = ResidualScale::Auto;
    options.factor_at_solution = false;
    options.max_nodes = 50_000;
    let mut solver = Solver::new(forced, options.clone());
    solve_by_continuation(
        &mut solver,
        &[0.0, 0.0],
        0,
        1.0,
        &guess,
        &PathOptions::default(),
        &options,
    )
    .map_err(|e| format!("independent model with a line force: {e}"))
}

/// Diameters \[m\] of a forced line at positions `s` \[m\].
pub fn forced_diameters(forced: &ForcedLine, s: &[f64]) -> Result<Vec<f64>, String> {
    let sol = solve_forced(forced)?;
    let line = &forced.line;
    Ok(s.iter()
        .map(|&si| line.diameter(&sol.eval((si / line.length).clamp(0.0, 1.0))))
        .collect())
}

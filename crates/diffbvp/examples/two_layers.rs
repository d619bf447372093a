//! A multipoint problem: steady heat conduction through a wall of two layers with different
//! conductivities, the temperature and the heat flux continuous at the interface.
//!
//! In layer `r` (thickness-normalised position `x`, interface at `x = ξ`):
//! `T' = −q / k_r`, `q' = s_r` (a uniform heat source `s_r`), `T(0) = 1`, `T(1) = 0`.
//! The states are `(T, q)`; each layer has its own right-hand side ([`Bvp::rhs_in_region`]),
//! the mesh holds the interface twice, and the default interface conditions make both states
//! continuous. Without sources the flux is that of two resistances in series,
//! `q = 1 / (ξ/k₀ + (1 − ξ)/k₁)`; the example checks it, then adds a source to the second
//! layer and prints the exact sensitivity of the interface temperature to it.
//!
//! ```text
//! cargo run --release -p diffbvp --example two_layers
//! ```

use diffbvp::mesh::multipoint_linspace;
use diffbvp::sensitivity::Sensitivities;
use diffbvp::{solve, Bvp, DualNum, Guess, SolveOptions};

/// Position of the interface (fraction of the wall's thickness).
const XI: f64 = 0.4;

/// Two layers of conductivities `k` (dimensionless); the model parameter `p[0]` is the heat
/// source in the second layer.
struct TwoLayers {
    k: [f64; 2],
}

impl Bvp for TwoLayers {
    fn dim(&self) -> usize {
        2
    }

    fn num_params(&self) -> usize {
        1
    }

    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D], f: &mut [D]) {
        self.rhs_in_region(usize::from(x > XI), x, y, p, f);
    }

    fn rhs_in_region<D: DualNum<Primitive = f64> + Copy>(
        &self,
        region: usize,
        _x: f64,
        y: &[D],
        p: &[D],
        f: &mut [D],
    ) {
        f[0] = -y[1] / self.k[region];
        f[1] = if region == 1 { p[0] } else { D::zero() };
    }

    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0] - 1.0;
        r[1] = yb[0];
    }

    fn interfaces(&self) -> &[f64] {
        &[XI]
    }
}

/// Solves the wall with and without a source; an error where a closed form is missed.
pub fn run() -> Result<(), Box<dyn std::error::Error>> {
    let wall = TwoLayers { k: [1.0, 3.0] };
    let guess = Guess::constant(multipoint_linspace(&[0.0, XI, 1.0], 5), &[0.5, 1.0]);
    let opts = SolveOptions::with_tol(1e-8);

    let sol = solve(&wall, &[0.0], &guess, &opts)?;
    let q = 1.0 / (XI / wall.k[0] + (1.0 - XI) / wall.k[1]);
    let t_interface = 1.0 - XI * q / wall.k[0];
    println!(
        "no source: {} nodes, q = {:.12} (series resistances: {q:.12}), T(ξ) = {:.12} ({t_interface:.12})",
        sol.nodes(),
        sol.eval(0.2)[1],
        sol.eval(XI)[0]
    );
    if (sol.eval(0.2)[1] - q).abs() > 1e-10 || (sol.eval(XI)[0] - t_interface).abs() > 1e-10 {
        return Err("the two-layer solution misses the closed form".into());
    }

    // a source in the second layer: how the interface temperature responds (exact, forward)
    let sol = solve(&wall, &[2.0], &guess, &opts)?;
    let sens = Sensitivities::compute(&wall, &sol)?;
    let dt = sens.at(XI)[0];
    // closed form: T is linear in s; with q(x) = q₀ + s (x − ξ) in layer 1, the temperature
    // drop across layer 1 is ∫ q/k₁ dx, so dT(ξ)/ds follows from T(1) = 0
    let l1 = 1.0 - XI;
    let r = XI / wall.k[0] + l1 / wall.k[1];
    let dq0 = -(l1 * l1 / (2.0 * wall.k[1])) / r;
    let exact = -XI * dq0 / wall.k[0];
    println!(
        "source 2 in layer 1: T(ξ) = {:.9}, dT(ξ)/ds = {dt:.9} (closed form {exact:.9})",
        sol.eval(XI)[0]
    );
    if (dt - exact).abs() > 1e-8 {
        return Err("the sensitivity misses the closed form".into());
    }
    Ok(())
}

#[allow(dead_code)]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    run()
}

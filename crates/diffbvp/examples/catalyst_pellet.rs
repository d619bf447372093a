//! Book, "Your own BVP fit": the catalyst pellet, a second worked domain written only against
//! diffbvp's public API, as an outside user would.
//!
//! A reactant diffuses into a spherical porous pellet and reacts on its inner surface with
//! Langmuir–Hinshelwood kinetics. In the dimensionless concentration `c` (1 at the surface) and
//! radius `x = r/R` (0 at the centre, 1 at the surface):
//!
//! ```text
//! c'' + (2/x) c' = φ² R(c),   R(c) = c / (1 + K c)²,   c'(0) = 0,  c(1) = 1,
//! ```
//!
//! with the Thiele modulus `φ = R_p a`, `a = sqrt(k/D)` \[1/mm\] the kinetic parameter (rate
//! constant over diffusivity), `R_p` \[mm\] the pellet radius and `K` (dimensionless) the
//! adsorption constant. The effectiveness factor, the mean reaction rate over the pellet
//! relative to the rate at surface conditions, is an integral functional:
//!
//! ```text
//! η = 3 ∫₀¹ x² R(c(x)) dx / R(1).
//! ```
//!
//! The example (1) follows the solution in φ by continuation, (2) checks η against the closed
//! form of first-order kinetics (K = 0), (3) fits (a, K) to effectiveness factors "measured" on
//! pellets of eight sizes (synthetic: a separate truth plus seeded 1 % noise), with
//! uncertainties, and (4) uses the exact gradient of η to say which pellet size to measure
//! next.
//!
//! Run with `cargo run --release -p diffbvp --example catalyst_pellet`.

// `tests/catalyst_pellet.rs` includes this file as a module and checks `run()`'s numbers.
#![allow(dead_code)]

use diffbvp::continuation::{continuation, sweep, ContinuationOptions};
use diffbvp::least_squares::{fit, BvpResiduals, BvpRun, FitOptions, ParamMap};
use diffbvp::mesh::linspace;
use diffbvp::sensitivity::{
    integral_adjoint, integral_forward, integral_value, IntegralFunction, PointFunction,
    Sensitivities,
};
use diffbvp::{Bvp, DualNum, Guess, Solution, SolveOptions, Solver};

// ANCHOR: problem
/// Langmuir–Hinshelwood rate `R(c) = c / (1 + K c)²`, for `f64` and dual numbers alike.
fn rate<D: DualNum<Primitive = f64> + Copy>(c: D, k: D) -> D {
    let den = k * c + 1.0;
    c / (den * den)
}

/// The pellet: states `y = (c, c')`, model parameters `p = (φ, K)`.
struct Pellet;

impl Bvp for Pellet {
    fn dim(&self) -> usize {
        2
    }
    fn num_params(&self) -> usize {
        2
    }
    /// `y' = S y / x + f`: `f` holds everything but the `(2/x) c'` term.
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = p[0] * p[0] * rate(y[0], p[1]);
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[1]; // symmetry at the centre (and the regularity condition S y(0) = 0)
        r[1] = yb[0] - 1.0; // surface concentration
    }
    /// `S = [[0, 0], [0, −2]]`: row 1 of `S y / x` is `−2 c'/x`, the sphere's `(2/x) c'`
    /// moved to the right-hand side.
    fn singular_term(&self) -> Option<Vec<f64>> {
        Some(vec![0.0, 0.0, 0.0, -2.0])
    }
}
// ANCHOR_END: problem

// ANCHOR: integral
/// The effectiveness factor `η = 3 ∫₀¹ x² R(c) dx / R(1)` as an integral functional.
struct Effectiveness;

impl IntegralFunction for Effectiveness {
    fn integrand<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D]) -> D {
        rate(y[0], p[1]) / rate(D::one(), p[1]) * (3.0 * x * x)
    }
}
// ANCHOR_END: integral

// ANCHOR: misfit
/// One pellet's weighted residual `(η − η_measured)/σ`, with η from the surface flux,
/// `η = 3 c'(1) / (φ² R(1))` (equal to the volume integral by the divergence theorem), observed
/// at the single point `x = 1`.
struct EtaMisfit {
    measured: f64,
    sigma: f64,
}

impl PointFunction for EtaMisfit {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, _j: usize, _x: f64, y: &[D], p: &[D]) -> D {
        let eta = y[1] * 3.0 / (p[0] * p[0] * rate(D::one(), p[1]));
        (eta - self.measured) / self.sigma
    }
}
// ANCHOR_END: misfit

/// First-order kinetics (K = 0): `η = 3 (φ coth φ − 1) / φ²`.
pub fn eta_first_order(phi: f64) -> f64 {
    3.0 * (phi / phi.tanh() - 1.0) / (phi * phi)
}

/// A small seeded generator of standard normal numbers (xorshift64* and Box–Muller), so that
/// the example needs no random-number crate and its output is reproducible.
struct Noise(u64);

impl Noise {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let v = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        ((v >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}

/// The numbers the chapter prints (checked by `tests/catalyst_pellet.rs`).
pub struct PelletSummary {
    /// Thiele modulus reached by continuation and the η there.
    pub continued_to: (f64, f64),
    /// Accepted and rejected continuation steps.
    pub continuation_steps: (usize, usize),
    /// Largest relative error of η (integral functional) against the first-order closed form.
    pub first_order_max_rel_error: f64,
    /// Largest relative difference between η from the surface flux and from the integral.
    pub flux_vs_integral: f64,
    /// Largest relative difference between adjoint and forward dη/dp over the design grid.
    pub adjoint_vs_forward: f64,
    /// The truth (a \[1/mm\], K).
    pub truth: [f64; 2],
    /// The fitted (a \[1/mm\], K).
    pub fitted: [f64; 2],
    /// Their standard errors.
    pub standard_errors: [f64; 2],
    /// The correlation of a and K.
    pub correlation: f64,
    /// Trial steps of the fit.
    pub iterations: usize,
    /// The design's choice: the pellet radius \[mm\] to measure next.
    pub next_radius_mm: f64,
    /// That ratio at the chosen radius.
    pub next_ratio: f64,
    /// The ratio at the smallest and the largest candidate radius.
    pub ratio_at_ends: (f64, f64),
    /// Standard errors of (a, K) predicted with the chosen measurement added.
    pub standard_errors_after: [f64; 2],
}

/// Runs the example.
pub fn run() -> Result<PelletSummary, Box<dyn std::error::Error>> {
    let opts = SolveOptions::with_tol(1e-8);
    let mesh = linspace(0.0, 1.0, 11);
    let flat = Guess::constant(mesh, &[1.0, 0.0]);

    // ANCHOR: continuation
    // Small φ: the concentration is nearly 1 everywhere and a flat guess converges. Large φ:
    // a thin reaction zone under the surface, reached by continuation in φ (model parameter 0).
    let mut solver = Solver::new(&Pellet, opts.clone());
    let easy = solver.solve(&[0.5, 0.8], &flat)?;
    let path = continuation(&mut solver, &easy, 0, 30.0, &ContinuationOptions::default())?;
    let far = &path.solution;
    let eta_far = integral_value(&Pellet, far, &Effectiveness)?;
    println!(
        "continuation φ = 0.5 -> 30: {} steps accepted, {} rejected, {} nodes at the end",
        path.steps_accepted,
        path.steps_rejected,
        far.x.len()
    );
    println!(
        "  φ = 30, K = 0.8: c(0) = {:.3e}, η = {eta_far:.6}",
        far.eval(0.0)[0]
    );
    // ANCHOR_END: continuation

    // ANCHOR: first_order
    // K = 0 is first-order kinetics, whose η has a closed form.
    let phis = [0.5, 1.0, 2.0, 5.0, 10.0, 20.0];
    let mut first_order_max = 0.0f64;
    let mut flux_vs_integral = 0.0f64;
    for (&phi, sol) in phis
        .iter()
        .zip(sweep(&mut solver, &[0.5, 0.0], 0, &phis, &flat))
    {
        let sol = sol?;
        let eta = integral_value(&Pellet, &sol, &Effectiveness)?;
        let flux = 3.0 * sol.eval(1.0)[1] / (phi * phi);
        let exact = eta_first_order(phi);
        first_order_max = first_order_max.max(((eta - exact) / exact).abs());
        flux_vs_integral = flux_vs_integral.max(((flux - eta) / eta).abs());
        println!(
            "  K = 0, φ = {phi:>4}: η = {eta:.10} closed form {exact:.10} ({} nodes)",
            sol.x.len()
        );
    }
    println!(
        "first order: largest relative error of η {first_order_max:.1e}; \
         flux vs integral {flux_vs_integral:.1e}"
    );
    // ANCHOR_END: first_order

    // ANCHOR: data
    // The "laboratory": a truth the fit never sees, eight pellet sizes, 1 % noise (seeded).
    let truth = [1.5, 0.8]; // a = sqrt(k/D) [1/mm], K
    let radii_mm = [0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0];
    let relative_noise = 0.01;
    let mut noise = Noise(0x5EED_CA7A_1457);
    let mut lab = Solver::new(&Pellet, opts.clone());
    let phis_true: Vec<f64> = radii_mm.iter().map(|r| r * truth[0]).collect();
    let mut measured = Vec::new();
    for (r, sol) in radii_mm
        .iter()
        .zip(sweep(&mut lab, &[0.0, truth[1]], 0, &phis_true, &flat))
    {
        let eta = integral_value(&Pellet, &sol?, &Effectiveness)?;
        let sigma = relative_noise * eta;
        let value = eta + sigma * noise.normal();
        println!("  pellet R = {r:>4} mm: η measured {value:.5} ± {sigma:.5} (truth {eta:.5})");
        measured.push((value, sigma));
    }
    // ANCHOR_END: data

    // ANCHOR: fit
    // Fit parameters θ = (a, K); pellet j's model parameters are φ = R_j a and K.
    let start = [0.7, 0.2];
    let phis_start: Vec<f64> = radii_mm.iter().map(|r| r * start[0]).collect();
    let starts = sweep(&mut solver, &[0.0, start[1]], 0, &phis_start, &flat);
    let mut residuals = BvpResiduals::new(2);
    for ((&r, &(value, sigma)), sol) in radii_mm.iter().zip(&measured).zip(starts) {
        let map = ParamMap::new(vec![0.0, 0.0])
            .link_affine(0, 0, r, 0.0) // φ = R_j · a
            .link(1, 1); // K
        let misfit = EtaMisfit {
            measured: value,
            sigma,
        };
        let run = BvpRun::new(
            Solver::new(&Pellet, opts.clone()),
            sol?,
            vec![1.0],
            misfit,
            map,
        )?;
        residuals.push(run)?;
    }
    let bounds = FitOptions::with_bounds(vec![0.05, 0.0], vec![20.0, 20.0]);
    let result = fit(&mut residuals, &start, &bounds)?;
    let se = result
        .standard_errors()
        .ok_or("singular Jacobian at the optimum")?;
    let cov = result
        .covariance()
        .ok_or("singular Jacobian at the optimum")?;
    let correlation = cov[1] / (cov[0] * cov[3]).sqrt();
    println!("fit from a = {}, K = {}:", start[0], start[1]);
    println!(
        "  a = {:.4} ± {:.4} 1/mm (truth {}), K = {:.4} ± {:.4} (truth {}), correlation {correlation:.3}",
        result.p[0], se[0], truth[0], result.p[1], se[1], truth[1]
    );
    println!(
        "  {} trial steps, χ² = 2·cost = {:.3} for {} pellets, stopped: {}",
        result.iterations,
        2.0 * result.cost,
        radii_mm.len(),
        result.termination
    );
    // ANCHOR_END: fit

    // ANCHOR: design
    // Which pellet (0.1 to 10 mm, what the lab can make) to measure next? The prediction's
    // standard deviation s(R) = sqrt(gᵀ C g), g = dη/dθ, against the measurement noise
    // σ = 0.01 η: the size where the fitted model is least certain relative to what a
    // measurement resolves is the one a new measurement informs most (for one added point the
    // D-optimal choice: det C shrinks by the factor 1 / (1 + s²/σ²)).
    let fitted = [result.p[0], result.p[1]];
    let candidates: Vec<f64> = (0..=20).map(|i| 0.1 * 1.25f64.powi(i)).collect();
    let phis_fit: Vec<f64> = candidates.iter().map(|r| r * fitted[0]).collect();
    let mut best = (0.0, f64::NEG_INFINITY, [0.0; 2], 0.0);
    let mut ratios = Vec::new();
    let mut adjoint_vs_forward = 0.0f64;
    for (i, (&r, sol)) in candidates
        .iter()
        .zip(sweep(&mut solver, &[0.0, fitted[1]], 0, &phis_fit, &flat))
        .enumerate()
    {
        let sol: Solution = sol?;
        // dη/d(φ, K) by one adjoint solve; the forward route only to show agreement
        let (eta, d) = integral_adjoint(&Pellet, &sol, &Effectiveness)?;
        let sens = Sensitivities::compute(&Pellet, &sol)?;
        let (_, d_fwd) = integral_forward(&Pellet, &sol, &sens, &Effectiveness)?;
        for j in 0..2 {
            adjoint_vs_forward = adjoint_vs_forward.max((d[j] - d_fwd[j]).abs() / d[j].abs());
        }
        let g = [d[0] * r, d[1]]; // dη/da = dη/dφ · R, dη/dK
        let var = g[0] * g[0] * cov[0] + 2.0 * g[0] * g[1] * cov[1] + g[1] * g[1] * cov[3];
        let ratio = var.sqrt() / (relative_noise * eta);
        if ratio > best.1 {
            best = (r, ratio, g, relative_noise * eta);
        }
        ratios.push(ratio);
        if i % 4 == 0 {
            println!(
                "  R = {r:>6.3} mm (φ = {:>6.3}): η = {eta:.4}, dη/da = {:>8.4} mm, \
                 dη/dK = {:>7.4}, s/σ = {ratio:.3}",
                r * fitted[0],
                g[0],
                g[1]
            );
        }
    }
    // the standard errors after adding the chosen measurement (rank-one update of C)
    let (g, sigma) = (best.2, best.3);
    let cg = [cov[0] * g[0] + cov[1] * g[1], cov[2] * g[0] + cov[3] * g[1]];
    let denom = sigma * sigma + g[0] * cg[0] + g[1] * cg[1];
    let se_after = [
        (cov[0] - cg[0] * cg[0] / denom).sqrt(),
        (cov[3] - cg[1] * cg[1] / denom).sqrt(),
    ];
    println!(
        "measure next: R = {:.2} mm (φ = {:.2}), prediction uncertainty {:.2} times the noise; \
         with it a ± {:.4}, K ± {:.4}",
        best.0,
        best.0 * fitted[0],
        best.1,
        se_after[0],
        se_after[1]
    );
    println!("adjoint and forward dη/dp agree to {adjoint_vs_forward:.1e} (relative)");
    // ANCHOR_END: design

    Ok(PelletSummary {
        continued_to: (far.params[0], eta_far),
        continuation_steps: (path.steps_accepted, path.steps_rejected),
        first_order_max_rel_error: first_order_max,
        flux_vs_integral,
        adjoint_vs_forward,
        truth,
        fitted,
        standard_errors: [se[0], se[1]],
        correlation,
        iterations: result.iterations,
        next_radius_mm: best.0,
        next_ratio: best.1,
        ratio_at_ends: (ratios[0], ratios[ratios.len() - 1]),
        standard_errors_after: se_after,
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    run().map(|_| ())
}

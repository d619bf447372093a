//! Book, tutorial 2: exact derivatives from dual numbers, against finite differences.
//!
//! A function written once, generically over `DualNum`, is evaluated with `f64` (its value) and
//! with `Dual64` (value and exact derivative). Finite differences of the same function lose
//! digits to truncation (large step) or cancellation (small step); the dual number does not.
//! Then the same mechanism on a BVP right-hand side: the solver's Jacobian entries.
//!
//! Run with `cargo run --release --example tutorial_dual_numbers`.

// `tests/book_examples.rs` includes this file as a module and checks `run()`'s numbers, so
// either `main` or the summary's fields are unused, depending on who compiles it.
#![allow(dead_code)]

use diffbvp::{Bvp, DualNum};
use num_dual::Dual64;

// ANCHOR: generic
/// f(x) = e^x / sqrt(sin³x + cos³x), the classic test function of the complex-step literature.
fn f<D: DualNum<Primitive = f64> + Copy>(x: D) -> D {
    x.exp() / (x.sin().powi(3) + x.cos().powi(3)).sqrt()
}
// ANCHOR_END: generic

/// The derivative of `f` by hand, for comparison only.
fn f_prime_by_hand(x: f64) -> f64 {
    let (s, c) = x.sin_cos();
    let q = s.powi(3) + c.powi(3);
    f(x) * (1.0 - (3.0 * s * s * c - 3.0 * c * c * s) / (2.0 * q))
}

/// Bratu's problem y'' + k e^y = 0 as a first-order system.
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

/// The numbers the tutorial prints (checked by `tests/book_examples.rs`).
pub struct DualSummary {
    /// |f'_dual − f'_by_hand| / |f'_by_hand| at x = 1.5.
    pub dual_relative_error: f64,
    /// Smallest relative error of forward differences over h = 1e-1 … 1e-13.
    pub best_forward_difference_error: f64,
    /// Smallest relative error of central differences over the same steps.
    pub best_central_difference_error: f64,
    /// ∂f₁/∂y₀ of Bratu's right-hand side at y = (0.5, 0), from a dual number.
    pub bratu_df1_dy0: f64,
}

/// Runs the tutorial and prints its table.
pub fn run() -> DualSummary {
    let x = 1.5;
    // ANCHOR: evaluate
    let value: f64 = f(x); // plain f64: the value
    let dual = f(Dual64::from_re(x).derivative()); // seeded with dx/dx = 1
    println!("f(1.5) = {value:.15}");
    println!("dual number: f = {:.15}, f' = {:.15}", dual.re, dual.eps);
    // ANCHOR_END: evaluate
    let exact = f_prime_by_hand(x);
    let dual_relative_error = ((dual.eps - exact) / exact).abs();
    println!("by hand:                          f' = {exact:.15}");
    println!("relative error of the dual number: {dual_relative_error:.1e}\n");

    println!(
        "{:>7}  {:>16}  {:>16}",
        "h", "forward diff.", "central diff."
    );
    let mut best_forward = f64::INFINITY;
    let mut best_central = f64::INFINITY;
    for e in 1..=13 {
        let h = 10f64.powi(-e);
        let forward = (f(x + h) - f(x)) / h;
        let central = (f(x + h) - f(x - h)) / (2.0 * h);
        let (ef, ec) = (
            ((forward - exact) / exact).abs(),
            ((central - exact) / exact).abs(),
        );
        best_forward = best_forward.min(ef);
        best_central = best_central.min(ec);
        println!("{h:>7.0e}  {ef:>16.3e}  {ec:>16.3e}");
    }

    // ANCHOR: bvp
    // What the solver does with your `rhs`: seed one state with a unit derivative and read
    // one column of the Jacobian ∂f/∂y. No derivative is written by hand.
    let problem = Bratu { k: 1.0 };
    let y = [Dual64::from_re(0.5).derivative(), Dual64::from_re(0.0)];
    let mut rhs = [Dual64::from_re(0.0); 2];
    problem.rhs(0.0, &y, &[], &mut rhs);
    println!(
        "\nBratu at y = (0.5, 0): f = ({}, {:.12}), ∂f/∂y₀ = ({}, {:.12})",
        rhs[0].re, rhs[1].re, rhs[0].eps, rhs[1].eps
    );
    println!("by hand: ∂f₁/∂y₀ = −k e^y₀ = {:.12}", -(0.5f64.exp()));
    // ANCHOR_END: bvp
    DualSummary {
        dual_relative_error,
        best_forward_difference_error: best_forward,
        best_central_difference_error: best_central,
        bratu_df1_dy0: rhs[1].eps,
    }
}

fn main() {
    run();
}

#![allow(clippy::needless_range_loop)]
//! Accuracy of the collocation solver: convergence order, exact Jacobians, singularly perturbed
//! problems, per-component residual scaling.

use crate::common;
use common::*;
use diffbvp::inspect::discrete_system;
use diffbvp::mesh::linspace;
use diffbvp::{solve, Bvp, DualNum, Guess, ResidualScale, SolveOptions};

/// Observed order of the C1 solution on uniform meshes (fixed mesh, Newton to round-off):
/// the maximum error of the interpolant over many points, mesh halved four times.
#[test]
fn observed_convergence_order_is_four() {
    let theta = 1.517164599050754;
    let p = Bratu { k: 1.0 };
    let mut errors = Vec::new();
    for m in [6usize, 11, 21, 41, 81] {
        let g = Guess::constant(linspace(0.0, 1.0, m), &[0.0, 0.0]);
        let s = solve(&p, &[], &g, &SolveOptions::fixed_mesh()).unwrap();
        assert_eq!(s.nodes(), m);
        let err = (0..=997)
            .map(|j| {
                let x = j as f64 / 997.0;
                (s.eval(x)[0] - bratu_exact(theta, x)).abs()
            })
            .fold(0.0f64, f64::max);
        errors.push(err);
    }
    let orders: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    let last = *orders.last().unwrap();
    assert!(
        (last - 4.0).abs() < 0.3,
        "errors {errors:?} orders {orders:?}"
    );
    // the whole sequence is in the asymptotic range
    for o in &orders[1..] {
        assert!((o - 4.0).abs() < 0.3, "errors {errors:?} orders {orders:?}");
    }
}

/// The analytic 2×4 block of scipy's test_compute_global_jac (y'' = -p² y, p = 3 unknown,
/// 5 nodes on [0, 1], y = (sin πx, π cos πx)).
#[test]
fn jacobian_blocks_match_scipy_analytic_formulas() {
    let pi = std::f64::consts::PI;
    let x = linspace(0.0, 1.0, 5);
    let g = Guess::from_fn(x.clone(), 2, |x, y| {
        y[0] = (pi * x).sin();
        y[1] = pi * (pi * x).cos();
    })
    .with_unknowns(&[3.0]);
    let sys = discrete_system(&SturmLiouville, &[], &g).unwrap();
    let size = sys.size;
    assert_eq!(size, 11);
    let p: f64 = 3.0;
    for i in 0..4 {
        let h = x[i + 1] - x[i];
        let (y1i, y2i) = (g.y[2 * i], g.y[2 * i + 1]);
        let (y1j, y2j) = (g.y[2 * i + 2], g.y[2 * i + 3]);
        let a = h * h * p * p / 12.0;
        let expected = [
            [
                a - 1.0,
                -h / 2.0,
                1.0 - a,
                -h / 2.0,
                p * h * h / 6.0 * (y1i - y1j),
            ],
            [
                h * p * p / 2.0,
                a - 1.0,
                h * p * p / 2.0,
                1.0 - a,
                p * (h * (y1i + y1j) + h * h / 6.0 * (y2i - y2j)),
            ],
        ];
        for r in 0..2 {
            let row = 2 * i + r;
            let cols = [2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3, 10];
            for (e, &c) in expected[r].iter().zip(&cols) {
                let got = sys.jacobian[row * size + c];
                assert!(
                    (got - e).abs() <= 1e-10 * e.abs().max(1.0),
                    "row {row} col {c}: {got} vs {e}"
                );
            }
        }
    }
}

/// The dual-number Jacobian of the global system agrees with central finite differences,
/// for states, unknowns and model parameters, on a nonlinear problem with parameters in f and g.
#[test]
fn dual_jacobian_matches_finite_differences() {
    struct Nl;
    impl Bvp for Nl {
        fn dim(&self) -> usize {
            3
        }
        fn num_unknowns(&self) -> usize {
            1
        }
        fn num_params(&self) -> usize {
            2
        }
        fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D], f: &mut [D]) {
            f[0] = y[1] * p[0];
            f[1] = (y[0] * p[1]).sin() + y[2] * y[2] * x;
            f[2] = (y[0] - y[1]).exp() * p[2] - p[0].powi(2);
        }
        fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
            r[0] = ya[0] - p[1];
            r[1] = yb[0] * yb[1] - 1.0;
            r[2] = ya[2] + p[0] * p[2];
            r[3] = yb[2] - ya[1] * p[0];
        }
    }
    let x = vec![0.0, 0.2, 0.5, 0.6, 1.0];
    let g = Guess::from_fn(x, 3, |x, y| {
        y[0] = 0.3 + x;
        y[1] = (2.0 * x).cos();
        y[2] = 0.1 * x * x - 0.2;
    })
    .with_unknowns(&[0.7]);
    let params = [1.3, 0.4];
    let base = discrete_system(&Nl, &params, &g).unwrap();
    let size = base.size;
    let h = 1e-6;
    let mut max_err: f64 = 0.0;
    for c in 0..size {
        let mut gp = g.clone();
        let mut gm = g.clone();
        if c < gp.y.len() {
            gp.y[c] += h;
            gm.y[c] -= h;
        } else {
            gp.unknowns[c - g.y.len()] += h;
            gm.unknowns[c - g.y.len()] -= h;
        }
        let rp = discrete_system(&Nl, &params, &gp).unwrap().residual;
        let rm = discrete_system(&Nl, &params, &gm).unwrap().residual;
        for r in 0..size {
            let fd = (rp[r] - rm[r]) / (2.0 * h);
            max_err = max_err.max((fd - base.jacobian[r * size + c]).abs() / (1.0 + fd.abs()));
        }
    }
    for j in 0..2 {
        let mut pp = params;
        let mut pm = params;
        pp[j] += h;
        pm[j] -= h;
        let rp = discrete_system(&Nl, &pp, &g).unwrap().residual;
        let rm = discrete_system(&Nl, &pm, &g).unwrap().residual;
        for r in 0..size {
            let fd = (rp[r] - rm[r]) / (2.0 * h);
            max_err = max_err.max((fd - base.param_jacobian[r * 2 + j]).abs() / (1.0 + fd.abs()));
        }
    }
    assert!(max_err < 1e-8, "max relative deviation {max_err:e}");
}

/// ε y'' = y, y(0) = 1, y(1) = 0: boundary layer at x = 0 (Cash-type, ε = 1e-4).
struct LayerLeft {
    eps: f64,
}
impl Bvp for LayerLeft {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = y[0] / self.eps;
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0] - 1.0;
        r[1] = yb[0];
    }
}

/// ε y'' + y' - (1 + ε) y = 0 on [-1, 1] (Cash problem 4): exact e^{x-1} + e^{-(1+ε)(1+x)/ε}.
struct Cash4 {
    eps: f64,
}
impl Bvp for Cash4 {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = (y[0] * (1.0 + self.eps) - y[1]) / self.eps;
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        let e = self.eps;
        r[0] = ya[0] - (1.0 + (-2.0f64).exp());
        r[1] = yb[0] - (1.0 + (-2.0 * (1.0 + e) / e).exp());
    }
}

/// Troesch's problem y'' = μ sinh(μ y), y(0) = 0, y(1) = 1 (nonlinear layer at x = 1).
pub struct Troesch {
    pub mu: f64,
}
impl Bvp for Troesch {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = (y[0] * self.mu).sinh() * self.mu;
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0] - 1.0;
    }
}

#[test]
fn singularly_perturbed_cash_problems() {
    let tol = 1e-6;
    // layer at x = 0
    let eps = 1e-4;
    let s = solve(
        &LayerLeft { eps },
        &[],
        &Guess::constant(linspace(0.0, 1.0, 11), &[0.0, 0.0]),
        &SolveOptions::with_tol(tol),
    )
    .unwrap();
    let r = 1.0 / eps.sqrt();
    let exact = |x: f64| ((-x * r).exp() - (-(2.0 - x) * r).exp()) / (1.0 - (-2.0 * r).exp());
    let err = (0..=2000)
        .map(|j| (s.eval(j as f64 / 2000.0)[0] - exact(j as f64 / 2000.0)).abs())
        .fold(0.0, f64::max);
    assert!(err < 1e-5, "layer: err {err:e} on {} nodes", s.nodes());

    // Cash problem 4 at eps = 1e-3
    let eps = 1e-3;
    let s = solve(
        &Cash4 { eps },
        &[],
        &Guess::constant(linspace(-1.0, 1.0, 11), &[0.0, 0.0]),
        &SolveOptions::with_tol(tol),
    )
    .unwrap();
    let exact = |x: f64| (x - 1.0).exp() + (-(1.0 + eps) * (1.0 + x) / eps).exp();
    let err = (0..=2000)
        .map(|j| {
            let x = -1.0 + 2.0 * j as f64 / 2000.0;
            (s.eval(x)[0] - exact(x)).abs()
        })
        .fold(0.0, f64::max);
    assert!(err < 1e-5, "cash4: err {err:e} on {} nodes", s.nodes());

    // Troesch mu = 5: y'(0) = 0.04575046140 (literature value)
    let s = solve(
        &Troesch { mu: 5.0 },
        &[],
        &Guess::from_fn(linspace(0.0, 1.0, 11), 2, |x, y| {
            y[0] = x;
            y[1] = 1.0;
        }),
        &SolveOptions::with_tol(tol),
    )
    .unwrap();
    assert!(
        (s.at_node(0, 1) - 0.0457504614).abs() < 2e-7,
        "troesch y'(0) = {}",
        s.at_node(0, 1)
    );
}

/// A state of magnitude 1e4 next to one of magnitude 1: with `ResidualScale::Auto` the mesh and
/// accuracy are those of the unscaled problem, at a tight tolerance.
#[test]
fn auto_scaling_handles_states_of_very_different_magnitude() {
    struct ScaledBratu;
    impl Bvp for ScaledBratu {
        fn dim(&self) -> usize {
            2
        }
        fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
            f[0] = y[1] * 1e-4;
            f[1] = -y[0].exp() * 1e4;
        }
        fn bc<D: DualNum<Primitive = f64> + Copy>(
            &self,
            ya: &[D],
            yb: &[D],
            _p: &[D],
            r: &mut [D],
        ) {
            r[0] = ya[0];
            r[1] = yb[0];
        }
    }
    let tol = 1e-8;
    let g = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);
    let plain = solve(&Bratu { k: 1.0 }, &[], &g, &SolveOptions::with_tol(tol)).unwrap();
    let opts = SolveOptions {
        scale: ResidualScale::Auto,
        ..SolveOptions::with_tol(tol)
    };
    let scaled = solve(&ScaledBratu, &[], &g, &opts).unwrap();
    let theta = 1.517164599050754;
    for &x in &[0.1, 0.5, 0.9] {
        assert!((scaled.eval(x)[0] - bratu_exact(theta, x)).abs() < 1e-8);
    }
    assert!(
        scaled.nodes() <= 2 * plain.nodes(),
        "scaled {} nodes vs plain {}",
        scaled.nodes(),
        plain.nodes()
    );
    let explicit = SolveOptions {
        scale: ResidualScale::PerComponent(vec![1.0, 1e4]),
        ..SolveOptions::with_tol(tol)
    };
    assert!(solve(&ScaledBratu, &[], &g, &explicit).is_ok());
}

/// Node removal keeps meshes lean: a solve started on a needlessly fine mesh ends with far fewer
/// nodes and still meets the tolerance.
#[test]
fn coarsening_removes_needless_nodes() {
    let g = Guess::constant(linspace(0.0, 1.0, 801), &[0.0, 0.0]);
    let s = solve(&Bratu { k: 1.0 }, &[], &g, &SolveOptions::with_tol(1e-6)).unwrap();
    assert!(s.nodes() < 200, "{} nodes", s.nodes());
    assert!(s.stats.mesh_coarsenings > 0);
    assert!(s.rms_residuals.iter().all(|&r| r < 1e-6));
}

/// Richardson extrapolation with the toolkit's pieces: a Bratu solution on an adaptive mesh at
/// tol 1e-4, re-solved on that mesh with every interval halved (`Guess::on_halved_mesh`, fixed
/// mesh), estimates its error against the exact solution as `(y_half − y) · RICHARDSON_FACTOR`.
/// At the nodes (where Lobatto IIIA's error is a smooth function of position, `C(x) h⁴`) the
/// estimate matches the error to 0.2 % of the largest error (measured: 0.02 % on 7 nodes);
/// without the factor 16/15 it would be 6.7 % off.
#[test]
fn the_halved_mesh_estimates_the_discretisation_error() {
    let theta = 1.517164599050754;
    let p = Bratu { k: 1.0 };
    let g = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);
    let coarse = solve(&p, &[], &g, &SolveOptions::with_tol(1e-4)).unwrap();
    let half = solve(
        &p,
        &[],
        &Guess::on_halved_mesh(&coarse),
        &SolveOptions::fixed_mesh(),
    )
    .unwrap();
    assert_eq!(half.nodes(), 2 * coarse.nodes() - 1);
    let (mut worst, mut largest) = (0.0f64, 0.0f64);
    for (i, &x) in coarse.x.iter().enumerate() {
        let err = coarse.at_node(i, 0) - bratu_exact(theta, x);
        let estimate =
            (coarse.at_node(i, 0) - half.at_node(2 * i, 0)) * diffbvp::solve::RICHARDSON_FACTOR;
        worst = worst.max((estimate - err).abs());
        largest = largest.max(err.abs());
    }
    assert!(largest > 1e-12, "no error to estimate: {largest:e}");
    assert!(
        worst <= 0.002 * largest,
        "Richardson off by {worst:e} against a largest error of {largest:e} ({} nodes)",
        coarse.nodes()
    );
    eprintln!(
        "RICHARDSON | {} nodes: largest error {largest:.3e}, estimate off by {worst:.3e} ({:.2} %)",
        coarse.nodes(),
        100.0 * worst / largest
    );
}

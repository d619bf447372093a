//! Solver benchmarks at tol 1e-6 (compare with benches/peers/scipy_solve_bvp.py), and the cost
//! of forward sensitivities and adjoint gradients relative to the solve they follow.

use criterion::{criterion_group, criterion_main, Criterion};
use diffbvp::mesh::linspace;
use diffbvp::sensitivity::{adjoint_gradient, PointFunction, Sensitivities};
use diffbvp::{solve, Bvp, DualNum, Guess, SolveOptions};
use std::hint::black_box;

struct Bratu;
impl Bvp for Bratu {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = -y[0].exp();
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0];
    }
}

struct Shock;
impl Bvp for Shock {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        let (pi, eps) = (std::f64::consts::PI, 1e-3);
        f[0] = y[1];
        f[1] = (y[1] * (-x) - eps * pi * pi * (pi * x).cos() - pi * x * (pi * x).sin()) / eps;
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0] + 2.0;
        r[1] = yb[0];
    }
}

/// Coupled Troesch (4 states): y1'' = μ sinh(μ y1) + y3, y3'' = y3 - y1; μ = 5 (model
/// parameter 0) and a boundary value b (parameter 1, b = 1): y1(1) = b.
struct CoupledTroesch;
impl Bvp for CoupledTroesch {
    fn dim(&self) -> usize {
        4
    }
    fn num_params(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = (y[0] * p[0]).sinh() * p[0] + y[2];
        f[2] = y[3];
        f[3] = y[2] - y[0];
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0] - p[1];
        r[2] = ya[2];
        r[3] = yb[2];
    }
}

fn troesch_guess() -> Guess {
    Guess::from_fn(linspace(0.0, 1.0, 11), 4, |x, y| {
        y[0] = x;
        y[1] = 1.0;
        y[2] = 0.0;
        y[3] = 0.0;
    })
}

struct Observe;
impl PointFunction for Observe {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, _i: usize, _x: f64, y: &[D], _p: &[D]) -> D {
        y[0] * y[0] + y[2]
    }
}

fn solvers(c: &mut Criterion) {
    let opts = SolveOptions::with_tol(1e-6);
    let mut g = c.benchmark_group("solve_tol_1e-6");
    let bratu_guess = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);
    let s = solve(&Bratu, &[], &bratu_guess, &opts).unwrap();
    println!("bratu: {} nodes", s.nodes());
    g.bench_function("bratu_k1", |b| {
        b.iter(|| solve(&Bratu, &[], black_box(&bratu_guess), &opts).unwrap())
    });
    let shock_guess = Guess::constant(linspace(-1.0, 1.0, 5), &[0.0, 0.0]);
    let s = solve(&Shock, &[], &shock_guess, &opts).unwrap();
    println!("shock eps=1e-3: {} nodes", s.nodes());
    g.bench_function("shock_eps_1e-3", |b| {
        b.iter(|| solve(&Shock, &[], black_box(&shock_guess), &opts).unwrap())
    });
    let tg = troesch_guess();
    let s = solve(&CoupledTroesch, &[5.0, 1.0], &tg, &opts).unwrap();
    println!(
        "coupled troesch mu=5: {} nodes, y2(0) = {:.10}",
        s.nodes(),
        s.at_node(0, 1)
    );
    g.bench_function("coupled_troesch_4_states", |b| {
        b.iter(|| solve(&CoupledTroesch, &[5.0, 1.0], black_box(&tg), &opts).unwrap())
    });
    let warm = Guess::from(&s);
    g.bench_function("coupled_troesch_warm_resolve_mu_5.01", |b| {
        b.iter(|| solve(&CoupledTroesch, &[5.01, 1.0], black_box(&warm), &opts).unwrap())
    });
    g.finish();

    let mut g = c.benchmark_group("derivatives_after_solve");
    let xs: Vec<f64> = (0..20).map(|i| (i as f64 + 0.5) / 20.0).collect();
    let w = vec![1.0; xs.len()];
    g.bench_function("forward_sensitivities_2_params", |b| {
        b.iter(|| Sensitivities::compute(&CoupledTroesch, black_box(&s)).unwrap())
    });
    g.bench_function("adjoint_gradient_20_points", |b| {
        b.iter(|| adjoint_gradient(&CoupledTroesch, black_box(&s), &xs, &w, &Observe).unwrap())
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = solvers
}
criterion_main!(benches);

//! Solver benchmarks at tol 1e-6 (compare with benches/peers/scipy_solve_bvp.py), and the cost
//! of forward sensitivities and adjoint gradients relative to the solve they follow.

use criterion::{criterion_group, criterion_main, Criterion};
use diffbvp::mesh::linspace;
use diffbvp::sensitivity::{adjoint_gradient, PointFunction, Sensitivities};
use diffbvp::{solve, DualNum, Guess, SolveOptions};
use std::hint::black_box;

// the test problems of the integration tests, shared (Bratu k = 1, shock ε = 1e-3, coupled
// Troesch with model parameters (μ, b))
#[path = "../tests/common/mod.rs"]
mod common;
use common::{Bratu, CoupledTroesch, Shock};

const BRATU: Bratu = Bratu { k: 1.0 };
const SHOCK: Shock = Shock { eps: 1e-3 };

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
    let s = solve(&BRATU, &[], &bratu_guess, &opts).unwrap();
    println!("bratu: {} nodes", s.nodes());
    g.bench_function("bratu_k1", |b| {
        b.iter(|| solve(&BRATU, &[], black_box(&bratu_guess), &opts).unwrap())
    });
    let shock_guess = Guess::constant(linspace(-1.0, 1.0, 5), &[0.0, 0.0]);
    let s = solve(&SHOCK, &[], &shock_guess, &opts).unwrap();
    println!("shock eps=1e-3: {} nodes", s.nodes());
    g.bench_function("shock_eps_1e-3", |b| {
        b.iter(|| solve(&SHOCK, &[], black_box(&shock_guess), &opts).unwrap())
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

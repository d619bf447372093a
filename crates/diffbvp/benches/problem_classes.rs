//! The problem classes of issue 63 at tol 1e-6: singular problems (Emden's equation, the
//! catalyst pellet; compare with benches/peers/scipy_singular.py) and a multipoint problem
//! against the same equations on one interval with as many nodes; scipy's 60-state problem
//! with and without its declared sparsity ([`Bvp::rhs_sparsity`]).

use criterion::{criterion_group, criterion_main, Criterion};
use diffbvp::mesh::{linspace, multipoint_linspace};
use diffbvp::{solve, Bvp, DualNum, Guess, SolveOptions};
use std::hint::black_box;

#[path = "../tests/common/mod.rs"]
mod common;
use common::{Emden, Pellet, ReactingLayer, LAYER_XI};

fn singular(c: &mut Criterion) {
    let opts = SolveOptions::with_tol(1e-6);
    let mut g = c.benchmark_group("singular_tol_1e-6");
    let guess = Guess::constant(linspace(0.0, 1.0, 5), &[1.0, 0.0]);
    let s = solve(&Emden { regular_bc: true }, &[], &guess, &opts).unwrap();
    println!("emden: {} nodes", s.nodes());
    g.bench_function("emden", |b| {
        b.iter(|| solve(&Emden { regular_bc: true }, &[], black_box(&guess), &opts).unwrap())
    });
    let guess = Guess::constant(linspace(0.0, 1.0, 5), &[0.5, 0.0]);
    let s = solve(&Pellet, &[3.0], &guess, &opts).unwrap();
    println!("pellet phi=3: {} nodes", s.nodes());
    g.bench_function("pellet_phi_3", |b| {
        b.iter(|| solve(&Pellet, &[3.0], black_box(&guess), &opts).unwrap())
    });
    g.finish();
}

fn multipoint(c: &mut Criterion) {
    // the same number of nodes (2 x 101 on two regions, 202 on one interval), a fixed mesh:
    // the cost of the Newton solve itself
    let opts = SolveOptions::fixed_mesh();
    let mut g = c.benchmark_group("multipoint_202_nodes_fixed_mesh");
    let two = Guess::constant(multipoint_linspace(&[0.0, LAYER_XI, 1.0], 101), &[0.5, 0.0]);
    let one = Guess::constant(linspace(0.0, 1.0, 202), &[0.5, 0.0]);
    let mp = ReactingLayer { multipoint: true };
    let sp = ReactingLayer { multipoint: false };
    let a = solve(&mp, &[5.0], &two, &opts).unwrap();
    let b = solve(&sp, &[5.0], &one, &opts).unwrap();
    println!(
        "two regions: {} nodes, {} Newton iterations; one interval: {} nodes, {} iterations",
        a.nodes(),
        a.stats.newton_iterations,
        b.nodes(),
        b.stats.newton_iterations
    );
    g.bench_function("two_regions", |bch| {
        bch.iter(|| solve(&mp, &[5.0], black_box(&two), &opts).unwrap())
    });
    g.bench_function("one_interval", |bch| {
        bch.iter(|| solve(&sp, &[5.0], black_box(&one), &opts).unwrap())
    });
    g.finish();
}

/// scipy's big problem: 60 states in pairs `y'' = -p_j² y` with two unknown eigenvalues; its
/// sparsity declared (`sparse`) or not.
struct BigPairs {
    deps: Vec<Vec<usize>>,
    sparse: bool,
}

impl BigPairs {
    fn new(sparse: bool) -> Self {
        let n = 60;
        let deps = (0..n)
            .map(|i| {
                if i % 2 == 0 {
                    vec![i + 1]
                } else {
                    vec![i - 1, n + (i / 2) % 2]
                }
            })
            .collect();
        BigPairs { deps, sparse }
    }
}

impl Bvp for BigPairs {
    fn dim(&self) -> usize {
        60
    }
    fn num_unknowns(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        for i in (0..60).step_by(2) {
            f[i] = y[i + 1];
            f[i + 1] = -p[(i / 2) % 2].powi(2) * y[i];
        }
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        for (j, i) in (0..60).step_by(2).enumerate() {
            r[j] = ya[i];
            r[30 + j] = yb[i];
        }
        r[60] = ya[1] - p[0];
        r[61] = ya[3] - p[1];
    }
    fn rhs_sparsity(&self) -> Option<&[Vec<usize>]> {
        self.sparse.then_some(self.deps.as_slice())
    }
}

fn sparse_jacobian(c: &mut Criterion) {
    // scipy's contract (tol 1e-3, its mesh rule): the same 17 nodes either way
    let opts = SolveOptions {
        tol: 1e-3,
        coarsen: false,
        mesh: diffbvp::mesh::MeshOptions::scipy(),
        ..SolveOptions::default()
    };
    let mut guess = Guess::constant(linspace(0.0, std::f64::consts::PI, 5), &[1.0; 60]);
    guess.unknowns = vec![0.5, 0.5];
    let mut g = c.benchmark_group("big_60_states_2_unknowns");
    for sparse in [true, false] {
        let bvp = BigPairs::new(sparse);
        let s = solve(&bvp, &[], &guess, &opts).unwrap();
        println!(
            "sparsity declared {sparse}: {} nodes, {} dual evaluations",
            s.nodes(),
            s.stats.rhs_dual_evaluations
        );
        let name = if sparse { "sparsity_declared" } else { "dense" };
        g.bench_function(name, |b| {
            b.iter(|| solve(&bvp, &[], black_box(&guess), &opts).unwrap())
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = singular, multipoint, sparse_jacobian
}
criterion_main!(benches);

//! Fiber model benchmarks: cold solve (continuation from c = 0) and warm re-solve from a nearby
//! (n, κ), experiment v0p53_p2, tol 1e-6; the cold start with the simple step control (default)
//! and with the paper's Adapter.

use criterion::{criterion_group, criterion_main, Criterion};
use diffbvp::continuation::ContinuationOptions as AdapterOptions;
use rheometer::model::simulate_from;
use rheometer::model::StepControl;
use rheometer::model::{Air, Experiment, Material};
use rheometer::{
    model::simulate, model::CarreauLike, model::FiberModel, model::Physics, model::SimulateOptions,
    model::Simulator,
};
use std::hint::black_box;

fn model() -> FiberModel<CarreauLike> {
    let exp = Experiment::pmma7n_v0p53_p2();
    FiberModel::new(
        &Material::pmma7n(),
        &Air::paper(),
        &exp,
        CarreauLike::new(),
        Physics::paper(),
    )
    .expect("valid experiment")
}

fn bench(c: &mut Criterion) {
    let m = model();
    let opts = SimulateOptions::with_tol(1e-6);
    let cold = simulate(&m, &[0.8, 11.71], &opts).expect("cold solve");
    let near = simulate(&m, &[0.79, 11.70], &opts).expect("nearby solve");
    // as in a fit, where the previous iterate's sensitivities were computed: its linearisation
    // is cached and the warm re-solve starts from the tangent predictor
    let near_linearized = near.clone();
    diffbvp::sensitivity::Sensitivities::compute(&m, &near_linearized.solution)
        .expect("sensitivities");
    let warm = simulate_from(&m, &[0.8, 11.71], &near, &opts).expect("warm solve");
    eprintln!(
        "nodes: cold {} (newton its {}, rhs evals {}), warm {} (newton its {}, rhs evals {})",
        cold.nodes(),
        cold.solution.stats.newton_iterations,
        cold.solution.stats.total_rhs_evaluations(),
        warm.nodes(),
        warm.solution.stats.newton_iterations,
        warm.solution.stats.total_rhs_evaluations()
    );
    c.bench_function("fiber_cold_v0p53_p2_tol1e-6", |b| {
        b.iter(|| simulate(black_box(&m), black_box(&[0.8, 11.71]), &opts).expect("cold"))
    });
    // the mesh rule before the smooth error constants (a second full pass on this experiment)
    let mut constant = opts.clone();
    constant.smooth_cold_final = false;
    c.bench_function("fiber_cold_constant_density_v0p53_p2_tol1e-6", |b| {
        b.iter(|| simulate(black_box(&m), black_box(&[0.8, 11.71]), &constant).expect("cold"))
    });
    let mut sim = Simulator::new(&m, opts.clone());
    c.bench_function("fiber_warm_reused_simulator_v0p53_p2_tol1e-6", |b| {
        b.iter(|| sim.warm(black_box(&[0.8, 11.71]), &near).expect("warm"))
    });
    c.bench_function("fiber_cold_reused_simulator_v0p53_p2_tol1e-6", |b| {
        b.iter(|| sim.cold(black_box(&[0.8, 11.71])).expect("cold"))
    });
    let mut adapter = opts.clone();
    adapter.continuation.step_control = StepControl::Adapter(AdapterOptions::default());
    let cold_adapter = simulate(&m, &[0.8, 11.71], &adapter).expect("cold adapter solve");
    eprintln!(
        "adapter cold start: nodes {}, final solve newton its {}",
        cold_adapter.nodes(),
        cold_adapter.solution.stats.newton_iterations
    );
    c.bench_function("fiber_cold_adapter_v0p53_p2_tol1e-6", |b| {
        b.iter(|| simulate(black_box(&m), black_box(&[0.8, 11.71]), &adapter).expect("cold"))
    });
    c.bench_function("fiber_warm_v0p53_p2_tol1e-6", |b| {
        b.iter(|| {
            simulate_from(black_box(&m), black_box(&[0.8, 11.71]), &near, &opts).expect("warm")
        })
    });
    let tangent =
        simulate_from(&m, &[0.8, 11.71], &near_linearized, &opts).expect("tangent warm solve");
    eprintln!(
        "warm from the tangent predictor: nodes {}, newton its {}, rhs evals {}",
        tangent.nodes(),
        tangent.solution.stats.newton_iterations,
        tangent.solution.stats.total_rhs_evaluations()
    );
    c.bench_function("fiber_warm_tangent_v0p53_p2_tol1e-6", |b| {
        b.iter(|| {
            simulate_from(
                black_box(&m),
                black_box(&[0.8, 11.71]),
                &near_linearized,
                &opts,
            )
            .expect("warm")
        })
    });
    c.bench_function(
        "fiber_warm_tangent_reused_simulator_v0p53_p2_tol1e-6",
        |b| {
            b.iter(|| {
                sim.warm(black_box(&[0.8, 11.71]), &near_linearized)
                    .expect("warm")
            })
        },
    );
}

fn bench_rhs(c: &mut Criterion) {
    use diffbvp::Bvp;
    use num_dual::DualSVec64;
    let m = model();
    let p = m.parameters(1.0, &[0.8, 11.71]).expect("params");
    let y = [2.0, 5000.0, 0.9, 3.0];
    let mut f = [0.0; 4];
    c.bench_function("fiber_rhs_f64", |b| {
        b.iter(|| {
            m.rhs(black_box(0.3), black_box(&y), &p, &mut f);
            f[3]
        })
    });
    let yd: Vec<DualSVec64<4>> = y
        .iter()
        .enumerate()
        .map(|(i, &v)| DualSVec64::from_re(v).derivative(i))
        .collect();
    let pd: Vec<DualSVec64<4>> = p.iter().map(|&v| DualSVec64::from_re(v)).collect();
    let mut fd = [DualSVec64::<4>::from_re(0.0); 4];
    c.bench_function("fiber_rhs_dual4", |b| {
        b.iter(|| {
            m.rhs(black_box(0.3), black_box(&yd), &pd, &mut fd);
            fd[3].re
        })
    });
    // the linearisation's pass: the four states and the four parameters (c, n, kappa, take-up
    // factor) seeded at once, one 8-wide pass as `Collocation::dual_pass` makes at a solution
    let seeds = 8;
    let yd8: Vec<DualSVec64<8>> = y
        .iter()
        .enumerate()
        .map(|(i, &v)| DualSVec64::from_re(v).derivative(i))
        .collect();
    let pd8: Vec<DualSVec64<8>> = p
        .iter()
        .enumerate()
        .map(|(j, &v)| {
            let d = DualSVec64::from_re(v);
            if y.len() + j < seeds {
                d.derivative(y.len() + j)
            } else {
                d
            }
        })
        .collect();
    let mut fd8 = [DualSVec64::<8>::from_re(0.0); 4];
    c.bench_function("fiber_rhs_dual8", |b| {
        b.iter(|| {
            m.rhs(black_box(0.3), black_box(&yd8), &pd8, &mut fd8);
            fd8[3].re
        })
    });
    // the same two passes with the solver's number type (slopes always stored)
    use diffbvp::dense_dual::DenseDual64;
    let yq: Vec<DenseDual64<4>> = y
        .iter()
        .enumerate()
        .map(|(i, &v)| DenseDual64::from_re(v).derivative(i))
        .collect();
    let pq: Vec<DenseDual64<4>> = p.iter().map(|&v| DenseDual64::from_re(v)).collect();
    let mut fq = [DenseDual64::<4>::from_re(0.0); 4];
    c.bench_function("fiber_rhs_dense4", |b| {
        b.iter(|| {
            m.rhs(black_box(0.3), black_box(&yq), &pq, &mut fq);
            fq[3].re
        })
    });
    let yq8: Vec<DenseDual64<8>> = y
        .iter()
        .enumerate()
        .map(|(i, &v)| DenseDual64::from_re(v).derivative(i))
        .collect();
    let pq8: Vec<DenseDual64<8>> = p
        .iter()
        .enumerate()
        .map(|(j, &v)| {
            let d = DenseDual64::from_re(v);
            if y.len() + j < seeds {
                d.derivative(y.len() + j)
            } else {
                d
            }
        })
        .collect();
    let mut fq8 = [DenseDual64::<8>::from_re(0.0); 4];
    c.bench_function("fiber_rhs_dense8", |b| {
        b.iter(|| {
            m.rhs(black_box(0.3), black_box(&yq8), &pq8, &mut fq8);
            fq8[3].re
        })
    });
}

criterion_group!(benches, bench, bench_rhs);
criterion_main!(benches);

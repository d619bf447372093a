//! The cold start of the fiber model: both step controls (simple loop, paper's Adapter) reach
//! the same solution at `c = 1`, and the Adapter's failure names how far it got.

use diffbvp::continuation::ContinuationOptions as AdapterOptions;
use diffbvp::BvpError;
use rheometer::model::StepControl;
use rheometer::model::{Air, Experiment, Material};
use rheometer::{
    model::simulate, model::CarreauLike, model::FiberModel, model::Physics, model::SimulateOptions,
    model::Simulator, FiberError,
};

fn model() -> FiberModel<CarreauLike> {
    let exp = Experiment::pmma7n_v0p53_p2();
    FiberModel::new(
        &Material::pmma7n(),
        &Air::paper(),
        &exp,
        CarreauLike::new(),
        Physics::paper(),
    )
    .unwrap()
}

fn adapter_options(tol: f64) -> SimulateOptions {
    let mut o = SimulateOptions::with_tol(tol);
    o.continuation.step_control = StepControl::Adapter(AdapterOptions::default());
    o
}

#[test]
fn adapter_and_simple_cold_starts_agree() {
    let m = model();
    let tol = 1e-6;
    let simple = simulate(&m, &[0.8, 11.71], &SimulateOptions::with_tol(tol)).unwrap();
    let adapter = simulate(&m, &[0.8, 11.71], &adapter_options(tol)).unwrap();
    assert_eq!(
        adapter.solution.params[0], 1.0,
        "the Adapter must end at c = 1"
    );
    let l = m.experiment.spinline_length;
    let positions: Vec<f64> = (0..=20).map(|i| l * i as f64 / 20.0).collect();
    let a = simple.profiles(&m, &positions);
    let b = adapter.profiles(&m, &positions);
    for (i, (da, db)) in a.diameter.iter().zip(&b.diameter).enumerate() {
        let rel = (da - db).abs() / da;
        assert!(
            rel < 1e-4,
            "diameter at s = {} m differs by {rel:e}",
            positions[i]
        );
    }
    let (fa, fb) = (a.force[0], b.force[0]);
    assert!((fa - fb).abs() < 1e-4 * fa.abs(), "force {fa} vs {fb}");
}

#[test]
fn adapter_cold_start_reports_a_stalled_path() {
    let m = model();
    let mut o = adapter_options(1e-6);
    // a node budget of the initial mesh's 21 nodes: the path stalls before c = 1
    o.max_nodes = 21;
    o.continuation.step_control = StepControl::Adapter(AdapterOptions {
        min_step: 0.05,
        ..AdapterOptions::default()
    });
    match simulate(&m, &[0.8, 11.71], &o) {
        Err(FiberError::Solver(BvpError::ContinuationStalled {
            reached, target, ..
        })) => {
            assert!(
                reached < 1.0 && target == 1.0,
                "reached {reached}, target {target}"
            );
        }
        Err(other) => panic!("expected a stalled continuation, got {other}"),
        Ok(s) => panic!(
            "expected a failure, got a solution with {} nodes",
            s.nodes()
        ),
    }
}

/// The discretisation check's solve (`SimulateOptions::halve_start_mesh`): from a solution at
/// tol 1e-4, the same parameters on its mesh with every interval halved (2m − 1 nodes, no
/// adaptation), whose diameter moves from the start's by about 15/16 of the start's error (a
/// solve at 1e-9, 40 times the nodes, measures it): the Richardson estimate within 6 % at the
/// position of the largest error (measured: 3.8 %). Without a start there is nothing to halve: an error.
#[test]
fn the_halved_mesh_solve_measures_the_start_s_discretisation_error() {
    let m = model();
    let p = [0.8, 11.71];
    let coarse = simulate(&m, &p, &SimulateOptions::with_tol(1e-4)).unwrap();
    let exact = simulate(&m, &p, &SimulateOptions::with_tol(1e-9)).unwrap();
    let mut o = SimulateOptions::with_tol(1e-6);
    o.halve_start_mesh = true;
    let mut sim = Simulator::new(&m, o.clone());
    let half = sim
        .solve(&coarse.solution.params, Some(&coarse.solution))
        .unwrap();
    let (mc, mh) = (coarse.solution.nodes(), half.solution.nodes());
    assert_eq!(mh, 2 * mc - 1, "{mc} nodes halved gave {mh}");
    assert!(exact.solution.nodes() > 10 * mc);
    let l = m.experiment.spinline_length;
    let positions: Vec<f64> = (0..=200).map(|i| l * i as f64 / 200.0).collect();
    let (dc, dh, de) = (
        coarse.profiles(&m, &positions).diameter,
        half.profiles(&m, &positions).diameter,
        exact.profiles(&m, &positions).diameter,
    );
    let (i, err) = dc
        .iter()
        .zip(&de)
        .map(|(c, e)| c - e)
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .unwrap();
    let estimate = (dc[i] - dh[i]) * diffbvp::solve::RICHARDSON_FACTOR;
    eprintln!(
        "HALVED | {mc} -> {mh} nodes (1e-9: {}); at s = {:.3} m: error {err:.3e} m, estimate \
         {estimate:.3e} m",
        exact.solution.nodes(),
        positions[i]
    );
    assert!(err.abs() > 1e-9 * de[i], "no error to measure: {err:e}");
    assert!(
        (estimate - err).abs() <= 0.06 * err.abs(),
        "at s = {} m: error {err:e} m, Richardson estimate {estimate:e} m",
        positions[i]
    );
    // a cold start has no mesh to halve
    let cold = Simulator::new(&m, o).solve(&coarse.solution.params, None);
    assert!(
        matches!(&cold, Err(FiberError::InvalidInput(msg)) if msg.contains("halve_start_mesh")),
        "{cold:?}"
    );
}

#[test]
fn a_failed_warm_start_falls_back_to_a_cold_start_unless_told_not_to() {
    let m = model();
    let o = SimulateOptions::with_tol(1e-4);
    let good = simulate(&m, &[0.8, 11.71], &o).unwrap();
    // a start no Newton iteration can use: its states are not numbers
    let mut broken = good.solution.clone();
    broken.y.fill(f64::NAN);
    let p = m.parameters(1.0, &[0.8, 11.71]).unwrap();
    let fallback = Simulator::new(&m, o.clone())
        .solve(&p, Some(&broken))
        .expect("the cold start after the failed warm start");
    assert_eq!(
        fallback.nodes(),
        good.nodes(),
        "the fallback is the cold start"
    );
    assert_eq!(fallback.solution.y, good.solution.y);
    let no_fallback = SimulateOptions {
        cold_fallback: false,
        ..o
    };
    match Simulator::new(&m, no_fallback).solve(&p, Some(&broken)) {
        Err(FiberError::Solver(_)) => {}
        Err(other) => panic!("expected the warm start's solver error, got {other}"),
        Ok(s) => panic!("expected the warm start to fail, got {} nodes", s.nodes()),
    }
}

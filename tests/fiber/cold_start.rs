//! The cold start of the fiber model: both step controls (simple loop, paper's Adapter) reach
//! the same solution at `c = 1`, and the Adapter's failure names how far it got.

use diffbvp::continuation::ContinuationOptions as AdapterOptions;
use diffbvp::fiber::cold_start::StepControl;
use diffbvp::fiber::setup::{Air, Experiment, Material};
use diffbvp::fiber::{simulate, CarreauLike, FiberError, FiberModel, Physics, SimulateOptions};
use diffbvp::BvpError;

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

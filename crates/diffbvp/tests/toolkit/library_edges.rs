//! Library probes with hostile-but-realistic inputs: non-finite evaluation points, degenerate
//! meshes, out-of-range accessors and invalid options. Each probe asserts that nothing panics
//! (unless the panic is the documented behaviour) and that the result is the documented one or
//! an error naming the option and its value.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::{Duration, Instant};

use crate::common::BratuInK;
use diffbvp::continuation::{continuation, sweep, ContinuationOptions};
use diffbvp::least_squares::{fit, FitError, FitOptions, LeastSquaresProblem};
use diffbvp::mesh::{coarsen, linspace, refine, validate};
use diffbvp::sensitivity::{residual_jacobian, PointFunction, Sensitivities};
use diffbvp::{solve, BvpError, DualNum, Guess, Solution, SolveOptions, Solver};

fn guess() -> Guess {
    Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0])
}

fn bratu() -> Solution {
    solve(&BratuInK, &[1.0], &guess(), &SolveOptions::with_tol(1e-6)).unwrap()
}

fn invalid_input(e: BvpError) -> String {
    match e {
        BvpError::InvalidInput(m) => m,
        other => panic!("expected InvalidInput, got {other}"),
    }
}

/// The value of the end interval's cubic Hermite interpolant at `x`, computed independently.
fn end_cubic(s: &Solution, x: f64, c: usize) -> f64 {
    let m = s.nodes();
    let (x0, x1) = (s.x[m - 2], s.x[m - 1]);
    let h = x1 - x0;
    let t = (x - x0) / h;
    let (y0, y1) = (s.y[(m - 2) * s.n + c], s.y[(m - 1) * s.n + c]);
    let (f0, f1) = (s.yp[(m - 2) * s.n + c], s.yp[(m - 1) * s.n + c]);
    let h00 = 2.0 * t.powi(3) - 3.0 * t * t + 1.0;
    let h10 = t.powi(3) - 2.0 * t * t + t;
    let h01 = -2.0 * t.powi(3) + 3.0 * t * t;
    let h11 = t.powi(3) - t * t;
    h00 * y0 + h10 * h * f0 + h01 * y1 + h11 * h * f1
}

#[test]
fn eval_at_non_finite_points_gives_nan() {
    let s = bratu();
    for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let r = catch_unwind(AssertUnwindSafe(|| (s.eval(x), s.eval_derivative(x))));
        let (y, yp) = r.unwrap_or_else(|_| panic!("eval({x}) panicked"));
        assert_eq!(y.len(), 2);
        assert!(
            y.iter().chain(&yp).all(|v| v.is_nan()),
            "eval({x}): {y:?} {yp:?}"
        );
    }
}

#[test]
fn eval_into_at_nan_overwrites_both_buffers() {
    let s = bratu();
    let mut y = [1.0, 2.0];
    let mut yp = [3.0, 4.0];
    s.eval_into(f64::NAN, &mut y, &mut yp);
    assert!(y.iter().chain(&yp).all(|v| v.is_nan()), "{y:?} {yp:?}");
}

#[test]
fn interval_of_non_finite_points_is_clamped() {
    let s = bratu();
    let last = s.nodes() - 2;
    assert_eq!(s.interval(f64::NAN), 0);
    assert_eq!(s.interval(f64::NEG_INFINITY), 0);
    assert_eq!(s.interval(f64::INFINITY), last);
    assert_eq!(s.interval(-1e300), 0);
    assert_eq!(s.interval(1e300), last);
}

#[test]
fn eval_outside_the_interval_extrapolates_the_end_cubic() {
    let s = bratu();
    for x in [1.5, 3.0, 100.0] {
        let y = s.eval(x);
        assert_eq!(y.len(), 2);
        for (c, &yc) in y.iter().enumerate() {
            let want = end_cubic(&s, x, c);
            assert!(
                (yc - want).abs() <= 1e-12 * want.abs().max(1.0),
                "x = {x}, component {c}: {yc} vs {want}"
            );
        }
    }
    // continuous at b: the extrapolation starts where the interpolant ends
    let (yb, yb_plus) = (s.eval(1.0), s.eval(1.0 + 1e-12));
    assert!((yb[1] - yb_plus[1]).abs() < 1e-9, "{yb:?} {yb_plus:?}");
    // far outside: the cubic's terms overflow (documented): a non-finite result, no panic
    let near = s.eval(1e6);
    assert!(near.iter().all(|v| v.is_finite()), "{near:?}");
    let far = catch_unwind(AssertUnwindSafe(|| s.eval(1e200))).expect("no panic");
    assert!(far.iter().all(|v| !v.is_finite()), "{far:?}");
}

#[test]
fn linspace_with_zero_and_one_nodes() {
    assert_eq!(linspace(0.0, 1.0, 0), Vec::<f64>::new());
    assert_eq!(linspace(0.0, 1.0, 1), vec![0.0]);
    assert_eq!(linspace(0.0, 1.0, 2), vec![0.0, 1.0]);
    let e = validate(&linspace(0.0, 1.0, 1)).unwrap_err().to_string();
    assert!(e.contains("at least 2 nodes, got 1"), "{e}");
}

#[test]
fn refine_and_coarsen_of_degenerate_meshes_return_them_unchanged() {
    assert_eq!(refine(&[], &[]), Vec::<f64>::new());
    assert_eq!(refine(&[0.5], &[]), vec![0.5]);
    assert_eq!(coarsen(&[], &[], 0.1), Vec::<f64>::new());
    assert_eq!(coarsen(&[0.5], &[], 0.1), vec![0.5]);
}

#[test]
fn solve_on_an_empty_or_non_finite_mesh_is_an_error() {
    let e = solve(
        &BratuInK,
        &[1.0],
        &Guess::constant(linspace(0.0, 1.0, 0), &[0.0, 0.0]),
        &SolveOptions::default(),
    )
    .unwrap_err();
    let m = invalid_input(e);
    assert!(m.contains("at least 2 nodes, got 0"), "{m}");
    let mut g = guess();
    g.x[2] = f64::NAN;
    let m = invalid_input(solve(&BratuInK, &[1.0], &g, &SolveOptions::default()).unwrap_err());
    assert!(m.contains("mesh node 2 is not finite"), "{m}");
    let mut g = guess();
    g.y.pop();
    let m = invalid_input(solve(&BratuInK, &[1.0], &g, &SolveOptions::default()).unwrap_err());
    assert!(m.contains("the guess has 9 values"), "{m}");
    let m = invalid_input(
        solve(&BratuInK, &[f64::NAN], &guess(), &SolveOptions::default()).unwrap_err(),
    );
    assert!(m.contains("not finite"), "{m}");
}

#[test]
fn at_node_and_component_out_of_range() {
    let s = bratu();
    let m = s.nodes();
    assert_eq!(s.get(0, 1), Some(s.at_node(0, 1)));
    assert_eq!(s.get(m - 1, 0), Some(s.at_node(m - 1, 0)));
    assert_eq!(s.get(m, 0), None);
    assert_eq!(s.get(0, 2), None);
    assert_eq!(s.get(usize::MAX, usize::MAX), None);
    assert_eq!(s.try_component(1), Some(s.component(1)));
    assert_eq!(s.try_component(2), None);
    // the documented panics: a component index past n must not read the next node's state
    let r = catch_unwind(AssertUnwindSafe(|| s.at_node(0, 2)));
    let msg = r.unwrap_err();
    let msg = msg.downcast_ref::<String>().cloned().unwrap_or_default();
    assert!(msg.contains("component 2 out of range (2 states)"), "{msg}");
    assert!(catch_unwind(AssertUnwindSafe(|| s.component(7))).is_err());
    assert!(catch_unwind(AssertUnwindSafe(|| s.at_node(m, 0))).is_err());
}

fn continuation_error(options: ContinuationOptions) -> (String, Duration) {
    let mut solver = Solver::new(&BratuInK, SolveOptions::with_tol(1e-6));
    let start = solver.solve(&[0.5], &guess()).unwrap();
    let t0 = Instant::now();
    // the target 10 lies beyond Bratu's fold (k ≈ 3.51): a path with valid options would fail
    // after many solves, so a quick failure shows the options were refused up front
    let e = continuation(&mut solver, &start, 0, 10.0, &options).unwrap_err();
    (invalid_input(e), t0.elapsed())
}

#[test]
fn continuation_refuses_a_nan_min_step_before_solving() {
    let (m, t) = continuation_error(ContinuationOptions {
        min_step: f64::NAN,
        ..Default::default()
    });
    assert!(m.contains("min_step = NaN"), "{m}");
    assert!(t < Duration::from_millis(100), "took {t:?}");
}

#[test]
fn continuation_refuses_invalid_step_options() {
    let d = ContinuationOptions::default();
    let cases: Vec<(ContinuationOptions, &str)> = vec![
        (
            ContinuationOptions {
                initial_step: 0.0,
                ..d.clone()
            },
            "initial_step = 0",
        ),
        (
            ContinuationOptions {
                initial_step: -0.1,
                ..d.clone()
            },
            "initial_step = -0.1",
        ),
        (
            ContinuationOptions {
                max_step: f64::INFINITY,
                ..d.clone()
            },
            "max_step = inf",
        ),
        (
            ContinuationOptions {
                min_step: -1e-4,
                ..d.clone()
            },
            "min_step = -0.0001",
        ),
        (
            ContinuationOptions {
                min_step: 0.5,
                max_step: 0.1,
                ..d.clone()
            },
            "must not exceed max_step = 0.1",
        ),
        (
            ContinuationOptions {
                shrink: 1.5,
                ..d.clone()
            },
            "shrink = 1.5",
        ),
        (
            ContinuationOptions {
                enlarge: 0.5,
                ..d.clone()
            },
            "enlarge = 0.5",
        ),
        (
            ContinuationOptions {
                divergence_divisor: 1.0,
                ..d.clone()
            },
            "divergence_divisor = 1",
        ),
        (
            ContinuationOptions {
                max_steps: 0,
                ..d.clone()
            },
            "max_steps = 0",
        ),
    ];
    for (options, needle) in cases {
        let (m, t) = continuation_error(options);
        assert!(m.contains(needle), "expected {needle:?} in {m}");
        assert!(t < Duration::from_millis(100), "{needle}: took {t:?}");
    }
}

#[test]
fn solve_options_are_validated_with_names_and_values() {
    let d = SolveOptions::default();
    let cases: Vec<(SolveOptions, &str)> = vec![
        (
            SolveOptions {
                tol: f64::NAN,
                ..d.clone()
            },
            "SolveOptions::tol must be positive and finite, got NaN",
        ),
        (
            SolveOptions {
                tol: -1e-3,
                ..d.clone()
            },
            "SolveOptions::tol must be positive and finite, got -0.001",
        ),
        (
            SolveOptions {
                bc_tol: Some(f64::INFINITY),
                ..d.clone()
            },
            "SolveOptions::bc_tol",
        ),
        (
            SolveOptions {
                newton_step_tol: Some(f64::NAN),
                ..d.clone()
            },
            "SolveOptions::newton_step_tol",
        ),
        (
            SolveOptions {
                max_nodes: 1,
                ..d.clone()
            },
            "SolveOptions::max_nodes must be at least 2, got 1",
        ),
        (
            SolveOptions {
                max_mesh_iterations: 0,
                ..d.clone()
            },
            "SolveOptions::max_mesh_iterations",
        ),
        (
            SolveOptions {
                max_jacobians_per_mesh: 0,
                ..d.clone()
            },
            "SolveOptions::max_jacobians_per_mesh",
        ),
        (
            SolveOptions {
                max_newton_iterations_per_mesh: 0,
                ..d.clone()
            },
            "SolveOptions::max_newton_iterations_per_mesh",
        ),
        (
            SolveOptions {
                scale: diffbvp::ResidualScale::PerComponent(vec![1.0]),
                ..d.clone()
            },
            "PerComponent needs 2 positive finite values",
        ),
    ];
    for (options, needle) in cases {
        let m = invalid_input(solve(&BratuInK, &[1.0], &guess(), &options).unwrap_err());
        assert!(m.contains(needle), "expected {needle:?} in {m}");
        assert!(options.validate(2).is_err());
    }
    assert!(SolveOptions::default().validate(2).is_ok());
}

#[test]
fn sweep_with_an_index_out_of_range_reports_every_value() {
    let mut solver = Solver::new(&BratuInK, SolveOptions::default());
    let r = sweep(&mut solver, &[1.0], 3, &[0.1, 0.2], &guess());
    assert_eq!(r.len(), 2);
    for e in r {
        let m = invalid_input(e.unwrap_err());
        assert!(m.contains("index 3 out of range"), "{m}");
    }
}

/// The point function y_0(x).
struct FirstState;
impl PointFunction for FirstState {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, _i: usize, _x: f64, y: &[D], _p: &[D]) -> D {
        y[0]
    }
}

#[test]
fn sensitivities_at_nan_and_residual_jacobian_at_nan_points() {
    let s = bratu();
    let sens = Sensitivities::compute(&BratuInK, &s).unwrap();
    let at = catch_unwind(AssertUnwindSafe(|| sens.at(f64::NAN))).expect("no panic");
    assert!(at.iter().all(|v| v.is_nan()), "{at:?}");
    let finite = sens.at(0.5);
    assert!(finite.iter().all(|v| v.is_finite()), "{finite:?}");
    let e = residual_jacobian(&BratuInK, &s, &sens, &[0.25, f64::NAN], &FirstState).unwrap_err();
    let m = invalid_input(e);
    assert!(m.contains("evaluation point 1 is not finite"), "{m}");
    let e = diffbvp::sensitivity::adjoint_gradient(&BratuInK, &s, &[0.5], &[f64::NAN], &FirstState)
        .unwrap_err();
    assert!(invalid_input(e).contains("weight 0 is not finite"));
}

/// r(p) = p - 1 (one parameter).
struct Shift;
impl LeastSquaresProblem for Shift {
    type Error = String;
    fn num_params(&self) -> usize {
        1
    }
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
        Ok((vec![p[0] - 1.0], vec![1.0]))
    }
}

#[test]
fn fit_options_are_validated_with_names_and_values() {
    let base = FitOptions::with_bounds(vec![-10.0], vec![10.0]);
    assert!((fit(&mut Shift, &[0.0], &base).unwrap().p[0] - 1.0).abs() < 1e-8);
    let cases: Vec<(FitOptions, &str)> = vec![
        (
            FitOptions {
                gtol: f64::NAN,
                ..base.clone()
            },
            "FitOptions::gtol",
        ),
        (
            FitOptions {
                xtol: -1.0,
                ..base.clone()
            },
            "FitOptions::xtol",
        ),
        (
            FitOptions {
                initial_radius: 0.0,
                ..base.clone()
            },
            "FitOptions::initial_radius",
        ),
        (
            FitOptions {
                max_radius: f64::INFINITY,
                ..base.clone()
            },
            "FitOptions::max_radius",
        ),
        (
            FitOptions {
                lower: vec![f64::NAN],
                ..base.clone()
            },
            "parameter 0",
        ),
    ];
    for (options, needle) in cases {
        let m = fit(&mut Shift, &[0.0], &options).unwrap_err().to_string();
        assert!(m.contains(needle), "expected {needle:?} in {m}");
    }
    let m = fit(&mut Shift, &[f64::NAN], &base).unwrap_err().to_string();
    assert!(m.contains("start NaN"), "{m}");
}

#[test]
fn discrete_system_refuses_a_dense_jacobian_beyond_its_limit() {
    use diffbvp::inspect::{discrete_system, MAX_DENSE_ENTRIES};
    let small = discrete_system(&BratuInK, &[1.0], &guess()).unwrap();
    assert_eq!(small.size, 10);
    assert_eq!(small.jacobian.len(), 100);
    // 20 000 nodes x 2 states: 1.6e9 dense entries (12.8 GB) — an error, not an abort
    let big = Guess::constant(linspace(0.0, 1.0, 20_000), &[0.0, 0.0]);
    let t0 = Instant::now();
    let m = invalid_input(discrete_system(&BratuInK, &[1.0], &big).unwrap_err());
    assert!(
        m.contains("20000 nodes x 2 states") && m.contains(&MAX_DENSE_ENTRIES.to_string()),
        "{m}"
    );
    assert!(t0.elapsed() < Duration::from_secs(1));
}

/// A slowly converging problem that sets its fit's cancellation flag at its `after`-th
/// evaluation and counts its evaluations.
struct CancelAfter {
    flag: std::sync::Arc<std::sync::atomic::AtomicBool>,
    after: usize,
    evaluations: usize,
}

impl LeastSquaresProblem for CancelAfter {
    type Error = String;
    fn num_params(&self) -> usize {
        2
    }
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
        self.evaluations += 1;
        if self.evaluations == self.after {
            self.flag.store(true, std::sync::atomic::Ordering::SeqCst);
        }
        // Rosenbrock: many iterations from (-1.2, 1)
        let (x, y) = (p[0], p[1]);
        Ok((
            vec![10.0 * (y - x * x), 1.0 - x],
            vec![-20.0 * x, 10.0, -1.0, 0.0],
        ))
    }
}

#[test]
fn a_set_cancel_flag_stops_the_fit_before_its_next_evaluation() {
    let flag = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let opts = FitOptions {
        cancel: Some(flag.clone()),
        ..FitOptions::with_bounds(vec![-5.0, -5.0], vec![5.0, 5.0])
    };
    // not set: the fit runs to its optimum
    let mut free = CancelAfter {
        flag: std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false)),
        after: usize::MAX,
        evaluations: 0,
    };
    let done = fit(&mut free, &[-1.2, 1.0], &opts).unwrap();
    assert!((done.p[0] - 1.0).abs() < 1e-6 && free.evaluations > 5);
    // set during the fit: stops after that evaluation, no further one
    let mut p = CancelAfter {
        flag: flag.clone(),
        after: 3,
        evaluations: 0,
    };
    match fit(&mut p, &[-1.2, 1.0], &opts) {
        Err(FitError::Cancelled { iterations }) => assert!(iterations >= 1),
        other => panic!("expected a cancelled fit, got {other:?}"),
    }
    assert_eq!(p.evaluations, 3);
    // set before the start: no evaluation at all
    let mut q = CancelAfter {
        flag: flag.clone(),
        after: usize::MAX,
        evaluations: 0,
    };
    assert!(matches!(
        fit(&mut q, &[-1.2, 1.0], &opts),
        Err(FitError::Cancelled { iterations: 0 })
    ));
    assert_eq!(q.evaluations, 0);
}

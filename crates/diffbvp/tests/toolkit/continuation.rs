#![allow(clippy::needless_range_loop)]
//! Homotopy continuation (Adapter step control) and parameter sweeps.

use diffbvp::continuation::{continuation, sweep, ContinuationOptions};
use diffbvp::mesh::linspace;
use diffbvp::{Bvp, DualNum, Guess, SolveOptions, Solver};

/// Troesch's problem y'' = μ sinh(μ y), y(0) = 0, y(1) = 1 with μ = 1 + 9 c; c is model parameter 0.
struct TroeschFamily;
impl Bvp for TroeschFamily {
    fn dim(&self) -> usize {
        2
    }
    fn num_params(&self) -> usize {
        1
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        let mu = p[0] * 9.0 + 1.0;
        f[0] = y[1];
        f[1] = (y[0] * mu).sinh() * mu;
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0] - 1.0;
    }
}

fn trivial_guess() -> Guess {
    Guess::from_fn(linspace(0.0, 1.0, 11), 2, |x, y| {
        y[0] = x;
        y[1] = 1.0;
    })
}

#[test]
fn continuation_reaches_target_where_plain_newton_fails() {
    let opts = SolveOptions::with_tol(1e-6);
    let mut solver = Solver::new(&TroeschFamily, opts);
    // μ = 10 from the linear guess: plain solve fails
    assert!(solver.solve(&[1.0], &trivial_guess()).is_err());
    let start = solver.solve(&[0.0], &trivial_guess()).unwrap();
    let path = continuation(&mut solver, &start, 0, 1.0, &ContinuationOptions::default()).unwrap();
    assert_eq!(path.solution.params[0], 1.0);
    // Troesch μ = 10: y'(0) = 3.5833778e-4 (literature value)
    let yp0 = path.solution.at_node(0, 1);
    assert!((yp0 - 3.5833778e-4).abs() < 1e-8, "y'(0) = {yp0:e}");
    assert!(path.steps_accepted >= 2);
    assert!(path.total_rhs_evaluations > 0);

    // The Adapter's step-size history: initial step 0.1; after an accepted step the next step is
    // 3/2 or 2/3 of it depending on whether the two half steps cost more than the full step; after
    // a rejected step it is halved; the path is monotone and ends exactly at the target.
    let h = &path.history;
    assert!((h[0].step - 0.1).abs() < 1e-15);
    let mut c = 0.0;
    for r in h {
        assert_eq!(r.from, c);
        if r.accepted {
            match (r.cost_full, r.cost_halves) {
                (Some(full), Some(halves)) => {
                    let factor = if halves > full { 1.5 } else { 2.0 / 3.0 };
                    assert!(
                        (r.next_step - (r.step.abs() * factor).min(1.0)).abs() < 1e-12,
                        "{r:?}"
                    );
                    assert_eq!(r.reached, r.from + r.step);
                }
                _ => assert!(r.next_step < r.step.abs(), "{r:?}"),
            }
            assert!(r.reached > r.from);
        } else {
            assert!((r.next_step - r.step.abs() / 2.0).abs() < 1e-15, "{r:?}");
            assert_eq!(r.reached, r.from);
        }
        c = r.reached;
    }
    assert_eq!(c, 1.0);
    assert_eq!(path.steps_accepted + path.steps_rejected, h.len());
}

/// y' = y^2 with y(0) = 1 + c: blows up before x = 1 once 1 + c >= 1.
struct Blowup;
impl Bvp for Blowup {
    fn dim(&self) -> usize {
        1
    }
    fn num_params(&self) -> usize {
        1
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        f[0] = y[0] * y[0];
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], _yb: &[D], p: &[D], r: &mut [D]) {
        r[0] = ya[0] - (p[0] + 1.0);
    }
}

/// A solver for [`Blowup`] (tol 1e-4, at most 2000 nodes) and its solution at c = -0.5.
fn blowup_start() -> (Solver<'static, Blowup>, diffbvp::Solution) {
    let opts = SolveOptions {
        max_nodes: 2000,
        ..SolveOptions::with_tol(1e-4)
    };
    let mut solver = Solver::new(&Blowup, opts);
    let g = Guess::from_fn(linspace(0.0, 1.0, 11), 1, |x, y| {
        y[0] = 0.5 / (1.0 - 0.5 * x)
    });
    let start = solver.solve(&[-0.5], &g).unwrap();
    (solver, start)
}

#[test]
fn continuation_stops_with_the_parameter_reached() {
    // from c = -0.5 upwards
    let (mut solver, start) = blowup_start();
    let err =
        continuation(&mut solver, &start, 0, 0.5, &ContinuationOptions::default()).unwrap_err();
    assert_stalled_before_blowup(err);
}

/// The path from c = -0.5 towards 0.5 stalls between -0.5 and 0.
fn assert_stalled_before_blowup(err: diffbvp::BvpError) {
    match err {
        diffbvp::BvpError::ContinuationStalled {
            reached, target, ..
        } => {
            // the solution exists only for c < 0 (blow-up at x = 1/(1 + c))
            assert!(reached <= 1e-9 && reached > -0.5, "reached {reached}");
            assert_eq!(target, 0.5);
        }
        other => panic!("expected ContinuationStalled, got {other}"),
    }
}

#[test]
fn sweep_warm_starts_each_value() {
    let mut solver = Solver::new(&TroeschFamily, SolveOptions::with_tol(1e-6));
    let values: Vec<f64> = (0..=10).map(|i| i as f64 * 0.05).collect();
    let results = sweep(&mut solver, &[0.0], 0, &values, &trivial_guess());
    assert_eq!(results.len(), values.len());
    let mut last = f64::INFINITY;
    for (r, v) in results.iter().zip(&values) {
        let s = r.as_ref().unwrap();
        assert_eq!(s.params[0], *v);
        // y'(0) decreases as μ grows
        assert!(s.at_node(0, 1) < last);
        last = s.at_node(0, 1);
    }
}

#[test]
fn follow_with_simple_steps_reaches_target_with_options_per_call() {
    use diffbvp::continuation::{follow, SimpleSteps, StepControl};
    let mut solver = Solver::new(&TroeschFamily, SolveOptions::with_tol(1e-3));
    let start = solver.solve(&[0.0], &trivial_guess()).unwrap();
    // the path's solves use these options, not the solver's (which stay as they are)
    let tight = SolveOptions::with_tol(1e-6);
    let control = StepControl::Simple(SimpleSteps::default());
    let path = follow(&mut solver, &start, 0, 1.0, &control, &tight).unwrap();
    assert_eq!(solver.options.tol, 1e-3);
    assert_eq!(path.solution.params[0], 1.0);
    let yp0 = path.solution.at_node(0, 1);
    assert!((yp0 - 3.5833778e-4).abs() < 1e-8, "y'(0) = {yp0:e}");
    assert!(path.solution.stats.max_residual <= 1e-6);
    // simple step control: first step 0.25, doubled after a success, halved after a failure
    let h = &path.history;
    assert!((h[0].step - 0.25).abs() < 1e-15, "{:?}", h[0]);
    let mut c = 0.0;
    for r in h {
        assert_eq!(r.from, c);
        if r.accepted {
            assert!(r.cost_full.is_some() && r.cost_halves.is_none());
            assert_eq!(r.reached, r.from + r.step);
        } else {
            assert_eq!(r.reached, r.from);
        }
        c = r.reached;
    }
    assert_eq!(c, 1.0);
    assert_eq!(path.steps_accepted + path.steps_rejected, h.len());
    assert!(path.total_rhs_evaluations > 0);
}

#[test]
fn follow_with_adapter_matches_continuation() {
    use diffbvp::continuation::{follow, StepControl};
    let opts = SolveOptions::with_tol(1e-6);
    let mut solver = Solver::new(&TroeschFamily, opts.clone());
    let start = solver.solve(&[0.0], &trivial_guess()).unwrap();
    let a = continuation(&mut solver, &start, 0, 1.0, &ContinuationOptions::default()).unwrap();
    let control = StepControl::Adapter(ContinuationOptions::default());
    let b = follow(&mut solver, &start, 0, 1.0, &control, &opts).unwrap();
    assert_eq!(a.history, b.history);
    assert_eq!(a.solution.y, b.solution.y);
}

#[test]
fn solve_by_continuation_goes_from_a_guess_to_the_target() {
    use diffbvp::continuation::{solve_by_continuation, PathOptions, StepControl};
    let mut solver = Solver::new(&TroeschFamily, SolveOptions::with_tol(0.5));
    let opts = SolveOptions::with_tol(1e-6);
    for control in [
        StepControl::default(),
        StepControl::Adapter(ContinuationOptions::default()),
    ] {
        let path = PathOptions {
            step_control: control,
            ..PathOptions::default()
        };
        let s = solve_by_continuation(&mut solver, &[0.0], 0, 1.0, &trivial_guess(), &path, &opts)
            .unwrap();
        assert_eq!(s.params[0], 1.0);
        let yp0 = s.at_node(0, 1);
        assert!((yp0 - 3.5833778e-4).abs() < 1e-8, "y'(0) = {yp0:e}");
        // the final solve used the caller's options: factorisation kept, tolerance met
        assert!(s.stats.max_residual <= 1e-6);
        assert!(diffbvp::sensitivity::Sensitivities::compute(&TroeschFamily, &s).is_ok());
    }
    assert_eq!(solver.options.tol, 0.5);
    // the loose options of the intermediate points
    let loose = PathOptions::default().intermediate(&opts);
    assert_eq!(loose.tol, 1e-3);
    assert_eq!(loose.bc_tol, Some(1e-3));
    assert!(!loose.factor_at_solution);
    // index out of range and invalid step options are refused before any solve
    let e = solve_by_continuation(
        &mut solver,
        &[0.0],
        1,
        1.0,
        &trivial_guess(),
        &PathOptions::default(),
        &opts,
    )
    .unwrap_err();
    assert!(e.to_string().contains("index 1 out of range"), "{e}");
    let bad = PathOptions {
        step_control: StepControl::Simple(diffbvp::continuation::SimpleSteps {
            shrink: 1.0,
            ..Default::default()
        }),
        ..PathOptions::default()
    };
    let e = solve_by_continuation(&mut solver, &[0.0], 0, 1.0, &trivial_guess(), &bad, &opts)
        .unwrap_err();
    assert!(e.to_string().contains("SimpleSteps::shrink = 1"), "{e}");
}

#[test]
fn simple_steps_stop_with_the_parameter_reached() {
    use diffbvp::continuation::{follow, SimpleSteps, StepControl};
    let (mut solver, start) = blowup_start();
    let opts = solver.options.clone();
    let control = StepControl::Simple(SimpleSteps {
        min_step: 1e-3,
        ..SimpleSteps::default()
    });
    assert_stalled_before_blowup(follow(&mut solver, &start, 0, 0.5, &control, &opts).unwrap_err());
}

/// y'' = 0, y(0) = 0, y(1) = c: the solution `y = c x` is linear in `c`.
struct Linear;
impl Bvp for Linear {
    fn dim(&self) -> usize {
        2
    }
    fn num_params(&self) -> usize {
        1
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = y[0] * 0.0;
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0] - p[0];
    }
}

#[test]
fn secant_guess_extrapolates_a_linear_family_exactly() {
    use diffbvp::continuation::secant_guess;
    let mut solver = Solver::new(&Linear, SolveOptions::with_tol(1e-8));
    let a = solver.solve(&[1.0], &trivial_guess()).unwrap();
    let b = solver
        .solve(&[0.5], &Guess::constant(linspace(0.0, 1.0, 4), &[0.0, 0.0]))
        .unwrap();
    // step from c = 1 to c = 2: t = (2 - 1) / (1 - 0.5) = 2
    let g = secant_guess(&a, &b, 2.0);
    assert_eq!(g.x, a.x);
    assert!(g.unknowns.is_empty());
    for (i, &x) in g.x.iter().enumerate() {
        assert!(
            (g.y[2 * i] - 2.0 * x).abs() < 1e-12,
            "y({x}) = {}",
            g.y[2 * i]
        );
        assert!((g.y[2 * i + 1] - 2.0).abs() < 1e-12);
    }
    let s = solver.solve(&[2.0], &g).unwrap();
    assert!((s.at_node(s.nodes() - 1, 0) - 2.0).abs() < 1e-12);
}

#[test]
fn bisect_step_halves_failed_steps_and_stops_when_asked() {
    use diffbvp::continuation::bisect_step;
    use std::cell::{Cell, RefCell};
    // a solve succeeds when the step from the last success is at most 0.3
    let last = Cell::new(0.0);
    let tried = RefCell::new(Vec::new());
    let mut solve_at = |c: f64| {
        tried.borrow_mut().push(c);
        if c - last.get() <= 0.3 {
            last.set(c);
            Ok(c)
        } else {
            Err(format!("step to {c} too large"))
        }
    };
    let never = || None::<String>;
    assert_eq!(bisect_step(0.0, 1.0, 2, &mut solve_at, &never), Ok(1.0));
    assert_eq!(*tried.borrow(), vec![1.0, 0.5, 0.25, 0.5, 1.0, 0.75, 1.0]);
    // without enough bisections the first unrecoverable error is returned
    last.set(0.0);
    tried.borrow_mut().clear();
    let e = bisect_step(0.0, 1.0, 1, &mut solve_at, &never).unwrap_err();
    assert_eq!(e, "step to 0.5 too large");
    assert_eq!(*tried.borrow(), vec![1.0, 0.5]);
    // the stop check runs before every solve
    last.set(0.0);
    tried.borrow_mut().clear();
    let calls = Cell::new(0);
    let stop = || {
        calls.set(calls.get() + 1);
        (calls.get() > 2).then(|| "stopped".to_string())
    };
    let e = bisect_step(0.0, 1.0, 3, &mut solve_at, &stop).unwrap_err();
    assert_eq!(e, "stopped");
    assert_eq!(*tried.borrow(), vec![1.0, 0.5]);
}

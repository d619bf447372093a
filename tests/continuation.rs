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

#[test]
fn continuation_stops_with_the_parameter_reached() {
    // y' = y^2 with y(0) = 1 + c: blows up before x = 1 once 1 + c >= 1; from c = -0.5 upwards
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
        fn bc<D: DualNum<Primitive = f64> + Copy>(
            &self,
            ya: &[D],
            _yb: &[D],
            p: &[D],
            r: &mut [D],
        ) {
            r[0] = ya[0] - (p[0] + 1.0);
        }
    }
    let opts = SolveOptions {
        max_nodes: 2000,
        ..SolveOptions::with_tol(1e-4)
    };
    let mut solver = Solver::new(&Blowup, opts);
    let g = Guess::from_fn(linspace(0.0, 1.0, 11), 1, |x, y| {
        y[0] = 0.5 / (1.0 - 0.5 * x)
    });
    let start = solver.solve(&[-0.5], &g).unwrap();
    let err =
        continuation(&mut solver, &start, 0, 0.5, &ContinuationOptions::default()).unwrap_err();
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

#![allow(clippy::needless_range_loop)]
//! The bounded trust-region Gauss–Newton driver on BVP parameter fits.

use diffbvp::least_squares::{
    fit, fit_observed, BvpResiduals, BvpRun, FitIteration, FitOptions, ParamMap, Termination,
};
use diffbvp::mesh::linspace;
use diffbvp::sensitivity::PointFunction;
use diffbvp::{Bvp, DualNum, Guess, SolveOptions, Solver};

/// y'' = -a e^y, y(0) = b, y(1) = 0 with model parameters (a, b).
struct BratuAB;
impl Bvp for BratuAB {
    fn dim(&self) -> usize {
        2
    }
    fn num_params(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = -p[0] * y[0].exp();
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        r[0] = ya[0] - p[1];
        r[1] = yb[0];
    }
}

/// r_j = y(x_j) - data_j
struct Misfit {
    data: Vec<f64>,
}
impl PointFunction for Misfit {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, j: usize, _x: f64, y: &[D], _p: &[D]) -> D {
        y[0] - self.data[j]
    }
}

/// The fit of (a, b) to y at 19 points: one run, model parameters = fit parameters.
type BvpFit = BvpResiduals<'static, BratuAB, Misfit>;

fn make_fit(truth: [f64; 2], start: [f64; 2]) -> BvpFit {
    let opts = SolveOptions::with_tol(1e-8);
    let mut solver = Solver::new(&BratuAB, opts);
    let g = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);
    let xs: Vec<f64> = (1..20).map(|i| i as f64 / 20.0).collect();
    let truth_sol = solver.solve(&truth, &g).unwrap();
    let data: Vec<f64> = xs.iter().map(|&x| truth_sol.eval(x)[0]).collect();
    let accepted = solver.solve(&start, &g).unwrap();
    let map = ParamMap::new(vec![0.0; 2]).link(0, 0).link(1, 1);
    let run = BvpRun::new(solver, accepted, xs, Misfit { data }, map).unwrap();
    BvpResiduals::new(2).with_run(run).unwrap()
}

#[test]
fn recovers_known_optimum() {
    let mut prob = make_fit([1.7, 0.4], [0.5, 0.0]);
    let opts = FitOptions::with_bounds(vec![0.0, -1.0], vec![3.0, 1.0]);
    let res = fit(&mut prob, &[0.5, 0.0], &opts).unwrap();
    assert!((res.p[0] - 1.7).abs() < 1e-6, "{:?}", res.p);
    assert!((res.p[1] - 0.4).abs() < 1e-6, "{:?}", res.p);
    assert!(res.cost < 1e-14);
    assert!(res.iterations < 30);
    assert_ne!(res.termination, Termination::MaxIterations);
    assert!(res.standard_errors().is_some());
}

#[test]
fn stops_at_an_active_bound() {
    // optimum a = 1.7 lies above the upper bound 1.2
    let mut prob = make_fit([1.7, 0.4], [0.5, 0.0]);
    let opts = FitOptions::with_bounds(vec![0.0, -1.0], vec![1.2, 1.0]);
    let res = fit(&mut prob, &[0.5, 0.0], &opts).unwrap();
    assert!(res.p[0] <= 1.2 && res.p[0] > 1.19, "{:?}", res.p);
    assert!(res.p.iter().zip([0.0, -1.0]).all(|(p, l)| *p >= l));
}

#[test]
fn failed_bvp_at_trial_point_is_a_rejected_step() {
    // Bratu has no solution for a beyond its turning point (≈ 3.51 at b = 0): a long first
    // Gauss–Newton step from a = 1 towards data made at a = 3.3 lands there and must be rejected.
    let mut prob = make_fit([3.3, 0.0], [1.0, 0.0]);
    let mut opts = FitOptions::with_bounds(vec![0.0, -1.0], vec![10.0, 1.0]);
    opts.initial_radius = 6.0;
    opts.max_radius = 6.0;
    let res = fit(&mut prob, &[1.0, 0.0], &opts).unwrap();
    assert!(res.failed_evaluations >= 1, "history {:?}", res.history);
    assert!(res
        .history
        .iter()
        .any(|h| h.failure.is_some() && !h.accepted));
    assert!((res.p[0] - 3.3).abs() < 1e-5, "{:?}", res.p);
}

#[test]
fn bad_start_is_an_error() {
    let mut prob = make_fit([1.7, 0.4], [0.5, 0.0]);
    let opts = FitOptions::with_bounds(vec![0.0, -1.0], vec![3.0, 1.0]);
    assert!(fit(&mut prob, &[5.0, 0.0], &opts).is_err());
    assert!(fit(&mut prob, &[0.5], &opts).is_err());
}

#[test]
fn observer_sees_every_iteration() {
    let mut prob = make_fit([1.7, 0.4], [0.5, 0.0]);
    let opts = FitOptions::with_bounds(vec![0.0, -1.0], vec![3.0, 1.0]);
    let mut seen: Vec<FitIteration> = Vec::new();
    let res = fit_observed(&mut prob, &[0.5, 0.0], &opts, &mut |it: &FitIteration| {
        seen.push(it.clone())
    })
    .unwrap();
    assert_eq!(seen.len(), res.iterations);
    assert_eq!(res.history.len(), res.iterations);
    for (k, (a, b)) in seen.iter().zip(&res.history).enumerate() {
        assert_eq!(a.iteration, k + 1);
        assert_eq!(a.p, b.p);
        assert_eq!(a.cost, b.cost);
    }
    assert_eq!(
        seen.iter().filter(|h| h.accepted).count(),
        res.accepted_steps
    );
    // the accepted costs decrease
    let costs: Vec<f64> = seen
        .iter()
        .filter(|h| h.accepted)
        .filter_map(|h| h.cost)
        .collect();
    assert!(costs.windows(2).all(|w| w[1] < w[0]), "{costs:?}");
    // the same fit without an observer
    let mut prob2 = make_fit([1.7, 0.4], [0.5, 0.0]);
    let res2 = fit(&mut prob2, &[0.5, 0.0], &opts).unwrap();
    assert_eq!(res.p, res2.p);
    assert_eq!(res.iterations, res2.iterations);
}

/// `y = a + b x` at 11 points (a linear model: one Gauss–Newton step from anywhere reaches its
/// least-squares optimum exactly).
struct Line {
    x: Vec<f64>,
    y: Vec<f64>,
}

impl diffbvp::least_squares::LeastSquaresProblem for Line {
    type Error = String;
    fn num_params(&self) -> usize {
        2
    }
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
        let r = self.x.iter().zip(&self.y).map(|(x, y)| p[0] + p[1] * x - y);
        let j = self.x.iter().flat_map(|&x| [1.0, x]);
        Ok((r.collect(), j.collect()))
    }
}

#[test]
fn the_gauss_newton_step_from_a_bound_reaches_the_unbounded_optimum() {
    let x: Vec<f64> = (0..11).map(|i| i as f64 / 10.0).collect();
    let y: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(i, x)| 2.0 + 0.5 * x + 0.01 * ((i * 7 % 5) as f64 - 2.0))
        .collect();
    // the unbounded least-squares line, by the normal equations
    let n = x.len() as f64;
    let (sx, sy) = (x.iter().sum::<f64>(), y.iter().sum::<f64>());
    let sxx: f64 = x.iter().map(|v| v * v).sum();
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
    let b = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    let a = (sy - b * sx) / n;
    // a bounded at 1.5: the fit stops there
    let opts = FitOptions::with_bounds(vec![-10.0, -10.0], vec![1.5, 10.0]);
    let mut line = Line { x, y };
    let res = fit(&mut line, &[0.0, 0.0], &opts).unwrap();
    assert!((res.p[0] - 1.5).abs() < 1e-6, "{:?}", res.p);
    let s = res.gauss_newton_step().unwrap();
    assert!(
        (res.p[0] + s[0] - a).abs() < 1e-9,
        "{} against {a}",
        res.p[0] + s[0]
    );
    assert!(
        (res.p[1] + s[1] - b).abs() < 1e-9,
        "{} against {b}",
        res.p[1] + s[1]
    );
    // under a robust loss the step of ½‖r‖² is not that fit's: none
    let robust = FitOptions {
        loss: diffbvp::least_squares::Loss::Huber,
        ..opts
    };
    let res = fit(&mut line, &[0.0, 0.0], &robust).unwrap();
    assert!(res.gauss_newton_step().is_none());
}

#![allow(clippy::needless_range_loop)]
//! Forward sensitivities and adjoint gradients against finite differences of re-solved
//! problems and against a closed form.

use diffbvp::mesh::linspace;
use diffbvp::sensitivity::{adjoint_gradient, residual_jacobian, PointFunction, Sensitivities};
use diffbvp::{solve, Bvp, DualNum, Guess, Solution, SolveOptions};

use crate::common;
use common::Oscillator;

/// y'' = p² y, y(0) = 1, y(1) = 0: y = sinh(p(1-x))/sinh(p).
struct Hyper;
impl Bvp for Hyper {
    fn dim(&self) -> usize {
        2
    }
    fn num_params(&self) -> usize {
        1
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = p[0] * p[0] * y[0];
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0] - 1.0;
        r[1] = yb[0];
    }
}

/// Bratu-type with parameters in f and g: y'' = -a e^y, y(0) = b, y(1) = a b / 2.
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
        r[1] = yb[0] - p[0] * p[1] * 0.5;
    }
}

/// g = y_0(x)^2 * p_last + y_1(x) (a functional touching states and a parameter)
struct Observe;
impl PointFunction for Observe {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, _i: usize, x: f64, y: &[D], p: &[D]) -> D {
        y[0] * y[0] * p[p.len() - 1] + y[1] * x
    }
}

fn fd_check<P: Bvp>(problem: &P, params: &[f64], guess: &Guess, xs: &[f64], rel: f64) {
    let opts = SolveOptions::fixed_mesh();
    let base = solve(problem, params, guess, &opts).unwrap();
    let sens = Sensitivities::compute(problem, &base).unwrap();
    let q = params.len();
    let n = problem.dim();
    let warm = Guess::from(&base);
    for j in 0..q {
        let h = 1e-5 * (1.0 + params[j].abs());
        let mut pp = params.to_vec();
        let mut pm = params.to_vec();
        pp[j] += h;
        pm[j] -= h;
        let sp = solve(problem, &pp, &warm, &opts).unwrap();
        let sm = solve(problem, &pm, &warm, &opts).unwrap();
        assert_eq!(sp.nodes(), base.nodes());
        let mut scale: f64 = 0.0;
        let mut max_dev: f64 = 0.0;
        for &x in xs {
            let fd: Vec<f64> = sp
                .eval(x)
                .iter()
                .zip(sm.eval(x))
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect();
            let an = sens.at(x);
            for c in 0..n {
                scale = scale.max(fd[c].abs());
                max_dev = max_dev.max((fd[c] - an[c * q + j]).abs());
            }
        }
        for (l, (a, b)) in sp.unknowns.iter().zip(&sm.unknowns).enumerate() {
            let fd = (a - b) / (2.0 * h);
            assert!(
                (fd - sens.d_unknowns[l * q + j]).abs() <= rel * fd.abs().max(1e-3),
                "unknown {l}"
            );
        }
        assert!(
            max_dev <= rel * scale,
            "param {j}: deviation {max_dev:e} vs scale {scale:e}"
        );
    }
}

fn points() -> Vec<f64> {
    (0..=40).map(|i| i as f64 / 40.0 * 0.999 + 0.0003).collect()
}

#[test]
fn forward_sensitivities_match_finite_differences_on_fixed_mesh() {
    let g = Guess::constant(linspace(0.0, 1.0, 30), &[0.0, 0.0]);
    fd_check(&BratuAB, &[1.2, 0.3], &g, &points(), 1e-7);
    let g = Guess::from_fn(linspace(0.0, 1.0, 40), 2, |x, y| {
        let pi = std::f64::consts::PI;
        y[0] = 0.5 * (pi * x).sin() / pi;
        y[1] = 0.5 * (pi * x).cos();
    })
    .with_unknowns(&[3.0]);
    fd_check(&Oscillator, &[2.0, 0.8], &g, &points(), 1e-7);
    fd_check(
        &Hyper,
        &[2.5],
        &Guess::constant(linspace(0.0, 1.0, 25), &[0.5, -1.0]),
        &points(),
        1e-7,
    );
}

#[test]
fn forward_sensitivity_matches_closed_form() {
    let p: f64 = 2.5;
    let s = solve(
        &Hyper,
        &[p],
        &Guess::constant(linspace(0.0, 1.0, 5), &[0.5, -1.0]),
        &SolveOptions::with_tol(1e-8),
    )
    .unwrap();
    let sens = Sensitivities::compute(&Hyper, &s).unwrap();
    let exact = |x: f64| {
        let (a, b) = ((p * (1.0 - x)).sinh(), p.sinh());
        ((1.0 - x) * (p * (1.0 - x)).cosh() * b - a * p.cosh()) / (b * b)
    };
    let mut max_dev: f64 = 0.0;
    for &x in &points() {
        max_dev = max_dev.max((sens.at(x)[0] - exact(x)).abs());
    }
    // discretisation error of a tol = 1e-8 solution
    assert!(max_dev < 1e-7, "max deviation {max_dev:e}");
}

fn adjoint_vs_forward(problem: &impl Bvp, sol: &Solution) {
    let xs = points();
    let w: Vec<f64> = xs.iter().map(|x| 1.0 + x).collect();
    let (value, grad) = adjoint_gradient(problem, sol, &xs, &w, &Observe).unwrap();
    let sens = Sensitivities::compute(problem, sol).unwrap();
    let (vals, jac) = residual_jacobian(problem, sol, &sens, &xs, &Observe).unwrap();
    let q = sol.params.len();
    let v2: f64 = vals.iter().zip(&w).map(|(a, b)| a * b).sum();
    assert!((value - v2).abs() <= 1e-14 * value.abs().max(1.0));
    for j in 0..q {
        let g2: f64 = (0..xs.len()).map(|i| w[i] * jac[i * q + j]).sum();
        assert!(
            (grad[j] - g2).abs() <= 1e-10 * g2.abs().max(1e-12),
            "param {j}: adjoint {} forward {}",
            grad[j],
            g2
        );
    }
}

#[test]
fn adjoint_gradient_equals_forward_gradient() {
    let s = solve(
        &BratuAB,
        &[1.2, 0.3],
        &Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]),
        &SolveOptions::with_tol(1e-6),
    )
    .unwrap();
    adjoint_vs_forward(&BratuAB, &s);
    let g = Guess::from_fn(linspace(0.0, 1.0, 9), 2, |x, y| {
        let pi = std::f64::consts::PI;
        y[0] = 0.5 * (pi * x).sin() / pi;
        y[1] = 0.5 * (pi * x).cos();
    })
    .with_unknowns(&[3.0]);
    let s = solve(&Oscillator, &[2.0, 0.8], &g, &SolveOptions::with_tol(1e-6)).unwrap();
    adjoint_vs_forward(&Oscillator, &s);
}

#[test]
fn sensitivities_with_adaptation_agree_to_discretisation_error() {
    // adaptive solves at p ± h have different meshes: agreement to the discretisation error
    let opts = SolveOptions::with_tol(1e-7);
    let g = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);
    let params = [1.2, 0.3];
    let base = solve(&BratuAB, &params, &g, &opts).unwrap();
    let sens = Sensitivities::compute(&BratuAB, &base).unwrap();
    let h = 1e-4;
    for j in 0..2 {
        let mut pp = params;
        let mut pm = params;
        pp[j] += h;
        pm[j] -= h;
        let sp = solve(&BratuAB, &pp, &g, &opts).unwrap();
        let sm = solve(&BratuAB, &pm, &g, &opts).unwrap();
        for &x in &points() {
            let fd = (sp.eval(x)[0] - sm.eval(x)[0]) / (2.0 * h);
            assert!(
                (fd - sens.at(x)[j]).abs() < 1e-4,
                "x {x} param {j}: fd {fd} vs {}",
                sens.at(x)[j]
            );
        }
    }
}

#[test]
fn factorization_solve_checks_the_right_hand_side_size() {
    let opts = SolveOptions {
        factor_at_solution: true,
        ..SolveOptions::with_tol(1e-8)
    };
    let s = solve(
        &Hyper,
        &[2.5],
        &Guess::constant(linspace(0.0, 1.0, 5), &[0.5, -1.0]),
        &opts,
    )
    .unwrap();
    let fact = s
        .factorization()
        .expect("factorisation kept at the solution");
    let size = fact.size();
    let mut short = vec![1.0; size - 1];
    assert!(matches!(
        fact.solve_in_place(&mut short, 1),
        Err(diffbvp::BvpError::InvalidInput(_))
    ));
    assert!(fact.solve_transpose_in_place(&mut short, 1).is_err());
    assert_eq!(
        short,
        vec![1.0; size - 1],
        "a rejected right-hand side is left untouched"
    );
    let mut ok = vec![1.0; 2 * size];
    fact.solve_in_place(&mut ok, 2).unwrap();
    assert!(ok.iter().all(|v| v.is_finite()));
}

/// `BratuAB` counting its right-hand-side evaluations (`f64` and dual separately).
#[derive(Default)]
struct CountingBratuAB {
    values: std::sync::atomic::AtomicUsize,
    duals: std::sync::atomic::AtomicUsize,
}
impl CountingBratuAB {
    fn counts(&self) -> (usize, usize) {
        use std::sync::atomic::Ordering::Relaxed;
        (self.values.load(Relaxed), self.duals.load(Relaxed))
    }
}
impl Bvp for CountingBratuAB {
    fn dim(&self) -> usize {
        2
    }
    fn num_params(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D], f: &mut [D]) {
        use std::sync::atomic::Ordering::Relaxed;
        if std::mem::size_of::<D>() > std::mem::size_of::<f64>() {
            self.duals.fetch_add(1, Relaxed);
        } else {
            self.values.fetch_add(1, Relaxed);
        }
        BratuAB.rhs(x, y, p, f)
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        BratuAB.bc(ya, yb, p, r)
    }
}

#[test]
fn derivatives_after_a_solve_reuse_its_linearisation() {
    let problem = CountingBratuAB::default();
    let pp = [1.0, 0.2];
    let g = Guess::constant(linspace(0.0, 1.0, 6), &[0.2, 0.0]);
    let xs = points();
    let weights = vec![1.0; xs.len()];
    // factor_at_solution: the solve leaves everything the derivatives need
    let eager_opts = SolveOptions {
        factor_at_solution: true,
        ..SolveOptions::with_tol(1e-8)
    };
    let eager = solve(&problem, &pp, &g, &eager_opts).unwrap();
    assert!(eager.factorization().is_some());
    let before = problem.counts();
    let sens_eager = Sensitivities::compute(&problem, &eager).unwrap();
    let (_, grad_eager) = adjoint_gradient(&problem, &eager, &xs, &weights, &Observe).unwrap();
    assert_eq!(problem.counts(), before, "no evaluation after the solve");

    // without it the solve pays nothing and the first request computes the linearisation
    // once: one dual pass (2 states + 2 parameters seeded at once) over nodes and midpoints,
    // no evaluation in f64; the adjoint that follows reuses it
    let opts = SolveOptions {
        factor_at_solution: false,
        ..SolveOptions::with_tol(1e-8)
    };
    let lazy = solve(&problem, &pp, &g, &opts).unwrap();
    assert!(lazy.factorization().is_none());
    assert_eq!(lazy.y, eager.y);
    let before = problem.counts();
    let sens_lazy = Sensitivities::compute(&problem, &lazy).unwrap();
    let after = problem.counts();
    assert_eq!(after.0, before.0, "no f64 evaluation");
    assert_eq!(after.1 - before.1, 2 * lazy.nodes() - 1, "one dual pass");
    assert!(lazy.factorization().is_some(), "cached in the solution");
    let copy = lazy.clone();
    let (_, grad_lazy) = adjoint_gradient(&problem, &copy, &xs, &weights, &Observe).unwrap();
    let _ = Sensitivities::compute(&problem, &lazy).unwrap();
    assert_eq!(problem.counts(), after, "the adjoint and a clone reuse it");

    for (a, b) in sens_eager.dy.iter().zip(&sens_lazy.dy) {
        assert!((a - b).abs() <= 1e-12 * (1.0 + a.abs()), "{a} vs {b}");
    }
    for (a, b) in grad_eager.iter().zip(&grad_lazy) {
        assert!((a - b).abs() <= 1e-12 * (1.0 + a.abs()), "{a} vs {b}");
    }
}

/// The tangent predictor is second-order accurate: its error at the new parameters is far below
/// the change of the solution, and an order smaller again for half the step.
#[test]
fn tangent_guess_is_a_second_order_predictor() {
    use diffbvp::sensitivity::tangent_guess;
    let opts = SolveOptions {
        mesh: diffbvp::mesh::MeshOptions::scipy(),
        ..SolveOptions::with_tol(1e-8)
    };
    let g = Guess::constant(linspace(0.0, 1.0, 6), &[0.2, 0.0]);
    let p0 = [1.0, 0.2];
    let base = solve(&BratuAB, &p0, &g, &opts).unwrap();
    let mut fixed = SolveOptions::fixed_mesh();
    fixed.tol = 1e-8;
    let errors: Vec<(f64, f64)> = [0.04, 0.02]
        .iter()
        .map(|h| {
            let p1 = [p0[0] + h, p0[1] - 0.5 * h];
            let exact = solve(&BratuAB, &p1, &Guess::from(&base), &fixed).unwrap();
            let pred = tangent_guess(&BratuAB, &base, &p1).unwrap();
            assert_eq!(pred.x, base.x);
            let change = max_diff(&exact.y, &base.y);
            let err = max_diff(&exact.y, &pred.y);
            (change, err)
        })
        .collect();
    for (change, err) in &errors {
        assert!(
            *err < 0.05 * change,
            "error {err:e} for a change of {change:e}"
        );
    }
    // halving the step divides the error by about 4
    let ratio = errors[0].1 / errors[1].1;
    assert!((3.0..5.5).contains(&ratio), "error ratio {ratio}");
    assert!(tangent_guess(&BratuAB, &base, &[1.0]).is_err());
    assert!(tangent_guess(&BratuAB, &base, &[f64::NAN, 0.2]).is_err());
}

/// `solve_near` starts with simplified Newton on the nearby solution's factorisation: the same
/// solution as an ordinary solve from the same guess (within the Newton tolerance), fewer
/// factorisations.
#[test]
fn solve_near_reuses_the_nearby_factorisation() {
    use diffbvp::sensitivity::tangent_guess;
    use diffbvp::Solver;
    let opts = SolveOptions {
        factor_at_solution: true,
        ..SolveOptions::with_tol(1e-8)
    };
    let g = Guess::constant(linspace(0.0, 1.0, 6), &[0.2, 0.0]);
    let base = solve(&BratuAB, &[1.0, 0.2], &g, &opts).unwrap();
    let p1 = [1.02, 0.19];
    let guess = tangent_guess(&BratuAB, &base, &p1).unwrap();
    let plain = Solver::new(&BratuAB, opts.clone())
        .solve(&p1, &guess)
        .unwrap();
    let near = Solver::new(&BratuAB, opts.clone())
        .solve_near(&p1, &guess, &base, &opts)
        .unwrap();
    assert_eq!(near.x, plain.x);
    assert!(
        max_diff(&near.y, &plain.y) < 1e-8,
        "{:e}",
        max_diff(&near.y, &plain.y)
    );
    assert!(near.stats.max_residual <= 1e-8);
    // one factorisation fewer (the final linearisation is counted in both)
    assert!(
        near.stats.jacobian_factorizations < plain.stats.jacobian_factorizations,
        "near {} vs plain {}",
        near.stats.jacobian_factorizations,
        plain.stats.jacobian_factorizations
    );
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

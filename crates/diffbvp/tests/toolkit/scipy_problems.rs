#![allow(clippy::needless_range_loop)]
//! scipy's own `solve_bvp` test problems (test_bvp.py), written out in
//! shared/docs/bvp-test-problems.md, plus Bratu's two branches.

use crate::common;
use common::*;
use diffbvp::mesh::linspace;
use diffbvp::{solve, Bvp, BvpError, DualNum, Guess, SolveOptions};

fn opts() -> SolveOptions {
    SolveOptions::default()
}

#[test]
fn a1_no_params_keeps_five_nodes_and_matches_exact() {
    let g = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);
    let s = solve(&Exp, &[], &g, &opts()).unwrap();
    assert_eq!(s.nodes(), 5);
    for (i, &x) in s.x.iter().enumerate() {
        assert!((s.at_node(i, 0) - exp_exact(x)).abs() <= 1e-5);
    }
    assert!(s.rms_residuals.iter().all(|&r| r < 1e-3));
    // the interpolant reproduces nodes
    for (i, &x) in s.x.iter().enumerate() {
        assert!((s.eval(x)[0] - s.at_node(i, 0)).abs() < 1e-12);
        assert!((s.eval_derivative(x)[1] - s.yp[i * 2 + 1]).abs() < 1e-10);
    }
}

#[test]
fn a2_with_unknown_parameter() {
    let pi = std::f64::consts::PI;
    let g = Guess::constant(linspace(0.0, pi, 5), &[1.0, 1.0]).with_unknowns(&[0.5]);
    let s = solve(&SturmLiouville, &[], &g, &opts()).unwrap();
    assert!((s.unknowns[0] - 1.0).abs() < 1e-4, "p = {}", s.unknowns[0]);
    assert!(s.nodes() < 10, "{} nodes", s.nodes());
    for (i, &x) in s.x.iter().enumerate() {
        assert!((s.at_node(i, 0) - x.sin()).abs() <= 1e-4 + 1e-4 * x.sin().abs());
        assert!((s.at_node(i, 1) - x.cos()).abs() <= 1e-4 + 1e-4 * x.cos().abs());
    }
}

#[test]
fn a4a_max_nodes_exceeded() {
    let g = Guess::constant(vec![0.0, 1.0], &[0.0, 0.0]);
    let o = SolveOptions {
        tol: 1e-5,
        max_nodes: 5,
        coarsen: false,
        ..opts()
    };
    match solve(&Exp, &[], &g, &o) {
        Err(BvpError::MaxNodesExceeded { max_nodes: 5, .. }) => {}
        other => panic!("expected MaxNodesExceeded, got {other:?}"),
    }
}

/// y1' = 0, y2' = 0 with y1(0) = 0, y1(1) = 1: inconsistent, singular.
struct Inconsistent;
impl Bvp for Inconsistent {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, _y: &[D], _p: &[D], f: &mut [D]) {
        f[0] = D::from(0.0);
        f[1] = D::from(0.0);
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0] - 1.0;
    }
}

#[test]
fn a4b_singular_jacobian_is_reported() {
    let g = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);
    match solve(&Inconsistent, &[], &g, &opts()) {
        Err(e @ BvpError::SingularJacobian { .. }) => {
            let msg = e.to_string();
            assert!(msg.contains("singular"), "{msg}");
        }
        other => panic!("expected SingularJacobian, got {other:?}"),
    }
}

/// 60 equations: y_{2i}' = y_{2i+1}, y_{2i+1}' = 0, y_{2i}(0) = 0, y_{2i}(1) = 1.
struct Big;
impl Bvp for Big {
    fn dim(&self) -> usize {
        60
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        for i in 0..30 {
            f[2 * i] = y[2 * i + 1];
            f[2 * i + 1] = D::from(0.0);
        }
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        for i in 0..30 {
            r[2 * i] = ya[2 * i];
            r[2 * i + 1] = yb[2 * i] - 1.0;
        }
    }
}

#[test]
fn a5_big_problem() {
    let g = Guess::constant(linspace(0.0, 1.0, 5), &[0.0; 60]);
    let s = solve(&Big, &[], &g, &opts()).unwrap();
    for (i, &x) in s.x.iter().enumerate() {
        assert!((s.at_node(i, 0) - x).abs() <= 1e-7 * x.abs() + 1e-12);
        assert!((s.at_node(i, 59) - 1.0).abs() <= 1e-7);
    }
}

/// 60 equations in 15 blocks with 2 unknown parameters (62 BCs).
struct BigWithParams;
impl Bvp for BigWithParams {
    fn dim(&self) -> usize {
        60
    }
    fn num_unknowns(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], p: &[D], f: &mut [D]) {
        for j in 0..15 {
            f[4 * j] = y[4 * j + 1];
            f[4 * j + 1] = -p[0] * p[0] * y[4 * j];
            f[4 * j + 2] = y[4 * j + 3];
            f[4 * j + 3] = -p[1] * p[1] * y[4 * j + 2];
        }
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        for j in 0..30 {
            r[j] = ya[2 * j];
            r[30 + j] = yb[2 * j];
        }
        r[60] = ya[1] - p[0];
        r[61] = ya[3] - p[1];
    }
}

#[test]
fn a6_big_problem_with_parameters() {
    let pi = std::f64::consts::PI;
    let g = Guess::constant(linspace(0.0, pi, 5), &[1.0; 60]).with_unknowns(&[0.5, 0.5]);
    let s = solve(&BigWithParams, &[], &g, &opts()).unwrap();
    assert!((s.unknowns[0] - 1.0).abs() < 1e-4);
    assert!((s.unknowns[1] - 1.0).abs() < 1e-4);
    for (i, &x) in s.x.iter().enumerate() {
        for j in 0..15 {
            for c in [4 * j, 4 * j + 2] {
                assert!((s.at_node(i, c) - x.sin()).abs() <= 1e-4 + 1e-4 * x.sin().abs());
            }
        }
    }
}

#[test]
fn a7_shock_layer() {
    let eps = 1e-3;
    let g = Guess::constant(linspace(-1.0, 1.0, 5), &[0.0, 0.0]);
    let s = solve(&Shock { eps }, &[], &g, &opts()).unwrap();
    assert!(s.nodes() < 110, "{} nodes", s.nodes());
    for (i, &x) in s.x.iter().enumerate() {
        let e = shock_exact(eps, x);
        assert!(
            (s.at_node(i, 0) - e).abs() <= 1e-5 + 1e-5 * e.abs(),
            "x={x} y={} exact={e}",
            s.at_node(i, 0)
        );
    }
}

/// φ'' = 0 on [0, 0.1] with Butler–Volmer boundary conditions.
struct ButlerVolmer;
impl Bvp for ButlerVolmer {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = D::from(0.0);
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        let (kappa, i0a, i0c, v, fc) = (1.64, 0.01, 1e-4, 0.5, 38.9);
        let ha = -ya[0];
        let hc = -yb[0] + (v - 1.0);
        let ia = ((ha * fc).exp() - (-ha * fc).exp()) * i0a;
        let ic = ((hc * fc).exp() - (-hc * fc).exp()) * i0c;
        r[0] = ia + ya[1] * kappa;
        r[1] = ic - yb[1] * kappa;
    }
}

#[test]
fn a8_nonlinear_boundary_conditions() {
    let g = Guess::constant(linspace(0.0, 0.1, 5), &[0.0, 0.0]);
    let s = solve(&ButlerVolmer, &[], &g, &opts()).unwrap();
    assert!(s.nodes() < 8);
    let (c, slope) = (-0.1342643744853716, -1.130871606066207);
    for (i, &x) in s.x.iter().enumerate() {
        let e = c + slope * x;
        assert!((s.at_node(i, 0) - e).abs() <= 1e-5 + 1e-5 * e.abs());
        assert!((s.at_node(i, 1) - slope).abs() <= 1e-5 + 1e-5 * slope.abs());
    }
}

#[test]
fn bratu_both_branches_from_two_guesses() {
    let p = Bratu { k: 1.0 };
    let x = linspace(0.0, 1.0, 5);
    let lower = solve(
        &p,
        &[],
        &Guess::constant(x.clone(), &[0.0, 0.0]),
        &SolveOptions::with_tol(1e-6),
    )
    .unwrap();
    let upper = solve(
        &p,
        &[],
        &Guess::constant(x, &[3.0, 0.0]),
        &SolveOptions::with_tol(1e-6),
    )
    .unwrap();
    assert!((lower.eval(0.5)[0] - 0.1405392144004718).abs() < 1e-6);
    assert!((lower.at_node(0, 1) - 0.5493527287752708).abs() < 1e-6);
    assert!((upper.eval(0.5)[0] - 4.09146724618926).abs() < 1e-5);
    assert!((upper.at_node(0, 1) - 10.84689901938945).abs() < 1e-4);
    for &x in &[0.1, 0.33, 0.77] {
        assert!((lower.eval(x)[0] - bratu_exact(1.517164599050754, x)).abs() < 1e-6);
        assert!((upper.eval(x)[0] - bratu_exact(10.93870277212211, x)).abs() < 1e-5);
    }
}

#[test]
fn sturm_liouville_docstring_finds_two_pi() {
    let pi = std::f64::consts::PI;
    // y'' + k^2 y = 0 on [0, 1], y(0) = y(1) = 0, y'(0) = k
    let g = Guess::from_fn(linspace(0.0, 1.0, 5), 2, |x, y| {
        y[0] = (2.0 * pi * x).sin();
        y[1] = 2.0 * pi * (2.0 * pi * x).cos();
    })
    .with_unknowns(&[6.0]);
    let s = solve(&SturmLiouville, &[], &g, &SolveOptions::with_tol(1e-6)).unwrap();
    assert!(
        (s.unknowns[0] - 2.0 * pi).abs() < 1e-5,
        "k = {}",
        s.unknowns[0]
    );
}

#[test]
fn bad_inputs_are_errors_not_panics() {
    let o = opts();
    let e = solve(
        &Exp,
        &[],
        &Guess::constant(vec![0.0, 0.5, 0.5, 1.0], &[0.0, 0.0]),
        &o,
    )
    .unwrap_err();
    assert!(matches!(e, BvpError::InvalidInput(_)), "{e}");
    let mut g = Guess::constant(linspace(0.0, 1.0, 4), &[0.0, 0.0]);
    g.y[3] = f64::NAN;
    assert!(matches!(
        solve(&Exp, &[], &g, &o),
        Err(BvpError::NonFinite { .. })
    ));
    let g = Guess::constant(linspace(0.0, 1.0, 4), &[0.0]);
    assert!(matches!(
        solve(&Exp, &[], &g, &o),
        Err(BvpError::InvalidInput(_))
    ));
    assert!(matches!(
        solve(
            &Exp,
            &[1.0],
            &Guess::constant(linspace(0.0, 1.0, 4), &[0.0, 0.0]),
            &o
        ),
        Err(BvpError::InvalidInput(_))
    ));
    let bad_tol = SolveOptions { tol: -1.0, ..o };
    assert!(matches!(
        solve(
            &Exp,
            &[],
            &Guess::constant(linspace(0.0, 1.0, 4), &[0.0, 0.0]),
            &bad_tol
        ),
        Err(BvpError::InvalidInput(_))
    ));
}

/// f = sqrt(y) at negative y is NaN: reported with component and position, not a panic.
#[test]
fn non_finite_rhs_is_reported() {
    struct Sqrt;
    impl Bvp for Sqrt {
        fn dim(&self) -> usize {
            1
        }
        fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
            f[0] = y[0].sqrt();
        }
        fn bc<D: DualNum<Primitive = f64> + Copy>(
            &self,
            ya: &[D],
            _yb: &[D],
            _p: &[D],
            r: &mut [D],
        ) {
            r[0] = ya[0] + 1.0;
        }
    }
    let g = Guess::constant(linspace(0.0, 1.0, 4), &[-1.0]);
    match solve(&Sqrt, &[], &g, &opts()) {
        Err(e @ BvpError::NonFinite { .. }) => assert!(e.to_string().contains("component 0")),
        other => panic!("expected NonFinite, got {other:?}"),
    }
}

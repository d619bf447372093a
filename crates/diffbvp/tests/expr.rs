//! The expression language (feature `expr`): values and exact derivatives of every function,
//! Python's precedence, error messages with positions, solves and sensitivities through
//! expressions, and a division by zero reported as a non-finite value.
#![cfg(feature = "expr")]

use diffbvp::expr::{ExprBvp, ExprError};
use diffbvp::mesh::linspace;
use diffbvp::sensitivity::Sensitivities;
use diffbvp::{solve, Bvp, BvpError, Guess, SolveOptions};
use num_dual::Dual64;

/// Value and derivative of a one-state right-hand side `fun[0]` at `y[0] = y0`.
fn value_and_slope(expr: &str, y0: f64) -> (f64, f64) {
    let bvp = ExprBvp::builder()
        .unknowns(&["lam"])
        .params(&["k"])
        .constant("c", 2.0)
        .build(&[expr], &["ya[0]", "yb[0] - 1"])
        .unwrap();
    let y = [Dual64::from_re(y0).derivative()];
    let p = [Dual64::from_re(0.5), Dual64::from_re(3.0)];
    let mut f = [Dual64::from_re(0.0)];
    bvp.rhs(0.25, &y, &p, &mut f);
    (f[0].re, f[0].eps)
}

#[test]
fn functions_have_exact_derivatives() {
    let y = 0.3_f64;
    let cases: &[(&str, f64, f64)] = &[
        ("exp(y[0])*k", y.exp() * 3.0, y.exp() * 3.0),
        ("log(y[0])", y.ln(), 1.0 / y),
        (
            "ln(y[0]) + sqrt(y[0])",
            y.ln() + y.sqrt(),
            1.0 / y + 0.5 / y.sqrt(),
        ),
        ("sin(y[0])*cos(y[0])", y.sin() * y.cos(), (2.0 * y).cos()),
        ("tan(y[0])", y.tan(), 1.0 / y.cos().powi(2)),
        (
            "sinh(y[0]) - cosh(y[0])",
            y.sinh() - y.cosh(),
            y.cosh() - y.sinh(),
        ),
        ("tanh(y[0])", y.tanh(), 1.0 - y.tanh().powi(2)),
        ("asin(y[0])", y.asin(), 1.0 / (1.0 - y * y).sqrt()),
        ("acos(y[0])", y.acos(), -1.0 / (1.0 - y * y).sqrt()),
        ("atan(y[0])", y.atan(), 1.0 / (1.0 + y * y)),
        ("atan2(y[0], -1)", y.atan2(-1.0), -1.0 / (1.0 + y * y)),
        ("abs(-y[0]*c)", 2.0 * y, 2.0),
        ("y[0]**3", y.powi(3), 3.0 * y * y),
        ("y[0]^2.5", y.powf(2.5), 2.5 * y.powf(1.5)),
        ("2**y[0]", 2f64.powf(y), 2f64.powf(y) * 2f64.ln()),
        ("y[0]**y[0]", y.powf(y), y.powf(y) * (y.ln() + 1.0)),
        ("-y[0]**2", -y * y, -2.0 * y),
        ("1/y[0] - x", 1.0 / y - 0.25, -1.0 / (y * y)),
        ("lam*y[0] + p[1]", 0.5 * y + 3.0, 0.5),
        ("where(y[0] < 0.5, y[0]**2, 1 - y[0])", y * y, 2.0 * y),
        ("where(y[0] >= 0.5, y[0]**2, 1 - y[0])", 1.0 - y, -1.0),
        ("min(y[0], 0.2) + max(y[0], 0.2)", 0.2 + y, 1.0),
        (
            "pi*y[0] + 1e-1",
            std::f64::consts::PI * y + 0.1,
            std::f64::consts::PI,
        ),
        ("2*3^2/c - -1", 10.0, 0.0),
    ];
    for &(expr, v, d) in cases {
        let (fv, fd) = value_and_slope(expr, y);
        assert!(
            (fv - v).abs() <= 1e-14 * (1.0 + v.abs()),
            "{expr}: value {fv} vs {v}"
        );
        assert!(
            (fd - d).abs() <= 1e-13 * (1.0 + d.abs()),
            "{expr}: derivative {fd} vs {d}"
        );
    }
}

#[test]
fn precedence_is_pythons() {
    // 2**3**2 = 2**9; -2**2 = -4; (1+2)*3 = 9; 8/4/2 = 1
    assert_eq!(value_and_slope("2**3**2", 0.0).0, 512.0);
    assert_eq!(value_and_slope("-2**2", 0.0).0, -4.0);
    assert_eq!(value_and_slope("(1+2)*3 + 8/4/2", 0.0).0, 10.0);
    assert_eq!(value_and_slope("2*-3", 0.0).0, -6.0);
}

fn error_of(rhs: &[&str], bc: &[&str]) -> ExprError {
    ExprBvp::builder()
        .params(&["k"])
        .build(rhs, bc)
        .expect_err("should not parse")
}

#[test]
fn errors_name_expression_position_and_symbol() {
    let e = error_of(&["y[1]", "-exp(y[0])*kk"], &["ya[0]", "yb[0]"]);
    assert_eq!(e.what, "fun[1]");
    assert_eq!(e.position, 11);
    assert!(e.message.contains("unknown symbol 'kk'"), "{e}");
    assert!(e.message.contains("k"), "{e}");
    let text = e.to_string();
    assert!(text.contains("fun[1] = \"-exp(y[0])*kk\""), "{text}");
    assert!(text.contains("\n               ^"), "{text}");

    let e = error_of(&["y[2]", "y[0]"], &["ya[0]", "yb[0]"]);
    assert_eq!((e.what.as_str(), e.position), ("fun[0]", 0));
    assert!(e.message.contains("index out of range: y[2]"), "{e}");

    let e = error_of(&["y[1]", "y[0]"], &["ya[0]", "y[0]"]);
    assert_eq!(e.what, "bc[1]");
    assert!(
        e.message.contains("not available in a boundary condition"),
        "{e}"
    );

    let e = error_of(&["y[1]", "y[0] +"], &["ya[0]", "yb[0]"]);
    assert_eq!((e.what.as_str(), e.position), ("fun[1]", 6));

    let e = error_of(&["y[1]", "y[0] 2"], &["ya[0]", "yb[0]"]);
    assert!(e.message.contains("unexpected '2'"), "{e}");

    let e = error_of(&["y[1]", "foo(y[0])"], &["ya[0]", "yb[0]"]);
    assert!(e.message.contains("unknown function 'foo'"), "{e}");

    let e = error_of(&["y[1]", "atan2(y[0])"], &["ya[0]", "yb[0]"]);
    assert!(e.message.contains("takes 2 arguments, got 1"), "{e}");

    let e = error_of(&["y[1]", ""], &["ya[0]", "yb[0]"]);
    assert!(e.message.contains("empty"), "{e}");

    let e = error_of(&["y[1]", "(y[0]"], &["ya[0]", "yb[0]"]);
    assert!(e.message.contains("expected ')'"), "{e}");

    let e = error_of(&["y[1]", "y[0]"], &["ya[0]"]);
    assert_eq!(e.what, "problem");
    assert!(
        e.message.contains("1 boundary conditions for 2 states"),
        "{e}"
    );

    let e = ExprBvp::builder()
        .params(&["exp"])
        .build(&["y[0]"], &["ya[0]"])
        .unwrap_err();
    assert!(e.message.contains("reserved"), "{e}");
    let e = ExprBvp::builder()
        .params(&["k"])
        .constant("k", 1.0)
        .build(&["y[0]"], &["ya[0]"])
        .unwrap_err();
    assert!(e.message.contains("given twice"), "{e}");
}

#[test]
fn bratu_and_sturm_liouville_solve() {
    let bratu = ExprBvp::builder()
        .params(&["k"])
        .build(&["y[1]", "-k*exp(y[0])"], &["ya[0]", "yb[0]"])
        .unwrap();
    let opts = SolveOptions::with_tol(1e-6);
    let g = Guess::constant(linspace(0.0, 1.0, 5), &[3.0, 0.0]);
    let s = solve(&bratu, &[1.0], &g, &opts).unwrap();
    assert!((s.eval(0.5)[0] - 4.0914672462).abs() < 1e-5);

    // y'' = -p^2 y, y(0) = y(pi) = 0, y'(0) = p: p = 1
    let sl = ExprBvp::builder()
        .unknowns(&["lam"])
        .build(
            &["y[1]", "-lam**2*y[0]"],
            &["ya[0]", "yb[0]", "ya[1] - p[0]"],
        )
        .unwrap();
    let pi = std::f64::consts::PI;
    let g = Guess::constant(linspace(0.0, pi, 5), &[1.0, 1.0]).with_unknowns(&[0.5]);
    let s = solve(&sl, &[], &g, &SolveOptions::default()).unwrap();
    assert!((s.unknowns[0] - 1.0).abs() < 1e-4, "{}", s.unknowns[0]);
}

#[test]
fn sensitivity_through_expressions_matches_closed_form() {
    // y' = -k y, y(0) = 1 (one state, one bc): y(1) = exp(-k), dy(1)/dk = -exp(-k)
    let decay = ExprBvp::builder()
        .params(&["k"])
        .build(&["-k*y[0]"], &["ya[0] - 1"])
        .unwrap();
    let s = solve(
        &decay,
        &[0.7],
        &Guess::constant(linspace(0.0, 1.0, 11), &[1.0]),
        &SolveOptions::with_tol(1e-8),
    )
    .unwrap();
    let sens = diffbvp::sensitivity::Sensitivities::compute(&decay, &s).unwrap();
    let d = sens.at(1.0)[0];
    assert!((d + (-0.7f64).exp()).abs() < 1e-6 * (-0.7f64).exp(), "{d}");
    // the adjoint gradient of G = y(1)^2 through an expression functional
    let g = ExprBvp::builder()
        .params(&["k"])
        .function(1, "y[0]**2")
        .unwrap();
    let (v, grad) = diffbvp::sensitivity::adjoint_gradient(&decay, &s, &[1.0], &[1.0], &g).unwrap();
    let e = (-1.4f64).exp();
    assert!((v - e).abs() < 1e-7 * e);
    assert!((grad[0] + 2.0 * e).abs() < 1e-6 * 2.0 * e, "{grad:?}");
}

#[test]
fn division_by_zero_is_a_non_finite_error() {
    let bad = ExprBvp::new(&["y[1]", "1/(y[0] - y[0])"], &["ya[0]", "yb[0] - 1"]).unwrap();
    let g = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);
    match solve(&bad, &[], &g, &SolveOptions::default()) {
        Err(BvpError::NonFinite { component, .. }) => assert_eq!(component, 1),
        other => panic!("expected NonFinite, got {other:?}"),
    }
}

/// The same problem without its declared sparsity: every Jacobian dense.
struct Dense<'a>(&'a ExprBvp);

impl Bvp for Dense<'_> {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn num_unknowns(&self) -> usize {
        self.0.num_unknowns()
    }
    fn num_params(&self) -> usize {
        self.0.num_params()
    }
    fn rhs<D: diffbvp::DualNum<Primitive = f64> + Copy>(
        &self,
        x: f64,
        y: &[D],
        p: &[D],
        f: &mut [D],
    ) {
        self.0.rhs(x, y, p, f)
    }
    fn bc<D: diffbvp::DualNum<Primitive = f64> + Copy>(
        &self,
        ya: &[D],
        yb: &[D],
        p: &[D],
        r: &mut [D],
    ) {
        self.0.bc(ya, yb, p, r)
    }
}

/// scipy's big problem: `n` states in pairs `y'' = -p_j² y` with two unknown eigenvalues, plus
/// a model parameter `c` in a weak coupling of the last pair (so the sparsity has a parameter
/// column shared by rows that also read states).
fn big(n: usize) -> ExprBvp {
    let fun: Vec<String> = (0..n)
        .map(|i| match i % 4 {
            0 | 2 => format!("y[{}]", i + 1),
            1 => format!("-p[0]**2*y[{}]", i - 1),
            _ if i == n - 1 => format!("-p[1]**2*y[{}] + c*sin(y[0])*0", i - 1),
            _ => format!("-p[1]**2*y[{}]", i - 1),
        })
        .collect();
    let mut bc: Vec<String> = (0..n).step_by(2).map(|i| format!("ya[{i}]")).collect();
    bc.extend((0..n).step_by(2).map(|i| format!("yb[{i}]")));
    bc.push("ya[1] - p[0]".into());
    bc.push("ya[3] - p[1]".into());
    let f: Vec<&str> = fun.iter().map(String::as_str).collect();
    let b: Vec<&str> = bc.iter().map(String::as_str).collect();
    ExprBvp::builder()
        .unknowns(&["", ""])
        .params(&["c"])
        .build(&f, &b)
        .unwrap()
}

#[test]
fn declared_sparsity_gives_the_same_solution_in_fewer_dual_passes() {
    let bvp = big(60);
    let deps = bvp.rhs_sparsity().unwrap();
    assert_eq!(deps[0], vec![1]);
    assert_eq!(deps[1], vec![0, 60]);
    assert_eq!(deps[59], vec![0, 58, 61, 62]);
    let mut guess = Guess::constant(linspace(0.0, std::f64::consts::PI, 5), &[1.0; 60]);
    guess.unknowns = vec![0.5, 0.5];
    let opts = SolveOptions::with_tol(1e-3);
    let sparse = solve(&bvp, &[0.3], &guess, &opts).unwrap();
    let dense = solve(&Dense(&bvp), &[0.3], &guess, &opts).unwrap();
    // the derivatives are the same numbers, so is every iterate
    assert_eq!(sparse.x, dense.x);
    assert_eq!(sparse.y, dense.y);
    assert_eq!(sparse.unknowns, dense.unknowns);
    assert_eq!(
        sparse.stats.newton_iterations,
        dense.stats.newton_iterations
    );
    // y'' = -p² y, y(0) = y(π) = 0, y'(0) = p: the eigenvalue p = 1 (y = sin x) for both
    assert!(
        sparse.unknowns.iter().all(|p| (p - 1.0).abs() < 1e-3),
        "{:?}",
        sparse.unknowns
    );
    // 60 state columns and 2 unknowns in 2 colours: one pass per point instead of 8
    assert!(
        sparse.stats.rhs_dual_evaluations * 4 <= dense.stats.rhs_dual_evaluations,
        "{} dual evaluations with the sparsity, {} without",
        sparse.stats.rhs_dual_evaluations,
        dense.stats.rhs_dual_evaluations
    );
    // sensitivities in the model parameter through the compressed Jacobians: as dense
    let a = Sensitivities::compute(&bvp, &sparse).unwrap();
    let b = Sensitivities::compute(&Dense(&bvp), &dense).unwrap();
    for x in [0.5, 1.5, 2.5] {
        assert_eq!(a.at(x), b.at(x), "x = {x}");
    }
}

/// A problem whose declared sparsity is out of range.
struct BadSparsity(Vec<Vec<usize>>);

impl Bvp for BadSparsity {
    fn dim(&self) -> usize {
        2
    }
    fn rhs<D: diffbvp::DualNum<Primitive = f64> + Copy>(
        &self,
        _x: f64,
        y: &[D],
        _p: &[D],
        f: &mut [D],
    ) {
        f[0] = y[1];
        f[1] = -y[0];
    }
    fn bc<D: diffbvp::DualNum<Primitive = f64> + Copy>(
        &self,
        ya: &[D],
        yb: &[D],
        _p: &[D],
        r: &mut [D],
    ) {
        r[0] = ya[0];
        r[1] = yb[0] - 1.0;
    }
    fn rhs_sparsity(&self) -> Option<&[Vec<usize>]> {
        Some(&self.0)
    }
}

#[test]
fn a_sparsity_out_of_range_is_refused_with_its_component() {
    let guess = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);
    let opts = SolveOptions::with_tol(1e-6);
    for (deps, want) in [
        (vec![vec![1], vec![2]], "component 1 lists input 2"),
        (vec![vec![1]], "lists 1 components for 2 states"),
    ] {
        match solve(&BadSparsity(deps), &[], &guess, &opts) {
            Err(BvpError::InvalidInput(m)) => assert!(m.contains(want), "{m}"),
            other => panic!("expected InvalidInput, got {other:?}"),
        }
    }
}

#[test]
fn integral_functional_through_expressions_matches_closed_form() {
    // y'' = k² y, y(0) = 1, y(1) = 0: y = sinh(k(1−x))/sinh(k); G = ∫ y dx + y'(0)² / 2
    let b = ExprBvp::builder().params(&["k"]);
    let bvp = b
        .clone()
        .build(&["y[1]", "k**2*y[0]"], &["ya[0] - 1", "yb[0]"])
        .unwrap();
    let k = 2.0f64;
    let guess = Guess::constant(linspace(0.0, 1.0, 11), &[0.5, -1.0]);
    let sol = solve(&bvp, &[k], &guess, &SolveOptions::with_tol(1e-9)).unwrap();
    let g = b.integral(2, "y[0]", Some("ya[1]**2/2")).unwrap();
    let (value, grad) = diffbvp::sensitivity::integral_adjoint(&bvp, &sol, &g).unwrap();
    // ∫ y = (cosh k − 1)/(k sinh k); y'(0) = −k coth k
    let mean = (k.cosh() - 1.0) / (k * k.sinh());
    let slope = -k / k.tanh();
    assert!(
        (value - (mean + slope * slope / 2.0)).abs() < 1e-7,
        "{value}"
    );
    let d_mean = (k * k.sinh() * k.sinh() - (k.cosh() - 1.0) * (k.sinh() + k * k.cosh()))
        / (k * k.sinh()).powi(2);
    // d/dk (k coth k)² / 2 = k coth k (coth k − k / sinh² k)
    let d_end = k / k.tanh() * (1.0 / k.tanh() - k / k.sinh().powi(2));
    let exact = d_mean + d_end;
    assert!(
        (grad[0] - exact).abs() < 1e-6 * exact.abs(),
        "{} vs {exact}",
        grad[0]
    );
    // an unknown symbol in the end-point term names its expression
    let e = b.integral(2, "y[0]", Some("y[0]")).unwrap_err();
    assert_eq!(e.what, "endpoint[0]");
}

//! The structured (almost-block-diagonal) elimination and faer's sparse LU give the same
//! solutions, sensitivities and adjoint gradients on every problem class, and `Auto` picks the
//! structured solver exactly when the boundary conditions are separated and `k <= n`.

use diffbvp::mesh::{linspace, MeshOptions};
use diffbvp::sensitivity::{adjoint_gradient, PointFunction, Sensitivities};
use diffbvp::{solve, Bvp, BvpError, DualNum, Guess, LinearSolverKind, Solution, SolveOptions};

use crate::common;
use common::{Bratu, CoupledTroesch, Oscillator, Shock};

const AGREE: f64 = 1e-12;

/// More unknowns than states (k = 2 > n = 1), one condition on the unknowns only:
/// y' = u0 + u1 x, y(0) = 0, y(1) = c, u0 = u1.
struct TwoUnknowns;
impl Bvp for TwoUnknowns {
    fn dim(&self) -> usize {
        1
    }
    fn num_unknowns(&self) -> usize {
        2
    }
    fn num_params(&self) -> usize {
        1
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, _y: &[D], p: &[D], f: &mut [D]) {
        f[0] = p[0] + p[1] * x;
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        r[0] = ya[0];
        r[1] = yb[0] - p[2];
        r[2] = p[0] - p[1];
    }
}

/// Periodic conditions (not separated): y'' = y - cos x + a sin x on [0, 2π],
/// y(0) = y(2π), y'(0) = y'(2π).
struct Periodic;
impl Bvp for Periodic {
    fn dim(&self) -> usize {
        2
    }
    fn num_params(&self) -> usize {
        1
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = y[0] - x.cos() + p[0] * x.sin();
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0] - yb[0];
        r[1] = ya[1] - yb[1];
    }
}

/// An observation touching the first and last state and the last parameter.
struct Observe;
impl PointFunction for Observe {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, _i: usize, x: f64, y: &[D], p: &[D]) -> D {
        let last = y[y.len() - 1] * x;
        match p.last() {
            Some(q) => y[0] * y[0] * *q + last,
            None => y[0] * y[0] + last,
        }
    }
}

fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(f64::MIN_POSITIVE, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

fn kind_of(s: &Solution) -> LinearSolverKind {
    s.factorization()
        .expect("factorisation kept at the solution")
        .kind()
}

/// Solutions, sensitivities and adjoint gradients of `b` agree with those of the reference `a`.
fn assert_agree<P: Bvp>(name: &str, problem: &P, a: &Solution, b: &Solution) {
    assert_eq!(a.x, b.x, "{name}: meshes differ");
    let e = rel_diff(&b.y, &a.y);
    assert!(e <= AGREE, "{name}: states differ by {e:e}");
    let e = rel_diff(&b.unknowns, &a.unknowns);
    assert!(e <= AGREE, "{name}: unknowns differ by {e:e}");
    if !a.params.is_empty() {
        let sa = Sensitivities::compute(problem, a).expect("sensitivities");
        let sb = Sensitivities::compute(problem, b).expect("sensitivities");
        let e = rel_diff(&sb.dy, &sa.dy);
        assert!(e <= AGREE, "{name}: sensitivities differ by {e:e}");
        let e = rel_diff(&sb.d_unknowns, &sa.d_unknowns);
        assert!(e <= AGREE, "{name}: unknown sensitivities differ by {e:e}");
    }
    let (x0, x1) = (a.x[0], a.x[a.x.len() - 1]);
    let xs: Vec<f64> = (0..25)
        .map(|i| x0 + (x1 - x0) * (i as f64 + 0.37) / 25.0)
        .collect();
    let w: Vec<f64> = xs.iter().map(|x| 1.0 + 0.1 * x).collect();
    let (va, ga) = adjoint_gradient(problem, a, &xs, &w, &Observe).expect("adjoint");
    let (vb, gb) = adjoint_gradient(problem, b, &xs, &w, &Observe).expect("adjoint");
    assert!(
        (va - vb).abs() <= AGREE * va.abs().max(1e-300),
        "{name}: functional"
    );
    let e = rel_diff(&gb, &ga);
    assert!(e <= AGREE, "{name}: adjoint gradients differ by {e:e}");
}

/// Solves with each solver kind and checks the agreement and which solver `Auto` chose.
fn check<P: Bvp>(
    name: &str,
    problem: &P,
    params: &[f64],
    guess: &Guess,
    base: &SolveOptions,
    auto_picks: LinearSolverKind,
) {
    let run = |kind| {
        // scipy's refinement inserts nodes at fixed fractions: the meshes of the two solvers are
        // then identical (the default equidistribution places nodes by the residual values, which
        // differ in the last digits between any two linear solvers)
        let opts = SolveOptions {
            linear_solver: kind,
            factor_at_solution: true,
            mesh: MeshOptions::scipy(),
            ..base.clone()
        };
        solve(problem, params, guess, &opts).unwrap_or_else(|e| panic!("{name} with {kind:?}: {e}"))
    };
    let sparse = run(LinearSolverKind::SparseLu);
    let structured = run(LinearSolverKind::Structured);
    let auto = run(LinearSolverKind::Auto);
    assert_eq!(kind_of(&sparse), LinearSolverKind::SparseLu, "{name}");
    assert_eq!(kind_of(&structured), LinearSolverKind::Structured, "{name}");
    assert_eq!(kind_of(&auto), auto_picks, "{name}");
    assert_agree(name, problem, &sparse, &structured);
    assert_agree(name, problem, &sparse, &auto);
}

#[test]
fn bratu_agrees() {
    let g = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);
    check(
        "bratu",
        &Bratu { k: 1.0 },
        &[],
        &g,
        &SolveOptions::with_tol(1e-6),
        LinearSolverKind::Structured,
    );
}

#[test]
fn shock_layer_agrees() {
    let g = Guess::constant(linspace(-1.0, 1.0, 5), &[0.0, 0.0]);
    check(
        "shock",
        &Shock { eps: 1e-3 },
        &[],
        &g,
        &SolveOptions::with_tol(1e-6),
        LinearSolverKind::Structured,
    );
}

#[test]
fn coupled_troesch_agrees() {
    let g = Guess::from_fn(linspace(0.0, 1.0, 11), 4, |x, y| {
        y.copy_from_slice(&[x, 1.0, 0.0, 0.0]);
    });
    check(
        "coupled troesch",
        &CoupledTroesch,
        &[5.0, 1.0],
        &g,
        &SolveOptions::with_tol(1e-6),
        LinearSolverKind::Structured,
    );
}

#[test]
fn unknown_parameter_problem_agrees() {
    let g = Guess::from_fn(linspace(0.0, 1.0, 40), 2, |x, y| {
        let pi = std::f64::consts::PI;
        y[0] = 0.5 * (pi * x).sin() / pi;
        y[1] = 0.5 * (pi * x).cos();
    })
    .with_unknowns(&[3.0]);
    check(
        "oscillator (k = 1)",
        &Oscillator,
        &[2.0, 0.8],
        &g,
        &SolveOptions::with_tol(1e-6),
        LinearSolverKind::Structured,
    );
}

#[test]
fn more_unknowns_than_states_fall_back_under_auto() {
    let g = Guess::constant(linspace(0.0, 1.0, 6), &[0.0]).with_unknowns(&[0.0, 0.0]);
    check(
        "two unknowns (k = 2 > n = 1)",
        &TwoUnknowns,
        &[1.5],
        &g,
        &SolveOptions::with_tol(1e-8),
        LinearSolverKind::SparseLu,
    );
    // y = u (x + x²/2) with u (3/2) = c
    let s = solve(
        &TwoUnknowns,
        &[1.5],
        &g,
        &SolveOptions {
            linear_solver: LinearSolverKind::Structured,
            ..SolveOptions::with_tol(1e-8)
        },
    )
    .expect("structured solve with a parameter-only boundary row");
    assert!((s.unknowns[0] - 1.0).abs() < 1e-10 && (s.unknowns[1] - 1.0).abs() < 1e-10);
}

#[test]
fn periodic_conditions_fall_back_under_auto_and_are_refused_by_structured() {
    let two_pi = 2.0 * std::f64::consts::PI;
    let g = Guess::constant(linspace(0.0, two_pi, 12), &[0.0, 0.0]);
    let opts = SolveOptions {
        factor_at_solution: true,
        ..SolveOptions::with_tol(1e-6)
    };
    let auto = solve(&Periodic, &[0.3], &g, &opts).expect("periodic solve");
    assert_eq!(kind_of(&auto), LinearSolverKind::SparseLu);
    let sparse = solve(
        &Periodic,
        &[0.3],
        &g,
        &SolveOptions {
            linear_solver: LinearSolverKind::SparseLu,
            ..opts.clone()
        },
    )
    .expect("periodic solve");
    assert_agree("periodic", &Periodic, &sparse, &auto);
    // y = (cos x - a sin x)/2
    for (i, &x) in auto.x.iter().enumerate() {
        let exact = 0.5 * (x.cos() - 0.3 * x.sin());
        assert!((auto.at_node(i, 0) - exact).abs() < 1e-5);
    }
    let err = solve(
        &Periodic,
        &[0.3],
        &g,
        &SolveOptions {
            linear_solver: LinearSolverKind::Structured,
            ..opts
        },
    )
    .expect_err("structured elimination needs separated conditions");
    match err {
        BvpError::InvalidInput(msg) => {
            assert!(msg.contains("boundary condition 0"), "{msg}");
            assert!(msg.contains("Structured"), "{msg}");
        }
        other => panic!("expected InvalidInput, got {other:?}"),
    }
}

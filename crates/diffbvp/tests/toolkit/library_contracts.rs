//! The library's input contracts, one test per "lib" row of the bad-input findings
//! (../shared/probes/bad-input-findings.md, commit d67ae64; the test name starts with the row's
//! id): non-finite residuals or Jacobian entries, wrong lengths, mismatched dimensions, absurd
//! options and degenerate meshes are errors that name what is wrong and where, never a panic
//! and never an `Ok` with a NaN cost or zero standard errors. The last tests cover the
//! non-panicking alternatives of the documented panics.

use crate::common::BratuInK;
use diffbvp::continuation::{
    secant_guess, solve_by_continuation, try_secant_guess, PathOptions, SimpleSteps, StepControl,
};
use diffbvp::least_squares::{fit, FitError, FitOptions, LeastSquaresProblem};
use diffbvp::mesh::{
    linspace, try_apply, try_coarsen, try_linspace, try_refine, validate, MeshOptions,
};
use diffbvp::{solve, Bvp, BvpError, DualNum, Guess, Solution, SolveOptions, Solver};

/// y''' = 0 with y(0) = 1, y'(0) = 0, y(1) = 2: a 3-state problem.
struct Cubic;
impl Bvp for Cubic {
    fn dim(&self) -> usize {
        3
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, _x: f64, y: &[D], _p: &[D], f: &mut [D]) {
        f[0] = y[1];
        f[1] = y[2];
        f[2] = D::zero();
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], _p: &[D], r: &mut [D]) {
        r[0] = ya[0] - 1.0;
        r[1] = ya[1];
        r[2] = yb[0] - 2.0;
    }
}

fn bratu_guess() -> Guess {
    Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0])
}

fn bratu(k: f64) -> Solution {
    solve(
        &BratuInK,
        &[k],
        &bratu_guess(),
        &SolveOptions::with_tol(1e-6),
    )
    .unwrap()
}

fn invalid_input(e: BvpError) -> String {
    match e {
        BvpError::InvalidInput(m) => m,
        other => panic!("expected BvpError::InvalidInput, got {other}"),
    }
}

fn invalid_fit(r: Result<diffbvp::least_squares::FitResult, FitError>) -> String {
    match r {
        Err(FitError::InvalidInput(m)) => m,
        Err(other) => panic!("expected FitError::InvalidInput, got {other}"),
        Ok(res) => panic!(
            "expected FitError::InvalidInput, got Ok with cost {} ({})",
            res.cost, res.termination
        ),
    }
}

/// A straight line `a + b t` through four points (optimum cost 0.0075 at a = 1.05, b = 1.95 for
/// the data below), with a way to break the evaluation.
struct Line {
    /// How `evaluate` misbehaves where `misbehave(p)` holds.
    breach: Breach,
    misbehave: fn(&[f64]) -> bool,
}

#[derive(Clone, Copy)]
enum Breach {
    None,
    InfJacobian,
    NanResiduals,
    ShortJacobian,
}

const T: [f64; 4] = [0.0, 1.0, 2.0, 3.0];
const D: [f64; 4] = [1.1, 2.9, 5.0, 6.9];

impl LeastSquaresProblem for Line {
    type Error = String;
    fn num_params(&self) -> usize {
        2
    }
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
        let mut r: Vec<f64> = T.iter().zip(D).map(|(t, d)| p[0] + p[1] * t - d).collect();
        let mut jac: Vec<f64> = T.iter().flat_map(|&t| [1.0, t]).collect();
        if (self.misbehave)(p) {
            match self.breach {
                Breach::None => {}
                Breach::InfJacobian => jac[5] = f64::INFINITY,
                Breach::NanResiduals => r.fill(f64::NAN),
                Breach::ShortJacobian => jac.truncate(3),
            }
        }
        Ok((r, jac))
    }
}

fn always(_: &[f64]) -> bool {
    true
}

/// Beyond a = 0.5: away from the start (0, 0), on the way to the optimum (1.05, 1.95).
fn beyond_half(p: &[f64]) -> bool {
    p[0] > 0.5
}

fn line_options() -> FitOptions {
    FitOptions::with_bounds(vec![-10.0; 2], vec![10.0; 2])
}

#[test]
fn ls_inf_jac_at_the_start_is_an_error_naming_the_entry() {
    let mut p = Line {
        breach: Breach::InfJacobian,
        misbehave: always,
    };
    let m = invalid_fit(fit(&mut p, &[0.0, 0.0], &line_options()));
    assert!(m.contains("at the start point [0.0, 0.0]"), "{m}");
    assert!(m.contains("non-finite Jacobian entry: J[2][1]"), "{m}");
    assert!(m.contains("= inf"), "{m}");
    // the same entry at a trial point only: a rejected step that names it, and the fit goes
    // on to the optimum with finite, non-zero standard errors
    let mut p = Line {
        breach: Breach::InfJacobian,
        misbehave: beyond_half,
    };
    let opts = FitOptions {
        max_radius: 10.0,
        initial_radius: 5.0,
        ..line_options()
    };
    let res = fit(&mut p, &[0.0, 0.0], &opts).unwrap();
    let failures: Vec<&str> = res
        .history
        .iter()
        .filter_map(|it| it.failure.as_deref())
        .collect();
    assert!(
        failures.iter().any(|f| f.contains("J[2][1]")),
        "{failures:?}"
    );
    assert!(res.cost.is_finite() && res.jacobian.iter().all(|v| v.is_finite()));
    let se = res.standard_errors().unwrap();
    assert!(se.iter().all(|&s| s > 0.0 && s.is_finite()), "{se:?}");
}

#[test]
fn ls_jac_wrong_len_is_an_error_naming_both_lengths() {
    let mut p = Line {
        breach: Breach::ShortJacobian,
        misbehave: always,
    };
    let m = invalid_fit(fit(&mut p, &[0.0, 0.0], &line_options()));
    assert!(
        m.contains("a Jacobian of 3 entries, expected 4 residuals x 2 parameters = 8"),
        "{m}"
    );
    // at a trial point: the same error (a broken contract, not a failed evaluation), no panic
    let mut p = Line {
        breach: Breach::ShortJacobian,
        misbehave: beyond_half,
    };
    let opts = FitOptions {
        max_radius: 10.0,
        initial_radius: 5.0,
        ..line_options()
    };
    let m = invalid_fit(fit(&mut p, &[0.0, 0.0], &opts));
    assert!(m.contains("a Jacobian of 3 entries"), "{m}");
    assert!(!m.contains("start point"), "{m}");
}

#[test]
fn ls_nan_resid_is_an_error_naming_the_residual() {
    let mut p = Line {
        breach: Breach::NanResiduals,
        misbehave: always,
    };
    let m = invalid_fit(fit(&mut p, &[0.0, 0.0], &line_options()));
    assert!(m.contains("non-finite residual: r[0] = NaN"), "{m}");
    assert!(m.contains("start point"), "{m}");
    // NaN residuals at trial points only: rejected steps, a finite optimum
    let mut p = Line {
        breach: Breach::NanResiduals,
        misbehave: |p| p[1] > 2.5,
    };
    let res = fit(&mut p, &[0.0, 0.0], &line_options()).unwrap();
    assert!((res.cost - 0.0075).abs() < 1e-10, "cost {}", res.cost);
    assert!((res.p[1] - 1.95).abs() < 1e-6, "{:?}", res.p);
    let mut clean = Line {
        breach: Breach::None,
        misbehave: always,
    };
    let reference = fit(&mut clean, &[0.0, 0.0], &line_options()).unwrap();
    assert!((res.cost - reference.cost).abs() < 1e-12);
}

#[test]
fn ls_max_it_0_is_refused_naming_the_option() {
    let mut p = Line {
        breach: Breach::None,
        misbehave: always,
    };
    let opts = FitOptions {
        max_iterations: 0,
        ..line_options()
    };
    let m = invalid_fit(fit(&mut p, &[0.0, 0.0], &opts));
    assert!(
        m.contains("FitOptions::max_iterations must be at least 1, got 0"),
        "{m}"
    );
    // relative stopping tolerances of 1 or more are refused alike
    for (opts, name) in [
        (
            FitOptions {
                xtol: 1.0,
                ..line_options()
            },
            "FitOptions::xtol must be below 1",
        ),
        (
            FitOptions {
                ftol: 5.0,
                ..line_options()
            },
            "FitOptions::ftol must be below 1",
        ),
    ] {
        let m = invalid_fit(fit(&mut p, &[0.0, 0.0], &opts));
        assert!(m.contains(name), "{m}");
    }
}

#[test]
fn secant_mismatch_is_an_error_naming_both_dimensions() {
    let a = bratu(1.0);
    let b = solve(
        &Cubic,
        &[],
        &Guess::constant(linspace(0.0, 1.0, 5), &[1.0, 0.0, 0.0]),
        &SolveOptions::with_tol(1e-6),
    )
    .unwrap();
    let m = invalid_input(try_secant_guess(&a, &b, 1.0).unwrap_err());
    assert!(m.contains("a has 2 states, b has 3"), "{m}");
    let m = invalid_input(try_secant_guess(&a, &bratu(1.1), f64::NAN).unwrap_err());
    assert!(m.contains("t = NaN is not finite"), "{m}");
    // the infallible predictor falls back to `a` itself, a valid warm start
    let g = secant_guess(&a, &b, 1.0);
    assert_eq!((g.x, g.y), (a.x.clone(), a.y.clone()));
    // matching solutions extrapolate as before
    let b = bratu(0.9);
    let g = try_secant_guess(&a, &b, 1.0).unwrap();
    let h = secant_guess(&a, &b, 1.0);
    assert_eq!(g.y, h.y);
    assert_ne!(g.y, a.y);
}

#[test]
fn tol_huge_is_refused_naming_the_option() {
    for tol in [1e300, 1.0] {
        let e = solve(
            &BratuInK,
            &[1.0],
            &bratu_guess(),
            &SolveOptions::with_tol(tol),
        )
        .unwrap_err();
        let m = invalid_input(e);
        assert!(m.contains("SolveOptions::tol must be below 1"), "{m}");
        assert!(m.contains("relative residual"), "{m}");
    }
    let opts = SolveOptions {
        newton_step_tol: Some(2.0),
        ..SolveOptions::default()
    };
    let m = invalid_input(opts.validate(2).unwrap_err());
    assert!(
        m.contains("SolveOptions::newton_step_tol must be below 1"),
        "{m}"
    );
    // the largest tolerance allowed still solves
    assert!(solve(
        &BratuInK,
        &[1.0],
        &bratu_guess(),
        &SolveOptions::with_tol(0.5)
    )
    .is_ok());
    // a path's intermediate tolerance alike
    let path = PathOptions {
        intermediate_tol: 3.0,
        ..PathOptions::default()
    };
    let mut solver = Solver::new(&BratuInK, SolveOptions::with_tol(1e-6));
    let e = solve_by_continuation(
        &mut solver,
        &[0.5],
        0,
        1.0,
        &bratu_guess(),
        &path,
        &SolveOptions::with_tol(1e-6),
    )
    .unwrap_err();
    assert!(invalid_input(e).contains("PathOptions::intermediate_tol = 3 must lie in (0, 1)"));
    let path = PathOptions {
        step_control: StepControl::Simple(SimpleSteps {
            max_steps: 0,
            ..SimpleSteps::default()
        }),
        ..PathOptions::default()
    };
    let e = solve_by_continuation(
        &mut solver,
        &[0.5],
        0,
        1.0,
        &bratu_guess(),
        &path,
        &SolveOptions::with_tol(1e-6),
    )
    .unwrap_err();
    assert!(invalid_input(e).contains("SimpleSteps::max_steps = 0 must be at least 1"));
}

#[test]
fn linspace_huge_gives_finite_equally_spaced_nodes() {
    let x = linspace(-f64::MAX, f64::MAX, 3);
    assert_eq!(x, vec![-f64::MAX, 0.0, f64::MAX]);
    assert_eq!(try_linspace(-f64::MAX, f64::MAX, 3).unwrap(), x);
    let x = linspace(-f64::MAX, f64::MAX, 5);
    let exact = [-f64::MAX, -f64::MAX / 2.0, 0.0, f64::MAX / 2.0, f64::MAX];
    for (v, e) in x.iter().zip(exact) {
        assert!((v - e).abs() <= 1e-15 * f64::MAX, "{x:?}");
    }
    // ordinary ends: the same nodes, bit for bit, from both
    for (a, b, m) in [(0.0, 1.0, 5), (-1.0, 1.0, 11), (0.3, 0.7, 7)] {
        assert_eq!(try_linspace(a, b, m).unwrap(), linspace(a, b, m));
    }
    // such a mesh is finite but degenerate for a solve: the width of each interval overflows
    let m = invalid_input(validate(&linspace(-f64::MAX, f64::MAX, 2)).unwrap_err());
    assert!(m.contains("the mesh is degenerate"), "{m}");
}

#[test]
fn linspace_inf_is_an_error_from_try_linspace() {
    let m = invalid_input(try_linspace(0.0, f64::INFINITY, 3).unwrap_err());
    assert!(m.contains("the end b = inf is not finite"), "{m}");
    let m = invalid_input(try_linspace(f64::NEG_INFINITY, 0.0, 3).unwrap_err());
    assert!(m.contains("the start a = -inf is not finite"), "{m}");
    // the unchecked function keeps its documented arithmetic
    assert!(linspace(0.0, f64::INFINITY, 3)
        .iter()
        .any(|v| !v.is_finite()));
    // a node count that cannot be allocated is an error, not an abort
    let m = invalid_input(try_linspace(0.0, 1.0, usize::MAX).unwrap_err());
    assert!(m.contains("cannot allocate"), "{m}");
}

#[test]
fn linspace_nan_is_an_error_from_try_linspace() {
    let m = invalid_input(try_linspace(f64::NAN, 1.0, 3).unwrap_err());
    assert!(m.contains("the start a = NaN is not finite"), "{m}");
    let m = invalid_input(try_linspace(0.0, f64::NAN, 0).unwrap_err());
    assert!(m.contains("the end b = NaN"), "{m}");
    // a solve on such nodes names the node
    let e = solve(
        &BratuInK,
        &[1.0],
        &Guess::constant(linspace(f64::NAN, 1.0, 3), &[0.0, 0.0]),
        &SolveOptions::default(),
    )
    .unwrap_err();
    assert!(invalid_input(e).contains("mesh node 0 is not finite"));
}

#[test]
fn mesh_huge_span_is_a_degenerate_mesh_error() {
    let e = solve(
        &BratuInK,
        &[1.0],
        &Guess::constant(vec![-1e308, 1e308], &[0.0, 0.0]),
        &SolveOptions::default(),
    )
    .unwrap_err();
    let m = invalid_input(e);
    assert!(m.contains("the mesh is degenerate"), "{m}");
    assert!(m.contains("interval 0"), "{m}");
    assert!(m.contains("overflows f64"), "{m}");
    assert!(m.contains("rescale the independent variable"), "{m}");
}

#[test]
fn mesh_tiny_span_is_a_degenerate_mesh_error() {
    let e = solve(
        &BratuInK,
        &[1.0],
        &Guess::constant(vec![0.0, 5e-324], &[0.0, 0.0]),
        &SolveOptions::default(),
    )
    .unwrap_err();
    let m = invalid_input(e);
    assert!(m.contains("the mesh is degenerate"), "{m}");
    assert!(m.contains("width 5e-324"), "{m}");
    assert!(m.contains("too small"), "{m}");
    // an interval below the resolution of f64 at its position
    let x = vec![0.0, 1.0, 1.0 + 4.0 * f64::EPSILON, 2.0];
    let m = invalid_input(validate(&x).unwrap_err());
    assert!(m.contains("interval 1"), "{m}");
    assert!(m.contains("the mesh is degenerate"), "{m}");
    // small meshes are fine when they are resolvable
    assert!(validate(&[0.0, 1e-300, 2e-300]).is_ok());
    assert!(validate(&[1e6, 1e6 + 1e-6]).is_ok());
}

#[test]
fn documented_panics_have_non_panicking_alternatives() {
    let x = [0.0, 1.0, 2.0];
    let m = invalid_input(try_refine(&x, &[1]).unwrap_err());
    assert!(m.contains("nodes_per_interval has 1 entries"), "{m}");
    assert!(m.contains("3 nodes has 2 intervals"), "{m}");
    assert_eq!(try_refine(&x, &[1, 0]).unwrap(), vec![0.0, 0.5, 1.0, 2.0]);
    let opts = MeshOptions::default();
    let m = invalid_input(try_apply(&x, &[1.0], &[], 1e-3, &opts, 100).unwrap_err());
    assert!(m.contains("rms has 1 entries"), "{m}");
    let m = invalid_input(
        try_apply(&x, &[1.0, 1.0], &[1], 1e-3, &MeshOptions::scipy(), 100).unwrap_err(),
    );
    assert!(m.contains("marks has 1 entries"), "{m}");
    assert!(try_apply(&x, &[1.0, 1.0], &[1, 1], 1e-3, &MeshOptions::scipy(), 100).is_ok());
    let m = invalid_input(try_coarsen(&x, &[0.0, 0.0, 0.0], 1.0).unwrap_err());
    assert!(m.contains("rms has 3 entries"), "{m}");
    assert_eq!(try_coarsen(&x, &[0.0, 0.0], 1.0).unwrap(), vec![0.0, 2.0]);
    let s = bratu(1.0);
    let (mut y, mut yp) = (vec![0.0; 1], vec![0.0; 2]);
    let m = invalid_input(s.try_eval_into(0.5, &mut y, &mut yp).unwrap_err());
    assert!(
        m.contains("the buffer y has 1 entries, the solution 2 states"),
        "{m}"
    );
    let mut y = vec![0.0; 2];
    s.try_eval_into(0.5, &mut y, &mut yp).unwrap();
    assert_eq!(y, s.eval(0.5));
}

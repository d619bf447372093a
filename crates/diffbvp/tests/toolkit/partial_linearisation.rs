//! A linearisation seeded in some of the model parameters
//! (`SolveOptions::linearization_params`): derivatives in those parameters are the columns of
//! the full ones, bit for bit (each derivative is the same floating-point operations whatever
//! else is seeded beside it), derivatives in the others stay exact (computed from the full linearisation
//! or, for the tangent predictor, from the parameters' own derivatives), the dual pass is
//! narrower, and bad index lists are errors.

use diffbvp::least_squares::{fit, BvpResiduals, BvpRun, FitOptions, ParamMap};
use diffbvp::mesh::linspace;
use diffbvp::sensitivity::{residual_jacobian, tangent_guess, PointFunction, Sensitivities};
use diffbvp::{solve, Bvp, BvpError, DualNum, Guess, Solution, SolveOptions, Solver};
use std::sync::Arc;

/// `y0' = y1`, `y1' = −p0 e^{y0} + p1 x u + 10⁻³ (p4 y1 + p5 − p6)` with the unknown initial
/// slope `u`: `y0(0) = p3`, `y1(0) = u`, `y0(1) = p2 / 5`. Two states, one unknown and seven
/// model parameters: the full dual pass has 10 inputs (two passes of 8), any 3 parameters fit
/// in one.
struct Mixed;
impl Bvp for Mixed {
    fn dim(&self) -> usize {
        2
    }
    fn num_unknowns(&self) -> usize {
        1
    }
    fn num_params(&self) -> usize {
        7
    }
    fn rhs<D: DualNum<Primitive = f64> + Copy>(&self, x: f64, y: &[D], p: &[D], f: &mut [D]) {
        // p = (u, p0, ..., p6)
        let (u, q) = (p[0], &p[1..]);
        f[0] = y[1];
        f[1] = -q[0] * y[0].exp() + q[1] * u * x + (q[4] * y[1] + q[5] - q[6]) * 1e-3;
    }
    fn bc<D: DualNum<Primitive = f64> + Copy>(&self, ya: &[D], yb: &[D], p: &[D], r: &mut [D]) {
        let (u, q) = (p[0], &p[1..]);
        r[0] = ya[0] - q[3];
        r[1] = ya[1] - u;
        r[2] = yb[0] - q[2] * 0.2;
    }
}

const P: [f64; 7] = [0.8, 0.6, 0.5, 0.3, 1.5, 2.0, 0.7];

fn guess() -> Guess {
    Guess::constant(linspace(0.0, 1.0, 11), &[0.3, 0.0]).with_unknowns(&[0.1])
}

fn solved(seeds: Option<&[usize]>) -> Solution {
    let opts = SolveOptions {
        factor_at_solution: true,
        linearization_params: seeds.map(Arc::from),
        ..SolveOptions::with_tol(1e-8)
    };
    solve(&Mixed, &P, &guess(), &opts).expect("Mixed solves")
}

/// The largest difference between `a` and `b` relative to the largest magnitude in `b`.
fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

/// Column `j` of a `rows × cols` row-major matrix.
fn column(m: &[f64], cols: usize, j: usize) -> Vec<f64> {
    m.iter().skip(j).step_by(cols).copied().collect()
}

struct Observe;
impl PointFunction for Observe {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, _i: usize, x: f64, y: &[D], p: &[D]) -> D {
        y[0] * y[0] * p[5] + y[1] * x + p[3]
    }
}

#[test]
fn sensitivities_in_a_subset_are_the_columns_of_the_full_ones() {
    let full_sol = solved(None);
    let full = Sensitivities::compute_unrefined(&Mixed, &full_sol).unwrap();
    let q = full.num_params();
    assert_eq!(full.columns(), &[0, 1, 2, 3, 4, 5, 6]);
    let xs: Vec<f64> = (0..9).map(|i| 0.05 + 0.11 * i as f64).collect();
    let (_, jac_full) = residual_jacobian(&Mixed, &full_sol, &full, &xs, &Observe).unwrap();
    for (seeds, cols) in [
        (Some(vec![1, 3]), vec![1, 3]),
        (Some(vec![1, 3]), vec![3]),
        (Some(vec![]), vec![0, 6]),
        (Some(vec![0, 1, 2, 3, 4, 5, 6]), vec![2, 5]),
        (None, vec![4]),
        // columns the solve's linearisation lacks: the full one is computed for them
        (Some(vec![1]), vec![0, 2, 6]),
    ] {
        let sol = solved(seeds.as_deref());
        assert_eq!(sol.y, full_sol.y, "the seeds do not change the solution");
        let part = Sensitivities::compute_for(&Mixed, &sol, &cols).unwrap();
        assert_eq!(part.columns(), &cols[..]);
        assert_eq!(part.num_params(), cols.len());
        let s = cols.len();
        let (_, jac) = residual_jacobian(&Mixed, &sol, &part, &xs, &Observe).unwrap();
        for (c, &j) in cols.iter().enumerate() {
            let what = format!("seeds {seeds:?}, column {j}");
            let d = rel_diff(&column(&part.dy, s, c), &column(&full.dy, q, j));
            assert!(d == 0.0, "{what}: dy differs by {d:e}");
            let d = rel_diff(&column(&part.dyp, s, c), &column(&full.dyp, q, j));
            assert!(d == 0.0, "{what}: dyp differs by {d:e}");
            let d = rel_diff(
                &column(&part.d_unknowns, s, c),
                &column(&full.d_unknowns, q, j),
            );
            assert!(d == 0.0, "{what}: d_unknowns differs by {d:e}");
            let d = rel_diff(&column(&jac, s, c), &column(&jac_full, q, j));
            assert!(d == 0.0, "{what}: residual Jacobian differs by {d:e}");
        }
        // the full sensitivities of a partly seeded solution are those of a fully seeded one
        let again = Sensitivities::compute_unrefined(&Mixed, &sol).unwrap();
        let d = rel_diff(&again.dy, &full.dy);
        assert!(d == 0.0, "seeds {seeds:?}: full dy differs by {d:e}");
    }
}

#[test]
fn the_dual_pass_is_narrower_with_fewer_parameters() {
    let full = solved(None);
    let part = solved(Some(&[1, 3]));
    let m = full.nodes();
    assert_eq!(part.nodes(), m);
    // 2 states + 1 unknown + 7 parameters: two passes of 8 at each of the 2m − 1 points;
    // with 2 parameters: one
    assert_eq!(
        full.stats.rhs_dual_evaluations - part.stats.rhs_dual_evaluations,
        2 * m - 1,
        "one pass fewer at every node and midpoint"
    );
}

#[test]
fn the_tangent_predictor_is_exact_in_parameters_the_linearisation_lacks() {
    let full = solved(None);
    let part = solved(Some(&[1]));
    let mut target = P;
    // one seeded parameter, one in f, one in g and one nobody seeded
    target[1] += 0.01;
    target[0] -= 0.02;
    target[2] += 0.03;
    target[6] += 0.05;
    let a = tangent_guess(&Mixed, &full, &target).unwrap();
    let b = tangent_guess(&Mixed, &part, &target).unwrap();
    let d = rel_diff(&b.y, &a.y);
    assert!(d == 0.0, "predicted states differ by {d:e}");
    let d = rel_diff(&b.unknowns, &a.unknowns);
    assert!(d == 0.0, "predicted unknowns differ by {d:e}");
    // and it predicts: closer to the solution at the target than the start is
    let exact = solve(
        &Mixed,
        &target,
        &Guess::from(&full),
        &SolveOptions::fixed_mesh(),
    )
    .unwrap();
    assert!(rel_diff(&b.y, &exact.y) < 0.1 * rel_diff(&full.y, &exact.y));
}

#[test]
fn bad_parameter_lists_are_errors() {
    for (seeds, needle) in [
        (vec![2, 1], "strictly increasing"),
        (vec![1, 1], "strictly increasing"),
        (vec![0, 7], "model parameter 7"),
    ] {
        let opts = SolveOptions {
            linearization_params: Some(Arc::from(seeds.clone())),
            ..SolveOptions::with_tol(1e-8)
        };
        match solve(&Mixed, &P, &guess(), &opts) {
            Err(BvpError::InvalidInput(msg)) => {
                assert!(msg.contains("linearization_params"), "{seeds:?}: {msg}");
                assert!(msg.contains(needle), "{seeds:?}: {msg}");
            }
            other => panic!("{seeds:?}: expected an input error, got {other:?}"),
        }
    }
    let sol = solved(None);
    for cols in [vec![3, 2], vec![7]] {
        let e = Sensitivities::compute_for(&Mixed, &sol, &cols).unwrap_err();
        assert!(format!("{e}").contains("compute_for"), "{cols:?}: {e}");
    }
}

/// `r_j = y0(x_j) − data_j`.
struct Misfit(Vec<f64>);
impl PointFunction for Misfit {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, j: usize, _x: f64, y: &[D], _p: &[D]) -> D {
        y[0] - self.0[j]
    }
}

/// A fit that frees two of the seven parameters and changes a third between fits (through
/// the map's base values) recovers them, with the same Jacobian as a fit whose solver
/// linearises in all parameters.
#[test]
fn a_fit_through_a_map_linearises_in_what_it_frees() {
    let xs: Vec<f64> = (1..=12).map(|i| i as f64 / 13.0).collect();
    let truth = solved(None);
    let data: Vec<f64> = xs.iter().map(|&x| truth.eval(x)[0]).collect();
    let start = [0.5, 0.9];
    let run = |all: bool| {
        let mut q0 = P;
        q0[0] = start[0];
        q0[2] = start[1];
        let mut opts = SolveOptions {
            factor_at_solution: true,
            ..SolveOptions::with_tol(1e-8)
        };
        if all {
            opts.linearization_params = Some(Arc::from(vec![0, 1, 2, 3, 4, 5, 6]));
        }
        let sol = solve(&Mixed, &q0, &guess(), &opts).unwrap();
        let map = ParamMap::new(q0.to_vec()).link(0, 0).link(2, 1);
        let run = BvpRun::new(
            Solver::new(&Mixed, opts),
            sol,
            xs.clone(),
            Misfit(data.clone()),
            map,
        )
        .unwrap();
        let mut problem = BvpResiduals::new(2);
        problem.push(run).unwrap();
        problem
    };
    let (mut narrow, mut wide) = (run(false), run(true));
    let (_, ja) = narrow.evaluate_from(&start, true, None).unwrap();
    let (_, jb) = wide.evaluate_from(&start, true, None).unwrap();
    let d = rel_diff(&ja, &jb);
    assert!(d == 0.0, "fit Jacobians differ by {d:e}");
    let r = fit(
        &mut narrow,
        &start,
        &FitOptions::with_bounds(vec![0.0; 2], vec![5.0; 2]),
    )
    .unwrap();
    assert!((r.p[0] - P[0]).abs() < 1e-6, "p0 = {}", r.p[0]);
    assert!((r.p[1] - P[2]).abs() < 1e-6, "p2 = {}", r.p[1]);
    let rw = fit(
        &mut wide,
        &start,
        &FitOptions::with_bounds(vec![0.0; 2], vec![5.0; 2]),
    )
    .unwrap();
    assert!(r.p == rw.p, "{:?} vs {:?}", r.p, rw.p);
    // a fixed parameter changed between fits: the next evaluation predicts along it too, and
    // the Jacobians still agree
    for problem in [&mut narrow, &mut wide] {
        problem.accept_pending();
        problem.runs_mut()[0].map_mut().base[6] += 0.5;
    }
    let (ra, ja) = narrow.evaluate_from(&r.p, true, None).unwrap();
    let (rb, jb) = wide.evaluate_from(&r.p, true, None).unwrap();
    assert!(
        rel_diff(&ra, &rb) == 0.0,
        "residuals differ by {:e}",
        rel_diff(&ra, &rb)
    );
    let d = rel_diff(&ja, &jb);
    assert!(d == 0.0, "fit Jacobians after the change differ by {d:e}");
    let moved = ra.iter().map(|v| v.abs()).fold(0.0, f64::max);
    assert!(moved > 1e-6, "the change moved the residuals ({moved:e})");
}

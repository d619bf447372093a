//! `SolveOptions::keep_newton_matrix`: a solve keeps its last factorised Newton matrix, and a
//! solve nearby on the same mesh (`Solver::solve_near`) starts simplified Newton from it. The
//! result meets the same tolerance as a solve with fresh Jacobians, with fewer dual-number
//! passes; the kept matrix is never mistaken for a linearisation at the solution.

use crate::common::BratuInK;
use diffbvp::mesh::linspace;
use diffbvp::{Guess, Solution, SolveOptions, Solver};

fn options(keep: bool) -> SolveOptions {
    SolveOptions {
        keep_newton_matrix: keep,
        // a fixed mesh: every solve of the walk is on the mesh of the one before
        adapt: false,
        ..SolveOptions::with_tol(1e-9)
    }
}

fn start() -> Guess {
    Guess::constant(linspace(0.0, 1.0, 41), &[0.0, 0.0])
}

/// The largest difference of the node values of two solutions on the same mesh.
fn max_diff(a: &Solution, b: &Solution) -> f64 {
    assert_eq!(a.x, b.x);
    a.y.iter()
        .zip(&b.y)
        .fold(0.0f64, |m, (u, v)| m.max((u - v).abs()))
}

#[test]
fn a_walk_from_kept_newton_matrices_matches_fresh_solves_with_fewer_dual_passes() {
    let mut kept = Solver::new(&BratuInK, options(true));
    let mut fresh = Solver::new(&BratuInK, options(false));
    let first = kept.solve(&[1.0], &start()).expect("BratuInK at a = 1");
    assert!(first.has_newton_matrix(), "the option keeps the matrix");
    assert!(
        first.factorization().is_none(),
        "the kept matrix is not an exact linearisation"
    );
    let (mut prev_kept, mut prev_fresh) = (first.clone(), first);
    let (mut dual_kept, mut dual_fresh) = (0, 0);
    for step in 1..=10 {
        let a = 1.0 + 0.02 * f64::from(step);
        let g = Guess::from(&prev_kept);
        let sk = kept
            .solve_near(&[a], &g, &prev_kept, &options(true))
            .expect("walk from the kept matrix");
        let sf = fresh
            .solve_with(&[a], &Guess::from(&prev_fresh), &options(false))
            .expect("walk with fresh Jacobians");
        assert!(
            sk.has_newton_matrix(),
            "step {step}: the matrix is carried on"
        );
        assert!(!sf.has_newton_matrix());
        // both meet the Newton tolerance on the same mesh: they agree far below it
        let d = max_diff(&sk, &sf);
        assert!(d < 1e-9, "step {step}: the two walks differ by {d:e}");
        dual_kept += sk.stats.rhs_dual_evaluations;
        dual_fresh += sf.stats.rhs_dual_evaluations;
        (prev_kept, prev_fresh) = (sk, sf);
    }
    assert!(
        2 * dual_kept < dual_fresh,
        "dual passes: {dual_kept} from kept matrices, {dual_fresh} fresh"
    );
}

#[test]
fn a_kept_matrix_is_neither_kept_by_default_nor_used_on_another_mesh() {
    let mut solver = Solver::new(&BratuInK, options(false));
    let plain = solver.solve(&[1.0], &start()).expect("BratuInK");
    assert!(!plain.has_newton_matrix(), "off by default");
    let mut keeper = Solver::new(&BratuInK, options(true));
    let near = keeper.solve(&[1.0], &start()).expect("BratuInK");
    // a guess on another mesh: solve_near is solve_with, and nothing is carried over
    let other = Guess::constant(linspace(0.0, 1.0, 31), &[0.0, 0.0]);
    let far = keeper
        .solve_near(&[1.05], &other, &near, &options(true))
        .expect("BratuInK on 31 nodes");
    assert_eq!(far.nodes(), 31);
    let again = solver
        .solve_with(&[1.05], &other, &options(false))
        .expect("BratuInK on 31 nodes, fresh");
    // on another mesh solve_near is solve_with: the same solve, bit for bit
    assert_eq!(far.y, again.y);
    assert_eq!(far.stats, again.stats);
    assert!(
        far.stats.rhs_dual_evaluations > 0,
        "on another mesh the solve evaluates its own Jacobian"
    );
    // with the exact linearisation requested, no second matrix is kept beside it
    let exact = SolveOptions {
        factor_at_solution: true,
        ..options(true)
    };
    let lin = keeper
        .solve_with(&[1.0], &start(), &exact)
        .expect("BratuInK");
    assert!(lin.factorization().is_some() && !lin.has_newton_matrix());
}

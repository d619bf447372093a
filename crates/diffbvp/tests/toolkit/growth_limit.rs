//! `SolveOptions::growth_limit`: a warm start far from the solution fails early with
//! `BvpError::MeshGrowthLimit` instead of refining towards `max_nodes`; a limit that does not
//! bind changes nothing.

use crate::common::Shock;
use diffbvp::mesh::linspace;
use diffbvp::{solve, BvpError, GrowthLimit, Guess, Solution, SolveOptions};

/// The shock layer at `eps = 0.1` (a smooth solution on a few nodes), the warm start of the
/// steep one at `eps = 1e-3` (about 600 nodes at tol 1e-6).
fn smooth_start() -> Solution {
    let g = Guess::constant(linspace(-1.0, 1.0, 5), &[0.0, 0.0]);
    solve(&Shock { eps: 0.1 }, &[], &g, &options(None)).unwrap()
}

/// Options at tol 1e-6 with growth limit `(factor, at_least)` (`None`: no limit).
fn options(limit: Option<(f64, usize)>) -> SolveOptions {
    SolveOptions {
        growth_limit: limit.map(|(factor, at_least)| GrowthLimit { factor, at_least }),
        ..SolveOptions::with_tol(1e-6)
    }
}

/// The shock layer at `eps` warm-started from `start`, with growth limit `limit`.
fn from(start: &Solution, eps: f64, limit: Option<(f64, usize)>) -> Result<Solution, BvpError> {
    solve(&Shock { eps }, &[], &Guess::from(start), &options(limit))
}

#[test]
fn a_far_warm_start_fails_at_the_limit() {
    let start = smooth_start();
    let m = start.nodes();
    let free = from(&start, 1e-3, None).unwrap();
    // the steep layer needs many times the smooth one's nodes: a limit of 3x binds
    assert!(free.nodes() > 3 * m, "{} nodes from {m}", free.nodes());
    let err = from(&start, 1e-3, Some((3.0, 10))).expect_err("the limit binds");
    let text = err.to_string();
    match err {
        BvpError::MeshGrowthLimit {
            start_nodes,
            nodes,
            limit,
            ..
        } => {
            assert_eq!(start_nodes, m);
            assert_eq!(limit, 3 * m);
            assert!(nodes > limit, "{nodes} nodes wanted, limit {limit}");
            assert!(text.contains("growth_limit"), "{text}");
        }
        other => panic!("expected MeshGrowthLimit, got {other:?}"),
    }
    // `at_least` lets a coarse start grow that far whatever the factor
    let s = from(&start, 1e-3, Some((1.0, free.nodes() * 4))).unwrap();
    assert_eq!(s.x, free.x);
}

#[test]
fn a_limit_that_does_not_bind_changes_nothing() {
    let start = smooth_start();
    let free = from(&start, 1e-2, None).unwrap();
    let factor = free.nodes() as f64 / start.nodes() as f64 + 1.0;
    let s = from(&start, 1e-2, Some((factor, 2))).unwrap();
    assert_eq!(s.x, free.x);
    assert_eq!(s.y, free.y);
    assert_eq!(s.stats.newton_iterations, free.stats.newton_iterations);
}

#[test]
fn a_growth_limit_below_one_is_refused() {
    for (factor, at_least) in [(0.5, 100), (f64::NAN, 100), (2.0, 1)] {
        let opts = SolveOptions {
            growth_limit: Some(GrowthLimit { factor, at_least }),
            ..SolveOptions::default()
        };
        match opts.validate(2) {
            Err(BvpError::InvalidInput(m)) => assert!(m.contains("growth_limit"), "{m}"),
            other => panic!("factor {factor}, at_least {at_least}: {other:?}"),
        }
    }
}

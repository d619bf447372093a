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
    solve(&Shock { eps: 0.1 }, &[], &g, &SolveOptions::with_tol(1e-6)).unwrap()
}

#[test]
fn a_far_warm_start_fails_at_the_limit() {
    let start = smooth_start();
    let m = start.nodes();
    let steep = Shock { eps: 1e-3 };
    let free = solve(
        &steep,
        &[],
        &Guess::from(&start),
        &SolveOptions::with_tol(1e-6),
    )
    .unwrap();
    // the steep layer needs many times the smooth one's nodes: a limit of 3x binds
    assert!(free.nodes() > 3 * m, "{} nodes from {m}", free.nodes());
    let limited = SolveOptions {
        growth_limit: Some(GrowthLimit {
            factor: 3.0,
            at_least: 10,
        }),
        ..SolveOptions::with_tol(1e-6)
    };
    match solve(&steep, &[], &Guess::from(&start), &limited) {
        Err(BvpError::MeshGrowthLimit {
            start_nodes,
            nodes,
            limit,
            ..
        }) => {
            assert_eq!(start_nodes, m);
            assert_eq!(limit, 3 * m);
            assert!(nodes > limit, "{nodes} nodes wanted, limit {limit}");
            let text = BvpError::MeshGrowthLimit {
                start_nodes,
                nodes,
                limit,
                max_residual: 1.0,
                tol: 1e-6,
            }
            .to_string();
            assert!(text.contains("growth_limit"), "{text}");
        }
        other => panic!("expected MeshGrowthLimit, got {other:?}"),
    }
    // `at_least` lets a coarse start grow that far whatever the factor
    let floor = SolveOptions {
        growth_limit: Some(GrowthLimit {
            factor: 1.0,
            at_least: free.nodes() * 4,
        }),
        ..SolveOptions::with_tol(1e-6)
    };
    let s = solve(&steep, &[], &Guess::from(&start), &floor).unwrap();
    assert_eq!(s.x, free.x);
}

#[test]
fn a_limit_that_does_not_bind_changes_nothing() {
    let start = smooth_start();
    let steep = Shock { eps: 1e-2 };
    let free = solve(
        &steep,
        &[],
        &Guess::from(&start),
        &SolveOptions::with_tol(1e-6),
    )
    .unwrap();
    let factor = free.nodes() as f64 / start.nodes() as f64 + 1.0;
    let limited = SolveOptions {
        growth_limit: Some(GrowthLimit {
            factor,
            at_least: 2,
        }),
        ..SolveOptions::with_tol(1e-6)
    };
    let s = solve(&steep, &[], &Guess::from(&start), &limited).unwrap();
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

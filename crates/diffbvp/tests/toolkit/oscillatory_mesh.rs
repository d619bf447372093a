//! Mesh control that settles on oscillatory solutions with tens of periods (issue 28, item 5):
//! with default options the solver converges wherever scipy's `solve_bvp` does, with at most
//! 1.2 times scipy's final node count. Before the cycle watch
//! ([`MeshOptions::settle`](diffbvp::mesh::MeshOptions::settle)) the default equidistribution
//! wandered around one mesh size and stopped with "tolerance not met after 40 mesh
//! iterations" on 15 of the 26 cases scipy solves.

use crate::common::{oscillatory_linear_exact, Oscillatory, OscillatoryKind};
use diffbvp::mesh::{linspace, MeshOptions};
use diffbvp::{solve, BvpError, Guess, Solution, SolveOptions};
use OscillatoryKind::{Airy, Linear, Pendulum};

/// scipy's figures: `python3 benches/peers/scipy_oscillatory.py` with scipy 1.17.1, numpy
/// 2.4.6, Python 3.11.7 (guess y = y' = 0 on 5 uniform nodes, bc_tol = tol, max_nodes =
/// 10000): (problem, ε, tol, converged, final nodes, y(0.5)).
const SCIPY: [(OscillatoryKind, f64, f64, bool, usize, f64); 30] = [
    (Linear, 0.01, 1e-3, true, 444, 0.51833740),
    (Linear, 0.01, 1e-6, true, 4447, 0.51815296),
    (Linear, 0.015, 1e-3, true, 289, -1.47372353),
    (Linear, 0.015, 1e-6, true, 2906, -1.47183590),
    (Linear, 0.02, 1e-3, true, 215, 0.50449499),
    (Linear, 0.02, 1e-6, true, 1938, 0.50443764),
    (Linear, 0.03, 1e-3, true, 139, -0.86977077),
    (Linear, 0.03, 1e-6, true, 1438, -0.87019830),
    (Linear, 0.04, 1e-3, true, 111, 0.50110479),
    (Linear, 0.04, 1e-6, true, 989, 0.50110329),
    (Pendulum, 0.01, 1e-3, false, 4053, f64::NAN),
    (Pendulum, 0.01, 1e-6, false, 8749, f64::NAN),
    (Pendulum, 0.015, 1e-3, false, 6128, f64::NAN),
    (Pendulum, 0.015, 1e-6, false, 8749, f64::NAN),
    (Pendulum, 0.02, 1e-3, true, 217, 0.25219220),
    (Pendulum, 0.02, 1e-6, true, 2002, 0.25287165),
    (Pendulum, 0.03, 1e-3, true, 135, -0.25823240),
    (Pendulum, 0.03, 1e-6, true, 1373, -0.25822268),
    (Pendulum, 0.04, 1e-3, true, 102, 0.27454895),
    (Pendulum, 0.04, 1e-6, true, 987, 0.27453879),
    (Airy, 0.01, 1e-3, true, 549, -0.17406121),
    (Airy, 0.01, 1e-6, true, 4935, -0.17547508),
    (Airy, 0.015, 1e-3, true, 351, -0.16778058),
    (Airy, 0.015, 1e-6, true, 3331, -0.16988458),
    (Airy, 0.02, 1e-3, true, 257, -0.94824115),
    (Airy, 0.02, 1e-6, true, 2468, -0.94794302),
    (Airy, 0.03, 1e-3, true, 180, -0.16813922),
    (Airy, 0.03, 1e-6, true, 1638, -0.16949369),
    (Airy, 0.04, 1e-3, true, 128, 0.81388379),
    (Airy, 0.04, 1e-6, true, 1241, 0.81441017),
];

/// scipy's largest error of the linear problem against the exact solution on 20001 points of
/// its interpolant (the same run as [`SCIPY`]): (ε, tol, max |error|).
const SCIPY_LINEAR_ERROR: [(f64, f64, f64); 10] = [
    (0.01, 1e-3, 7.03e-3),
    (0.01, 1e-6, 2.11e-7),
    (0.015, 1e-3, 2.24e-3),
    (0.015, 1e-6, 1.45e-7),
    (0.02, 1e-3, 1.08e-2),
    (0.02, 1e-6, 1.44e-6),
    (0.03, 1e-3, 7.47e-4),
    (0.03, 1e-6, 2.02e-8),
    (0.04, 1e-3, 1.36e-2),
    (0.04, 1e-6, 2.73e-6),
];

fn guess() -> Guess {
    Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0])
}

/// The largest change along the solution of a quantity the equation conserves, relative to
/// its scale: for the pendulum `ε² y'²/2 + 1 − cos y` (energy), for the linear problem
/// `ε² y'² + y²`. On the nodes (an independent check that the solution solves the equation).
fn conserved_drift(kind: OscillatoryKind, eps: f64, s: &Solution) -> Option<f64> {
    let e2 = eps * eps;
    let energy = |y: f64, yp: f64| match kind {
        Linear => Some(e2 * yp * yp + y * y),
        Pendulum => Some(0.5 * e2 * yp * yp + 1.0 - y.cos()),
        Airy => None,
    };
    let values: Vec<f64> = (0..s.nodes())
        .map(|i| energy(s.at_node(i, 0), s.at_node(i, 1)))
        .collect::<Option<_>>()?;
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    Some((hi - lo) / hi)
}

#[test]
fn the_oscillatory_family_converges_where_scipy_does_with_at_most_1_2_times_its_nodes() {
    let mut failures = Vec::new();
    eprintln!(
        "problem    eps     tol   nodes  scipy  ratio  switched  y(0.5)     scipy y(0.5)  check"
    );
    for &(kind, eps, tol, scipy_ok, scipy_nodes, scipy_y) in &SCIPY {
        let problem = Oscillatory { kind, eps };
        let result = solve(&problem, &[], &guess(), &SolveOptions::with_tol(tol));
        let s = match result {
            Ok(s) => s,
            Err(e) => {
                eprintln!("{kind:?} {eps} {tol}: {e}");
                if scipy_ok {
                    failures.push(format!("{kind:?} eps {eps} tol {tol}: {e}"));
                }
                continue;
            }
        };
        assert!(s.rms_residuals.iter().all(|&r| r <= tol));
        let ratio = s.nodes() as f64 / scipy_nodes as f64;
        // the linear problem against its exact solution (on 20001 points, as the peer script);
        // the others by the drift of their conserved quantity (the Airy problem has none)
        let check = match kind {
            Linear => (0..=20000)
                .map(|i| {
                    let x = i as f64 / 20000.0;
                    (s.eval(x)[0] - oscillatory_linear_exact(eps, x)).abs()
                })
                .fold(0.0, f64::max),
            _ => conserved_drift(kind, eps, &s).unwrap_or(f64::NAN),
        };
        let y_half = s.eval(0.5)[0];
        eprintln!(
            "{:<9} {eps:<6} {tol:<6.0e} {:>6} {scipy_nodes:>6} {ratio:>6.2}  {:>8}  {y_half:>9.5}  {:>12.5}  {check:.1e}",
            format!("{kind:?}"),
            s.nodes(),
            s.stats
                .mesh_rule_switched_at
                .map_or("-".to_string(), |k| k.to_string()),
            scipy_y,
        );
        if !scipy_ok {
            continue;
        }
        if ratio > 1.2 {
            failures.push(format!(
                "{kind:?} eps {eps} tol {tol}: {} nodes, scipy {scipy_nodes}",
                s.nodes()
            ));
        }
        match kind {
            // the global error of many periods is far above the local tolerance (the phase
            // error accumulates): compared with scipy's own; with 0.8-0.95 times its nodes
            // (h^4: up to 2.2 times its error) it measured 0.7-3.3 times scipy's error
            Linear => {
                let scipy_err = SCIPY_LINEAR_ERROR
                    .iter()
                    .find(|r| r.0 == eps && r.1 == tol)
                    .map_or(f64::NAN, |r| r.2);
                assert!(
                    check <= 4.0 * scipy_err,
                    "{eps} {tol}: max error {check:e}, scipy's {scipy_err:e}"
                );
            }
            Pendulum => assert!(check < tol, "{eps} {tol}: energy drift {check:e}"),
            Airy => {}
        }
        // the same solution as scipy's where the problem has only one (the pendulum has
        // several near the zero guess: the default options find another one for ε = 0.02
        // and 0.03 than scipy's rule does; both conserve their energy, see `check`)
        if kind != Pendulum {
            let scale = if tol < 1e-4 { 1e-3 } else { 2e-2 };
            assert!(
                (y_half - scipy_y).abs() < scale,
                "{kind:?} {eps} {tol}: y(0.5) = {y_half} against scipy's {scipy_y}"
            );
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn a_cycling_mesh_without_the_switch_names_the_node_counts_and_the_options_to_try() {
    let problem = Oscillatory {
        kind: Linear,
        eps: 0.01,
    };
    let opts = SolveOptions {
        mesh: MeshOptions {
            settle: false,
            ..MeshOptions::default()
        },
        ..SolveOptions::with_tol(1e-3)
    };
    match solve(&problem, &[], &guess(), &opts) {
        Err(BvpError::MeshCycling(c)) => {
            assert_eq!((c.switched_at, c.iterations), (None, 40));
            let (low, high) = (c.low, c.high);
            let m = BvpError::MeshCycling(c).to_string();
            eprintln!("{m}");
            assert!(
                low <= high && high as f64 <= 1.2 * low as f64,
                "{low} {high}"
            );
            assert!(
                m.contains(&format!("cycled between {low} and {high} nodes")),
                "{m}"
            );
            assert!(m.contains("MeshOptions::scipy()"), "{m}");
            assert!(m.contains("ResidualScale::Auto"), "{m}");
            assert!(m.contains("max_mesh_iterations"), "{m}");
        }
        other => panic!("expected MeshCycling, got {other:?}"),
    }
    // with the switch (the default) it settles, and says when it switched
    let s = solve(&problem, &[], &guess(), &SolveOptions::with_tol(1e-3)).unwrap();
    let k = s.stats.mesh_rule_switched_at.expect("a switch");
    assert!(k < s.stats.mesh_refinements + 1, "{k}");
}

#[test]
fn a_cycle_that_scipys_rule_cannot_settle_in_the_budget_says_so() {
    // the switch happens, then the budget runs out before scipy's rule settles
    let problem = Oscillatory {
        kind: Linear,
        eps: 0.01,
    };
    let opts = SolveOptions::with_tol(1e-6);
    let s = solve(&problem, &[], &guess(), &opts).unwrap();
    let k = s.stats.mesh_rule_switched_at.expect("a switch");
    let short = SolveOptions {
        max_mesh_iterations: k + 1,
        ..opts
    };
    match solve(&problem, &[], &guess(), &short) {
        Err(BvpError::MeshCycling(c)) => {
            assert_eq!(c.switched_at, Some(k));
            let m = BvpError::MeshCycling(c).to_string();
            assert!(
                m.contains("scipy's refinement rule, switched to after mesh iteration"),
                "{m}"
            );
            assert!(!m.contains("MeshOptions::scipy()"), "{m}");
            assert!(m.contains("ResidualScale::Auto"), "{m}");
        }
        other => panic!("expected MeshCycling, got {other:?}"),
    }
}

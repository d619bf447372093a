//! Adaptive mesh refinement on layer problems at tol 1e-6: the solve must meet the tolerance on
//! its own mesh with no more nodes than scipy's `solve_bvp` ends on (measured with
//! benches/peers/scipy_solve_bvp.py: Bratu 29, shock layer ε = 1e-3 645, coupled Troesch μ = 5
//! 239) and in at most half the meshes scipy's refinement rule needs from the same guess
//! (Bratu 4 meshes, shock 10, Troesch 7; `diffbvp::mesh::RefineRule::Scipy`).

use crate::common;
use common::{shock_exact, Bratu, CoupledTroesch, Shock};
use diffbvp::mesh::linspace;
use diffbvp::{solve, Guess, Solution, SolveOptions};

const TOL: f64 = 1e-6;

fn opts() -> SolveOptions {
    SolveOptions::with_tol(TOL)
}

/// Meshes solved on: the initial one plus one per mesh change.
fn meshes(s: &Solution) -> usize {
    s.stats.mesh_refinements + 1
}

fn report(name: &str, s: &Solution) {
    let st = &s.stats;
    eprintln!(
        "{name}: {} nodes, {} mesh changes ({} coarsenings), {} Newton iterations, {} factorisations, {} rhs + {} dual evaluations, max rms {:.2e}",
        s.nodes(),
        st.mesh_refinements,
        st.mesh_coarsenings,
        st.newton_iterations,
        st.jacobian_factorizations,
        st.rhs_evaluations,
        st.rhs_dual_evaluations,
        st.max_residual
    );
    assert_eq!(s.rms_residuals.len(), s.nodes() - 1);
    assert!(
        s.rms_residuals.iter().all(|&r| r <= TOL),
        "{name}: an interval above tol"
    );
}

#[test]
fn bratu_nodes_and_passes() {
    let g = Guess::constant(linspace(0.0, 1.0, 5), &[0.0, 0.0]);
    let s = solve(&Bratu { k: 1.0 }, &[], &g, &opts()).unwrap();
    report("bratu", &s);
    assert!(s.nodes() <= 29, "{} nodes", s.nodes());
    assert!(meshes(&s) * 2 <= 4, "{} meshes", meshes(&s));
}

#[test]
fn shock_layer_nodes_and_passes() {
    let g = Guess::constant(linspace(-1.0, 1.0, 5), &[0.0, 0.0]);
    let s = solve(&Shock { eps: 1e-3 }, &[], &g, &opts()).unwrap();
    report("shock", &s);
    assert!(s.nodes() <= 645, "{} nodes", s.nodes());
    // the global error stays that of scipy's mesh (1e-9 at the nodes, benches/peers)
    let err =
        s.x.iter()
            .enumerate()
            .map(|(i, &x)| (s.at_node(i, 0) - shock_exact(1e-3, x)).abs())
            .fold(0.0f64, f64::max);
    eprintln!("shock: max nodal error {err:.2e}");
    assert!(err < 1e-2 * TOL, "max nodal error {err:e}");
    assert!(meshes(&s) * 2 <= 10, "{} meshes", meshes(&s));
}

#[test]
fn coupled_troesch_nodes_and_passes() {
    let g = Guess::from_fn(linspace(0.0, 1.0, 11), 4, |x, y| {
        y[0] = x;
        y[1] = 1.0;
        y[2] = 0.0;
        y[3] = 0.0;
    });
    let s = solve(&CoupledTroesch, &[5.0, 1.0], &g, &opts()).unwrap();
    report("troesch", &s);
    assert!(s.nodes() <= 239, "{} nodes", s.nodes());
    assert!(meshes(&s) * 2 <= 7, "{} meshes", meshes(&s));
}

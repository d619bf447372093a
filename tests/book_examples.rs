//! The book's tutorial examples, run as tests: each example's `run()` is compiled here from the
//! example's own source file, and the claims the book makes about its output are checked.

#[path = "../examples/tutorial_dual_numbers.rs"]
mod tutorial_dual_numbers;

#[path = "../examples/tutorial_continuation.rs"]
mod tutorial_continuation;

#[path = "../examples/tutorial_fit.rs"]
mod tutorial_fit;

#[path = "../examples/tutorial_custom_term.rs"]
mod tutorial_custom_term;

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn dual_numbers_are_exact_where_differences_are_not() {
    let s = tutorial_dual_numbers::run();
    // the book: the dual number agrees with the hand derivative to rounding
    assert!(s.dual_relative_error < 1e-14, "{:e}", s.dual_relative_error);
    // the book: no step size lets forward differences get within 1e-9, central within 1e-12
    assert!(
        s.best_forward_difference_error > 1e-9,
        "{:e}",
        s.best_forward_difference_error
    );
    assert!(
        s.best_central_difference_error > 1e-12,
        "{:e}",
        s.best_central_difference_error
    );
    assert!(rel(s.bratu_df1_dy0, -(0.5f64.exp())) < 1e-15);
}

#[test]
fn continuation_tutorial_reaches_troesch_at_mu_10() {
    let s = tutorial_continuation::run().unwrap();
    assert!(s.direct_failed, "the direct solve was expected to fail");
    assert!(
        (s.slope_at_zero - 3.5833778e-4).abs() < 1e-8,
        "{:e}",
        s.slope_at_zero
    );
    assert!(s.steps.0 >= 2);
    assert!(s.nodes > 11);
}

#[test]
fn fit_tutorial_sensitivities_adjoint_and_fit() {
    let s = tutorial_fit::run().unwrap();
    for j in 0..2 {
        // forward sensitivities agree with differences of re-solves
        assert!(
            rel(s.dy_dp_half[j], s.dy_dp_half_differences[j]) < 1e-6,
            "{j}: {} vs {}",
            s.dy_dp_half[j],
            s.dy_dp_half_differences[j]
        );
        // the adjoint gradient equals the one assembled from forward sensitivities
        assert!(
            rel(s.adjoint[j], s.forward[j]) < 1e-9,
            "{j}: {} vs {}",
            s.adjoint[j],
            s.forward[j]
        );
        assert!(s.standard_errors[j] > 0.0 && s.standard_errors[j] < 0.05);
    }
    // the book: the truth (1.7, 0.4) lies within two standard errors of the estimate
    assert!(
        (s.fitted[0] - 1.7).abs() < 2.0 * s.standard_errors[0],
        "{:?}",
        s.fitted
    );
    assert!(
        (s.fitted[1] - 0.4).abs() < 2.0 * s.standard_errors[1],
        "{:?}",
        s.fitted
    );
    assert!(s.iterations < 30);
}

#[test]
fn custom_term_matches_builtin_radiation() {
    let s = tutorial_custom_term::run().unwrap();
    let [paper, mine, builtin] = &s.diameters;
    let [t_paper, t_mine, t_builtin] = &s.temperatures;
    for i in 0..paper.len() {
        // the user's SI term and the built-in term are the same physics: same solution up to
        // round-off (measured: identical)
        assert!(rel(mine[i], builtin[i]) < 1e-12, "d at {i}");
        assert!(rel(t_mine[i], t_builtin[i]) < 1e-12, "T at {i}");
        assert!(s.user_term[i] < 0.0, "radiation cools");
    }
    // radiation cools the fiber: colder below the nozzle than without it
    assert!(
        t_mine[3] < t_paper[3] - 1.0,
        "{} vs {}",
        t_mine[3],
        t_paper[3]
    );
    // near the nozzle it is of the order of convection (model-closure.md)
    let ratio = s.user_term[0] / s.convection[0];
    assert!(ratio > 0.3 && ratio < 3.0, "radiation/convection = {ratio}");
}

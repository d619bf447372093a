//! The book's tutorial examples, run as tests: each example's `run()` is compiled here from the
//! example's own source file, and the claims the book makes about its output are checked.

#[path = "../examples/tutorial_dual_numbers.rs"]
mod tutorial_dual_numbers;

#[path = "../examples/tutorial_continuation.rs"]
mod tutorial_continuation;

#[path = "../examples/tutorial_fit.rs"]
mod tutorial_fit;

#[path = "../examples/two_layers.rs"]
mod two_layers;

#[test]
fn two_layer_wall_matches_its_closed_forms() {
    // the multipoint example: the flux of two resistances in series, the interface
    // temperature, and its exact sensitivity to a source in the second layer
    if let Err(e) = two_layers::run() {
        panic!("{e}");
    }
}

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

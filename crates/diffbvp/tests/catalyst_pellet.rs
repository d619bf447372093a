//! The catalyst-pellet example (book: "Your own BVP fit"), run as a test: its `run()` is compiled
//! here from the example's own source file and the claims the chapter makes are checked.

#[path = "../examples/catalyst_pellet.rs"]
mod catalyst_pellet;

#[test]
fn pellet_example_numbers_hold() {
    let s = catalyst_pellet::run().unwrap();
    // continuation reached φ = 30; the thin-zone asymptote of a slab,
    // η ≈ (3/φ) sqrt(2 ∫₀¹ R dc) / R(1) (K = 0.8), lies above the sphere's by its O(1/φ)
    // curvature correction (for first order exactly the factor 1 − 1/φ)
    assert_eq!(s.continued_to.0, 30.0);
    let k: f64 = 0.8;
    // ∫₀¹ c/(1+Kc)² dc = (ln(1+K) + 1/(1+K) − 1)/K²
    let int_r = ((1.0 + k).ln() + 1.0 / (1.0 + k) - 1.0) / (k * k);
    let r1 = 1.0 / ((1.0 + k) * (1.0 + k));
    let asymptote = 3.0 / 30.0 * (2.0 * int_r).sqrt() / r1;
    let below = (asymptote - s.continued_to.1) / asymptote;
    assert!(
        below > 0.0 && below < 3.0 / 30.0,
        "η(30) = {} asymptote {asymptote}",
        s.continued_to.1
    );
    // the integral functional against the first-order closed form (tol 1e-8 solves)
    assert!(
        s.first_order_max_rel_error < 1e-7,
        "{:e}",
        s.first_order_max_rel_error
    );
    assert!(s.flux_vs_integral < 1e-7, "{:e}", s.flux_vs_integral);
    // adjoint and forward differentiate the same discrete functional
    assert!(s.adjoint_vs_forward < 1e-9, "{:e}", s.adjoint_vs_forward);
    // the fit: each parameter within two standard errors of the truth, the errors plausible
    for j in 0..2 {
        let (f, t, se) = (s.fitted[j], s.truth[j], s.standard_errors[j]);
        assert!(
            se > 0.0 && se < 0.2 * t,
            "parameter {j}: standard error {se}"
        );
        assert!(
            (f - t).abs() < 2.0 * se,
            "parameter {j}: {f} ± {se}, truth {t}"
        );
    }
    assert!(s.correlation.abs() < 1.0);
    // the design: small pellets (η ≈ 1 whatever the kinetics) carry no information, the chosen
    // size more than a measurement's noise, and adding it shrinks both standard errors
    assert!(s.ratio_at_ends.0 < 0.01, "{}", s.ratio_at_ends.0);
    assert!(s.next_ratio > 0.5, "{}", s.next_ratio);
    assert!(s.next_radius_mm > 3.0, "{}", s.next_radius_mm);
    for j in 0..2 {
        assert!(s.standard_errors_after[j] < s.standard_errors[j]);
    }
}

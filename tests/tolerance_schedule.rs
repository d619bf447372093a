//! The tolerance schedule of the fits (`least_squares::Accuracy::Scheduled`, the rheometer's
//! `IdentifyOptions::loose_tolerance`): loose BVP solves in the inner iterations, full
//! accuracy for the final ones. The estimates and their standard errors must not change by
//! more than 1e-4 of the standard errors against a fit with every solve at the tight tolerance.

use diffbvp::fiber::effects::{Effect, EffectSetting, ModelSpec};
use diffbvp::fiber::input::load_experiments;
use diffbvp::fiber::rheometer::{Estimator, Identification, IdentifyOptions, Rheometer};
use std::path::Path;

fn fit(rh: &Rheometer, loose: Option<f64>) -> Identification {
    let mut o = IdentifyOptions::with_estimator(Estimator::Principled);
    o.loose_tolerance = loose;
    rh.identify([0.7, 11.51], &o).unwrap()
}

/// Compares the scheduled fit with the fixed-tolerance one, parameter by parameter, in units
/// of the fixed fit's standard errors.
fn compare(rh: &Rheometer, label: &str) {
    let fixed = fit(rh, None);
    let scheduled = fit(rh, Some(1e-3));
    assert_eq!(fixed.fit.loose_iterations, 0, "{label}");
    assert!(fixed.fit.switch_model_error.is_none(), "{label}");
    // the schedule was used: loose trial steps, then a switch to full accuracy
    assert!(
        scheduled.fit.loose_iterations > 0,
        "{label}: no loose iteration"
    );
    let err = scheduled.fit.switch_model_error.expect("a switch");
    assert!(err.is_finite(), "{label}");
    let se = fixed.fit.standard_errors().unwrap();
    let se2 = scheduled.fit.standard_errors().unwrap();
    let mut worst: f64 = 0.0;
    for i in 0..se.len() {
        let dp = (scheduled.fit.p[i] - fixed.fit.p[i]).abs() / se[i];
        let dse = (se2[i] - se[i]).abs() / se[i];
        worst = worst.max(dp).max(dse);
        assert!(
            dp <= 1e-4 && dse <= 1e-4,
            "{label}: parameter {i}: estimate moved {dp:.2e} SE, SE changed {dse:.2e} SE"
        );
    }
    eprintln!(
        "{label}: worst change {worst:.2e} SE; iterations {} (fixed) vs {} ({} loose); model \
         error at the switch {err:.2e} (residual units); (n, κ) = ({:.6}, {:.6})",
        fixed.fit.iterations,
        scheduled.fit.iterations,
        scheduled.fit.loose_iterations,
        scheduled.law()[0],
        scheduled.law()[1]
    );
}

#[test]
fn shipped_data_estimates_and_errors_unchanged() {
    let set = load_experiments(Path::new("data/pmma7n_synthetic/experiments.toml")).unwrap();
    let rh = Rheometer::new(&set).unwrap();
    compare(&rh, "pmma7n_synthetic");
}

#[test]
fn radiation_data_with_fitted_radiation_unchanged() {
    let set = load_experiments(Path::new("data/hidden_radiation/experiments.toml")).unwrap();
    let spec = ModelSpec::default().with(EffectSetting::fitted(Effect::Radiation));
    let rh = Rheometer::with_spec(&set, spec).unwrap();
    compare(&rh, "hidden_radiation + radiation");
}

//! The trust region of a fit with effects runs in units of each effect's range
//! (`Layout::x_scale`, `FitOptions::x_scale`): an air speed in m/s is no longer moved by at
//! most 1 m/s per iteration. On data from the independent model with a strong aspirator jet
//! (150 m/s at the take-up, decay length 0.08 m; the inverse-square decay of the fit makes it
//! 386 m/s), the co-flow fitted from 10 m/s reaches the optimum of a fit started at the truth
//! (66 iterations against 19), without running out of iterations (with unit scales
//! such refits of the diagnosis ended at their 100-iteration limit, 4–60 % above the optimum).

use crate::independent;

use diffbvp::least_squares::Termination;
use independent::scenarios;
use rheometer::data::input::load_experiments;
use rheometer::fit::{FitStart, IdentifyOptions, Rheometer};
use rheometer::model::{Effect, EffectSetting, LawChoice, ModelSpec};

#[test]
fn a_far_co_flow_start_reaches_the_optimum_of_the_truth_start() {
    let sc = scenarios::aspirator_strong();
    let set = load_experiments(&sc.generate().unwrap().toml).unwrap();
    // the decay length fitted, the tail of an inverse-square decay fixed (the jet's is a
    // Lorentzian)
    let coflow = Effect::AirCoflow {
        decay_length: None,
        tail: Some(0.5),
    };
    let spec = ModelSpec::new(LawChoice::Carreau).with(EffectSetting::fitted(coflow));
    let rh = Rheometer::with_spec(&set, spec).unwrap();
    let opts = IdentifyOptions::default();
    let start = |v: f64, decay: f64| FitStart {
        strengths: vec![
            ("air_coflow".to_string(), v),
            ("air_coflow.decay_length".to_string(), decay),
        ],
        ..FitStart::at([0.8, 11.7])
    };
    let truth = rh.identify_from(&start(150.0, 0.08), &opts).unwrap();
    let far = rh.identify_from(&start(10.0, 0.05), &opts).unwrap();
    let strength = |id: &rheometer::fit::Identification| {
        id.names
            .iter()
            .position(|n| n == "air_coflow")
            .map(|i| id.fit.p[i])
            .unwrap()
    };
    println!(
        "from 10 m/s: {} iterations ({:?}), J {:.6e}, {:.2} m/s; from the truth: {} iterations, \
         J {:.6e}, {:.2} m/s",
        far.fit.iterations,
        far.fit.termination,
        far.summary.cost,
        strength(&far),
        truth.fit.iterations,
        truth.summary.cost,
        strength(&truth)
    );
    // converged (with unit scales, 375 m/s to travel at 1 m/s per iteration: the 100
    // iterations run out)
    assert_ne!(far.fit.termination, Termination::MaxIterations);
    assert!(
        far.summary.cost <= truth.summary.cost * 1.001,
        "from 10 m/s J {:e}, from the truth {:e}",
        far.summary.cost,
        truth.summary.cost
    );
    assert!(
        (strength(&far) - strength(&truth)).abs() < 0.05 * strength(&truth),
        "{} against {} m/s",
        strength(&far),
        strength(&truth)
    );
}

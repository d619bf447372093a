//! A model with fitted effects never ends worse than the same model without them
//! (`Rheometer::identify_nested`, issue 26), checked on data from the independent model with
//! warm air and an aspirator co-flow for three effects: the plain model held inside the larger
//! one reproduces the plain optimum, and the kept fit is no higher than it nor than the fit
//! from the heuristic start. (On these data the start from the plain optimum ends lowest for
//! all three, by 0.001–0.08 %.)

use crate::independent;

use independent::scenarios;
use rheometer::data::input::load_experiments;
use rheometer::fit::{Estimator, IdentifyOptions, NestedStart, Rheometer};
use rheometer::model::{Effect, EffectSetting, LawChoice, ModelSpec};

#[test]
fn a_fitted_effect_never_leaves_the_fit_worse_than_without_it() {
    let sc = scenarios::warm_air_and_coflow();
    let set = load_experiments(&sc.generate().unwrap().toml).unwrap();
    let opts = IdentifyOptions {
        estimator: Estimator::Principled,
        ..IdentifyOptions::default()
    };
    let plain = Rheometer::with_spec(&set, ModelSpec::new(LawChoice::Carreau)).unwrap();
    let start = plain.start_heuristic(&opts).unwrap().start;
    let j_plain = plain.identify(start, &opts).unwrap().summary.cost;
    for name in ["air_temperature_profile", "air_coflow", "radiation"] {
        let effect: Effect = name.parse().unwrap();
        let spec = ModelSpec::new(LawChoice::Carreau).with(EffectSetting::fitted(effect));
        let rh = Rheometer::with_spec(&set, spec).unwrap();
        let nested = rh.identify_nested(start, &opts).unwrap();
        let j = nested.fit.summary.cost;
        println!(
            "NESTED | {name} | plain J {j_plain:.6e} | from the heuristic start {:?} | kept {j:.6e} \
             ({:?})",
            nested.given_cost, nested.start
        );
        assert_ne!(nested.start, NestedStart::Plain);
        // the plain model's optimum is one start: the kept fit can only be lower
        let j_plain_here = nested.plain_cost().unwrap();
        assert!(
            (j_plain_here - j_plain).abs() <= 1e-6 * j_plain,
            "{name}: the plain model with the effect held neutral gave J {j_plain_here:e}, the \
             plain model {j_plain:e}"
        );
        assert!(
            j <= j_plain * (1.0 + 1e-9),
            "{name}: J {j:e} with the effect fitted is above the plain model's {j_plain:e}"
        );
        if let Some(g) = nested.given_cost {
            assert!(j <= g, "{name}: kept J {j:e} above the given start's {g:e}");
        }
    }
}

//! `uniform_air` (tests only): a uniform air flow along the whole line, `v_air = V`, strength
//! = its speed `V` \[m/s\]. A built-in effect added the way the recipe of
//! [`modifiers`](super) says: this file (the type, its hook, its descriptor standing in for the
//! catalog's) and its line in the registry. The test below simulates it and checks its exact
//! derivative.

use super::{add, AirProfile, Modifier, Values, SLOTS};
use crate::model::catalog::{Category, EffectDescriptor};
use crate::model::contributions::{Coefficients, Strength};
use num_dual::DualNum;

/// Its descriptor (a built-in one lives in the catalog's family file and in
/// [`BUILTIN`](crate::model::catalog::BUILTIN)).
pub(crate) const UNIFORM_AIR: EffectDescriptor = EffectDescriptor {
    unit: "m/s",
    symbol: "V",
    describe: "uniform air flow along the line, strength = its speed",
    search_range: (-20.0, 20.0),
    physical_range: (-10.0, 10.0),
    default_candidate: false,
    ..EffectDescriptor::builtin("uniform_air", Category::Physics)
};

/// The uniform air flow (no settings of its own: setting its strength adds it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct UniformAir;

impl Modifier for UniformAir {
    const EFFECT: &'static EffectDescriptor = &UNIFORM_AIR;

    fn switched_on() -> (Self, [Strength; SLOTS]) {
        (UniformAir, [Strength::Off; SLOTS])
    }

    fn moves_air(&self) -> bool {
        true
    }

    #[inline]
    fn air<D: DualNum<Primitive = f64> + Copy>(
        &self,
        v: Values<'_, D>,
        _s: f64,
        co: &Coefficients,
        air: &mut AirProfile<D>,
    ) {
        if let Some(speed) = v.get(0) {
            add(&mut air.speed, speed * co.si.velocity.recip());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The recipe's test: the effect of this file, registered by its line, is a model parameter
    /// named by its descriptor, neutral at 0 (the paper's model bit for bit), changes the fiber,
    /// and is fitted back from diameters it made.
    #[test]
    fn a_modifier_added_in_one_file_is_fitted() {
        use crate::model::setup::{Air, Experiment, Material};
        use crate::{
            model::bvp::FiberModel, model::contributions::Physics,
            model::material_law::CarreauLike, model::simulate::simulate,
            model::simulate::SimulateOptions,
        };

        let diameters = |physics: Physics| {
            let model = FiberModel::new(
                &Material::pmma7n(),
                &Air::paper(),
                &Experiment::pmma7n_v0p53_p2(),
                CarreauLike::new(),
                physics,
            )
            .unwrap();
            simulate(&model, &[0.8, 11.71], &SimulateOptions::default())
                .unwrap()
                .uniform_profiles(&model, 21)
                .diameter
        };
        let with_speed = |v: f64| {
            let physics = Physics::paper().strength("uniform_air", Strength::Fixed(v));
            diameters(physics.unwrap())
        };

        // setting its strength adds it; its descriptor names the parameter
        let p = Physics::paper()
            .strength("uniform_air", Strength::Parameter(0.0))
            .unwrap();
        assert_eq!(p.strength_parameters(), vec![("uniform_air", 0.0)]);
        assert_eq!(p.strength_of(UNIFORM_AIR.id()), Strength::Parameter(0.0));
        assert!(p.has_air_flow());
        let unknown = Physics::paper().strength("uniform_air.width", Strength::Off);
        let listed = unknown.unwrap_err().to_string();
        assert!(
            listed.contains("vft_t_vf_offset, uniform_air, air_coflow.tail"),
            "{listed}"
        );

        // neutral at 0: the paper's model bit for bit
        let base = diameters(Physics::paper());
        let bits = |d: &[f64]| d.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&with_speed(0.0)), bits(&base));

        // air of 1 m/s against the spinning direction changes the fiber by more than 0.1 %
        let truth = with_speed(-1.0);
        let change = truth
            .iter()
            .zip(&base)
            .map(|(a, b)| (a / b - 1.0).abs())
            .fold(0.0f64, f64::max);
        assert!(change > 1e-3, "largest relative change {change:e}");

        // fitted back: golden-section search of the squared relative misfit over the speed
        let misfit = |v: f64| -> f64 {
            let d = with_speed(v);
            d.iter()
                .zip(&truth)
                .map(|(a, b)| (a / b - 1.0).powi(2))
                .sum()
        };
        let r = (5f64.sqrt() - 1.0) / 2.0;
        let (mut lo, mut hi) = (-3.0, 2.0);
        let (mut a, mut b) = (hi - r * (hi - lo), lo + r * (hi - lo));
        let (mut fa, mut fb) = (misfit(a), misfit(b));
        while hi - lo > 1e-4 {
            if fa < fb {
                (hi, b, fb) = (b, a, fa);
                a = hi - r * (hi - lo);
                fa = misfit(a);
            } else {
                (lo, a, fa) = (a, b, fb);
                b = lo + r * (hi - lo);
                fb = misfit(b);
            }
        }
        let fitted = 0.5 * (lo + hi);
        assert!((fitted + 1.0).abs() < 1e-3, "fitted speed {fitted} m/s");
    }
}

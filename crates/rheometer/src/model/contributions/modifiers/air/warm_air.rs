//! `air_temperature_profile`: warm air near the nozzle,
//! `T_air(s) = T_air + strength · ΔT exp(−s/ℓ)`. Slots: the factor on `ΔT`, the decay length
//! `ℓ` \[m\].

use crate::model::catalog::{EffectDescriptor, AIR_TEMPERATURE_PROFILE, WARM_AIR_DECAY};
use crate::model::contributions::modifiers::{add, AirProfile, Modifier, Part, Values, SLOTS};
use crate::model::contributions::NusseltLaw;
use crate::model::contributions::{Coefficients, Physics, Strength};
use num_dual::DualNum;

/// The warm-air profile with excess `ΔT` \[K\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct WarmAir {
    /// `ΔT` \[K\].
    excess: f64,
}

impl Modifier for WarmAir {
    const EFFECT: &'static EffectDescriptor = &AIR_TEMPERATURE_PROFILE;
    const ADDED_BY: Option<(&'static str, &'static str)> =
        Some(("with_warm_air", "warm-air profile"));

    fn switched_on() -> (Self, [Strength; SLOTS]) {
        warm(1.0, WARM_AIR_DECAY.default)
    }

    #[inline]
    fn air<D: DualNum<Primitive = f64> + Copy>(
        &self,
        v: Values<'_, D>,
        s: f64,
        co: &Coefficients,
        air: &mut AirProfile<D>,
    ) {
        let (Some(f), Some(ell)) = (v.get(0), v.get(1)) else {
            return;
        };
        let decay = (D::from(-s * co.si.length) / ell).exp();
        add(
            &mut air.excess,
            f * decay * (self.excess / co.si.temperature),
        );
    }
}

/// The profile of excess `excess` \[K\] and decay length `length` \[m\].
fn warm(excess: f64, length: f64) -> (WarmAir, [Strength; SLOTS]) {
    (
        WarmAir { excess },
        [Strength::Fixed(1.0), Strength::Fixed(length), Strength::Off],
    )
}

impl<H: NusseltLaw> Physics<H> {
    /// Warm air near the nozzle: `T_air(s) = T_air + ΔT exp(−s/ℓ)`, `excess` = ΔT \[K\],
    /// `length` = ℓ \[m\] (its strength `"air_temperature_profile"`, shape
    /// `"air_temperature_profile.decay_length"`).
    pub fn with_warm_air(mut self, excess: f64, length: f64) -> Self {
        let (k, strengths) = warm(excess, length);
        self.put(Part {
            kind: crate::model::contributions::modifiers::Kind::WarmAir(k),
            strengths,
        });
        self
    }
}

//! `die_temperature_offset`: the melt leaves the die `ΔT` \[K\] off the nominal inlet temperature,
//! `T(0) = T_in + ΔT`. Slot: `ΔT` \[K\].

use crate::model::catalog::{EffectDescriptor, DIE_TEMPERATURE_OFFSET};
use crate::model::contributions::modifiers::{add, InletFactors, Modifier, Values, SLOTS};
use crate::model::contributions::Strength;
use num_dual::DualNum;

/// `die_temperature_offset` (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DieTemperature;

impl Modifier for DieTemperature {
    const EFFECT: &'static EffectDescriptor = &DIE_TEMPERATURE_OFFSET;

    fn switched_on() -> (Self, [Strength; SLOTS]) {
        (DieTemperature, [Strength::Off; SLOTS])
    }

    #[inline]
    fn inlet<D: DualNum<Primitive = f64> + Copy>(
        &self,
        v: Values<'_, D>,
        temperature_scale: f64,
        f: &mut InletFactors<D>,
    ) {
        if let Some(d) = v.get(0) {
            add(&mut f.die_temperature, d * temperature_scale.recip());
        }
    }
}

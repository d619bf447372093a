//! `gauge_scale`: the gauge reads `(1 + g) d` (before its offset); not in the balances, only in the
//! predicted measurement. Slot: `g` \[-\].

use crate::model::catalog::{EffectDescriptor, GAUGE_SCALE};
use crate::model::contributions::modifiers::{Modifier, Values, SLOTS};
use crate::model::contributions::Strength;
use num_dual::DualNum;

/// `gauge_scale` (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GaugeScale;

impl Modifier for GaugeScale {
    const EFFECT: &'static EffectDescriptor = &GAUGE_SCALE;

    fn switched_on() -> (Self, [Strength; SLOTS]) {
        (GaugeScale, [Strength::Off; SLOTS])
    }

    #[inline]
    fn gauge<D: DualNum<Primitive = f64> + Copy>(
        &self,
        v: Values<'_, D>,
        _diameter_scale: f64,
        reading: &mut D,
    ) {
        if let Some(g) = v.get(0) {
            *reading *= g + 1.0;
        }
    }
}

//! `gauge_offset`: the gauge reads `d + o`, `o` in µm (after its scale); not in the balances, only
//! in the predicted measurement. Slot: `o` \[µm\].

use crate::model::catalog::{EffectDescriptor, GAUGE_OFFSET};
use crate::model::contributions::modifiers::{Modifier, Values, SLOTS};
use crate::model::contributions::Strength;
use num_dual::DualNum;

/// `gauge_offset` (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GaugeOffset;

impl Modifier for GaugeOffset {
    const EFFECT: &'static EffectDescriptor = &GAUGE_OFFSET;

    fn switched_on() -> (Self, [Strength; SLOTS]) {
        (GaugeOffset, [Strength::Off; SLOTS])
    }

    #[inline]
    fn gauge<D: DualNum<Primitive = f64> + Copy>(
        &self,
        v: Values<'_, D>,
        diameter_scale: f64,
        reading: &mut D,
    ) {
        if let Some(o) = v.get(0) {
            *reading += o * (1e-6 / diameter_scale);
        }
    }
}

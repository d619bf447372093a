//! `vft_t_vf_offset`: the VFT temperature `T_VF + ΔT_VF`, the level at `T_o` held. Slot: `ΔT_VF`
//! \[K\].

use crate::model::catalog::{EffectDescriptor, VFT_T_VF_OFFSET};
use crate::model::contributions::modifiers::{add, Modifier, Values, SLOTS};
use crate::model::contributions::Strength;
use num_dual::DualNum;

/// `vft_t_vf_offset` (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct VftTvf;

impl Modifier for VftTvf {
    const EFFECT: &'static EffectDescriptor = &VFT_T_VF_OFFSET;

    fn switched_on() -> (Self, [Strength; SLOTS]) {
        (VftTvf, [Strength::Off; SLOTS])
    }

    #[inline]
    fn material<D: DualNum<Primitive = f64> + Copy>(
        &self,
        v: Values<'_, D>,
        temperature_scale: f64,
        shift: &mut [Option<D>; 2],
    ) {
        if let Some(t) = v.get(0) {
            add(&mut shift[1], t * temperature_scale.recip());
        }
    }
}

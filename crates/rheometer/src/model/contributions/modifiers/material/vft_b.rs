//! `vft_b_offset`: the VFT parameter `B + ΔB`, the zero-rate viscosity at the reference temperature
//! `T_o` held (see
//! [`ZeroRateViscosity::eval_shifted`](crate::model::material_law::ZeroRateViscosity::eval_shifted)).
//! Slot: `ΔB` \[K\].

use crate::model::catalog::{EffectDescriptor, VFT_B_OFFSET};
use crate::model::contributions::modifiers::{add, Modifier, Values, SLOTS};
use crate::model::contributions::Strength;
use num_dual::DualNum;

/// `vft_b_offset` (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct VftB;

impl Modifier for VftB {
    const EFFECT: &'static EffectDescriptor = &VFT_B_OFFSET;

    fn switched_on() -> (Self, [Strength; SLOTS]) {
        (VftB, [Strength::Off; SLOTS])
    }

    #[inline]
    fn material<D: DualNum<Primitive = f64> + Copy>(
        &self,
        v: Values<'_, D>,
        temperature_scale: f64,
        shift: &mut [Option<D>; 2],
    ) {
        if let Some(b) = v.get(0) {
            add(&mut shift[0], b * temperature_scale.recip());
        }
    }
}

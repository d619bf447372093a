//! `inlet_diameter`: die swell `δ` \[-\], the inlet diameter `(1 + δ) d_in` at the same mass flow,
//! so `u(0) = u_in/(1 + δ)²`. Slot: `δ`.

use crate::model::catalog::{EffectDescriptor, INLET_DIAMETER};
use crate::model::contributions::modifiers::{InletFactors, Modifier, Values, SLOTS};
use crate::model::contributions::Strength;
use num_dual::DualNum;

/// `inlet_diameter` (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct InletDiameter;

impl Modifier for InletDiameter {
    const EFFECT: &'static EffectDescriptor = &INLET_DIAMETER;

    fn switched_on() -> (Self, [Strength; SLOTS]) {
        (InletDiameter, [Strength::Off; SLOTS])
    }

    #[inline]
    fn inlet<D: DualNum<Primitive = f64> + Copy>(
        &self,
        v: Values<'_, D>,
        _temperature_scale: f64,
        f: &mut InletFactors<D>,
    ) {
        if let Some(d) = v.get(0) {
            let g = d + 1.0;
            f.velocity = Some(f.velocity.unwrap_or(D::one()) / (g * g));
        }
    }
}

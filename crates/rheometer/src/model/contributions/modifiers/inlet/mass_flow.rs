//! `mass_flow_scale`: the true mass flow is `(1 + δ) Q`. Slot: `δ` \[-\].

use crate::model::catalog::{EffectDescriptor, MASS_FLOW_SCALE};
use crate::model::contributions::modifiers::{scale, InletFactors, Modifier, Values, SLOTS};
use crate::model::contributions::Strength;
use num_dual::DualNum;

/// `mass_flow_scale` (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MassFlow;

impl Modifier for MassFlow {
    const EFFECT: &'static EffectDescriptor = &MASS_FLOW_SCALE;

    fn switched_on() -> (Self, [Strength; SLOTS]) {
        (MassFlow, [Strength::Off; SLOTS])
    }

    #[inline]
    fn inlet<D: DualNum<Primitive = f64> + Copy>(
        &self,
        v: Values<'_, D>,
        _temperature_scale: f64,
        f: &mut InletFactors<D>,
    ) {
        if let Some(d) = v.get(0) {
            scale(&mut f.mass_flow, d + 1.0);
        }
    }
}

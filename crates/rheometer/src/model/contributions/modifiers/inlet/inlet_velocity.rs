//! `inlet_velocity`: the relative error `δ` \[-\] of the inlet velocity (die swell), `u(0) = (1 +
//! δ) u_in`. Slot: `δ`.

use crate::model::catalog::{EffectDescriptor, INLET_VELOCITY};
use crate::model::contributions::modifiers::{scale, InletFactors, Modifier, Values, SLOTS};
use crate::model::contributions::Strength;
use num_dual::DualNum;

/// `inlet_velocity` (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct InletVelocity;

impl Modifier for InletVelocity {
    const EFFECT: &'static EffectDescriptor = &INLET_VELOCITY;

    fn switched_on() -> (Self, [Strength; SLOTS]) {
        (InletVelocity, [Strength::Off; SLOTS])
    }

    #[inline]
    fn inlet<D: DualNum<Primitive = f64> + Copy>(
        &self,
        v: Values<'_, D>,
        _temperature_scale: f64,
        f: &mut InletFactors<D>,
    ) {
        if let Some(d) = v.get(0) {
            scale(&mut f.velocity, d + 1.0);
        }
    }
}

impl<H: crate::model::contributions::NusseltLaw> crate::model::contributions::Physics<H> {
    /// Makes the relative inlet-velocity error `δ` (`u(0) = (1 + δ) u_in`) a model parameter
    /// named `"inlet_velocity"` with default value `error` \[-\].
    pub fn with_inlet_velocity_error(mut self, error: f64) -> Self {
        self.put(crate::model::contributions::modifiers::Part {
            kind: crate::model::contributions::modifiers::Kind::InletVelocity(InletVelocity),
            strengths: [Strength::Parameter(error), Strength::Off, Strength::Off],
        });
        self
    }
}

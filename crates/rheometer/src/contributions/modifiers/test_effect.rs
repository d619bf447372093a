//! `uniform_air` (tests only): a uniform air flow along the whole line, `v_air = V`, strength
//! = its speed `V` \[m/s\]. A built-in effect added the way the recipe of
//! [`modifiers`](super) says: this file (the type, its hook, its descriptor standing in for the
//! catalog's) and its line in the registry. The test below simulates it and checks its exact
//! derivative.

use super::{add, AirProfile, Modifier, Values, SLOTS};
use crate::catalog::{Category, EffectDescriptor};
use crate::contributions::{Coefficients, Strength};
use num_dual::DualNum;

/// Its descriptor (a built-in one lives in the catalog's family file and in
/// [`BUILTIN`](crate::catalog::BUILTIN)).
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

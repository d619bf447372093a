//! `air_coflow`: an aspirator co-flow near the take-up, `v_air(s) = strength · V φ_r((L − s)/ℓ)`
//! with the decay `φ_r(u) = (1 + r u)^(−1/r)`: `φ_0(u) = exp(−u)`, an algebraic tail
//! `u^(−1/r)` for `r > 0` (`r = 1/2`: inverse square, as the entrainment towards a sink;
//! `r = 1`: inverse, as a jet). Slots: the factor on `V`, the decay length `ℓ` \[m\], the tail
//! `r` \[-\].

use crate::model::catalog::{EffectDescriptor, AIR_COFLOW, COFLOW_DECAY};
use crate::model::contributions::modifiers::{add, AirProfile, Modifier, Part, Values, SLOTS};
use crate::model::contributions::NusseltLaw;
use crate::model::contributions::{Coefficients, Physics, Strength};
use num_dual::DualNum;

/// The aspirator co-flow with amplitude `V` \[m/s\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CoFlow {
    /// `V` \[m/s\].
    speed: f64,
}

impl Modifier for CoFlow {
    const EFFECT: &'static EffectDescriptor = &AIR_COFLOW;
    const ADDED_BY: Option<(&'static str, &'static str)> = Some(("with_coflow", "air co-flow"));

    fn switched_on() -> (Self, [Strength; SLOTS]) {
        coflow(1.0, COFLOW_DECAY.default)
    }

    fn moves_air(&self) -> bool {
        true
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
        let u = D::from((co.length - s) * co.si.length) / ell;
        let decay = match v.get(2) {
            Some(r) => coflow_decay(u, r),
            None => (-u).exp(),
        };
        add(&mut air.speed, f * decay * (self.speed / co.si.velocity));
    }
}

/// The co-flow of amplitude `speed` \[m/s\] and decay length `length` \[m\], exponential.
fn coflow(speed: f64, length: f64) -> (CoFlow, [Strength; SLOTS]) {
    (
        CoFlow { speed },
        [
            Strength::Fixed(1.0),
            Strength::Fixed(length),
            Strength::Fixed(0.0),
        ],
    )
}

impl<H: NusseltLaw> Physics<H> {
    /// Aspirator co-flow `v_air(s) = V exp(−(L − s)/ℓ)`, `speed` = V \[m/s\], `length` = ℓ \[m\]
    /// (its strength `"air_coflow"`, shapes `"air_coflow.decay_length"` and `"air_coflow.tail"`).
    pub fn with_coflow(mut self, speed: f64, length: f64) -> Self {
        let (k, strengths) = coflow(speed, length);
        self.put(Part {
            kind: crate::model::contributions::modifiers::Kind::CoFlow(k),
            strengths,
        });
        self
    }
}

/// The co-flow's decay `φ_r(u) = (1 + r u)^(−1/r)` at `u = (L − s)/ℓ >= 0`, tail `r >= 0`:
/// `exp(−ln(1 + r u)/r)`, with `ln(1 + x)/r = u (1 − x/2 + x²/3 − …)` for `|x| = |r u| < 10⁻²`
/// (relative error below 10⁻¹⁵), so that `r = 0` gives `exp(−u)` with the right derivative
/// `∂φ/∂r = u² e^(−u)/2` as well.
pub(crate) fn coflow_decay<D: DualNum<Primitive = f64> + Copy>(u: D, r: D) -> D {
    let x = r * u;
    let log = if x.re().abs() < 1e-2 {
        let mut q = x * (1.0 / 7.0) - 1.0 / 6.0;
        q = q * x + 0.2;
        q = q * x - 0.25;
        q = q * x + 1.0 / 3.0;
        q = q * x - 0.5;
        q = q * x + 1.0;
        u * q
    } else {
        x.ln_1p() / r
    };
    (-log).exp()
}

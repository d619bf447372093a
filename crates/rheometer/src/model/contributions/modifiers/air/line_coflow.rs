//! `air_coflow_line`: an air co-flow along the spin line switched on smoothly after an onset,
//! `v_air(s) = strength · V / (1 + exp(−(s − s₀)/w))`, added to the aspirator's. Slots: the
//! factor on `V`, the onset `s₀` \[m\], the ramp width `w` \[m\].

use crate::model::catalog::{
    EffectDescriptor, AIR_COFLOW_LINE, COFLOW_LINE_ONSET, COFLOW_LINE_RAMP,
};
use crate::model::contributions::modifiers::{add, AirProfile, Modifier, Part, Values, SLOTS};
use crate::model::contributions::NusseltLaw;
use crate::model::contributions::{Coefficients, Physics, Strength};
use num_dual::DualNum;

/// The co-flow along the line with speed `V` \[m/s\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LineCoflow {
    /// `V` \[m/s\].
    speed: f64,
}

impl Modifier for LineCoflow {
    const EFFECT: &'static EffectDescriptor = &AIR_COFLOW_LINE;
    const ADDED_BY: Option<(&'static str, &'static str)> =
        Some(("with_line_coflow", "air co-flow along the line"));

    fn switched_on() -> (Self, [Strength; SLOTS]) {
        line(1.0, COFLOW_LINE_ONSET.default, COFLOW_LINE_RAMP.default)
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
        let (Some(f), Some(s0), Some(w)) = (v.get(0), v.get(1), v.get(2)) else {
            return;
        };
        // logistic 1/(1 + e^(−z)) written without overflow for either sign of z
        let z = (-s0 + s * co.si.length) / w;
        let ramp = if z.re() >= 0.0 {
            ((-z).exp() + 1.0).recip()
        } else {
            let e = z.exp();
            e / (e + 1.0)
        };
        add(&mut air.speed, f * ramp * (self.speed / co.si.velocity));
    }
}

/// The co-flow of speed `speed` \[m/s\], onset `onset` \[m\] and ramp width `ramp_width` \[m\].
fn line(speed: f64, onset: f64, ramp_width: f64) -> (LineCoflow, [Strength; SLOTS]) {
    (
        LineCoflow { speed },
        [
            Strength::Fixed(1.0),
            Strength::Fixed(onset),
            Strength::Fixed(ramp_width),
        ],
    )
}

impl<H: NusseltLaw> Physics<H> {
    /// Air co-flow along the line `v_air(s) = V / (1 + exp(−(s − s₀)/w))`, `speed` = V \[m/s\],
    /// `onset` = s₀ \[m\], `ramp_width` = w \[m\] (added to an aspirator co-flow; its strength
    /// `"air_coflow_line"`, shapes `"air_coflow_line.onset"` and `"air_coflow_line.ramp_width"`).
    pub fn with_line_coflow(mut self, speed: f64, onset: f64, ramp_width: f64) -> Self {
        let (k, strengths) = line(speed, onset, ramp_width);
        self.put(Part {
            kind: crate::model::contributions::modifiers::Kind::LineCoflow(k),
            strengths,
        });
        self
    }
}

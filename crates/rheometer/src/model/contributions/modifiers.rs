//! The built-in effects that change the model without adding a force or heat term: the air's
//! speed and temperature along the line, the inlet conditions and the mass flow, the gauge's
//! reading and the material data. Each is a small type in its own file implementing
//! `Modifier` and registered by one line of the registry below; its descriptor in
//! [`catalog`](crate::model::catalog) names its strength (slot 0) and its shape parameters (slots
//! 1.., in the descriptor's order), so nothing else names them.
//!
//! **Adding a built-in effect**: a file here with its type, its `Modifier` impl (the
//! descriptor, how it is switched on, the hook it fills) and, if it has settings of its own, its
//! `Physics::with_*` builder; its line in the registry; its descriptor in the catalog (and its
//! row in the catalog's table). The unit test `a_modifier_added_in_one_file_is_fitted` adds one
//! this way.
//!
//! The registry's order is the order of evaluation and of the parameters in `p`: each
//! modifier's strength and the shapes fitted with it, modifier by modifier, then the shapes that
//! are not (the co-flow's tail). Evaluation is resolved once
//! ([`StrengthPlan`](super::StrengthPlan)) and dispatched by a `match` on `Kind`: no trait
//! objects and no allocation per point.

use super::{Coefficients, Source, Strength};
use crate::model::catalog::EffectDescriptor;
use num_dual::DualNum;
use std::fmt;

mod air;
mod gauge;
mod inlet;
mod material;
#[cfg(test)]
pub(crate) mod test_effect;

#[cfg(test)]
pub(crate) use air::coflow::coflow_decay;

/// Strength slots of a modifier: its strength and up to two shape parameters.
pub(crate) const SLOTS: usize = 3;

/// A modifier's strength and shape values at one evaluation, resolved by the plan.
#[derive(Clone, Copy)]
pub(crate) struct Values<'a, D> {
    sources: &'a [Source; SLOTS],
    sp: &'a [D],
}

impl<D: DualNum<Primitive = f64> + Copy> Values<'_, D> {
    /// Slot `i` (0: the strength, then the shapes); `None` where it is switched off.
    #[inline]
    pub(crate) fn get(&self, i: usize) -> Option<D> {
        self.sources[i].value(self.sp)
    }
}

/// The air along the line as the modifiers build it (dimensionless; `None`: nothing added).
#[derive(Clone, Copy)]
pub(crate) struct AirProfile<D> {
    /// Air temperature over the experiment's uniform one, `T̃_air − T̃_air,0` \[-\].
    pub(crate) excess: Option<D>,
    /// Air speed along the fiber `ṽ_air` \[-\].
    pub(crate) speed: Option<D>,
}

/// The inlet and mass-flow factors as the modifiers build them (`None`: nominal).
#[derive(Clone, Copy)]
pub(crate) struct InletFactors<D> {
    /// Factor on the nominal inlet velocity \[-\].
    pub(crate) velocity: Option<D>,
    /// Die temperature offset `ΔT/T_o` \[-\].
    pub(crate) die_temperature: Option<D>,
    /// Mass-flow factor `1 + δ` \[-\].
    pub(crate) mass_flow: Option<D>,
}

/// `acc + x` (`x` where nothing was added yet).
#[inline]
pub(crate) fn add<D: DualNum<Primitive = f64> + Copy>(acc: &mut Option<D>, x: D) {
    *acc = Some(match *acc {
        Some(a) => a + x,
        None => x,
    });
}

/// `acc · x` (`x` where nothing was multiplied yet).
#[inline]
pub(crate) fn scale<D: DualNum<Primitive = f64> + Copy>(acc: &mut Option<D>, x: D) {
    *acc = Some(match *acc {
        Some(a) => a * x,
        None => x,
    });
}

/// A built-in effect that changes the model without a term of its own. Every hook is a no-op
/// unless the modifier fills it; `v` holds its strength and shapes.
pub(crate) trait Modifier: Copy + fmt::Debug + PartialEq + Send + Sync {
    /// The effect it carries: the descriptor names its strength and shapes.
    const EFFECT: &'static EffectDescriptor;
    /// The builder that adds it and what it is, for the error of a strength set without it;
    /// `None`: setting its strength adds it (it has no settings of its own).
    const ADDED_BY: Option<(&'static str, &'static str)> = None;
    /// The modifier at unit amplitude with its shapes at their defaults, and its slots'
    /// strengths (what [`Physics::enable`](super::Physics::enable) adds).
    fn switched_on() -> (Self, [Strength; SLOTS]);
    /// Whether it moves the air (the Nusselt law then widens the crossing, see
    /// [`COFLOW_INCLINATION_REGULARISATION`](super::COFLOW_INCLINATION_REGULARISATION)).
    fn moves_air(&self) -> bool {
        false
    }
    /// Adds to the air's temperature or speed at `s` (dimensionless position).
    #[inline]
    fn air<D: DualNum<Primitive = f64> + Copy>(
        &self,
        _v: Values<'_, D>,
        _s: f64,
        _co: &Coefficients,
        _air: &mut AirProfile<D>,
    ) {
    }
    /// Changes the inlet conditions or the mass flow (`temperature_scale` = `T_o` \[K\]).
    #[inline]
    fn inlet<D: DualNum<Primitive = f64> + Copy>(
        &self,
        _v: Values<'_, D>,
        _temperature_scale: f64,
        _f: &mut InletFactors<D>,
    ) {
    }
    /// Changes the gauge's reading of the (dimensionless) diameter (`diameter_scale` = `d_o`
    /// \[m\]).
    #[inline]
    fn gauge<D: DualNum<Primitive = f64> + Copy>(
        &self,
        _v: Values<'_, D>,
        _diameter_scale: f64,
        _reading: &mut D,
    ) {
    }
    /// Shifts the VFT parameters `(ΔB/T_o, ΔT_VF/T_o)` (`temperature_scale` = `T_o` \[K\]).
    #[inline]
    fn material<D: DualNum<Primitive = f64> + Copy>(
        &self,
        _v: Values<'_, D>,
        _temperature_scale: f64,
        _shift: &mut [Option<D>; 2],
    ) {
    }
}

/// A registered modifier switched on: its kind, its slots' strengths and its builder (see
/// [`Modifier::ADDED_BY`]).
pub(crate) type Registered = (
    Kind,
    [Strength; SLOTS],
    Option<(&'static str, &'static str)>,
);

/// The registry: one line per built-in modifier, in evaluation and parameter order. Makes
/// [`Kind`] (one variant per modifier) and its dispatch.
macro_rules! registry {
    ($($(#[$meta:meta])* $variant:ident($ty:ty),)*) => {
        /// A registered modifier (its settings in the variant).
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub(crate) enum Kind {
            $($(#[$meta])* #[doc = stringify!($ty)] $variant($ty),)*
        }

        impl Kind {
            /// Its effect's descriptor.
            pub(crate) fn effect(&self) -> &'static EffectDescriptor {
                match self {
                    $($(#[$meta])* Kind::$variant(_) => <$ty as Modifier>::EFFECT,)*
                }
            }

            /// Its position in the registry.
            pub(crate) fn rank(&self) -> usize {
                let mut i = 0;
                $($(#[$meta])* {
                    if matches!(self, Kind::$variant(_)) {
                        return i;
                    }
                    i += 1;
                })*
                i
            }

            /// Whether it moves the air.
            pub(crate) fn moves_air(&self) -> bool {
                match self {
                    $($(#[$meta])* Kind::$variant(k) => k.moves_air(),)*
                }
            }

            /// See [`Modifier::air`].
            #[inline]
            pub(crate) fn air<D: DualNum<Primitive = f64> + Copy>(
                &self,
                v: Values<'_, D>,
                s: f64,
                co: &Coefficients,
                air: &mut AirProfile<D>,
            ) {
                match self {
                    $($(#[$meta])* Kind::$variant(k) => k.air(v, s, co, air),)*
                }
            }

            /// See [`Modifier::inlet`].
            #[inline]
            pub(crate) fn inlet<D: DualNum<Primitive = f64> + Copy>(
                &self,
                v: Values<'_, D>,
                temperature_scale: f64,
                f: &mut InletFactors<D>,
            ) {
                match self {
                    $($(#[$meta])* Kind::$variant(k) => k.inlet(v, temperature_scale, f),)*
                }
            }

            /// See [`Modifier::gauge`].
            #[inline]
            pub(crate) fn gauge<D: DualNum<Primitive = f64> + Copy>(
                &self,
                v: Values<'_, D>,
                diameter_scale: f64,
                reading: &mut D,
            ) {
                match self {
                    $($(#[$meta])* Kind::$variant(k) => k.gauge(v, diameter_scale, reading),)*
                }
            }

            /// See [`Modifier::material`].
            #[inline]
            pub(crate) fn material<D: DualNum<Primitive = f64> + Copy>(
                &self,
                v: Values<'_, D>,
                temperature_scale: f64,
                shift: &mut [Option<D>; 2],
            ) {
                match self {
                    $($(#[$meta])* Kind::$variant(k) => k.material(v, temperature_scale, shift),)*
                }
            }
        }

        /// Every registered modifier switched on ([`Modifier::switched_on`]) with the builder
        /// that adds it ([`Modifier::ADDED_BY`]), in registry order.
        pub(crate) fn registered() -> Vec<Registered> {
            let mut v = Vec::new();
            $($(#[$meta])* {
                let (k, s) = <$ty as Modifier>::switched_on();
                v.push((Kind::$variant(k), s, <$ty as Modifier>::ADDED_BY));
            })*
            v
        }
    };
}

registry! {
    CoFlow(air::coflow::CoFlow),
    LineCoflow(air::line_coflow::LineCoflow),
    WarmAir(air::warm_air::WarmAir),
    InletVelocity(inlet::inlet_velocity::InletVelocity),
    InletDiameter(inlet::inlet_diameter::InletDiameter),
    DieTemperature(inlet::die_temperature::DieTemperature),
    MassFlow(inlet::mass_flow::MassFlow),
    GaugeScale(gauge::gauge_scale::GaugeScale),
    GaugeOffset(gauge::gauge_offset::GaugeOffset),
    VftB(material::vft_b::VftB),
    VftTvf(material::vft_t_vf::VftTvf),
    #[cfg(test)]
    UniformAir(test_effect::UniformAir),
}

/// A modifier in a [`Physics`](super::Physics): its kind and the strengths of its slots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Part {
    pub(crate) kind: Kind,
    pub(crate) strengths: [Strength; SLOTS],
}

impl Part {
    /// Its slots: `(slot, parameter name, fitted with the strength)`, the strength first.
    pub(crate) fn slots(&self) -> impl Iterator<Item = (usize, &'static str, bool)> {
        let e = self.kind.effect();
        std::iter::once((0, e.model_param, true)).chain(
            e.shapes
                .iter()
                .enumerate()
                .map(|(i, s)| (i + 1, s.model_param, s.fitted_with_strength)),
        )
    }

    /// The values of its slots with strength parameters `sp`, resolved by `sources`.
    #[inline]
    pub(crate) fn values<'a, D>(sources: &'a [Source; SLOTS], sp: &'a [D]) -> Values<'a, D> {
        Values { sources, sp }
    }
}

/// `(part, slot)` of every slot of `parts` in parameter order: each part's strength and the
/// shapes fitted with it, then the other shapes.
pub(crate) fn slot_order(parts: &[Part]) -> Vec<(usize, usize, &'static str)> {
    let mut out = Vec::new();
    for fitted in [true, false] {
        for (i, p) in parts.iter().enumerate() {
            for (slot, name, f) in p.slots() {
                if f == fitted {
                    out.push((i, slot, name));
                }
            }
        }
    }
    out
}

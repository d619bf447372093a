//! Candidate effects: named contributions a user's model may lack, each with a **strength
//! parameter** whose neutral value 0 switches it off exactly and which is a model parameter of
//! the [`FiberModel`](crate::fiber::FiberModel) (so derivatives with respect to it are exact,
//! through the dual numbers). Some have **shape parameters** (decay lengths, an onset position),
//! model parameters too, fitted together with the strength unless fixed.
//!
//! Each effect has a [`Category`]: missing **physics**, a **process** condition that differs
//! from the nominal one, an **instrument** (diameter gauge) error, or **material** data (the VFT
//! law) off. Each has a *physical range*
//! ([`Effect::physical_range`], what real spinning lines do) and a wider *search range*
//! ([`Effect::bounds`]) so that a best fit outside physics can be seen and reported
//! ([`Effect::judge`]).
//!
//! | name | strength (unit) | enters as | shape parameters (unit, default, bounds) | category | physical range | neutral |
//! |---|---|---|---|---|---|---|
//! | `strain_thinning` | `1 − n` (-) | Carreau-type law with power index `n = 1 − s` | – | physics | [0, 1] | 0 (Newtonian) |
//! | `radiation` | emissivity `ε` (-) | heat loss `π d ε σ (T⁴ − T_air⁴)` | – | physics | [0, 1] | 0 |
//! | `air_coflow` | amplitude `V` (m/s) | air speed `v_air = V (1 + r (L − s)/ℓ)^(−1/r)` (aspirator near the take-up; `r = 0`: `V exp(−(L − s)/ℓ)`) | `decay_length` ℓ (m, 0.1, [0.01, min(1.5, 1.5 L)]), `tail` r (-, 0, [0, 1]; not fitted: `diagnose` scans 0 and 0.5) | physics | [−50, 400] | 0 |
//! | `air_coflow_line` | speed `V` (m/s) | air speed `v_air = V / (1 + exp(−(s − s₀)/w))` (co-flow along the line after `s₀`) | `onset` s₀ (m, 0.2, [0, L]), `ramp_width` w (m, 0.02, [0.002, min(0.5, L)]) | physics | [−50, 400] | 0 |
//! | `air_temperature_profile` | excess `ΔT` (K) | `T_air(s) = T_air + ΔT exp(−s/ℓ)` | `decay_length` ℓ (m, 0.05, [0.005, min(1, L)]) | physics | [−50, 400] | 0 |
//! | `nusselt_scale` | `s` (-) | Nusselt law `𝒩 → (1 + s) 𝒩` | – | physics | [−0.5, 1] | 0 |
//! | `inlet_diameter` | die swell `δ` (-) | inlet diameter `(1 + δ) d_in` at the same mass flow: `u(0) = u_in/(1 + δ)²` | – | process | [−0.1, 0.6] | 0 |
//! | `inlet_velocity` | relative error `δ` (-) | `u(0) = (1 + δ) u_in` (same physics as `inlet_diameter`; not a default candidate) | – | process | [−0.6, 0.25] | 0 |
//! | `die_temperature_offset` | `ΔT` (K) | `T(0) = T_in + ΔT` (and the melt density there) | – | process | [−30, 30] | 0 |
//! | `mass_flow_scale` | `δ` (-) | true mass flow `(1 + δ) Q` | – | process | [−0.2, 0.2] | 0 |
//! | `gauge_scale` | `g` (-) | measured diameter `(1 + g) d + o` | – | instrument | [−0.1, 0.1] | 0 |
//! | `gauge_offset` | `o` (µm) | measured diameter `(1 + g) d + o` | – | instrument | [−20, 20] | 0 |
//! | `vft_b_offset` | `ΔB` (K) | VFT `B + ΔB`, zero-rate viscosity at `T_o` held (not a default candidate) | – | material | [−400, 400] | 0 |
//! | `vft_t_vf_offset` | `ΔT_VF` (K) | VFT `T_VF + ΔT_VF`, level at `T_o` held (not a default candidate) | – | material | [−30, 15] | 0 |
//! | user term | its own factor (-) | `strength ×` the user's [`FiberTerm`] | – | physics | its bounds | 0 |
//!
//! **Sign conventions.** `die_temperature_offset = +10 K` means the melt leaves the die 10 K
//! *hotter* than the nominal inlet temperature of the experiment file. `gauge_scale = 0.03`
//! means the gauge reads 3% high. `mass_flow_scale = 0.05`: the true mass flow is 5% above the
//! nominal one. A positive co-flow speed blows along the spinning direction (towards the
//! take-up); the air may be faster than the fiber: the drag then pulls the fiber forward and the
//! Nusselt law uses the magnitude of the relative speed.
//!
//! **Process conditions.** `die_temperature_offset`, `mass_flow_scale` and `inlet_diameter` are
//! exactly the model of the experiment file with the inlet temperature, mass flow or inlet
//! diameter changed (the inlet velocity follows from `4 Q/(π ρ(T(0)) d²)` when the file gives the
//! inlet diameter; with an inlet velocity in the file, the mass flow and temperature change the
//! diameter instead). **Instrument** effects do not enter the boundary-value problem, only the
//! predicted measurement.
//!
//! **Strain thinning.** The user's Newtonian model is the Carreau-type law at `n = 1` (where
//! `κ` has no effect). The strength is `s = 1 − n`; its derivative at `s = 0` is
//! `−∂μ_e/∂n = −½ μ_e0 ln(1 + De² (μ_e0 ε̇/K̃)²)`, which depends on the stress scale `K = e^κ`
//! left undetermined by the Newtonian fit: the linearised score uses `κ` =
//! [`STRAIN_THINNING_REFERENCE_KAPPA`]; a refit frees both `n` and `κ` (two parameters in the
//! information criterion).
//!
//! **Settings on the command line** ([`EffectSetting`]): `name` (strength fitted, shapes fitted
//! with it), `name=value` (strength fixed, shapes fixed at their defaults) and, after a colon,
//! shape parameters fixed at a value: `air_coflow:decay_length=0.2` (strength fitted, ℓ fixed),
//! `air_coflow=40:decay_length=0.2` (both fixed), `air_coflow_line:onset=0.3:ramp_width=0.05`.
//! A shape parameter `name.shape` is a model parameter, e.g. `air_coflow.decay_length` \[m\].
//!
//! **The co-flow's tail.** Air drawn towards an aspirator slows with the distance `z = L − s`
//! from it algebraically, not exponentially (as the flow towards a sink, `∝ z⁻²`, or along a
//! jet, `∝ z⁻¹`), and a slow co-flow far upstream still pulls on the slow fiber there. The tail
//! `r` spans these: `(1 + r z/ℓ)^(−1/r)` decays like `z^(−1/r)` far away and is the exponential at
//! `r = 0`. It is a discrete choice of `diagnose` (both 0 and 0.5 are scanned and the better
//! variant refined with `r` held), not a fitted parameter; `fit --with air_coflow:tail=0.5`
//! fixes it.

use crate::fiber::contributions::{Balance, FiberTerm, Physics, Strength};
use crate::fiber::error::FiberError;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;
use std::sync::Arc;

/// Default decay length `ℓ` \[m\] of the aspirator co-flow `V exp(−(L − s)/ℓ)`.
pub const DEFAULT_COFLOW_DECAY_LENGTH: f64 = 0.1;

/// Default decay length `ℓ` \[m\] of the warm-air profile `ΔT exp(−s/ℓ)`.
pub const DEFAULT_WARM_AIR_DECAY_LENGTH: f64 = 0.05;

/// Default onset position `s₀` \[m\] of the co-flow along the line.
pub const DEFAULT_COFLOW_LINE_ONSET: f64 = 0.2;

/// Default (start) ramp width `w` \[m\] of the co-flow along the line.
pub const DEFAULT_COFLOW_LINE_RAMP_WIDTH: f64 = 0.02;

/// `κ = ln(K / 1 Pa)` \[-\] at which the strain-thinning direction of a Newtonian model is taken
/// (the middle of the default κ range (7, 20)).
pub const STRAIN_THINNING_REFERENCE_KAPPA: f64 = 13.5;

/// What kind of cause an effect is (JSON: `"physics"`, `"process"`, `"instrument"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Category {
    /// Physics missing from the model (a term or an environment profile).
    Physics,
    /// A process condition (die temperature, mass flow, inlet diameter) off its nominal value.
    Process,
    /// The diameter gauge reads wrong (scale or offset).
    Instrument,
    /// Material data of the model (the VFT law of the zero-rate viscosity) off.
    Material,
}

impl Category {
    /// Lower-case name (`"physics"`, `"process"`, `"instrument"`, `"material"`).
    pub fn name(&self) -> &'static str {
        match self {
            Category::Physics => "physics",
            Category::Process => "process",
            Category::Instrument => "instrument",
            Category::Material => "material",
        }
    }
}

impl fmt::Display for Category {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A shape parameter of an effect (decay length, onset position, ...): a model parameter named
/// [`model_param`](Self::model_param), in SI units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ShapeParameter {
    /// Name in settings (`decay_length`, `onset`, `ramp_width`).
    pub name: &'static str,
    /// Name of the model parameter (`"<effect>.<name>"`, e.g. `"air_coflow.decay_length"`).
    pub model_param: &'static str,
    /// Unit (`"m"`).
    pub unit: &'static str,
    /// Default (start) value.
    pub default: f64,
    /// Bounds of the value in fits (before [`bounds_for_length`](Self::bounds_for_length)).
    pub bounds: (f64, f64),
    /// Upper bound at most this multiple of the spin-line length `L` (`None`: no such limit).
    pub max_per_length: Option<f64>,
    /// Whether it is fitted with the strength when not fixed (`false`: fixed at its default
    /// unless given).
    pub fitted_with_strength: bool,
    /// Whether `diagnose`'s global search scans it across its range as variants of the effect
    /// (`false`: the scan holds it at its default and only the refinement fits it).
    pub scanned: bool,
    /// What it is, in words.
    pub describe: &'static str,
}

impl ShapeParameter {
    /// The bounds for a spin line of length `length` \[m\]: the upper bound limited to
    /// `max_per_length · L` (never below the lower bound).
    pub fn bounds_for_length(&self, length: f64) -> (f64, f64) {
        let (lo, hi) = self.bounds;
        match self.max_per_length {
            Some(f) if length.is_finite() && length > 0.0 => (lo, hi.min(f * length).max(lo)),
            _ => (lo, hi),
        }
    }
}

const COFLOW_DECAY: ShapeParameter = ShapeParameter {
    name: "decay_length",
    model_param: "air_coflow.decay_length",
    unit: "m",
    default: DEFAULT_COFLOW_DECAY_LENGTH,
    bounds: (0.01, 1.5),
    max_per_length: Some(1.5),
    fitted_with_strength: true,
    scanned: true,
    describe: "decay length of the co-flow away from the take-up",
};

const COFLOW_TAIL: ShapeParameter = ShapeParameter {
    name: "tail",
    model_param: "air_coflow.tail",
    unit: "-",
    default: 0.0,
    bounds: (0.0, 1.0),
    max_per_length: None,
    fitted_with_strength: false,
    scanned: true,
    describe: "tail r of the co-flow's decay away from the take-up, (1 + r z/l)^(-1/r): \
               0 exponential, 0.5 inverse square (entrainment towards a sink), 1 inverse (a jet)",
};

const COFLOW_LINE_ONSET: ShapeParameter = ShapeParameter {
    name: "onset",
    model_param: "air_coflow_line.onset",
    unit: "m",
    default: DEFAULT_COFLOW_LINE_ONSET,
    bounds: (0.0, 2.0),
    max_per_length: Some(1.0),
    fitted_with_strength: true,
    scanned: true,
    describe: "position where the co-flow along the line sets in",
};

const COFLOW_LINE_RAMP: ShapeParameter = ShapeParameter {
    name: "ramp_width",
    model_param: "air_coflow_line.ramp_width",
    unit: "m",
    default: DEFAULT_COFLOW_LINE_RAMP_WIDTH,
    bounds: (0.002, 0.5),
    max_per_length: Some(1.0),
    fitted_with_strength: true,
    scanned: false,
    describe: "width of the logistic ramp of the co-flow along the line",
};

const WARM_AIR_DECAY: ShapeParameter = ShapeParameter {
    name: "decay_length",
    model_param: "air_temperature_profile.decay_length",
    unit: "m",
    default: DEFAULT_WARM_AIR_DECAY_LENGTH,
    bounds: (0.005, 1.0),
    max_per_length: Some(1.0),
    fitted_with_strength: true,
    scanned: true,
    describe: "decay length of the warm air below the nozzle",
};

/// A user-written effect: a [`FiberTerm`] (SI force or heat per length, written once generically
/// over dual numbers) multiplied by its own strength parameter (neutral 0, bounds
/// `bounds`, default `(−10, 10)`; its physical range is its bounds).
#[derive(Clone)]
pub struct UserEffect {
    name: &'static str,
    balance: Balance,
    bounds: (f64, f64),
    add: Arc<dyn Fn(Physics) -> Physics + Send + Sync>,
}

impl UserEffect {
    /// The term `term` in `balance`, named `name` (its strength parameter has the same name).
    pub fn new<T: FiberTerm + Clone + 'static>(
        name: &'static str,
        balance: Balance,
        term: T,
    ) -> Self {
        UserEffect {
            name,
            balance,
            bounds: (-10.0, 10.0),
            add: Arc::new(move |p: Physics| p.with_custom(name, balance, term.clone())),
        }
    }

    /// Sets the bounds of the strength in fits.
    pub fn with_bounds(mut self, lower: f64, upper: f64) -> Self {
        self.bounds = (lower, upper);
        self
    }

    /// The balance the term enters.
    pub fn balance(&self) -> Balance {
        self.balance
    }
}

impl fmt::Debug for UserEffect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "UserEffect({}, {:?})", self.name, self.balance)
    }
}

/// A candidate effect. Shape parameters are `Option<f64>`: `None` fits them with the strength
/// (or keeps the default where the shape is not fitted, see
/// [`ShapeParameter::fitted_with_strength`]), `Some(v)` fixes them at `v`.
#[derive(Debug, Clone)]
pub enum Effect {
    /// `strain_thinning`: Carreau-type law instead of Newtonian, strength `1 − n` \[-\].
    StrainThinning,
    /// `radiation`: grey-body radiation, strength = emissivity ε \[-\].
    Radiation,
    /// `air_coflow`: aspirator co-flow near the take-up, strength = amplitude `V` \[m/s\].
    AirCoflow {
        /// Decay length `ℓ` \[m\] fixed, or `None` (fitted, start [`DEFAULT_COFLOW_DECAY_LENGTH`]).
        decay_length: Option<f64>,
        /// Tail `r` \[-\] of the decay `(1 + r z/ℓ)^(−1/r)` fixed, or `None` (0, the
        /// exponential; not fitted: `diagnose` scans 0 and 0.5, the fit keeps the better).
        tail: Option<f64>,
    },
    /// `air_coflow_line`: co-flow along the line after an onset, strength = speed `V` \[m/s\].
    AirCoflowLine {
        /// Onset `s₀` \[m\] fixed, or `None` (fitted, start [`DEFAULT_COFLOW_LINE_ONSET`]).
        onset: Option<f64>,
        /// Ramp width `w` \[m\] fixed, or `None` (fitted, start [`DEFAULT_COFLOW_LINE_RAMP_WIDTH`];
        /// `diagnose` scans the onset and fits the width only in its refinement).
        ramp_width: Option<f64>,
    },
    /// `air_temperature_profile`: warm air near the nozzle, strength = excess `ΔT` \[K\].
    AirTemperatureProfile {
        /// Decay length `ℓ` \[m\] fixed, or `None` (fitted, start
        /// [`DEFAULT_WARM_AIR_DECAY_LENGTH`]).
        decay_length: Option<f64>,
    },
    /// `nusselt_scale`: `𝒩 → (1 + s) 𝒩`, strength `s` \[-\].
    NusseltScale,
    /// `inlet_velocity`: relative inlet-velocity error δ \[-\], `u(0) = (1 + δ) u_in` (process).
    InletVelocity,
    /// `inlet_diameter`: die swell δ \[-\], inlet diameter `(1 + δ) d_in` at the same mass flow.
    InletDiameter,
    /// `die_temperature_offset`: `T(0) = T_in + ΔT`, strength ΔT \[K\].
    DieTemperatureOffset,
    /// `mass_flow_scale`: true mass flow `(1 + δ) Q`, strength δ \[-\].
    MassFlowScale,
    /// `gauge_scale`: the gauge reads `(1 + g) d + o`, strength `g` \[-\].
    GaugeScale,
    /// `gauge_offset`: the gauge reads `(1 + g) d + o`, strength `o` \[µm\].
    GaugeOffset,
    /// `vft_b_offset`: VFT parameter `B + ΔB`, the zero-rate viscosity at the reference
    /// temperature `T_o` held, strength ΔB \[K\] (material data; not a default candidate).
    VftBOffset,
    /// `vft_t_vf_offset`: VFT temperature `T_VF + ΔT_VF`, the level at `T_o` held, strength
    /// ΔT_VF \[K\] (material data; not a default candidate).
    VftTvfOffset,
    /// A user-written term with its own strength.
    Custom(UserEffect),
}

/// Canonical names of the built-in candidates, in [`Effect::builtin`] order.
pub const BUILTIN_NAMES: [&str; 11] = [
    "strain_thinning",
    "radiation",
    "air_coflow",
    "air_coflow_line",
    "air_temperature_profile",
    "nusselt_scale",
    "inlet_diameter",
    "die_temperature_offset",
    "mass_flow_scale",
    "gauge_scale",
    "gauge_offset",
];

/// Every built-in effect name a setting may use: [`BUILTIN_NAMES`], `inlet_velocity` (the
/// same physics as `inlet_diameter` in another variable, so not a default candidate) and the
/// material-data offsets `vft_b_offset`, `vft_t_vf_offset` (for the error budget and `fit
/// --with`; not default candidates: an error of the temperature dependence of the viscosity is
/// a question for rheometry, not for the spin line).
pub const ALL_NAMES: [&str; 14] = [
    "strain_thinning",
    "radiation",
    "air_coflow",
    "air_coflow_line",
    "air_temperature_profile",
    "nusselt_scale",
    "inlet_diameter",
    "inlet_velocity",
    "die_temperature_offset",
    "mass_flow_scale",
    "gauge_scale",
    "gauge_offset",
    "vft_b_offset",
    "vft_t_vf_offset",
];

impl Effect {
    /// The built-in candidates of `diagnose` (shapes fitted): physics, then process conditions,
    /// then the instrument ([`BUILTIN_NAMES`]).
    pub fn builtin() -> Vec<Effect> {
        vec![
            Effect::StrainThinning,
            Effect::Radiation,
            Effect::AirCoflow {
                decay_length: None,
                tail: None,
            },
            Effect::AirCoflowLine {
                onset: None,
                ramp_width: None,
            },
            Effect::AirTemperatureProfile { decay_length: None },
            Effect::NusseltScale,
            Effect::InletDiameter,
            Effect::DieTemperatureOffset,
            Effect::MassFlowScale,
            Effect::GaugeScale,
            Effect::GaugeOffset,
        ]
    }

    /// Every built-in effect ([`ALL_NAMES`]): [`builtin`](Self::builtin), `inlet_velocity` and
    /// the VFT offsets.
    pub fn all() -> Vec<Effect> {
        let mut v = Self::builtin();
        v.insert(7, Effect::InletVelocity);
        v.extend([Effect::VftBOffset, Effect::VftTvfOffset]);
        v
    }

    /// A user-written effect (see [`UserEffect::new`]).
    pub fn custom<T: FiberTerm + Clone + 'static>(
        name: &'static str,
        balance: Balance,
        term: T,
    ) -> Self {
        Effect::Custom(UserEffect::new(name, balance, term))
    }

    /// Canonical name (CLI, JSON, docs).
    pub fn name(&self) -> &'static str {
        match self {
            Effect::StrainThinning => "strain_thinning",
            Effect::Radiation => "radiation",
            Effect::AirCoflow { .. } => "air_coflow",
            Effect::AirCoflowLine { .. } => "air_coflow_line",
            Effect::AirTemperatureProfile { .. } => "air_temperature_profile",
            Effect::NusseltScale => "nusselt_scale",
            Effect::InletVelocity => "inlet_velocity",
            Effect::InletDiameter => "inlet_diameter",
            Effect::DieTemperatureOffset => "die_temperature_offset",
            Effect::MassFlowScale => "mass_flow_scale",
            Effect::GaugeScale => "gauge_scale",
            Effect::GaugeOffset => "gauge_offset",
            Effect::VftBOffset => "vft_b_offset",
            Effect::VftTvfOffset => "vft_t_vf_offset",
            Effect::Custom(u) => u.name,
        }
    }

    /// Unit of the strength, for reports.
    pub fn unit(&self) -> &'static str {
        match self {
            Effect::AirCoflow { .. } | Effect::AirCoflowLine { .. } => "m/s",
            Effect::AirTemperatureProfile { .. }
            | Effect::DieTemperatureOffset
            | Effect::VftBOffset
            | Effect::VftTvfOffset => "K",
            Effect::GaugeOffset => "µm",
            _ => "-",
        }
    }

    /// Symbol of the strength in messages (`ε`, `V`, `ΔT`, ...).
    pub fn symbol(&self) -> &'static str {
        match self {
            Effect::StrainThinning => "1 - n",
            Effect::Radiation => "ε",
            Effect::AirCoflow { .. } | Effect::AirCoflowLine { .. } => "V",
            Effect::AirTemperatureProfile { .. } | Effect::DieTemperatureOffset => "ΔT",
            Effect::NusseltScale => "s",
            Effect::InletVelocity | Effect::InletDiameter | Effect::MassFlowScale => "δ",
            Effect::GaugeScale => "g",
            Effect::GaugeOffset => "o",
            Effect::VftBOffset => "ΔB",
            Effect::VftTvfOffset => "ΔT_VF",
            Effect::Custom(_) => "factor",
        }
    }

    /// What the strength is, in words.
    pub fn describe(&self) -> &'static str {
        match self {
            Effect::StrainThinning => "strain thinning (Carreau-type law), strength 1 - n",
            Effect::Radiation => "thermal radiation, strength = emissivity",
            Effect::AirCoflow { .. } => {
                "aspirator air co-flow near the take-up, strength = air speed amplitude"
            }
            Effect::AirCoflowLine { .. } => {
                "air co-flow along the spin line after an onset position, strength = air speed"
            }
            Effect::AirTemperatureProfile { .. } => {
                "warm air near the nozzle, strength = air temperature excess"
            }
            Effect::NusseltScale => "scale on the Nusselt law, strength s in (1 + s) Nu",
            Effect::InletVelocity => "inlet-velocity error, strength = relative error",
            Effect::InletDiameter => {
                "inlet diameter (die swell) off, strength = relative diameter error"
            }
            Effect::DieTemperatureOffset => {
                "melt temperature at the die off the nominal inlet temperature, strength = offset"
            }
            Effect::MassFlowScale => "mass flow off its nominal value, strength = relative error",
            Effect::GaugeScale => "diameter gauge scale error, strength = relative error",
            Effect::GaugeOffset => "diameter gauge zero offset, strength = offset",
            Effect::VftBOffset => {
                "VFT parameter B off (viscosity at T_o held), strength = offset of B"
            }
            Effect::VftTvfOffset => {
                "VFT temperature T_VF off (viscosity at T_o held), strength = offset of T_VF"
            }
            Effect::Custom(_) => "user-written contribution, strength = its factor",
        }
    }

    /// Physics missing, process condition off, instrument error, or material data off.
    pub fn category(&self) -> Category {
        match self {
            Effect::InletVelocity
            | Effect::InletDiameter
            | Effect::DieTemperatureOffset
            | Effect::MassFlowScale => Category::Process,
            Effect::GaugeScale | Effect::GaugeOffset => Category::Instrument,
            Effect::VftBOffset | Effect::VftTvfOffset => Category::Material,
            _ => Category::Physics,
        }
    }

    /// Neutral strength (the effect is absent): 0 for every effect.
    pub fn neutral(&self) -> f64 {
        0.0
    }

    /// Search range of the strength in fits (wider than the
    /// [`physical_range`](Self::physical_range), so that a best fit outside physics shows).
    pub fn bounds(&self) -> (f64, f64) {
        match self {
            Effect::StrainThinning => (0.0, 1.0),
            Effect::Radiation => (-0.5, 2.0),
            Effect::AirCoflow { .. } | Effect::AirCoflowLine { .. } => (-100.0, 600.0),
            Effect::AirTemperatureProfile { .. } => (-60.0, 600.0),
            Effect::NusseltScale => (-0.9, 3.0),
            Effect::InletVelocity => (-0.7, 1.0),
            Effect::InletDiameter => (-0.3, 1.0),
            Effect::DieTemperatureOffset => (-60.0, 60.0),
            Effect::MassFlowScale => (-0.5, 0.5),
            Effect::GaugeScale => (-0.3, 0.3),
            Effect::GaugeOffset => (-50.0, 50.0),
            Effect::VftBOffset => (-1000.0, 1000.0),
            // the VFT law is singular at T = T_VF, and the fiber cools towards the air (about
            // 290–300 K against T_VF ≈ 273 K for PMMA): raising T_VF is searched less far
            Effect::VftTvfOffset => (-60.0, 15.0),
            Effect::Custom(u) => u.bounds,
        }
    }

    /// Range of the strength that real spinning lines show (in the strength's unit).
    pub fn physical_range(&self) -> (f64, f64) {
        match self {
            Effect::StrainThinning => (0.0, 1.0),
            Effect::Radiation => (0.0, 1.0),
            Effect::AirCoflow { .. } | Effect::AirCoflowLine { .. } => (-50.0, 400.0),
            Effect::AirTemperatureProfile { .. } => (-50.0, 400.0),
            Effect::NusseltScale => (-0.5, 1.0),
            Effect::InletVelocity => (-0.6, 0.25),
            Effect::InletDiameter => (-0.1, 0.6),
            Effect::DieTemperatureOffset => (-30.0, 30.0),
            Effect::MassFlowScale => (-0.2, 0.2),
            Effect::GaugeScale => (-0.1, 0.1),
            Effect::GaugeOffset => (-20.0, 20.0),
            Effect::VftBOffset => (-400.0, 400.0),
            Effect::VftTvfOffset => (-30.0, 15.0),
            Effect::Custom(u) => u.bounds,
        }
    }

    /// Whether `value` (a strength in the effect's unit) is physical, in words: `None` inside
    /// the [`physical_range`](Self::physical_range), else e.g. `"radiation would need ε = 2 > 1:
    /// not physical"`. A non-finite value is never physical.
    pub fn judge(&self, value: f64) -> Option<String> {
        let (lo, hi) = self.physical_range();
        let unit = match self.unit() {
            "-" => String::new(),
            u => format!(" {u}"),
        };
        let what = format!(
            "{} would need {} = {}{unit}",
            self.name(),
            self.symbol(),
            g(value)
        );
        if !value.is_finite() {
            Some(format!("{what}: not a number, not physical"))
        } else if value > hi {
            Some(format!("{what} > {}{unit}: not physical", g(hi)))
        } else if value < lo {
            Some(format!("{what} < {}{unit}: not physical", g(lo)))
        } else {
            None
        }
    }

    /// The effect's shape parameters (empty for most).
    pub fn shape_parameters(&self) -> Vec<ShapeParameter> {
        match self {
            Effect::AirCoflow { .. } => vec![COFLOW_DECAY, COFLOW_TAIL],
            Effect::AirCoflowLine { .. } => vec![COFLOW_LINE_ONSET, COFLOW_LINE_RAMP],
            Effect::AirTemperatureProfile { .. } => vec![WARM_AIR_DECAY],
            _ => Vec::new(),
        }
    }

    /// Each shape parameter with its fixed value (`None`: not fixed), in
    /// [`shape_parameters`](Self::shape_parameters) order.
    pub fn shape_settings(&self) -> Vec<(ShapeParameter, Option<f64>)> {
        match self {
            Effect::AirCoflow { decay_length, tail } => {
                vec![(COFLOW_DECAY, *decay_length), (COFLOW_TAIL, *tail)]
            }
            Effect::AirCoflowLine { onset, ramp_width } => {
                vec![(COFLOW_LINE_ONSET, *onset), (COFLOW_LINE_RAMP, *ramp_width)]
            }
            Effect::AirTemperatureProfile { decay_length } => {
                vec![(WARM_AIR_DECAY, *decay_length)]
            }
            _ => Vec::new(),
        }
    }

    /// The shape parameters a fit frees with the strength (not fixed and
    /// [`fitted_with_strength`](ShapeParameter::fitted_with_strength)).
    pub fn free_shapes(&self) -> Vec<ShapeParameter> {
        self.shape_settings()
            .into_iter()
            .filter(|(s, v)| v.is_none() && s.fitted_with_strength)
            .map(|(s, _)| s)
            .collect()
    }

    /// The value of every shape parameter in the model (fixed value or default).
    pub fn shape_values(&self) -> Vec<(ShapeParameter, f64)> {
        self.shape_settings()
            .into_iter()
            .map(|(s, v)| (s, v.unwrap_or(s.default)))
            .collect()
    }

    /// The effect with shape parameter `name` fixed at `value` (must lie within its bounds);
    /// errors name the shape parameter.
    pub fn with_shape(mut self, name: &str, value: f64) -> Result<Effect, String> {
        let shapes = self.shape_parameters();
        let Some(sp) = shapes.iter().find(|s| s.name == name) else {
            return Err(if shapes.is_empty() {
                format!("{} has no shape parameters (got \"{name}\")", self.name())
            } else {
                format!(
                    "{} has no shape parameter \"{name}\"; its shape parameters are {}",
                    self.name(),
                    shapes.iter().map(|s| s.name).collect::<Vec<_>>().join(", ")
                )
            });
        };
        let (lo, hi) = sp.bounds;
        if !(value.is_finite() && value >= lo && value <= hi) {
            let unit = match sp.unit {
                "-" => String::new(),
                u => format!(" {u}"),
            };
            return Err(format!(
                "{}:{name} = {value} is outside its admissible range [{lo}, {hi}]{unit}",
                self.name()
            ));
        }
        match (&mut self, name) {
            (Effect::AirCoflow { decay_length, .. }, "decay_length") => *decay_length = Some(value),
            (Effect::AirCoflow { tail, .. }, "tail") => *tail = Some(value),
            (Effect::AirTemperatureProfile { decay_length }, "decay_length") => {
                *decay_length = Some(value)
            }
            (Effect::AirCoflowLine { onset, .. }, "onset") => *onset = Some(value),
            (Effect::AirCoflowLine { ramp_width, .. }, "ramp_width") => *ramp_width = Some(value),
            _ => return Err(format!("{} has no shape parameter \"{name}\"", self.name())),
        }
        Ok(self)
    }

    /// Parameters a refit with the effect adds: its strength and the shapes fitted with it
    /// (`strain_thinning`: `n` and `κ`, the stress scale a Newtonian model leaves free).
    pub fn extra_parameters(&self) -> usize {
        match self {
            Effect::StrainThinning => 2,
            _ => 1 + self.free_shapes().len(),
        }
    }

    /// Name of the model parameter (in [`FiberModel::param_names`](crate::fiber::FiberModel::param_names))
    /// that carries the strength.
    pub fn model_param(&self) -> &'static str {
        match self {
            Effect::StrainThinning => "n",
            // one name per effect: the strength parameter carries the effect's name
            _ => self.name(),
        }
    }

    /// Model-parameter value for a strength (`1 − s` for `strain_thinning`, `1 + s` for
    /// `nusselt_scale`, `s` otherwise).
    pub fn param_value(&self, strength: f64) -> f64 {
        match self {
            Effect::StrainThinning => 1.0 - strength,
            Effect::NusseltScale => 1.0 + strength,
            _ => strength,
        }
    }

    /// Strength for a model-parameter value (inverse of [`param_value`](Self::param_value)).
    pub fn strength_of(&self, param: f64) -> f64 {
        match self {
            Effect::StrainThinning => 1.0 - param,
            Effect::NusseltScale => param - 1.0,
            _ => param,
        }
    }

    /// `d(model parameter)/d(strength)`: ±1.
    pub fn param_per_strength(&self) -> f64 {
        match self {
            Effect::StrainThinning => -1.0,
            _ => 1.0,
        }
    }

    /// Adds the effect to `physics` at its neutral strength, as a model parameter (nothing for
    /// `strain_thinning`, which lives in the law), with its shape parameters as model parameters
    /// at their fixed or default values. Errors if the strength cannot be named in `physics`
    /// (a user effect whose term does not carry its name).
    pub fn apply(&self, physics: Physics) -> Result<Physics, FiberError> {
        let par = Strength::Parameter(self.param_value(self.neutral()));
        let added = match self {
            Effect::StrainThinning => return Ok(physics),
            Effect::Radiation => physics.with_radiation(1.0),
            Effect::AirCoflow { .. } => physics.with_coflow(1.0, DEFAULT_COFLOW_DECAY_LENGTH),
            Effect::AirCoflowLine { .. } => physics.with_line_coflow(
                1.0,
                DEFAULT_COFLOW_LINE_ONSET,
                DEFAULT_COFLOW_LINE_RAMP_WIDTH,
            ),
            Effect::AirTemperatureProfile { .. } => {
                physics.with_warm_air(1.0, DEFAULT_WARM_AIR_DECAY_LENGTH)
            }
            Effect::Custom(u) => (u.add)(physics),
            _ => physics,
        };
        // a user effect whose name is taken by another strength is refused by
        // `ModelSpec::validate`; here a missing strength is an error, not a panic
        let mut p = added.strength(self.model_param(), par)?;
        for (s, v) in self.shape_values() {
            p.set_strength(s.model_param, Strength::Parameter(v))?;
        }
        Ok(p)
    }
}

/// A number in short form for messages.
fn g(v: f64) -> String {
    if v == v.trunc() && v.abs() < 1e6 {
        format!("{v}")
    } else {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

impl Effect {
    /// Adds the effect to `physics` at `strength` (in the effect's unit, see
    /// [`unit`](Self::unit)) — e.g. a fitted strength from a fit report — with its shape
    /// parameters at their fixed or default values. Errors for `strain_thinning`, which is not a
    /// term of the physics but the law's `n = 1 − strength`, and for a strength outside the
    /// search range [`bounds`](Self::bounds).
    pub fn apply_at(&self, physics: Physics, strength: f64) -> Result<Physics, String> {
        if matches!(self, Effect::StrainThinning) {
            return Err(
                "strain_thinning is the viscosity law's n = 1 - strength; set n instead".into(),
            );
        }
        let (lo, hi) = self.bounds();
        if !(strength.is_finite() && strength >= lo && strength <= hi) {
            return Err(format!(
                "{} = {strength} is outside its admissible range [{lo}, {hi}] {}",
                self.name(),
                self.unit()
            ));
        }
        let par = Strength::Parameter(self.param_value(strength));
        self.apply(physics)
            .and_then(|p| p.strength(self.model_param(), par))
            .map_err(|e| e.to_string())
    }
}

/// The paper's physics plus `effects` at the given strengths (e.g. the effects of a fit
/// report); errors name an effect whose strength is inadmissible.
pub fn physics_with(effects: &[(Effect, f64)]) -> Result<Physics, String> {
    effects
        .iter()
        .try_fold(Physics::paper(), |p, (e, v)| e.apply_at(p, *v))
}

impl FromStr for Effect {
    type Err = String;
    /// A built-in effect by name ([`ALL_NAMES`]), shapes not fixed.
    fn from_str(s: &str) -> Result<Self, String> {
        let s = s.trim();
        Effect::all()
            .into_iter()
            .find(|e| e.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown effect \"{s}\"; the candidates are {}",
                    ALL_NAMES.join(", ")
                )
            })
    }
}

/// An effect in a model: its strength fitted (`value: None`) or fixed.
#[derive(Debug, Clone)]
pub struct EffectSetting {
    /// The effect (its fixed shape parameters included).
    pub effect: Effect,
    /// Fixed strength, or `None` to fit it.
    pub value: Option<f64>,
}

impl EffectSetting {
    /// The effect with its strength fitted.
    pub fn fitted(effect: Effect) -> Self {
        EffectSetting {
            effect,
            value: None,
        }
    }

    /// The effect with a fixed strength.
    pub fn fixed(effect: Effect, value: f64) -> Self {
        EffectSetting {
            effect,
            value: Some(value),
        }
    }
}

fn parse_number(token: &str, what: &str, whole: &str) -> Result<f64, String> {
    let x: f64 = token
        .trim()
        .parse()
        .map_err(|_| format!("\"{token}\" is not a number (in \"{whole}\")"))?;
    if !x.is_finite() {
        return Err(format!("the {what} in \"{whole}\" is not finite"));
    }
    Ok(x)
}

impl FromStr for EffectSetting {
    type Err = String;
    /// `name` (fitted) or `name=value` (fixed), e.g. `radiation=0.9`, optionally followed by
    /// shape parameters fixed at values, each after a colon: `air_coflow:decay_length=0.2`,
    /// `air_coflow=40:decay_length=0.2`. Errors name the bad token.
    fn from_str(s: &str) -> Result<Self, String> {
        let mut tokens = s.split(':');
        let head = tokens.next().unwrap_or_default();
        let (name, value) = match head.split_once('=') {
            Some((n, v)) => (n, Some(parse_number(v, "strength", s)?)),
            None => (head, None),
        };
        let mut effect: Effect = name.parse()?;
        if let Some(x) = value {
            let (lo, hi) = effect.bounds();
            if x < lo || x > hi {
                return Err(format!(
                    "{} = {x} is outside its admissible range [{lo}, {hi}] {}",
                    effect.name(),
                    effect.unit()
                ));
            }
        }
        for token in tokens {
            let Some((shape, v)) = token.split_once('=') else {
                return Err(format!(
                    "\"{token}\" in \"{s}\": give a shape parameter as SHAPE=VALUE \
                     (e.g. {}:decay_length=0.2)",
                    effect.name()
                ));
            };
            let x = parse_number(v, shape.trim(), s)?;
            effect = effect
                .with_shape(shape.trim(), x)
                .map_err(|e| format!("\"{token}\" in \"{s}\": {e}"))?;
        }
        Ok(EffectSetting { effect, value })
    }
}

/// The viscosity law of a user's model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LawChoice {
    /// Newtonian (`n = 1`); strain thinning is a candidate.
    Newtonian,
    /// The paper's Carreau-type law with `(n, κ)` fitted.
    #[default]
    Carreau,
}

impl FromStr for LawChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "newtonian" => Ok(LawChoice::Newtonian),
            "carreau" => Ok(LawChoice::Carreau),
            o => Err(format!(
                "unknown model \"{o}\"; expected newtonian or carreau"
            )),
        }
    }
}

/// A model for the rheometer: the law, the effects it has (fitted or fixed) and the candidates
/// carried along at neutral strength (present as parameters so that sensitivities with respect
/// to them come with every solve, but neither fitted nor changing the model).
#[derive(Debug, Clone)]
pub struct ModelSpec {
    /// The viscosity law.
    pub law: LawChoice,
    /// Effects in the model.
    pub effects: Vec<EffectSetting>,
    /// Candidates at neutral strength.
    pub candidates: Vec<Effect>,
}

impl Default for ModelSpec {
    /// The paper's model: Carreau-type law, no extra effects.
    fn default() -> Self {
        ModelSpec {
            law: LawChoice::Carreau,
            effects: Vec::new(),
            candidates: Vec::new(),
        }
    }
}

impl ModelSpec {
    /// The paper's physics with `law`.
    pub fn new(law: LawChoice) -> Self {
        ModelSpec {
            law,
            ..Default::default()
        }
    }

    /// Adds an effect (fitted or fixed).
    pub fn with(mut self, setting: EffectSetting) -> Self {
        self.effects.push(setting);
        self
    }

    /// Whether an effect named `name` is in the model or a candidate.
    pub fn contains(&self, name: &str) -> bool {
        self.effects.iter().any(|e| e.effect.name() == name)
            || self.candidates.iter().any(|e| e.name() == name)
    }

    /// Adds `effects` as neutral candidates, skipping those already present (and
    /// `strain_thinning` for a Carreau law, which has it).
    pub fn with_candidates(mut self, effects: &[Effect]) -> Self {
        for e in effects {
            if self.contains(e.name())
                || (self.law == LawChoice::Carreau && matches!(e, Effect::StrainThinning))
            {
                continue;
            }
            self.candidates.push(e.clone());
        }
        self
    }

    /// Checks for duplicate effects and `strain_thinning` in a Carreau model.
    pub fn validate(&self) -> Result<(), String> {
        let mut names: Vec<&str> = Vec::new();
        for e in self
            .effects
            .iter()
            .map(|s| &s.effect)
            .chain(self.candidates.iter())
        {
            if names.contains(&e.name()) {
                return Err(format!("effect {} given twice", e.name()));
            }
            if let Effect::Custom(u) = e {
                let paper = Physics::paper();
                let taken = ALL_NAMES.contains(&u.name)
                    || u.name.contains('.')
                    || paper.terms.iter().any(|t| t.name == u.name)
                    || paper
                        .strength_parameters()
                        .iter()
                        .any(|(n, _)| *n == u.name)
                    || ["n", "kappa"].contains(&u.name);
                if taken {
                    return Err(format!(
                        "user effect \"{}\": the name is taken by a built-in term or effect; \
                         choose another",
                        u.name
                    ));
                }
            }
            if self.law == LawChoice::Carreau && matches!(e, Effect::StrainThinning) {
                return Err(
                    "strain_thinning is already part of the Carreau model (use --model newtonian)"
                        .into(),
                );
            }
            names.push(e.name());
        }
        Ok(())
    }

    /// The physics: the paper's terms plus every effect and candidate at neutral strength (an
    /// error names a strength that cannot be set; run [`validate`](Self::validate) first).
    pub fn physics(&self) -> Result<Physics, FiberError> {
        self.effects
            .iter()
            .map(|s| &s.effect)
            .chain(self.candidates.iter())
            .try_fold(Physics::paper(), |p, e| e.apply(p))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn search_ranges_contain_physical_ranges_and_neutral() {
        for e in Effect::all() {
            let (lo, hi) = e.bounds();
            let (plo, phi) = e.physical_range();
            assert!(lo <= plo && plo <= phi && phi <= hi, "{}", e.name());
            assert!((plo..=phi).contains(&e.neutral()), "{}", e.name());
            for s in e.shape_parameters() {
                assert!(
                    s.bounds.0 <= s.default && s.default <= s.bounds.1,
                    "{}",
                    s.name
                );
                assert!(s.model_param.starts_with(e.name()));
            }
        }
        assert_eq!(Effect::all().len(), ALL_NAMES.len());
        let names: Vec<&str> = Effect::builtin().iter().map(|e| e.name()).collect();
        assert_eq!(names, BUILTIN_NAMES);
    }

    #[test]
    fn judge_words_and_shape_bounds_for_length() {
        assert_eq!(
            Effect::Radiation.judge(2.0).as_deref(),
            Some("radiation would need ε = 2 > 1: not physical")
        );
        assert_eq!(
            Effect::GaugeOffset.judge(-25.0).as_deref(),
            Some("gauge_offset would need o = -25 µm < -20 µm: not physical")
        );
        assert!(Effect::MassFlowScale.judge(0.1).is_none());
        assert_eq!(COFLOW_DECAY.bounds_for_length(0.5), (0.01, 0.75));
        assert_eq!(WARM_AIR_DECAY.bounds_for_length(2.0), (0.005, 1.0));
        assert_eq!(
            COFLOW_DECAY.bounds_for_length(f64::NAN),
            COFLOW_DECAY.bounds
        );
    }

    #[test]
    fn shapes_fixed_by_settings_are_not_freed() {
        let s: EffectSetting = "air_coflow_line:onset=0.25".parse().unwrap();
        // the fixed onset is not fitted; the ramp width (not given) still is
        let free: Vec<_> = s
            .effect
            .free_shapes()
            .iter()
            .map(|f| f.model_param)
            .collect();
        assert_eq!(free, ["air_coflow_line.ramp_width"]);
        let vals: Vec<f64> = s.effect.shape_values().iter().map(|v| v.1).collect();
        assert_eq!(vals, [0.25, DEFAULT_COFLOW_LINE_RAMP_WIDTH]);
        let both: EffectSetting = "air_coflow_line:onset=0.25:ramp_width=0.05"
            .parse()
            .unwrap();
        assert!(both.effect.free_shapes().is_empty());
        let free = Effect::AirCoflow {
            decay_length: None,
            tail: None,
        }
        .free_shapes();
        assert_eq!(free.len(), 1);
        assert_eq!(free[0].model_param, "air_coflow.decay_length");
    }
}

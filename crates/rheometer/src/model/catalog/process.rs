//! Built-in effects of the category process: a process condition off its nominal value (the
//! experiment file's inlet diameter, inlet velocity, die temperature or mass flow). Each is
//! exactly the model of the experiment file with that condition changed, and each is an
//! error-budget source.

use super::descriptor::{one_per_unit, BudgetSource, Category, EffectDescriptor, Scope};
use crate::model::setup::{Experiment, Inlet};

/// The effect `inlet_diameter` is the relative error of `d_in` itself (at the same mass flow;
/// `u_in = 4Q/(πρ d_in²)` follows): it applies where the experiment gives `d_in`.
fn from_inlet_diameter(e: &Experiment) -> Option<f64> {
    matches!(e.inlet, Inlet::Diameter(_)).then_some(1.0)
}

/// `inlet_velocity` applies where the experiment gives `u_in`.
fn from_inlet_velocity(e: &Experiment) -> Option<f64> {
    matches!(e.inlet, Inlet::Velocity(_)).then_some(1.0)
}

const DIE_SWELL_CHECK: &str =
    "measure the die swell (the diameter just below the die, e.g. on a photograph)";

/// `inlet_diameter`: die swell `δ` \[-\], inlet diameter `(1 + δ) d_in` at the same mass flow,
/// `u(0) = u_in/(1 + δ)²`.
pub const INLET_DIAMETER: EffectDescriptor = EffectDescriptor {
    symbol: "δ",
    describe: "inlet diameter (die swell) off, strength = relative diameter error",
    search_range: (-0.3, 1.0),
    physical_range: (-0.1, 0.6),
    independent_check: Some(DIE_SWELL_CHECK),
    budget: Some(BudgetSource {
        key: "inlet_diameter_rel",
        unit: "-",
        what: "inlet diameter",
        word_unit: ("%", 0.01),
        default: 0.02,
        max: 0.5,
        scope: Scope::Common,
        per_unit: from_inlet_diameter,
        fallback: None,
        remedy: "measure the swollen strand below the die or add inlet_diameter to the fit",
    }),
    ..EffectDescriptor::builtin("inlet_diameter", Category::Process)
};

/// `inlet_velocity`: relative inlet-velocity error `δ` \[-\], `u(0) = (1 + δ) u_in` (the same
/// physics as `inlet_diameter` in another variable, so not a default candidate).
pub const INLET_VELOCITY: EffectDescriptor = EffectDescriptor {
    symbol: "δ",
    describe: "inlet-velocity error, strength = relative error",
    search_range: (-0.7, 1.0),
    physical_range: (-0.6, 0.25),
    independent_check: Some(DIE_SWELL_CHECK),
    budget: Some(BudgetSource {
        key: "inlet_velocity_rel",
        unit: "-",
        what: "inlet velocity",
        word_unit: ("%", 0.01),
        default: 0.04,
        max: 0.5,
        scope: Scope::Common,
        per_unit: from_inlet_velocity,
        fallback: None,
        remedy: "measure the inlet velocity or add inlet_velocity to the fit",
    }),
    default_candidate: false,
    ..EffectDescriptor::builtin("inlet_velocity", Category::Process)
};

/// `die_temperature_offset`: `T(0) = T_in + ΔT` (and the melt density there), strength `ΔT`
/// \[K\]; `+10 K`: the melt leaves the die 10 K hotter than the file's inlet temperature.
pub const DIE_TEMPERATURE_OFFSET: EffectDescriptor = EffectDescriptor {
    unit: "K",
    symbol: "ΔT",
    describe: "melt temperature at the die off the nominal inlet temperature, strength = offset",
    search_range: (-60.0, 60.0),
    physical_range: (-30.0, 30.0),
    independent_check: Some(
        "measure the melt temperature at the die exit (a thermocouple in the melt)",
    ),
    budget: Some(BudgetSource {
        key: "inlet_temperature_K",
        unit: "K",
        what: "inlet (die) temperature",
        word_unit: ("K", 1.0),
        default: 2.0,
        max: 50.0,
        scope: Scope::Common,
        per_unit: one_per_unit,
        fallback: None,
        remedy: "measure the melt temperature at the die or add die_temperature_offset to the fit",
    }),
    ..EffectDescriptor::builtin("die_temperature_offset", Category::Process)
};

/// `mass_flow_scale`: true mass flow `(1 + δ) Q`, strength `δ` \[-\].
pub const MASS_FLOW_SCALE: EffectDescriptor = EffectDescriptor {
    symbol: "δ",
    describe: "mass flow off its nominal value, strength = relative error",
    search_range: (-0.5, 0.5),
    physical_range: (-0.2, 0.2),
    independent_check: Some("weigh the extrudate collected over a timed interval"),
    budget: Some(BudgetSource {
        key: "mass_flow_rel",
        unit: "-",
        what: "mass flow",
        word_unit: ("%", 0.01),
        default: 0.01,
        max: 0.5,
        scope: Scope::PerExperiment,
        per_unit: one_per_unit,
        fallback: None,
        remedy: "weigh the throughput of each run or add mass_flow_scale to the fit",
    }),
    ..EffectDescriptor::builtin("mass_flow_scale", Category::Process)
};

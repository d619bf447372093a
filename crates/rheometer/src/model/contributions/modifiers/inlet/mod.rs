//! The modifiers of the inlet: its velocity (`inlet_velocity`), diameter (`inlet_diameter`),
//! temperature at the die (`die_temperature`) and the mass flow (`mass_flow`).

pub(super) mod die_temperature;
pub(super) mod inlet_diameter;
pub(super) mod inlet_velocity;
pub(super) mod mass_flow;

//! The modifiers of the air: a co-flow along the spin line (`coflow`, `line_coflow`) and warm
//! air near the die (`warm_air`).

pub(super) mod coflow;
pub(super) mod line_coflow;
pub(super) mod warm_air;

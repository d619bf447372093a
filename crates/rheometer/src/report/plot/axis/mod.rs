//! The axes of a panel: their ranges and scales (`axes`) and their ticks (`ticks`).

pub(super) mod axes;
pub(super) mod ticks;

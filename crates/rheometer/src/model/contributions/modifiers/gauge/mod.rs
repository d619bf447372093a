//! The modifiers of the diameter gauge: its scale (`gauge_scale`) and offset (`gauge_offset`).

pub(super) mod gauge_offset;
pub(super) mod gauge_scale;

//! The look of a figure: the colours (`colors`) and the embedded fonts and text widths
//! (`fonts`).

pub(super) mod colors;
pub(super) mod fonts;

//! The bundled font (DejaVu Sans), registered with plotters on first use, so that no system
//! font or font library is needed.

use std::sync::OnceLock;

use plotters::style::{register_font, FontStyle};

/// DejaVu Sans (see `assets/fonts/LICENSE-DejaVu.txt`), used for every label.
static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Family name under which the bundled font is registered and used.
pub(super) const FONT: &str = "sans-serif";

/// Registers the bundled font once; returns whether it is available.
pub(super) fn ensure_font() -> bool {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    *REGISTERED.get_or_init(|| {
        // "sans-serif" is what we use; the other generic names make plotters' defaults work too.
        [FONT, "serif", "monospace"]
            .iter()
            .all(|name| register_font(name, FontStyle::Normal, DEJAVU_SANS).is_ok())
    })
}

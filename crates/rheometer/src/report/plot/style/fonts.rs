//! The bundled font (DejaVu Sans), registered with plotters on first use, so that no system
//! font or font library is needed.

use std::sync::OnceLock;

use plotters::style::{register_font, FontStyle};

/// DejaVu Sans (see `assets/fonts/LICENSE-DejaVu.txt`), used for every label.
static DEJAVU_SANS: &[u8] = include_bytes!("../../../../assets/fonts/DejaVuSans.ttf");

/// Family name under which the bundled font is registered and used.
pub(in crate::report::plot) const FONT: &str = "sans-serif";

/// Registers the bundled font once; returns whether it is available.
pub(in crate::report::plot) fn ensure_font() -> bool {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    *REGISTERED.get_or_init(|| {
        // "sans-serif" is what we use; the other generic names make plotters' defaults work too.
        [FONT, "serif", "monospace"]
            .iter()
            .all(|name| register_font(name, FontStyle::Normal, DEJAVU_SANS).is_ok())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::plot::axis::axes::font_px;
    use plotters::prelude::*;

    /// The lowest row with ink (coverage above half) of `text` drawn at `(4, 4)` at `size`.
    fn lowest_ink_row(text: &str, size: f64) -> usize {
        let (w, h) = (60usize, 60usize);
        let mut buf = vec![255u8; w * h * 3];
        {
            let root =
                BitMapBackend::with_buffer(&mut buf, (w as u32, h as u32)).into_drawing_area();
            let style = (FONT, size).into_font().color(&BLACK);
            root.draw_text(text, &style, (4, 4)).unwrap();
        }
        // ink: darker than half-way between white and the glyph's darkest pixel (a small
        // point may not cover any pixel fully)
        let darkest = buf.iter().copied().min().unwrap_or(255);
        let threshold = (255 + u32::from(darkest)) / 2;
        (0..h)
            .rev()
            .find(|&y| (0..w).any(|x| u32::from(buf[(y * w + x) * 3]) < threshold))
            .unwrap_or(0)
    }

    #[test]
    fn decimal_points_sit_on_the_baseline() {
        assert!(ensure_font());
        // the flat foot of "1" and the decimal point end on the same pixel row at every
        // font size the figures use
        let mut raised = 0;
        for tenth in 80..=280 {
            let size = f64::from(tenth) / 10.0;
            let even = font_px(size);
            assert_eq!(
                lowest_ink_row("1", even),
                lowest_ink_row(".", even),
                "size {even}"
            );
            if lowest_ink_row("1", size) != lowest_ink_row(".", size) {
                raised += 1;
            }
        }
        // the cause: at a fractional size plotters' truncation of `size / 2 + glyph_top`
        // puts the point a pixel off the digits' baseline (for a good share of the sizes)
        assert!(raised > 20, "{raised}");
    }
}

//! Axes: ranges of the data, tick values (including logarithmic axes), tick labels, and the
//! font and label-area sizes of a chart.

/// Magnitude beyond which data are clamped for range computation.
pub(in crate::report::plot) const HUGE: f64 = 1e300;

/// Font sizes, stroke widths and label-area sizes scaled to the space available for one chart,
/// in pixels of the canvas being drawn (which is `scale` times the figure's pixels when a PNG is
/// rendered supersampled).
#[derive(Debug, Clone, Copy)]
pub(in crate::report::plot) struct Metrics {
    /// Canvas pixels per figure pixel (1 for SVG, 2 or 3 for a supersampled PNG).
    pub(in crate::report::plot) scale: f64,
    pub(in crate::report::plot) title: f64,
    pub(in crate::report::plot) label: f64,
    pub(in crate::report::plot) tick: f64,
    pub(in crate::report::plot) margin: u32,
    pub(in crate::report::plot) x_area: u32,
    pub(in crate::report::plot) y_area: u32,
    /// Line width of series.
    pub(in crate::report::plot) stroke: u32,
    /// Marker radius.
    pub(in crate::report::plot) radius: i32,
}

/// A font size in canvas pixels rounded to an even whole number.
///
/// plotters' glyph placement (`ab_glyph` backend) puts each glyph at
/// `(size / 2.0 + glyph_top) as i32`: with a fractional `size / 2` the truncation toward zero
/// moves glyphs that reach above the middle line (digits) and glyphs below it (the decimal
/// point, the comma) one pixel apart, which is what made "0.804" read "0·804". With an even
/// size `size / 2` is whole and every glyph keeps its baseline.
pub(in crate::report::plot) fn font_px(size: f64) -> f64 {
    (2.0 * (0.5 * size).round()).max(2.0)
}

impl Metrics {
    /// Metrics for a chart area of `w × h` canvas pixels drawn at `scale` canvas pixels per
    /// figure pixel.
    pub(in crate::report::plot) fn for_area(w: u32, h: u32, scale: f64) -> Self {
        let scale = if scale.is_finite() && scale >= 1.0 {
            scale
        } else {
            1.0
        };
        let (w, h) = (f64::from(w) / scale, f64::from(h) / scale);
        let base = (w.min(h) / 24.0).clamp(9.0, 22.0);
        let tick = base * 0.85;
        let px = |v: f64| (v * scale).round() as u32;
        Self {
            scale,
            title: font_px(base * 1.25 * scale),
            label: font_px(base * scale),
            tick: font_px(tick * scale),
            margin: px(base * 0.6),
            x_area: px(tick * 1.6 + base * 1.7),
            y_area: px(tick * 4.2 + base * 1.7),
            stroke: px((base / 7.0).round().clamp(1.0, 3.0)).max(1),
            radius: px((base / 4.0).round().clamp(2.0, 5.0)).max(1) as i32,
        }
    }

    /// `v` figure pixels in canvas pixels.
    pub(in crate::report::plot) fn px(&self, v: f64) -> i32 {
        (v * self.scale).round() as i32
    }
}

/// Range of the usable values (finite, and positive for a log axis), padded by 5 % (of the
/// decades for a log axis); degenerate and empty cases get a sensible non-empty range.
pub(in crate::report::plot) fn axis_range(
    values: impl Iterator<Item = f64>,
    log: bool,
    pad: bool,
) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && (!log || *v > 0.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return if log { (1.0, 10.0) } else { (0.0, 1.0) };
    }
    // Keep the span finite (and tick generation sane) for values near the f64 limits.
    let (lo, hi) = (lo.clamp(-HUGE, HUGE), hi.clamp(-HUGE, HUGE));
    if log {
        let (llo, lhi) = (lo.log10(), hi.log10());
        let span = lhi - llo;
        if span < 1e-9 {
            return (lo / 2.0, hi * 2.0);
        }
        let p = if pad { 0.05 * span } else { 0.0 };
        (10f64.powf(llo - p), 10f64.powf(lhi + p))
    } else {
        let span = hi - lo;
        let scale = lo.abs().max(hi.abs());
        if span <= scale * 1e-12 {
            let d = if scale == 0.0 { 1.0 } else { 0.1 * scale };
            return (lo - d, hi + d);
        }
        if !pad || !span.is_finite() {
            return (lo, hi);
        }
        let (a, b) = (lo - 0.05 * span, hi + 0.05 * span);
        if a.is_finite() && b.is_finite() {
            (a, b)
        } else {
            (lo, hi)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn font_sizes_are_even_and_scale() {
        assert_eq!(font_px(11.33), 12.0);
        assert_eq!(font_px(9.5), 10.0);
        assert_eq!(font_px(0.3), 2.0);
        let one = Metrics::for_area(420, 320, 1.0);
        let three = Metrics::for_area(3 * 420, 3 * 320, 3.0);
        for m in [one, three] {
            for size in [m.title, m.label, m.tick] {
                assert_eq!(size % 2.0, 0.0, "{size}");
            }
        }
        assert!((three.tick / one.tick - 3.0).abs() < 0.2);
        assert_eq!(three.stroke, 3 * one.stroke);
        assert_eq!(three.px(2.0), 6);
    }

    #[test]
    fn ranges_are_padded_and_never_degenerate() {
        let (a, b) = axis_range([0.0, 10.0].into_iter(), false, true);
        assert!((a + 0.5).abs() < 1e-12 && (b - 10.5).abs() < 1e-12);
        assert_eq!(axis_range(std::iter::empty(), false, true), (0.0, 1.0));
        assert_eq!(axis_range([f64::NAN].into_iter(), true, true), (1.0, 10.0));
        let (a, b) = axis_range([3.0, 3.0, f64::NAN].into_iter(), false, true);
        assert!(a < 3.0 && b > 3.0);
        let (a, b) = axis_range([0.0].into_iter(), false, true);
        assert!(a < 0.0 && b > 0.0);
        let (a, b) = axis_range([-1.0, 1e-3, 1e3].into_iter(), true, true);
        assert!(a < 1e-3 && a > 0.0 && b > 1e3);
        let (a, b) = axis_range([f64::MAX, -f64::MAX].into_iter(), false, true);
        assert!(a.is_finite() && b.is_finite() && a < b);
    }
}

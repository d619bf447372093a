//! Colours: the series palette, the heat-map marker colours, the viridis colour map and the
//! colour scale of a heat map.

use plotters::style::RGBColor;

/// Colour of missing heat-map cells.
pub(in crate::report::plot) const MISSING: RGBColor = RGBColor(190, 190, 190);

/// Series colours (matplotlib's "tab10"); [`Series::color`](crate::report::plot::Series::color)
/// indexes this list cyclically.
pub const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Colours of heat-map markers, chosen to stand out against the viridis colour map.
pub(in crate::report::plot) const MARKER_COLORS: [RGBColor; 5] = [
    RGBColor(228, 26, 28),
    RGBColor(255, 255, 255),
    RGBColor(255, 0, 255),
    RGBColor(0, 255, 255),
    RGBColor(255, 165, 0),
];

/// Viridis colour map at `t` in `[0, 1]` (piecewise linear through 9 samples).
pub(in crate::report::plot) fn viridis(t: f64) -> RGBColor {
    const STOPS: [(f64, f64, f64); 9] = [
        (68.0, 1.0, 84.0),
        (71.0, 44.0, 122.0),
        (59.0, 81.0, 139.0),
        (44.0, 113.0, 142.0),
        (33.0, 144.0, 141.0),
        (39.0, 173.0, 129.0),
        (92.0, 200.0, 99.0),
        (170.0, 220.0, 50.0),
        (253.0, 231.0, 37.0),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let s = t * (STOPS.len() - 1) as f64;
    let k = (s.floor() as usize).min(STOPS.len() - 2);
    let f = s - k as f64;
    let (a, b) = (STOPS[k], STOPS[k + 1]);
    let mix = |p: f64, q: f64| (p + f * (q - p)).round().clamp(0.0, 255.0) as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Colour scale of a heat map: value range and mapping to `[0, 1]`.
#[derive(Debug, Clone, Copy)]
pub(in crate::report::plot) struct ColorScale {
    pub(in crate::report::plot) lo: f64,
    pub(in crate::report::plot) hi: f64,
    pub(in crate::report::plot) log: bool,
}

impl ColorScale {
    pub(in crate::report::plot) fn usable(&self, v: f64) -> bool {
        v.is_finite() && (!self.log || v > 0.0)
    }

    pub(in crate::report::plot) fn color(&self, v: f64) -> RGBColor {
        if !self.usable(v) {
            return MISSING;
        }
        let t = if self.log {
            (v / self.lo).log10() / (self.hi / self.lo).log10()
        } else {
            (v - self.lo) / (self.hi - self.lo)
        };
        viridis(t)
    }

    pub(in crate::report::plot) fn value_at(&self, t: f64) -> f64 {
        if self.log {
            self.lo * (self.hi / self.lo).powf(t)
        } else {
            self.lo + t * (self.hi - self.lo)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_endpoints() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(f64::NAN), RGBColor(68, 1, 84));
    }
}

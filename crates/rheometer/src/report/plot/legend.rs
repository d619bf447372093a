//! Legends drawn by this module (not plotters'): measured from their text, placed where they
//! cover no data (the emptiest corner of the plotting area, or outside it), and drawn with a
//! swatch per entry.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::axis::axes::Metrics;
use super::style::fonts::FONT;
use super::write::DrawResult;

/// A rectangle in backend pixels, `x0 ≤ x1`, `y0 ≤ y1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct PixelRect {
    pub(super) x0: i32,
    pub(super) y0: i32,
    pub(super) x1: i32,
    pub(super) y1: i32,
}

impl PixelRect {
    pub(super) fn new((x0, y0): (i32, i32), (x1, y1): (i32, i32)) -> Self {
        Self {
            x0: x0.min(x1),
            y0: y0.min(y1),
            x1: x0.max(x1),
            y1: y0.max(y1),
        }
    }

    fn width(&self) -> i32 {
        self.x1 - self.x0
    }

    fn contains(&self, (x, y): (i32, i32)) -> bool {
        x >= self.x0 && x <= self.x1 && y >= self.y0 && y <= self.y1
    }

    fn grown(&self, d: i32) -> Self {
        Self {
            x0: self.x0 - d,
            y0: self.y0 - d,
            x1: self.x1 + d,
            y1: self.y1 + d,
        }
    }

    fn intersects(&self, o: &PixelRect) -> bool {
        self.x0 <= o.x1 && o.x0 <= self.x1 && self.y0 <= o.y1 && o.y0 <= self.y1
    }

    /// Whether the segment `a–b` passes through the rectangle (Liang–Barsky clipping).
    fn meets_segment(&self, a: (i32, i32), b: (i32, i32)) -> bool {
        let (x0, y0) = (f64::from(a.0), f64::from(a.1));
        let (dx, dy) = (f64::from(b.0) - x0, f64::from(b.1) - y0);
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        let edges = [
            (-dx, x0 - f64::from(self.x0)),
            (dx, f64::from(self.x1) - x0),
            (-dy, y0 - f64::from(self.y0)),
            (dy, f64::from(self.y1) - y0),
        ];
        for (p, q) in edges {
            if p == 0.0 {
                if q < 0.0 {
                    return false;
                }
            } else {
                let r = q / p;
                if p < 0.0 {
                    t0 = t0.max(r);
                } else {
                    t1 = t1.min(r);
                }
                if t0 > t1 {
                    return false;
                }
            }
        }
        true
    }
}

/// What a legend must not cover, in backend pixels.
#[derive(Debug, Default)]
pub(super) struct Obstacles {
    /// Markers: centre and radius.
    pub(super) points: Vec<((i32, i32), i32)>,
    /// Line pieces (series lines, band edges, reference lines).
    pub(super) segments: Vec<((i32, i32), (i32, i32))>,
    /// Filled regions (label boxes, horizontal bands).
    pub(super) rects: Vec<PixelRect>,
}

impl Obstacles {
    /// Whether `r` touches any obstacle.
    pub(super) fn hit(&self, r: &PixelRect) -> bool {
        self.points
            .iter()
            .any(|&(c, radius)| r.grown(radius).contains(c))
            || self.segments.iter().any(|&(a, b)| r.meets_segment(a, b))
            || self.rects.iter().any(|o| r.intersects(o))
    }

    /// Adds the outline of a shaded region (a closed polygon). Only its edges are obstacles:
    /// a legend may sit inside a wide band (a noise band often fills the whole plot) as long
    /// as it crosses no edge and covers no data drawn over the band.
    pub(super) fn add_outline(&mut self, vertices: &[(i32, i32)]) {
        let n = vertices.len();
        if n >= 2 {
            self.segments
                .extend((0..n).map(|i| (vertices[i], vertices[(i + 1) % n])));
        }
    }

    /// Adds the polyline through `points` as segments.
    pub(super) fn add_polyline(&mut self, points: &[(i32, i32)]) {
        self.segments
            .extend(points.windows(2).map(|w| (w[0], w[1])));
        if let [p] = points {
            self.points.push((*p, 1));
        }
    }
}

/// The sample drawn before a legend entry's text.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Swatch {
    /// A solid or dashed line.
    Line { color: RGBColor, dashed: bool },
    /// A filled circle.
    Marker(RGBColor),
    /// An open circle.
    Ring(RGBColor),
    /// A filled circle with a black outline (heat-map markers).
    Outlined(RGBColor),
    /// A filled rectangle (bands, missing cells).
    Fill { color: RGBColor, opacity: f64 },
}

/// One legend line.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct LegendEntry {
    pub(super) label: String,
    pub(super) swatch: Swatch,
}

/// Layout sizes of a legend, in canvas pixels.
struct Geometry {
    pad: i32,
    row: i32,
    sample: i32,
    gap: i32,
}

fn geometry(m: &Metrics) -> Geometry {
    Geometry {
        pad: m.px(5.0),
        row: (m.tick * 1.45).round() as i32,
        sample: m.px(24.0),
        gap: m.px(6.0),
    }
}

/// Width of one legend column: swatch, gap and the widest text.
fn column_width<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
    m: &Metrics,
) -> i32 {
    let g = geometry(m);
    let font = TextStyle::from((FONT, m.tick).into_font());
    let text = entries
        .iter()
        .map(|e| {
            area.estimate_text_size(&e.label, &font)
                .map(|(w, _)| w as i32)
                .unwrap_or((e.label.chars().count() as f64 * m.tick * 0.6) as i32)
        })
        .max()
        .unwrap_or(0);
    g.sample + g.gap + text + g.pad
}

/// Width and height (canvas pixels) of the legend box of `entries` in `columns` columns
/// (filled row by row).
pub(super) fn legend_size<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
    m: &Metrics,
    columns: usize,
) -> (i32, i32) {
    let g = geometry(m);
    let columns = columns.clamp(1, entries.len().max(1));
    let rows = entries.len().div_ceil(columns) as i32;
    (
        g.pad + columns as i32 * column_width(area, entries, m),
        2 * g.pad + g.row * rows,
    )
}

/// The first corner of `plot` (upper right, upper left, lower right, lower left), inset by
/// `inset`, where a `size` box touches no obstacle.
pub(super) fn free_corner(
    plot: &PixelRect,
    size: (i32, i32),
    inset: i32,
    obstacles: &Obstacles,
) -> Option<PixelRect> {
    let (w, h) = size;
    if w + 2 * inset > plot.width() || h + 2 * inset > plot.y1 - plot.y0 {
        return None;
    }
    let (left, right) = (plot.x0 + inset, plot.x1 - inset - w);
    let (top, bottom) = (plot.y0 + inset, plot.y1 - inset - h);
    [(right, top), (left, top), (right, bottom), (left, bottom)]
        .into_iter()
        .map(|(x, y)| PixelRect::new((x, y), (x + w, y + h)))
        .find(|r| !obstacles.hit(&r.grown(inset / 2)))
}

/// Draws the legend box `rect` (backend pixels) with its entries in `columns` columns on
/// `area`.
pub(super) fn draw_legend<DB>(
    area: &DrawingArea<DB, Shift>,
    rect: &PixelRect,
    entries: &[LegendEntry],
    m: &Metrics,
    columns: usize,
) -> DrawResult
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
{
    let g = geometry(m);
    let (bx, by) = area.get_base_pixel();
    let at = |x: i32, y: i32| (x - bx, y - by);
    area.draw(&Rectangle::new(
        [at(rect.x0, rect.y0), at(rect.x1, rect.y1)],
        WHITE.mix(0.9).filled(),
    ))?;
    area.draw(&Rectangle::new(
        [at(rect.x0, rect.y0), at(rect.x1, rect.y1)],
        RGBColor(150, 150, 150).stroke_width(m.px(1.0).max(1) as u32),
    ))?;
    let stroke = m.stroke;
    let font = (FONT, m.tick).into_font().color(&BLACK);
    let columns = columns.clamp(1, entries.len().max(1));
    let column = column_width(area, entries, m);
    for (k, e) in entries.iter().enumerate() {
        let (row, col) = ((k / columns) as i32, (k % columns) as i32);
        let cy = rect.y0 + g.pad + g.row * row + g.row / 2;
        let x0 = rect.x0 + g.pad + col * column;
        let x1 = x0 + g.sample;
        let mid = (x0 + x1) / 2;
        match e.swatch {
            Swatch::Line { color, dashed } => {
                let style = color.stroke_width(stroke);
                if dashed {
                    let dash = (x1 - x0) / 5;
                    for i in [0, 2, 4] {
                        area.draw(&PathElement::new(
                            vec![at(x0 + i * dash, cy), at(x0 + (i + 1) * dash, cy)],
                            style,
                        ))?;
                    }
                } else {
                    area.draw(&PathElement::new(vec![at(x0, cy), at(x1, cy)], style))?;
                }
            }
            Swatch::Marker(color) => {
                area.draw(&Circle::new(at(mid, cy), m.radius, color.filled()))?;
            }
            Swatch::Ring(color) => {
                area.draw(&Circle::new(
                    at(mid, cy),
                    m.radius * 2,
                    color.stroke_width(stroke),
                ))?;
            }
            Swatch::Outlined(color) => {
                let r = (m.radius * 3) / 2;
                area.draw(&Circle::new(at(mid, cy), r, color.filled()))?;
                area.draw(&Circle::new(at(mid, cy), r, BLACK.stroke_width(stroke)))?;
            }
            Swatch::Fill { color, opacity } => {
                let h = g.row / 3;
                area.draw(&Rectangle::new(
                    [at(x0, cy - h), at(x1, cy + h)],
                    color.mix(opacity.max(0.25)).filled(),
                ))?;
            }
        }
        area.draw(&Text::new(
            e.label.clone(),
            at(x1 + g.gap, cy),
            font.pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_and_boxes() {
        let r = PixelRect::new((10, 10), (20, 20));
        assert!(r.meets_segment((0, 0), (30, 30)));
        assert!(r.meets_segment((15, 0), (15, 30)));
        assert!(!r.meets_segment((0, 0), (30, 5)));
        assert!(!r.meets_segment((21, 0), (40, 40)));
        assert!(r.meets_segment((12, 12), (13, 13)));
    }

    #[test]
    fn the_first_free_corner_is_taken() {
        let plot = PixelRect::new((0, 0), (200, 100));
        let mut o = Obstacles::default();
        // a curve falling from the upper left to the lower right: upper right is free
        o.add_polyline(&[(0, 0), (100, 60), (200, 100)]);
        let r = free_corner(&plot, (50, 20), 4, &o).expect("a corner");
        assert_eq!((r.x1, r.y0), (196, 4));
        // data in both upper corners: a lower corner
        o.points.push(((180, 10), 3));
        o.points.push(((20, 10), 3));
        let r = free_corner(&plot, (50, 20), 4, &o).expect("a corner");
        assert_eq!((r.x0, r.y1), (4, 96));
        // a band edge across the whole bottom too: none
        o.segments.push(((0, 90), (200, 90)));
        assert!(free_corner(&plot, (50, 20), 4, &o).is_none());
        // inside a band wider than the plot: free, no edge is crossed
        let mut o = Obstacles::default();
        o.add_outline(&[(-10, -10), (300, -10), (300, 200), (-10, 200)]);
        assert!(free_corner(&plot, (50, 20), 4, &o).is_some());
        // a band edge through the upper corners: a lower corner
        o.add_outline(&[(0, 10), (200, 10), (200, 30), (0, 30)]);
        let r = free_corner(&plot, (50, 20), 4, &o).expect("a corner");
        assert_eq!(r.y1, 96);
        // a legend larger than the plot: none
        assert!(free_corner(&plot, (300, 20), 4, &Obstacles::default()).is_none());
    }
}

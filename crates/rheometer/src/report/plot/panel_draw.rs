//! Drawing a [`Panel`]: axis ranges and ticks, bands, reference lines, series, and the legend
//! placed where it covers no data.

use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::axis::axes::{axis_range, Metrics, HUGE};
use super::axis::ticks::TickedAxis;
use super::error::{invalid, PlotError};
use super::legend::{
    draw_legend, free_corner, legend_size, LegendEntry, Obstacles, PixelRect, Swatch,
};
use super::panels::{BandShape, LegendPlacement, Panel, Style};
use super::style::colors::PALETTE;
use super::style::fonts::FONT;
use super::write::{render_figure, render_svg, write_figure, DrawResult, Figure};
use std::path::Path;

/// Neutral colour of bands and reference lines without a palette index.
const NEUTRAL: RGBColor = RGBColor(90, 90, 90);

/// A grid of panels, filled row by row.
pub(super) struct PanelGrid<'a> {
    pub(super) panels: &'a [Panel],
    pub(super) rows: usize,
    pub(super) columns: usize,
}

impl Figure for PanelGrid<'_> {
    fn draw<DB>(&self, root: &DrawingArea<DB, Shift>, scale: f64) -> DrawResult
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static,
    {
        let areas = root.split_evenly((self.rows, self.columns));
        for (panel, area) in self.panels.iter().zip(areas.iter()) {
            draw_panel(area, panel, scale)?;
        }
        Ok(())
    }
}

/// Whether `(x, y)` can be drawn on the panel's axes.
fn usable(panel: &Panel, (x, y): (f64, f64)) -> bool {
    x.is_finite() && y.is_finite() && (!panel.log_x || x > 0.0) && (!panel.log_y || y > 0.0)
}

/// Runs of consecutive usable points, clamped like the axis range.
pub(super) fn finite_runs(panel: &Panel, points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let mut runs = Vec::new();
    let mut current = Vec::new();
    for &p in points {
        if usable(panel, p) {
            // Same clamp as the axis range, so that every point maps inside the axes.
            current.push((p.0.clamp(-HUGE, HUGE), p.1.clamp(-HUGE, HUGE)));
        } else if !current.is_empty() {
            runs.push(std::mem::take(&mut current));
        }
    }
    if !current.is_empty() {
        runs.push(current);
    }
    runs
}

/// The axis ranges of a panel: series, band and reference-line values, padded.
fn panel_ranges(panel: &Panel) -> ((f64, f64), (f64, f64)) {
    let mut xs = Vec::new();
    let mut ys = Vec::new();
    let mut push = |(x, y): (f64, f64)| {
        if usable(panel, (x, y)) {
            xs.push(x);
            ys.push(y);
        }
    };
    for s in &panel.series {
        s.points.iter().copied().for_each(&mut push);
    }
    let mut only_y = Vec::new();
    let mut only_x = Vec::new();
    for b in &panel.bands {
        match &b.shape {
            BandShape::Between { lower, upper } => {
                lower.iter().chain(upper).copied().for_each(&mut push);
            }
            BandShape::Horizontal { lo, hi } => only_y.extend([*lo, *hi]),
            BandShape::Vertical { lo, hi } => only_x.extend([*lo, *hi]),
        }
    }
    only_y.extend(panel.ref_lines.iter().map(|l| l.y));
    let x = axis_range(xs.into_iter().chain(only_x), panel.log_x, true);
    let y = axis_range(ys.into_iter().chain(only_y), panel.log_y, true);
    (x, y)
}

fn series_color(index: Option<usize>, k: usize) -> RGBColor {
    PALETTE[index.unwrap_or(k) % PALETTE.len()]
}

fn band_color(index: Option<usize>) -> RGBColor {
    index.map_or(NEUTRAL, |i| PALETTE[i % PALETTE.len()])
}

/// The legend entries of a panel: bands first, then series, skipping empty labels.
pub(super) fn legend_entries(panel: &Panel) -> Vec<LegendEntry> {
    let bands = panel.bands.iter().filter(|b| !b.label.is_empty()).map(|b| {
        let color = band_color(b.color);
        LegendEntry {
            label: b.label.clone(),
            swatch: Swatch::Fill {
                color,
                opacity: b.opacity,
            },
        }
    });
    let series = panel
        .series
        .iter()
        .enumerate()
        .filter(|(_, s)| !s.label.is_empty())
        .map(|(k, s)| {
            let color = series_color(s.color, k);
            let swatch = match s.style {
                Style::Line => Swatch::Line {
                    color,
                    dashed: false,
                },
                Style::Dashed => Swatch::Line {
                    color,
                    dashed: true,
                },
                Style::Markers => Swatch::Marker(color),
                Style::Rings => Swatch::Ring(color),
            };
            LegendEntry {
                label: s.label.clone(),
                swatch,
            }
        });
    bands.chain(series).collect()
}

fn draw_panel<DB>(area: &DrawingArea<DB, Shift>, panel: &Panel, scale: f64) -> DrawResult
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
{
    let (w, h) = area.dim_in_pixel();
    let m = Metrics::for_area(w, h, scale);
    let body = if panel.title.is_empty() {
        area.clone()
    } else {
        // a little air above the title (plotters draws it flush with the area's top)
        area.margin(m.px(6.0).max(0) as u32, 0, 0, 0)
            .titled(&panel.title, (FONT, m.title))?
    };
    let ((x_lo, x_hi), (y_lo, y_hi)) = panel_ranges(panel);
    let axes = Axes { panel, m: &m };
    axes.draw_on(
        &body,
        || TickedAxis::new(x_lo, x_hi, panel.log_x),
        || TickedAxis::new(y_lo, y_hi, panel.log_y),
    )
}

/// What one panel's chart needs besides its coordinate types.
struct Axes<'p> {
    panel: &'p Panel,
    m: &'p Metrics,
}

impl Axes<'_> {
    fn builder<'a, 'b, DB: DrawingBackend>(
        &self,
        on: &'a DrawingArea<DB, Shift>,
    ) -> ChartBuilder<'a, 'b, DB> {
        let m = self.m;
        let mut b = ChartBuilder::on(on);
        b.margin(m.margin)
            .margin_right(m.margin * 2)
            .x_label_area_size(m.x_area)
            .y_label_area_size(m.y_area);
        b
    }

    /// Builds the chart (twice when the legend must go outside: once to measure, once on the
    /// narrowed area), draws it and the legend.
    fn draw_on<DB, XS, YS, X, Y>(
        &self,
        body: &DrawingArea<DB, Shift>,
        x_spec: impl Fn() -> XS,
        y_spec: impl Fn() -> YS,
    ) -> DrawResult
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static,
        XS: plotters::coord::ranged1d::AsRangedCoord<CoordDescType = X, Value = f64>,
        YS: plotters::coord::ranged1d::AsRangedCoord<CoordDescType = Y, Value = f64>,
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let entries = legend_entries(self.panel);
        let mut chart = self.builder(body).build_cartesian_2d(x_spec(), y_spec())?;
        if entries.is_empty() || self.panel.legend == LegendPlacement::Hidden {
            return self.fill(&mut chart).map(|_| ());
        }
        let one_column = legend_size(body, &entries, self.m, 1);
        if self.panel.legend == LegendPlacement::Auto {
            let obstacles = self.obstacles(&chart);
            let (xr, yr) = chart.plotting_area().get_pixel_range();
            let plot = PixelRect::new((xr.start, yr.start), (xr.end, yr.end));
            if let Some(rect) = free_corner(&plot, one_column, self.m.px(6.0), &obstacles) {
                self.fill(&mut chart)?;
                return draw_legend(body, &rect, &entries, self.m, 1);
            }
        }
        // Outside: to the right when that leaves the plot at least 60 % of the width,
        // otherwise below it in as many columns as fit.
        let (bw, bh) = body.dim_in_pixel();
        let (bx, by) = body.get_base_pixel();
        let gap = self.m.px(8.0);
        if f64::from(one_column.0 + gap) <= 0.4 * f64::from(bw) {
            let (main, _) = body.split_horizontally(bw as i32 - one_column.0 - gap);
            let mut chart = self.builder(&main).build_cartesian_2d(x_spec(), y_spec())?;
            self.fill(&mut chart)?;
            let (_, yr) = chart.plotting_area().get_pixel_range();
            let x0 = bx + bw as i32 - one_column.0 - self.m.px(2.0);
            let rect = PixelRect::new((x0, yr.start), (x0 + one_column.0, yr.start + one_column.1));
            return draw_legend(body, &rect, &entries, self.m, 1);
        }
        let usable = bw as i32 - 2 * self.m.margin as i32;
        let columns = ((usable / one_column.0.max(1)).max(1) as usize).min(entries.len());
        let size = legend_size(body, &entries, self.m, columns);
        let (main, _) = body.split_vertically(bh as i32 - size.1 - gap);
        let mut chart = self.builder(&main).build_cartesian_2d(x_spec(), y_spec())?;
        self.fill(&mut chart)?;
        let x0 = bx + (bw as i32 - size.0).max(0) / 2;
        let y0 = by + bh as i32 - size.1 - self.m.px(2.0);
        let rect = PixelRect::new((x0, y0), (x0 + size.0, y0 + size.1));
        draw_legend(body, &rect, &entries, self.m, columns)
    }

    /// What the legend must not cover, in backend pixels of `chart`.
    fn obstacles<DB, X, Y>(&self, chart: &ChartContext<'_, DB, Cartesian2d<X, Y>>) -> Obstacles
    where
        DB: DrawingBackend,
        X: Ranged<ValueType = f64>,
        Y: Ranged<ValueType = f64>,
    {
        let panel = self.panel;
        let mut o = Obstacles::default();
        let px = |p: &(f64, f64)| chart.backend_coord(p);
        let xr = chart.x_range();
        for s in &panel.series {
            for run in finite_runs(panel, &s.points) {
                let pixels: Vec<(i32, i32)> = run.iter().map(px).collect();
                match s.style {
                    Style::Markers => o.points.extend(pixels.iter().map(|&c| (c, self.m.radius))),
                    Style::Rings => o
                        .points
                        .extend(pixels.iter().map(|&c| (c, 2 * self.m.radius))),
                    Style::Line | Style::Dashed => o.add_polyline(&pixels),
                }
            }
        }
        for b in &panel.bands {
            match &b.shape {
                BandShape::Between { lower, upper } => {
                    let polygon = band_polygon(panel, lower, upper);
                    let pixels: Vec<(i32, i32)> = polygon.iter().map(px).collect();
                    o.add_outline(&pixels);
                }
                BandShape::Horizontal { lo, hi } => {
                    for y in [*lo, *hi] {
                        if usable(panel, (xr.start, y)) {
                            o.segments.push((px(&(xr.start, y)), px(&(xr.end, y))));
                        }
                    }
                }
                BandShape::Vertical { .. } => {}
            }
        }
        for line in &panel.ref_lines {
            if usable(panel, (xr.start, line.y)) {
                let (a, b) = (px(&(xr.start, line.y)), px(&(xr.end, line.y)));
                o.segments.push((a, b));
                if !line.label.is_empty() {
                    let w = (line.label.chars().count() as f64 * self.m.tick * 0.62) as i32;
                    let h = self.m.tick as i32 + self.m.px(4.0);
                    o.rects.push(PixelRect::new((b.0 - w, b.1 - h), b));
                }
            }
        }
        o
    }

    /// Mesh, bands, reference lines and series.
    fn fill<'a, DB, X, Y>(
        &self,
        chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    ) -> Result<(), Box<dyn std::error::Error + Send + Sync>>
    where
        DB: DrawingBackend + 'a,
        DB::ErrorType: 'static,
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let m = self.m;
        let thin = m.px(1.0).max(1) as u32;
        chart
            .configure_mesh()
            .x_desc(self.panel.x_label.as_str())
            .y_desc(self.panel.y_label.as_str())
            .label_style((FONT, m.tick))
            .axis_desc_style((FONT, m.label))
            .set_all_tick_mark_size(m.px(4.0))
            .axis_style(RGBColor(60, 60, 60).stroke_width(thin))
            .light_line_style(RGBColor(240, 240, 240).stroke_width(thin))
            .bold_line_style(RGBColor(218, 218, 218).stroke_width(thin))
            .draw()?;
        self.draw_bands(chart)?;
        self.draw_ref_lines(chart)?;
        self.draw_series(chart)?;
        Ok(())
    }

    fn draw_bands<'a, DB, X, Y>(
        &self,
        chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    ) -> DrawResult
    where
        DB: DrawingBackend + 'a,
        DB::ErrorType: 'static,
        X: Ranged<ValueType = f64>,
        Y: Ranged<ValueType = f64>,
    {
        let panel = self.panel;
        let (xr, yr) = (chart.x_range(), chart.y_range());
        let clamp_y = |v: f64| v.clamp(yr.start, yr.end);
        let clamp_x = |v: f64| v.clamp(xr.start, xr.end);
        for b in &panel.bands {
            let fill = band_color(b.color).mix(b.opacity).filled();
            match &b.shape {
                BandShape::Between { lower, upper } => {
                    let polygon = band_polygon(panel, lower, upper);
                    if polygon.len() >= 3 {
                        chart.draw_series(std::iter::once(Polygon::new(polygon, fill)))?;
                    }
                }
                BandShape::Horizontal { lo, hi } if lo.is_finite() && hi.is_finite() => {
                    let corners = [(xr.start, clamp_y(*lo)), (xr.end, clamp_y(*hi))];
                    chart.draw_series(std::iter::once(Rectangle::new(corners, fill)))?;
                }
                BandShape::Vertical { lo, hi } if lo.is_finite() && hi.is_finite() => {
                    let corners = [(clamp_x(*lo), yr.start), (clamp_x(*hi), yr.end)];
                    chart.draw_series(std::iter::once(Rectangle::new(corners, fill)))?;
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn draw_ref_lines<'a, DB, X, Y>(
        &self,
        chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    ) -> DrawResult
    where
        DB: DrawingBackend + 'a,
        DB::ErrorType: 'static,
        X: Ranged<ValueType = f64>,
        Y: Ranged<ValueType = f64>,
    {
        let m = self.m;
        let xr = chart.x_range();
        for line in &self.panel.ref_lines {
            if !usable(self.panel, (xr.start, line.y)) {
                continue;
            }
            let color = band_color(line.color);
            let style = color.stroke_width(m.stroke);
            let ends = vec![(xr.start, line.y), (xr.end, line.y)];
            if line.dashed {
                let dash = m.stroke as i32 * 5;
                chart.draw_series(DashedLineSeries::new(ends, dash, dash * 2 / 3, style))?;
            } else {
                chart.draw_series(LineSeries::new(ends, style))?;
            }
            if !line.label.is_empty() {
                let (x, y) = chart.backend_coord(&(xr.end, line.y));
                let (bx, by) = chart.plotting_area().get_base_pixel();
                let font = (FONT, m.tick)
                    .into_font()
                    .color(&color)
                    .pos(Pos::new(HPos::Right, VPos::Bottom));
                chart.plotting_area().strip_coord_spec().draw(&Text::new(
                    line.label.clone(),
                    (x - bx - m.px(4.0), y - by - m.px(3.0)),
                    font,
                ))?;
            }
        }
        Ok(())
    }

    fn draw_series<'a, DB, X, Y>(
        &self,
        chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    ) -> DrawResult
    where
        DB: DrawingBackend + 'a,
        DB::ErrorType: 'static,
        X: Ranged<ValueType = f64>,
        Y: Ranged<ValueType = f64>,
    {
        let m = self.m;
        let stroke = m.stroke;
        let radius = m.radius;
        for (k, series) in self.panel.series.iter().enumerate() {
            let color = series_color(series.color, k);
            let line = color.stroke_width(stroke);
            for run in finite_runs(self.panel, &series.points) {
                match series.style {
                    Style::Markers => {
                        chart.draw_series(
                            run.iter().map(|&p| Circle::new(p, radius, color.filled())),
                        )?;
                    }
                    Style::Rings => {
                        chart.draw_series(run.iter().map(|&p| Circle::new(p, 2 * radius, line)))?;
                    }
                    _ if run.len() == 1 => {
                        // An isolated point between gaps would be invisible as a line.
                        chart.draw_series(
                            run.iter()
                                .map(|&p| Circle::new(p, stroke + 1, color.filled())),
                        )?;
                    }
                    Style::Line => {
                        chart.draw_series(LineSeries::new(run, line))?;
                    }
                    Style::Dashed => {
                        let dash = (stroke * 4) as i32;
                        chart.draw_series(DashedLineSeries::new(run, dash, dash * 2 / 3, line))?;
                    }
                }
            }
        }
        Ok(())
    }
}

/// The polygon of a band between `lower` and `upper`: the usable lower points, then the usable
/// upper points in reverse.
fn band_polygon(panel: &Panel, lower: &[(f64, f64)], upper: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let keep = |p: &&(f64, f64)| usable(panel, **p);
    lower
        .iter()
        .filter(keep)
        .chain(upper.iter().rev().filter(keep))
        .map(|&(x, y)| (x.clamp(-HUGE, HUGE), y.clamp(-HUGE, HUGE)))
        .collect()
}

/// Checks the request of a panel grid; returns the number of rows and columns.
fn grid_shape(path: &Path, panels: &[Panel], columns: usize) -> Result<(usize, usize), PlotError> {
    if panels.is_empty() {
        return Err(invalid(path, "no panels to draw"));
    }
    if columns == 0 {
        return Err(invalid(path, "the number of columns must be at least 1"));
    }
    let columns = columns.min(panels.len());
    Ok((panels.len().div_ceil(columns), columns))
}

/// Writes `panels` as a grid with `columns` columns (rows as needed, filled row by row) into a
/// `size.0 × size.1` pixel figure at `path` (`.png` or `.svg`).
///
/// `columns` larger than the number of panels is reduced to it. Errors if there are no panels,
/// `columns` is 0, or the size is 0 or larger than `MAX_SIDE`.
pub fn save_panels(
    path: &Path,
    panels: &[Panel],
    columns: usize,
    size: (u32, u32),
) -> Result<(), PlotError> {
    write_figure(path, size, &PanelGrid::new(path, panels, columns)?)
}

/// The grid of [`save_panels`] rendered in memory as the file `path` would hold it (PNG or
/// SVG by its extension), without writing it.
pub(crate) fn render_panels(
    path: &Path,
    panels: &[Panel],
    columns: usize,
    size: (u32, u32),
) -> Result<Vec<u8>, PlotError> {
    render_figure(path, size, &PanelGrid::new(path, panels, columns)?)
}

/// The grid of [`save_panels`] as an SVG document in memory (e.g. to embed in an HTML page);
/// errors name `"<svg>"` as the path.
pub fn panels_svg(panels: &[Panel], columns: usize, size: (u32, u32)) -> Result<String, PlotError> {
    let path = Path::new("<svg>");
    render_svg(path, size, &PanelGrid::new(path, panels, columns)?)
}

impl<'a> PanelGrid<'a> {
    /// `panels` in `columns` columns and as many rows as needed (see `grid_shape`; `path`
    /// names the figure in errors).
    fn new(path: &Path, panels: &'a [Panel], columns: usize) -> Result<Self, PlotError> {
        let (rows, columns) = grid_shape(path, panels, columns)?;
        Ok(PanelGrid {
            panels,
            rows,
            columns,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_break_at_non_finite_points() {
        let pts = [
            (0.0, 1.0),
            (1.0, f64::NAN),
            (2.0, 2.0),
            (3.0, 3.0),
            (4.0, -1.0),
        ];
        let lin = Panel::default();
        assert_eq!(finite_runs(&lin, &pts).len(), 2);
        let log = Panel::default().with_log_y(true);
        assert_eq!(
            finite_runs(&log, &pts),
            vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)]]
        );
        let log_x = Panel::default().with_log_x(true);
        assert_eq!(
            finite_runs(&log_x, &pts)[0],
            vec![(2.0, 2.0), (3.0, 3.0), (4.0, -1.0)]
        );
    }

    #[test]
    fn bands_and_reference_lines_widen_the_ranges() {
        let p = Panel::default()
            .with_series(super::super::Series::line("", vec![(0.0, 0.0), (1.0, 1.0)]))
            .with_noise_band("noise", 3.0)
            .with_ref_line(super::super::panels::RefLine::new("", 10.0));
        let ((x0, x1), (y0, y1)) = panel_ranges(&p);
        assert!(x0 < 0.0 && x1 > 1.0 && y0 < -3.0 && y1 > 10.0);
    }
}

//! Line, dashed-line and marker panels: [`Series`], [`Panel`], and a grid of panels
//! ([`save_panels`]).

use std::path::Path;

use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::axes::{axis_range, format_tick, log_ticks, Metrics, HUGE};
use super::colors::PALETTE;
use super::error::{invalid, PlotError};
use super::fonts::FONT;
use super::write::{write_figure, DrawResult, Figure};

/// How a [`Series`] is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Style {
    /// A solid line through the points (broken at non-finite points).
    #[default]
    Line,
    /// Filled circles at the points.
    Markers,
    /// A dashed line through the points (broken at non-finite points).
    Dashed,
    /// Open circles, twice the marker size, around the points (to flag points drawn by
    /// another series, e.g. outliers).
    Rings,
}

/// One labelled set of points in a [`Panel`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// Legend text; an empty label leaves the series out of the legend.
    pub label: String,
    /// The `(x, y)` points, drawn in the given order. Non-finite points are skipped.
    pub points: Vec<(f64, f64)>,
    /// Line, dashed line or markers.
    pub style: Style,
    /// Index into [`PALETTE`] (taken modulo its length); `None` uses the series' position.
    pub color: Option<usize>,
}

impl Series {
    /// A series with the given style and automatic colour.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>, style: Style) -> Self {
        Self {
            label: label.into(),
            points,
            style,
            color: None,
        }
    }

    /// A solid line.
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self::new(label, points, Style::Line)
    }

    /// A dashed line.
    pub fn dashed(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self::new(label, points, Style::Dashed)
    }

    /// Markers only.
    pub fn markers(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self::new(label, points, Style::Markers)
    }

    /// Open rings around the points (see [`Style::Rings`]).
    pub fn rings(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self::new(label, points, Style::Rings)
    }

    /// Sets the palette index (so that, e.g., data and model of one experiment share a colour).
    pub fn with_color(mut self, palette_index: usize) -> Self {
        self.color = Some(palette_index);
        self
    }
}

/// One set of axes with a title, axis labels, series and a legend.
///
/// Axis ranges are automatic: the finite data plus 5 % padding; a single value or an empty
/// panel still gets a non-degenerate range.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Panel {
    /// Title above the axes.
    pub title: String,
    /// Horizontal-axis label.
    pub x_label: String,
    /// Vertical-axis label.
    pub y_label: String,
    /// The series, drawn in order (later ones on top).
    pub series: Vec<Series>,
    /// Logarithmic vertical axis; points with `y <= 0` are then skipped.
    pub log_y: bool,
}

impl Panel {
    /// An empty panel with a title and axis labels.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            log_y: false,
        }
    }

    /// Adds a series.
    pub fn with_series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// Sets a logarithmic (`true`) or linear (`false`) vertical axis.
    pub fn with_log_y(mut self, log_y: bool) -> Self {
        self.log_y = log_y;
        self
    }
}

/// Writes `panels` as a grid with `columns` columns (rows as needed, filled row by row) into a
/// `size.0 × size.1` pixel figure at `path` (`.png` or `.svg`).
///
/// `columns` larger than the number of panels is reduced to it. Errors if there are no panels,
/// `columns` is 0, or the size is 0 or larger than [`MAX_SIDE`](super::MAX_SIDE).
pub fn save_panels(
    path: &Path,
    panels: &[Panel],
    columns: usize,
    size: (u32, u32),
) -> Result<(), PlotError> {
    if panels.is_empty() {
        return Err(invalid(path, "no panels to draw"));
    }
    if columns == 0 {
        return Err(invalid(path, "the number of columns must be at least 1"));
    }
    let columns = columns.min(panels.len());
    let rows = panels.len().div_ceil(columns);
    write_figure(
        path,
        size,
        &PanelGrid {
            panels,
            rows,
            columns,
        },
    )
}

/// Runs of consecutive usable points (finite, and `y > 0` for a log axis).
fn finite_runs(points: &[(f64, f64)], log_y: bool) -> Vec<Vec<(f64, f64)>> {
    let mut runs = Vec::new();
    let mut current = Vec::new();
    for &(x, y) in points {
        if x.is_finite() && y.is_finite() && (!log_y || y > 0.0) {
            // Same clamp as the axis range, so that every point maps inside the axes.
            current.push((x.clamp(-HUGE, HUGE), y.clamp(-HUGE, HUGE)));
        } else if !current.is_empty() {
            runs.push(std::mem::take(&mut current));
        }
    }
    if !current.is_empty() {
        runs.push(current);
    }
    runs
}

struct PanelGrid<'a> {
    panels: &'a [Panel],
    rows: usize,
    columns: usize,
}

impl Figure for PanelGrid<'_> {
    fn draw<DB>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static,
    {
        let areas = root.split_evenly((self.rows, self.columns));
        for (panel, area) in self.panels.iter().zip(areas.iter()) {
            draw_panel(area, panel)?;
        }
        Ok(())
    }
}

fn draw_panel<DB>(area: &DrawingArea<DB, Shift>, panel: &Panel) -> DrawResult
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
{
    let (w, h) = area.dim_in_pixel();
    let m = Metrics::for_area(w, h);
    let usable = |&(x, y): &(f64, f64)| x.is_finite() && y.is_finite() && (!panel.log_y || y > 0.0);
    let points = || {
        panel
            .series
            .iter()
            .flat_map(|s| s.points.iter().copied())
            .filter(usable)
    };
    let (x_lo, x_hi) = axis_range(points().map(|p| p.0), false, true);
    let (y_lo, y_hi) = axis_range(points().map(|p| p.1), panel.log_y, true);

    let mut builder = ChartBuilder::on(area);
    builder
        .margin(m.margin)
        .margin_right(m.margin * 2)
        .x_label_area_size(m.x_area)
        .y_label_area_size(m.y_area);
    if !panel.title.is_empty() {
        builder.caption(&panel.title, (FONT, m.title));
    }
    if panel.log_y {
        let y_axis = (y_lo..y_hi)
            .log_scale()
            .with_key_points(log_ticks(y_lo, y_hi));
        let mut chart = builder.build_cartesian_2d(x_lo..x_hi, y_axis)?;
        fill_panel(&mut chart, panel, &m)
    } else {
        let mut chart = builder.build_cartesian_2d(x_lo..x_hi, y_lo..y_hi)?;
        fill_panel(&mut chart, panel, &m)
    }
}

fn fill_panel<'a, DB, Y>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, Y>>,
    panel: &Panel,
    m: &Metrics,
) -> DrawResult
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .label_style((FONT, m.tick))
        .axis_desc_style((FONT, m.label))
        .x_labels(6)
        .y_labels(6)
        .x_label_formatter(&format_tick)
        .y_label_formatter(&format_tick)
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()?;

    let stroke = (m.label / 7.0).round().clamp(1.0, 3.0) as u32;
    let radius = (m.label / 4.0).round().clamp(2.0, 5.0) as i32;
    for (k, series) in panel.series.iter().enumerate() {
        let color = PALETTE[series.color.unwrap_or(k) % PALETTE.len()];
        let line = color.stroke_width(stroke);
        for run in finite_runs(&series.points, panel.log_y) {
            match series.style {
                Style::Markers => {
                    chart
                        .draw_series(run.iter().map(|&p| Circle::new(p, radius, color.filled())))?;
                }
                Style::Rings => {
                    chart.draw_series(
                        run.iter()
                            .map(|&p| Circle::new(p, 2 * radius, color.stroke_width(stroke))),
                    )?;
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
        if !series.label.is_empty() {
            let style = series.style;
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())?
                .label(series.label.as_str())
                .legend(move |(x, y)| {
                    let (line, dot, gap) = match style {
                        Style::Line => (color.stroke_width(stroke), TRANSPARENT.filled(), 20),
                        Style::Dashed => (color.stroke_width(stroke), TRANSPARENT.filled(), 7),
                        Style::Markers => (TRANSPARENT.stroke_width(0), color.filled(), 20),
                        Style::Rings => {
                            (TRANSPARENT.stroke_width(0), color.stroke_width(stroke), 20)
                        }
                    };
                    EmptyElement::at((x, y))
                        + PathElement::new(vec![(0, 0), (gap, 0)], line)
                        + PathElement::new(vec![(20 - gap, 0), (20, 0)], line)
                        + Circle::new((10, 0), radius, dot)
                });
        }
    }
    if panel.series.iter().any(|s| !s.label.is_empty()) {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font((FONT, m.tick))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.4))
            .draw()?;
    }
    Ok(())
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
        assert_eq!(finite_runs(&pts, false).len(), 2);
        assert_eq!(
            finite_runs(&pts, true),
            vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)]]
        );
    }
}

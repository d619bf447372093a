//! Heat maps: a scalar field on a rectilinear grid with a colour bar and marked points
//! ([`Heatmap`], [`save_heatmap`]).

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::axis::axes::{axis_range, Metrics};
use super::axis::ticks::TickedAxis;
use super::error::{invalid, PlotError};
use super::legend::{draw_legend, legend_size, LegendEntry, PixelRect, Swatch};
use super::style::colors::{viridis, ColorScale, MARKER_COLORS, MISSING};
use super::style::fonts::FONT;
use super::write::{render_figure, write_figure, DrawResult, Figure};

/// A scalar field on a rectilinear grid, e.g. a cost landscape `J(x, y)`, with a colour bar.
///
/// `values` is row-major with one row per `ys` entry: `values[j * xs.len() + i]` belongs to
/// `(xs[i], ys[j])`. `xs` and `ys` are cell centres, finite and strictly monotonic (not
/// necessarily evenly spaced); cell edges lie half-way between neighbours. Non-finite values
/// (and, with [`log_color`](Self::log_color), values `<= 0`) are missing and drawn grey.
///
/// Build one with [`Heatmap::new`] and struct-update syntax for the optional fields.
#[derive(Debug, Clone, PartialEq)]
pub struct Heatmap<'a> {
    /// Figure title.
    pub title: &'a str,
    /// Horizontal-axis label.
    pub x_label: &'a str,
    /// Vertical-axis label.
    pub y_label: &'a str,
    /// Colour-bar label (the plotted quantity).
    pub value_label: &'a str,
    /// Cell centres along the horizontal axis.
    pub xs: &'a [f64],
    /// Cell centres along the vertical axis.
    pub ys: &'a [f64],
    /// Row-major values, `ys.len() × xs.len()`.
    pub values: &'a [f64],
    /// Points to mark (e.g. start and optimum), each `(x, y, legend label)`; markers with the
    /// same label share a colour and one legend entry; markers outside
    /// the grid's cells (or non-finite) are not drawn.
    pub markers: &'a [(f64, f64, String)],
    /// Logarithmic colour scale.
    pub log_color: bool,
    /// Logarithmic horizontal axis (then all `xs` must be positive).
    pub log_x: bool,
    /// Logarithmic vertical axis (then all `ys` must be positive).
    pub log_y: bool,
    /// Figure size in pixels (width, height).
    pub size: (u32, u32),
}

impl<'a> Heatmap<'a> {
    /// A heat map with no labels or markers, linear axes and colour scale, and a 900 × 700 size.
    pub fn new(xs: &'a [f64], ys: &'a [f64], values: &'a [f64]) -> Self {
        Self {
            title: "",
            x_label: "",
            y_label: "",
            value_label: "",
            xs,
            ys,
            values,
            markers: &[],
            log_color: false,
            log_x: false,
            log_y: false,
            size: (900, 700),
        }
    }
}

/// Writes a heat map with a colour bar, and a legend for its markers, to `path` (`.png` or
/// `.svg`).
///
/// Errors if the grid is empty or not finite and strictly monotonic, if `values` does not have
/// `xs.len() * ys.len()` entries, or if the size is 0 or larger than
/// `MAX_SIDE`.
pub fn save_heatmap(path: &Path, heatmap: &Heatmap<'_>) -> Result<(), PlotError> {
    validate(path, heatmap)?;
    write_figure(path, heatmap.size, heatmap)
}

/// The heat map of [`save_heatmap`] rendered in memory as the file `path` would hold it (PNG or
/// SVG by its extension), without writing it.
pub(crate) fn render_heatmap(path: &Path, heatmap: &Heatmap<'_>) -> Result<Vec<u8>, PlotError> {
    validate(path, heatmap)?;
    render_figure(path, heatmap.size, heatmap)
}

/// The checks of [`save_heatmap`]: non-empty, finite, monotonic coordinates (positive on a
/// logarithmic axis) and one value per cell.
fn validate(path: &Path, hm: &Heatmap<'_>) -> Result<(), PlotError> {
    for (name, c, log) in [("xs", hm.xs, hm.log_x), ("ys", hm.ys, hm.log_y)] {
        if c.is_empty() {
            return Err(invalid(path, format!("heat map: {name} is empty")));
        }
        if c.iter().any(|v| !v.is_finite()) {
            return Err(invalid(
                path,
                format!("heat map: {name} has non-finite entries"),
            ));
        }
        if log && c.iter().any(|v| *v <= 0.0) {
            return Err(invalid(
                path,
                format!("heat map: {name} must be positive on a logarithmic axis"),
            ));
        }
        let increasing = c.windows(2).all(|w| w[1] > w[0]);
        let decreasing = c.windows(2).all(|w| w[1] < w[0]);
        if !(increasing || decreasing) {
            return Err(invalid(
                path,
                format!("heat map: {name} is not strictly monotonic"),
            ));
        }
    }
    let expected = hm.xs.len().checked_mul(hm.ys.len());
    if expected != Some(hm.values.len()) {
        return Err(invalid(
            path,
            format!(
                "heat map: values has {} entries, expected ys.len() × xs.len() = {} × {}",
                hm.values.len(),
                hm.ys.len(),
                hm.xs.len()
            ),
        ));
    }
    Ok(())
}

/// Cell edges for cell centres `c` (finite, strictly monotonic, non-empty, and positive if
/// `log`): `c.len() + 1` entries, half-way between neighbours (geometrically if `log`) and
/// extended by half a spacing at the ends.
fn cell_edges(c: &[f64], log: bool) -> Vec<f64> {
    if log {
        let logs: Vec<f64> = c.iter().map(|v| v.log10()).collect();
        let mut e = cell_edges(&logs, false);
        if c.len() == 1 {
            e = vec![logs[0] - 0.05, logs[0] + 0.05];
        }
        return e.into_iter().map(|v| 10f64.powf(v)).collect();
    }
    match c {
        [] => vec![0.0, 1.0],
        [v] => {
            let half = if *v == 0.0 { 0.5 } else { 0.1 * v.abs() };
            vec![v - half, v + half]
        }
        _ => {
            let n = c.len();
            let mut e = Vec::with_capacity(n + 1);
            e.push(c[0] - 0.5 * (c[1] - c[0]));
            e.extend(c.windows(2).map(|w| 0.5 * (w[0] + w[1])));
            e.push(c[n - 1] + 0.5 * (c[n - 1] - c[n - 2]));
            e
        }
    }
}

/// What filling the main chart needs.
struct HeatContext<'a> {
    m: &'a Metrics,
    scale: &'a ColorScale,
    xe: &'a [f64],
    ye: &'a [f64],
    /// Palette index of each marker drawn (`None`: off the grid).
    marker_colors: &'a [Option<usize>],
}

/// Palette indices of the markers (shared by markers with the same label), `None` for markers
/// off the grid's cells `[x_lo, x_hi] × [y_lo, y_hi]`, and the legend entries.
fn marker_legend(
    hm: &Heatmap<'_>,
    (x_lo, x_hi): (f64, f64),
    (y_lo, y_hi): (f64, f64),
    missing: bool,
) -> (Vec<Option<usize>>, Vec<LegendEntry>) {
    let mut entries = Vec::new();
    if missing {
        entries.push(LegendEntry {
            label: "no value".into(),
            swatch: Swatch::Fill {
                color: MISSING,
                opacity: 1.0,
            },
        });
    }
    let mut labels: Vec<&str> = Vec::new();
    let mut colors = Vec::with_capacity(hm.markers.len());
    for (mx, my, label) in hm.markers {
        let on_grid = (x_lo..=x_hi).contains(mx) && (y_lo..=y_hi).contains(my);
        if !on_grid {
            colors.push(None);
            continue;
        }
        let k = match labels.iter().position(|l| *l == label.as_str()) {
            Some(k) if !label.is_empty() => k,
            _ => {
                labels.push(label.as_str());
                let k = labels.len() - 1;
                if !label.is_empty() {
                    entries.push(LegendEntry {
                        label: label.clone(),
                        swatch: Swatch::Outlined(MARKER_COLORS[k % MARKER_COLORS.len()]),
                    });
                }
                k
            }
        };
        colors.push(Some(k));
    }
    (colors, entries)
}

impl Figure for Heatmap<'_> {
    fn draw<DB>(&self, root: &DrawingArea<DB, Shift>, scale: f64) -> DrawResult
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static,
    {
        let (w, h) = root.dim_in_pixel();
        let m = Metrics::for_area(w, h, scale);
        let body = if self.title.is_empty() {
            root.clone()
        } else {
            root.margin(m.px(6.0).max(0) as u32, 0, 0, 0)
                .titled(self.title, (FONT, m.title))?
        };
        let (lo, hi) = axis_range(self.values.iter().copied(), self.log_color, false);
        let color_scale = ColorScale {
            lo,
            hi,
            log: self.log_color,
        };

        let xe = cell_edges(self.xs, self.log_x);
        let ye = cell_edges(self.ys, self.log_y);
        let span = |e: &[f64]| {
            let (a, b) = (e[0], e[e.len() - 1]);
            (a.min(b), a.max(b))
        };
        let (x_lo, x_hi) = span(&xe);
        let (y_lo, y_hi) = span(&ye);
        let missing = self.values.iter().any(|&v| !color_scale.usable(v));
        let (marker_colors, entries) = marker_legend(self, (x_lo, x_hi), (y_lo, y_hi), missing);

        // The legend goes below the map (every cell of the map is data), in as many columns
        // as fit.
        let (bw, bh) = body.dim_in_pixel();
        let mut body = body;
        let mut legend_rect = None;
        let mut columns = 1;
        if !entries.is_empty() {
            let one = legend_size(&body, &entries, &m, 1);
            columns = ((bw as i32 - 2 * m.margin as i32) / one.0.max(1)).max(1) as usize;
            let size = legend_size(&body, &entries, &m, columns);
            let (bx, by) = body.get_base_pixel();
            let x0 = bx + (bw as i32 - size.0).max(0) / 2;
            let y0 = by + bh as i32 - size.1 - m.px(2.0);
            legend_rect = Some(PixelRect::new((x0, y0), (x0 + size.0, y0 + size.1)));
            let (top, _) = body.split_vertically(bh as i32 - size.1 - m.px(8.0));
            body = top;
        }
        let (bw, _) = body.dim_in_pixel();
        let bar_width = (f64::from(bw) * 0.16).clamp(40.0 * m.scale, 220.0 * m.scale) as u32;
        let (main, bar) = body.split_horizontally(bw.saturating_sub(bar_width));

        // Main chart.
        let ctx = HeatContext {
            m: &m,
            scale: &color_scale,
            xe: &xe,
            ye: &ye,
            marker_colors: &marker_colors,
        };
        let mut builder = ChartBuilder::on(&main);
        builder
            .margin(m.margin)
            .x_label_area_size(m.x_area)
            .y_label_area_size(m.y_area);
        let mut chart = builder.build_cartesian_2d(
            TickedAxis::new(x_lo, x_hi, self.log_x),
            TickedAxis::new(y_lo, y_hi, self.log_y),
        )?;
        fill_heatmap(&mut chart, self, &ctx)?;

        // Colour bar, aligned with the main plotting area.
        let mut bar_builder = ChartBuilder::on(&bar);
        bar_builder
            .margin(m.margin)
            .margin_left(0)
            .x_label_area_size(m.x_area)
            .right_y_label_area_size(bar_width.saturating_sub(bar_width / 4 + m.margin));
        let mut cb =
            bar_builder.build_cartesian_2d(0.0..1.0, TickedAxis::new(lo, hi, self.log_color))?;
        fill_colorbar(&mut cb, self, &m, &color_scale)?;
        if let Some(rect) = legend_rect {
            draw_legend(root, &rect, &entries, &m, columns)?;
        }
        Ok(())
    }
}

fn fill_heatmap<'a, DB>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<TickedAxis, TickedAxis>>,
    hm: &Heatmap<'_>,
    ctx: &HeatContext<'_>,
) -> DrawResult
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
{
    let m = ctx.m;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(hm.x_label)
        .y_desc(hm.y_label)
        .label_style((FONT, m.tick))
        .axis_desc_style((FONT, m.label))
        .set_all_tick_mark_size(m.px(4.0))
        .axis_style(RGBColor(60, 60, 60).stroke_width(m.px(1.0).max(1) as u32))
        .draw()?;
    let nx = hm.xs.len();
    let (xe, ye) = (ctx.xe, ctx.ye);
    let cells = hm.values.iter().enumerate().map(|(k, &v)| {
        let (i, j) = (k % nx, k / nx);
        let corners = [(xe[i], ye[j]), (xe[i + 1], ye[j + 1])];
        Rectangle::new(corners, ctx.scale.color(v).filled())
    });
    chart.draw_series(cells)?;

    let radius = (m.label / 2.5).round().clamp(3.0 * m.scale, 9.0 * m.scale) as i32;
    let outline = BLACK.stroke_width(m.stroke.max(2));
    for ((mx, my, _), k) in hm.markers.iter().zip(ctx.marker_colors) {
        let Some(k) = k else { continue };
        let color = MARKER_COLORS[k % MARKER_COLORS.len()];
        let marker = EmptyElement::at((*mx, *my))
            + Circle::new((0, 0), radius, color.filled())
            + Circle::new((0, 0), radius, outline);
        chart.draw_series(std::iter::once(marker))?;
    }
    Ok(())
}

fn fill_colorbar<DB>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, TickedAxis>>,
    hm: &Heatmap<'_>,
    m: &Metrics,
    scale: &ColorScale,
) -> DrawResult
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
{
    const STEPS: usize = 128;
    chart.draw_series((0..STEPS).map(|k| {
        let (t0, t1) = (k as f64 / STEPS as f64, (k + 1) as f64 / STEPS as f64);
        let color = viridis(0.5 * (t0 + t1));
        Rectangle::new(
            [(0.0, scale.value_at(t0)), (1.0, scale.value_at(t1))],
            color.filled(),
        )
    }))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(hm.value_label)
        .label_style((FONT, m.tick))
        .axis_desc_style((FONT, m.label))
        .set_all_tick_mark_size(m.px(4.0))
        .draw()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_edges_are_midpoints() {
        assert_eq!(
            cell_edges(&[0.0, 1.0, 3.0], false),
            vec![-0.5, 0.5, 2.0, 4.0]
        );
        assert_eq!(cell_edges(&[2.0, 1.0], false), vec![2.5, 1.5, 0.5]);
        let e = cell_edges(&[5.0], false);
        assert!(e[0] < 5.0 && e[1] > 5.0);
        let e = cell_edges(&[1.0, 100.0], true);
        assert!(
            (e[0] - 0.1).abs() < 1e-12 && (e[1] - 10.0).abs() < 1e-9 && (e[2] - 1e3).abs() < 1e-9
        );
        let e = cell_edges(&[5.0], true);
        assert!(e[0] < 5.0 && e[1] > 5.0);
    }
}

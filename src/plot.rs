//! Figures: grids of line/marker panels and heat maps with a colour bar, written as PNG or SVG.
//!
//! The module is model-agnostic: it plots `(x, y)` point lists ([`Series`]) in panels
//! ([`Panel`], laid out in a grid by [`save_panels`]) and scalar fields on a rectilinear grid
//! ([`Heatmap`], written by [`save_heatmap`]), e.g. the diameter profiles of a spinning
//! experiment or a cost landscape `J(n, κ)`.
//!
//! * The output format follows the file extension: `.png` (bitmap) or `.svg` (vector); any
//!   other extension is an error.
//! * Missing parent directories are created. The only file written is the one named.
//! * Text is rendered with DejaVu Sans, which is bundled in the crate and registered on first
//!   use, so no system font or font library is needed at build or run time.
//! * Non-finite points are skipped (a line is broken at them), empty or all-`NaN` series give
//!   empty axes, and missing heat-map values are shown grey; none of them panics.
//!
//! # Example
//!
//! ```
//! use diffbvp::plot::{save_heatmap, save_panels, Heatmap, Panel, Series};
//!
//! let dir = std::env::temp_dir().join("diffbvp-plot-doc");
//! let z: Vec<f64> = (0..=20).map(|i| f64::from(i) * 0.05).collect();
//! let model: Vec<(f64, f64)> = z.iter().map(|&z| (z, (-2.0 * z).exp())).collect();
//! let data: Vec<(f64, f64)> = z.iter().step_by(4).map(|&z| (z, 1.02 * (-2.0 * z).exp())).collect();
//! let panel = Panel::new("Experiment 1", "z / m", "D / D₀")
//!     .with_series(Series::markers("measured", data))
//!     .with_series(Series::line("model", model));
//! save_panels(&dir.join("profiles.png"), &[panel.clone(), panel], 2, (900, 400))?;
//!
//! // A cost landscape on a 3 × 4 grid (rows are ys, columns xs), one value missing.
//! let xs = [0.2, 0.4, 0.6, 0.8];
//! let ys = [1.0, 2.0, 3.0];
//! let values: Vec<f64> = (0..12).map(|k| if k == 5 { f64::NAN } else { 1.0 + f64::from(k) }).collect();
//! let markers = [(0.4, 2.0, "optimum".to_string())];
//! let map = Heatmap {
//!     title: "J(n, κ)",
//!     x_label: "n",
//!     y_label: "κ",
//!     value_label: "J",
//!     log_color: true,
//!     markers: &markers,
//!     ..Heatmap::new(&xs, &ys, &values)
//! };
//! save_heatmap(&dir.join("landscape.svg"), &map)?;
//! # Ok::<(), diffbvp::plot::PlotError>(())
//! ```

use std::error::Error as StdError;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use thiserror::Error;

/// DejaVu Sans (see `assets/fonts/LICENSE-DejaVu.txt`), used for every label.
static DEJAVU_SANS: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

/// Family name under which the bundled font is registered and used.
const FONT: &str = "sans-serif";

/// Largest accepted figure side, in pixels (guards against huge allocations).
pub const MAX_SIDE: u32 = 16_384;

/// Magnitude beyond which data are clamped for range computation.
const HUGE: f64 = 1e300;

/// Colour of missing heat-map cells.
const MISSING: RGBColor = RGBColor(190, 190, 190);

/// Series colours (matplotlib's "tab10"); [`Series::color`] indexes this list cyclically.
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
const MARKER_COLORS: [RGBColor; 5] = [
    RGBColor(228, 26, 28),
    RGBColor(255, 255, 255),
    RGBColor(255, 0, 255),
    RGBColor(0, 255, 255),
    RGBColor(255, 165, 0),
];

/// Why a figure could not be written. Every variant names the output path.
#[derive(Debug, Error)]
pub enum PlotError {
    /// The extension is neither `.png` nor `.svg`.
    #[error("cannot write plot {path}: unsupported file extension (use .png or .svg)")]
    UnsupportedFormat {
        /// The requested output path.
        path: PathBuf,
    },
    /// The figure description is unusable (sizes, grid shapes, column count, ...).
    #[error("cannot write plot {path}: {reason}")]
    InvalidInput {
        /// The requested output path.
        path: PathBuf,
        /// What is wrong with the input.
        reason: String,
    },
    /// Creating a parent directory or writing the file failed.
    #[error("cannot write plot {path}: {source}")]
    Io {
        /// The requested output path.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The bundled font could not be registered.
    #[error("cannot write plot {path}: the bundled font could not be registered")]
    Font {
        /// The requested output path.
        path: PathBuf,
    },
    /// The drawing backend or the PNG encoder failed.
    #[error("cannot write plot {path}: drawing failed: {source}")]
    Draw {
        /// The requested output path.
        path: PathBuf,
        /// The backend's error.
        #[source]
        source: Box<dyn StdError + Send + Sync>,
    },
}

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

/// Writes `panels` as a grid with `columns` columns (rows as needed, filled row by row) into a
/// `size.0 × size.1` pixel figure at `path` (`.png` or `.svg`).
///
/// `columns` larger than the number of panels is reduced to it. Errors if there are no panels,
/// `columns` is 0, or the size is 0 or larger than [`MAX_SIDE`].
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

/// Writes a heat map with a colour bar, and a legend for its markers, to `path` (`.png` or
/// `.svg`).
///
/// Errors if the grid is empty or not finite and strictly monotonic, if `values` does not have
/// `xs.len() * ys.len()` entries, or if the size is 0 or larger than [`MAX_SIDE`].
pub fn save_heatmap(path: &Path, heatmap: &Heatmap<'_>) -> Result<(), PlotError> {
    let hm = heatmap;
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
    write_figure(path, hm.size, hm)
}

// ---------------------------------------------------------------------------------------------
// Output plumbing

type DrawResult = Result<(), Box<dyn StdError + Send + Sync>>;

/// Something that can draw itself onto any plotters backend.
trait Figure {
    fn draw<DB>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static;
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    Png,
    Svg,
}

fn invalid(path: &Path, reason: impl Into<String>) -> PlotError {
    PlotError::InvalidInput {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

fn format_of(path: &Path) -> Result<Format, PlotError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => Ok(Format::Png),
        Some("svg") => Ok(Format::Svg),
        _ => Err(PlotError::UnsupportedFormat {
            path: path.to_path_buf(),
        }),
    }
}

/// Registers the bundled font once; returns whether it is available.
fn ensure_font() -> bool {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    *REGISTERED.get_or_init(|| {
        // "sans-serif" is what we use; the other generic names make plotters' defaults work too.
        [FONT, "serif", "monospace"]
            .iter()
            .all(|name| register_font(name, FontStyle::Normal, DEJAVU_SANS).is_ok())
    })
}

/// Validates, renders in memory, and only then creates directories and writes `path` (through a
/// temporary sibling renamed into place).
fn write_figure<F: Figure>(path: &Path, size: (u32, u32), figure: &F) -> Result<(), PlotError> {
    let format = format_of(path)?;
    let (w, h) = size;
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(invalid(
            path,
            format!("figure size {w} × {h} must be between 1 and {MAX_SIDE} pixels per side"),
        ));
    }
    if path.is_dir() {
        return Err(invalid(path, "the output path is an existing directory"));
    }
    if !ensure_font() {
        return Err(PlotError::Font {
            path: path.to_path_buf(),
        });
    }
    let draw_err = |source: Box<dyn StdError + Send + Sync>| PlotError::Draw {
        path: path.to_path_buf(),
        source,
    };
    let io_err = |source: std::io::Error| PlotError::Io {
        path: path.to_path_buf(),
        source,
    };

    // Render first so that a drawing failure leaves no file behind.
    let mut rgb = Vec::new();
    let mut svg = String::new();
    match format {
        Format::Png => {
            rgb = vec![255u8; w as usize * h as usize * 3];
            let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
            render(&root, figure).map_err(draw_err)?;
        }
        Format::Svg => {
            let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
            render(&root, figure).map_err(draw_err)?;
        }
    }

    if let Some(parent) = path.parent() {
        if !parent.as_os_str().is_empty() {
            fs::create_dir_all(parent).map_err(io_err)?;
        }
    }
    // written to a temporary sibling and renamed into place: never a half-written figure, and
    // an existing file (or hard link) at `path` is replaced, not truncated
    let tmp = temporary_sibling(path);
    let written = match format {
        Format::Png => {
            let mut backend = BitMapBackend::new(&tmp, size);
            backend
                .blit_bitmap((0, 0), size, &rgb)
                .and_then(|()| backend.present())
                .map_err(|e| draw_err(Box::new(e)))
        }
        Format::Svg => fs::write(&tmp, svg).map_err(io_err),
    }
    .and_then(|()| fs::rename(&tmp, path).map_err(io_err));
    if written.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    written
}

/// A fresh temporary path next to `path` with the same extension (`.NAME.tmp-PID-N.EXT`).
fn temporary_sibling(path: &Path) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "figure".into());
    let ext = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp-{}-{n}{ext}", std::process::id()))
}

fn render<DB, F>(root: &DrawingArea<DB, Shift>, figure: &F) -> DrawResult
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
    F: Figure,
{
    root.fill(&WHITE)?;
    figure.draw(root)?;
    root.present()?;
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Ranges and colours

/// Font sizes and label-area sizes scaled to the space available for one chart.
#[derive(Debug, Clone, Copy)]
struct Metrics {
    title: f64,
    label: f64,
    tick: f64,
    margin: u32,
    x_area: u32,
    y_area: u32,
}

impl Metrics {
    fn for_area(w: u32, h: u32) -> Self {
        let base = (f64::from(w.min(h)) / 24.0).clamp(9.0, 22.0);
        let tick = base * 0.85;
        Self {
            title: base * 1.25,
            label: base,
            tick,
            margin: (base * 0.6).round() as u32,
            x_area: (tick * 1.6 + base * 1.7).round() as u32,
            y_area: (tick * 4.2 + base * 1.7).round() as u32,
        }
    }
}

/// Range of the usable values (finite, and positive for a log axis), padded by 5 % (of the
/// decades for a log axis); degenerate and empty cases get a sensible non-empty range.
fn axis_range(values: impl Iterator<Item = f64>, log: bool, pad: bool) -> (f64, f64) {
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

/// `m × 10^e` computed so that the result is the correctly rounded decimal (e.g. exactly `0.3`).
fn decimal(m: f64, e: i32) -> f64 {
    if e >= 0 {
        m * 10f64.powi(e)
    } else {
        m / 10f64.powi(-e)
    }
}

/// Tick values for a logarithmic axis over `[lo, hi]` (`0 < lo < hi`): decades, or 1-2-5 / 1…9
/// mantissas when the range spans only about a decade, or plain decimal steps for a narrow range.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    const MAX_TICKS: usize = 8;
    let e0 = lo.log10().floor() as i32;
    let e1 = hi.log10().floor() as i32;
    let in_range = |v: &f64| *v >= lo * (1.0 - 1e-12) && *v <= hi * (1.0 + 1e-12);
    let with = |mantissas: &[f64]| -> Vec<f64> {
        (e0..=e1)
            .flat_map(|e| mantissas.iter().map(move |&m| decimal(m, e)))
            .filter(in_range)
            .collect()
    };
    let all: Vec<f64> = (1..=9).map(f64::from).collect();
    for mantissas in [&all[..], &[1.0, 2.0, 5.0], &[1.0]] {
        let ticks = with(mantissas);
        if ticks.len() <= MAX_TICKS && ticks.len() >= 3 {
            return ticks;
        }
        if ticks.len() < 3 {
            break;
        }
    }
    let decades = with(&[1.0]);
    if decades.len() > MAX_TICKS {
        let stride = decades.len().div_ceil(MAX_TICKS);
        return decades.into_iter().step_by(stride).collect();
    }
    // Narrow range: evenly spaced decimal ticks.
    let raw = (hi - lo) / 4.0;
    let e = raw.log10().floor() as i32;
    let m = raw / decimal(1.0, e);
    let m = if m < 1.5 {
        1.0
    } else if m < 3.5 {
        2.0
    } else if m < 7.5 {
        5.0
    } else {
        10.0
    };
    let step = decimal(m, e);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first - 1..=last + 1)
        .map(|k| decimal(k as f64 * m, e))
        .filter(in_range)
        .collect()
}

/// Viridis colour map at `t` in `[0, 1]` (piecewise linear through 9 samples).
fn viridis(t: f64) -> RGBColor {
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

/// Tick label: plain decimals for moderate magnitudes, `1.5e6` style otherwise, no float noise.
fn format_tick(v: &f64) -> String {
    let v = *v;
    let a = v.abs();
    if a == 0.0 || !v.is_finite() {
        return if v.is_finite() {
            "0".into()
        } else {
            format!("{v}")
        };
    }
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:.3e}");
        return match s.split_once('e') {
            Some((mantissa, exp)) if mantissa.contains('.') => {
                let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
                format!("{mantissa}e{exp}")
            }
            _ => s,
        };
    }
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
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

// ---------------------------------------------------------------------------------------------
// Panels

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

// ---------------------------------------------------------------------------------------------
// Heat map

/// Colour scale of a heat map: value range and mapping to `[0, 1]`.
#[derive(Debug, Clone, Copy)]
struct ColorScale {
    lo: f64,
    hi: f64,
    log: bool,
}

impl ColorScale {
    fn usable(&self, v: f64) -> bool {
        v.is_finite() && (!self.log || v > 0.0)
    }

    fn color(&self, v: f64) -> RGBColor {
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

    fn value_at(&self, t: f64) -> f64 {
        if self.log {
            self.lo * (self.hi / self.lo).powf(t)
        } else {
            self.lo + t * (self.hi - self.lo)
        }
    }
}

// Builds the main heat-map chart with each axis linear or logarithmic (four coordinate types)
// and fills it.
macro_rules! build_heatmap_chart {
    ($builder:expr, $hm:expr, $m:expr, $scale:expr, $xe:expr, $ye:expr,
     ($x_lo:expr, $x_hi:expr), ($y_lo:expr, $y_hi:expr)) => {{
        let log_x = ($x_lo..$x_hi)
            .log_scale()
            .with_key_points(log_ticks($x_lo, $x_hi));
        let log_y = ($y_lo..$y_hi)
            .log_scale()
            .with_key_points(log_ticks($y_lo, $y_hi));
        match ($hm.log_x, $hm.log_y) {
            (false, false) => {
                let mut c = $builder.build_cartesian_2d($x_lo..$x_hi, $y_lo..$y_hi)?;
                fill_heatmap(&mut c, $hm, $m, $scale, $xe, $ye)
            }
            (true, false) => {
                let mut c = $builder.build_cartesian_2d(log_x, $y_lo..$y_hi)?;
                fill_heatmap(&mut c, $hm, $m, $scale, $xe, $ye)
            }
            (false, true) => {
                let mut c = $builder.build_cartesian_2d($x_lo..$x_hi, log_y)?;
                fill_heatmap(&mut c, $hm, $m, $scale, $xe, $ye)
            }
            (true, true) => {
                let mut c = $builder.build_cartesian_2d(log_x, log_y)?;
                fill_heatmap(&mut c, $hm, $m, $scale, $xe, $ye)
            }
        }
    }};
}

impl Figure for Heatmap<'_> {
    fn draw<DB>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB: DrawingBackend,
        DB::ErrorType: 'static,
    {
        let (w, h) = root.dim_in_pixel();
        let m = Metrics::for_area(w, h);
        let body = if self.title.is_empty() {
            root.clone()
        } else {
            root.titled(self.title, (FONT, m.title))?
        };
        let (bw, _) = body.dim_in_pixel();
        let bar_width = (f64::from(bw) * 0.16).clamp(40.0, 220.0) as u32;
        let (main, bar) = body.split_horizontally(bw.saturating_sub(bar_width));

        let (lo, hi) = axis_range(self.values.iter().copied(), self.log_color, false);
        let scale = ColorScale {
            lo,
            hi,
            log: self.log_color,
        };

        // Main chart.
        let xe = cell_edges(self.xs, self.log_x);
        let ye = cell_edges(self.ys, self.log_y);
        let span = |e: &[f64]| {
            let (a, b) = (e[0], e[e.len() - 1]);
            (a.min(b), a.max(b))
        };
        let (x_lo, x_hi) = span(&xe);
        let (y_lo, y_hi) = span(&ye);
        let mut builder = ChartBuilder::on(&main);
        builder
            .margin(m.margin)
            .x_label_area_size(m.x_area)
            .y_label_area_size(m.y_area);
        build_heatmap_chart!(
            builder,
            self,
            &m,
            &scale,
            &xe,
            &ye,
            (x_lo, x_hi),
            (y_lo, y_hi)
        )?;

        // Colour bar, aligned with the main plotting area.
        let mut bar_builder = ChartBuilder::on(&bar);
        bar_builder
            .margin(m.margin)
            .margin_left(0)
            .x_label_area_size(m.x_area)
            .right_y_label_area_size(bar_width.saturating_sub(bar_width / 4 + m.margin));
        if self.log_color {
            let bar_axis = (lo..hi).log_scale().with_key_points(log_ticks(lo, hi));
            let mut cb = bar_builder.build_cartesian_2d(0.0..1.0, bar_axis)?;
            fill_colorbar(&mut cb, self, &m, &scale)
        } else {
            let mut cb = bar_builder.build_cartesian_2d(0.0..1.0, lo..hi)?;
            fill_colorbar(&mut cb, self, &m, &scale)
        }
    }
}

fn fill_heatmap<'a, DB, X, Y>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    hm: &Heatmap<'_>,
    m: &Metrics,
    scale: &ColorScale,
    xe: &[f64],
    ye: &[f64],
) -> DrawResult
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(hm.x_label)
        .y_desc(hm.y_label)
        .label_style((FONT, m.tick))
        .axis_desc_style((FONT, m.label))
        .x_labels(6)
        .y_labels(6)
        .x_label_formatter(&format_tick)
        .y_label_formatter(&format_tick)
        .draw()?;
    let nx = hm.xs.len();
    let cells = hm.values.iter().enumerate().map(|(k, &v)| {
        let (i, j) = (k % nx, k / nx);
        let corners = [(xe[i], ye[j]), (xe[i + 1], ye[j + 1])];
        Rectangle::new(corners, scale.color(v).filled())
    });
    chart.draw_series(cells)?;

    let radius = (m.label / 2.5).round().clamp(3.0, 9.0) as i32;
    let mut any_legend = false;
    if hm.values.iter().any(|&v| !scale.usable(v)) {
        any_legend = true;
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())?
            .label("no value")
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], MISSING.filled()));
    }
    let (x_range, y_range) = (chart.x_range(), chart.y_range());
    // Markers sharing a label share a colour and one legend entry.
    let mut labels: Vec<&str> = Vec::new();
    for (mx, my, label) in hm.markers.iter() {
        // Markers off the grid are not drawn (nor listed in the legend).
        if !(x_range.contains(mx) || *mx == x_range.end)
            || !(y_range.contains(my) || *my == y_range.end)
        {
            continue;
        }
        let (k, first) = match labels.iter().position(|l| *l == label.as_str()) {
            Some(k) if !label.is_empty() => (k, false),
            _ => {
                labels.push(label.as_str());
                (labels.len() - 1, true)
            }
        };
        let color = MARKER_COLORS[k % MARKER_COLORS.len()];
        let marker = EmptyElement::at((*mx, *my))
            + Circle::new((0, 0), radius, color.filled())
            + Circle::new((0, 0), radius, BLACK.stroke_width(2));
        let series = chart.draw_series(std::iter::once(marker))?;
        if first && !label.is_empty() {
            any_legend = true;
            series.label(label.as_str()).legend(move |(x, y)| {
                EmptyElement::at((x + 7, y))
                    + Circle::new((0, 0), radius, color.filled())
                    + Circle::new((0, 0), radius, BLACK.stroke_width(2))
            });
        }
    }
    if any_legend {
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

fn fill_colorbar<DB, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, Y>>,
    hm: &Heatmap<'_>,
    m: &Metrics,
    scale: &ColorScale,
) -> DrawResult
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
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
        .y_labels(8)
        .y_label_formatter(&format_tick)
        .draw()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn log_ticks_are_readable() {
        assert_eq!(log_ticks(0.2, 1.05), vec![0.2, 0.5, 1.0]);
        assert_eq!(log_ticks(0.5, 5.0), vec![0.5, 1.0, 2.0, 5.0]);
        assert_eq!(
            log_ticks(1e-3, 1e3),
            vec![1e-3, 1e-2, 0.1, 1.0, 10.0, 100.0, 1e3]
        );
        assert!((3..=8).contains(&log_ticks(1e-30, 1e30).len()));
        assert_eq!(log_ticks(0.96, 1.04), vec![0.96, 0.98, 1.0, 1.02, 1.04]);
        assert_eq!(log_ticks(2.0, 8.0), vec![2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
    }

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

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(format_tick(&0.30000000000000004), "0.3");
        assert_eq!(format_tick(&14.0), "14");
        assert_eq!(format_tick(&-2.5), "-2.5");
        assert_eq!(format_tick(&0.0), "0");
        assert_eq!(format_tick(&1e300), "1e300");
        assert_eq!(format_tick(&1.5e6), "1.5e6");
        assert_eq!(format_tick(&-2.0e-5), "-2e-5");
        assert_eq!(format_tick(&1e-3), "0.001");
    }

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

    #[test]
    fn format_follows_extension() {
        assert_eq!(format_of(Path::new("a/b.PNG")).ok(), Some(Format::Png));
        assert_eq!(format_of(Path::new("b.svg")).ok(), Some(Format::Svg));
        assert!(matches!(
            format_of(Path::new("b.pdf")),
            Err(PlotError::UnsupportedFormat { .. })
        ));
        assert!(format_of(Path::new("noext")).is_err());
    }

    #[test]
    fn viridis_endpoints() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(f64::NAN), RGBColor(68, 1, 84));
    }
}

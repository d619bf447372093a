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
//! use rheometer::report::plot::{save_heatmap, save_panels, Heatmap, Panel, Series};
//!
//! // under the build directory (`cargo test` runs doc examples from the crate root)
//! let dir = std::path::Path::new("target").join("diffbvp-plot-doc");
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
//! # Ok::<(), rheometer::report::plot::PlotError>(())
//! ```
//!
//! # Layout
//!
//! * `panels`: [`Series`] and [`Panel`], and drawing them in a grid ([`save_panels`]);
//! * `heatmap`: [`Heatmap`] and its colour bar ([`save_heatmap`]);
//! * `axis::axes`, `axis::ticks`: axis ranges, tick values and labels, font and label-area sizes;
//! * `style::colors`: the series [`PALETTE`], marker colours and the viridis colour map;
//! * `style::fonts`: the bundled font;
//! * `write`: format choice (PNG/SVG), rendering in memory and atomic writing;
//! * `error`: [`PlotError`].

mod axis;
mod error;
mod flow_curve;
mod heatmap;
mod legend;
mod panel_draw;
mod panels;
mod style;
mod write;

pub use error::PlotError;
pub(crate) use flow_curve::render_flow_curve;
pub use flow_curve::{flow_curve_svg, save_flow_curve, FlowCurvePlot, ReferencePoints};
pub(crate) use heatmap::render_heatmap;
pub use heatmap::{save_heatmap, Heatmap};
pub(crate) use panel_draw::render_panels;
pub use panel_draw::{panels_svg, save_panels};
pub(crate) use panels::Band;
pub use panels::{Panel, Series, Style};
pub use style::colors::PALETTE;
pub use write::FigureFormat;

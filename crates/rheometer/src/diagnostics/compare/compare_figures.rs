//! Figures of a comparison: diameters, `1/d²`, residual along `s` with the noise band, and
//! residuals against the local strain rate, temperature and speed.

use super::{CompareError, Comparison, FigureFormat};
use crate::data::statistics::median;
use crate::model::simulate::Profiles;
use crate::report::figures::{
    experiment_panel_pages, panel_page_names, ExperimentView, ModelCurves, View,
};
use crate::report::output_files::OutputFile;
use crate::report::plot::{render_panels, Panel, Series};
use std::path::Path;

fn grid_size(panels: usize, columns: usize) -> (u32, u32) {
    let rows = panels.div_ceil(columns).max(1) as u32;
    ((420 * columns as u32).max(900), 320 * rows)
}

/// Bins of `s/L` of the pooled trend.
const TREND_BINS: usize = 12;

/// The pooled trend across experiments: per bin of `s/L` with at least 3 points, the median
/// residual (outliers left out) at the bin's mean position, as `(s [m], residual [%])` with
/// `s = (s/L) · length`.
fn pooled_trend(cmp: &Comparison, length: f64) -> Vec<(f64, f64)> {
    let mut bins: Vec<(Vec<f64>, Vec<f64>)> = vec![(Vec::new(), Vec::new()); TREND_BINS];
    for (k, e) in cmp.experiments.iter().enumerate() {
        let l = cmp
            .noise
            .model
            .as_ref()
            .and_then(|m| m.lengths_m.get(k).copied())
            .unwrap_or(length);
        for p in e.points.iter().filter(|p| !p.outlier) {
            let x = p.position_m / l;
            let b = ((x * TREND_BINS as f64).floor().max(0.0) as usize).min(TREND_BINS - 1);
            bins[b].0.push(x);
            bins[b].1.push(p.residual);
        }
    }
    bins.into_iter()
        .filter(|(x, _)| x.len() >= 3)
        .map(|(x, mut r)| {
            let xm = x.iter().sum::<f64>() / x.len() as f64;
            (xm * length, 100.0 * median(&mut r))
        })
        .collect()
}

/// The names of the figures [`render_figures`] renders for `experiments` experiments.
pub fn figure_names(experiments: usize, format: FigureFormat) -> Vec<String> {
    let ext = format.extension();
    let mut v = Vec::new();
    for stem in ["compare_diameters", "compare_inverse_d2"] {
        v.extend(panel_page_names(stem, ext, experiments));
    }
    v.extend(["compare_residuals", "compare_residual_trends"].map(|s| format!("{s}.{ext}")));
    v
}

/// Renders the figures of `cmp` as files in `dir`:
/// * `compare_diameters.EXT`: measured and simulated diameters per experiment (µm);
/// * `compare_inverse_d2.EXT`: `1/d²` measured and simulated per experiment (1/mm²);
///   (both split into `NAME_1.EXT`, `NAME_2.EXT`, … beyond
///   [`MAX_PANELS_PER_FIGURE`](crate::report::figures::MAX_PANELS_PER_FIGURE) experiments);
/// * `compare_residuals.EXT`: relative residual vs `s`, per experiment, with the noise model's
///   `±2σ(s/L)` band (varying along the line; plus the given `±2σ` if one was given), the
///   pooled trend across experiments (median of the residuals in bins of `s/L`, outliers left
///   out) and the outliers ringed; below, the pooled station mean with its `±2 se` band;
/// * `compare_residual_trends.EXT`: residuals against strain rate, temperature and speed, one
///   colour per experiment.
///
/// Returns the rendered files (nothing is written).
pub fn render_figures(
    cmp: &Comparison,
    dir: &Path,
    format: FigureFormat,
) -> Result<Vec<OutputFile>, CompareError> {
    let ext = format.extension();
    let mut out = diameter_pages(cmp, dir, ext)?;
    let mut save = |name: &str, panels: &[Panel], columns: usize| -> Result<(), CompareError> {
        let path = dir.join(format!("{name}.{ext}"));
        let bytes = render_panels(&path, panels, columns, grid_size(panels.len(), columns))?;
        out.push(OutputFile::new(path, bytes));
        Ok(())
    };
    let range = station_range(cmp);
    let residuals = [residual_panel(cmp, range), station_mean_panel(cmp, range)];
    save("compare_residuals", &residuals, 1)?;
    save("compare_residual_trends", &trend_panels(cmp), 3)?;
    Ok(out)
}

/// Measured against model per experiment, as `d` and as `1/d²` (the rheometer's figure
/// panels): renders `compare_diameters.EXT` and `compare_inverse_d2.EXT` (split into pages).
fn diameter_pages(
    cmp: &Comparison,
    dir: &Path,
    ext: &str,
) -> Result<Vec<OutputFile>, CompareError> {
    let mut out = Vec::new();
    let measured: Vec<(Vec<f64>, Vec<f64>)> = cmp
        .experiments
        .iter()
        .map(|e| e.points.iter().map(|p| (p.position_m, p.d_meas_m)).unzip())
        .collect();
    let views: Vec<ExperimentView> = cmp
        .experiments
        .iter()
        .zip(&measured)
        .map(|(e, (s, d))| ExperimentView {
            name: &e.name,
            length: e.curve_position_m.last().copied().unwrap_or(0.0),
            positions: s,
            diameters: d,
            smooth: None,
        })
        .collect();
    let curves: Vec<Profiles> = cmp
        .experiments
        .iter()
        .map(|e| Profiles {
            position: e.curve_position_m.clone(),
            diameter: e.curve_diameter_m.clone(),
            ..Profiles::default()
        })
        .collect();
    let model = [ModelCurves {
        label: "model",
        profiles: &curves,
        dashed: false,
    }];
    for (name, view) in [
        ("compare_diameters", View::Diameter),
        ("compare_inverse_d2", View::InverseSquare),
    ] {
        let path = dir.join(format!("{name}.{ext}"));
        out.extend(experiment_panel_pages(&path, &views, &model, view)?);
    }
    Ok(out)
}

/// The range `(s_lo, s_hi)` \[m\] of the stations.
fn station_range(cmp: &Comparison) -> (f64, f64) {
    cmp.stations
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), st| {
            (a.min(st.position_m), b.max(st.position_m))
        })
}

/// The relative residual against `s` per experiment, with the noise model's `±2σ(s/L)` band
/// (and the given `±2σ`), the pooled trend and the outliers ringed; the bands span the
/// stations' range `(s_lo, s_hi)`.
fn residual_panel(cmp: &Comparison, (s_lo, s_hi): (f64, f64)) -> Panel {
    let mut each = Panel::new("relative residual per experiment", "s (m)", "residual (%)");
    for (k, e) in cmp.experiments.iter().enumerate() {
        each = each.with_series(
            Series::markers(
                e.name.as_str(),
                e.points
                    .iter()
                    .map(|p| (p.position_m, 100.0 * p.residual))
                    .collect(),
            )
            .with_color(k),
        );
    }
    let length = cmp.noise.model.as_ref().map_or_else(
        || {
            cmp.experiments
                .iter()
                .filter_map(|e| e.curve_position_m.last().copied())
                .fold(0.0, f64::max)
        },
        |m| m.lengths_m.iter().copied().fold(0.0, f64::max),
    );
    if let Some(nm) = &cmp.noise.model {
        let band: Vec<(f64, f64)> = (0..=60)
            .map(|i| {
                let s = s_lo + (s_hi - s_lo) * f64::from(i) / 60.0;
                (s, 200.0 * nm.local_sigma(s / length))
            })
            .collect();
        let lower: Vec<(f64, f64)> = band.iter().map(|(s, v)| (*s, -v)).collect();
        each = each
            .with_series(Series::dashed("±2σ(s) noise model", band).with_color(9))
            .with_series(Series::dashed("", lower).with_color(9));
    }
    if cmp.noise.declared() {
        let two_sigma = 200.0 * cmp.noise.level;
        each = each
            .with_series(
                Series::dashed("±2σ given", vec![(s_lo, two_sigma), (s_hi, two_sigma)])
                    .with_color(7),
            )
            .with_series(
                Series::dashed("", vec![(s_lo, -two_sigma), (s_hi, -two_sigma)]).with_color(7),
            );
    }
    each = each.with_series(Series::line("pooled trend", pooled_trend(cmp, length)).with_color(3));
    let outliers: Vec<(f64, f64)> = cmp
        .experiments
        .iter()
        .flat_map(|e| e.points.iter().filter(|p| p.outlier))
        .map(|p| (p.position_m, 100.0 * p.residual))
        .collect();
    if !outliers.is_empty() {
        let label = format!("outliers ({})", outliers.len());
        each = each.with_series(Series::rings(label, outliers).with_color(3));
    }
    each
}

/// The pooled station mean of the residuals with its `±2 se` band, and the zero line over
/// `(s_lo, s_hi)`.
fn station_mean_panel(cmp: &Comparison, (s_lo, s_hi): (f64, f64)) -> Panel {
    let st = &cmp.stations;
    Panel::new("pooled residual (station mean)", "s (m)", "residual (%)")
        .with_series(
            Series::line(
                "mean",
                st.iter().map(|s| (s.position_m, 100.0 * s.mean)).collect(),
            )
            .with_color(0),
        )
        .with_series(
            Series::dashed(
                "±2 se",
                st.iter()
                    .map(|s| (s.position_m, 200.0 * s.std_error))
                    .collect(),
            )
            .with_color(9),
        )
        .with_series(
            Series::dashed(
                "",
                st.iter()
                    .map(|s| (s.position_m, -200.0 * s.std_error))
                    .collect(),
            )
            .with_color(9),
        )
        .with_series(Series::line("", vec![(s_lo, 0.0), (s_hi, 0.0)]).with_color(7))
}

/// The residuals against strain rate, temperature and speed, one colour per experiment.
fn trend_panels(cmp: &Comparison) -> Vec<Panel> {
    type Getter = fn(&super::ComparedPoint) -> f64;
    let quantities: [(&str, &str, Getter); 3] = [
        ("vs strain rate", "strain rate (1/s)", |p| p.strain_rate_1_s),
        ("vs temperature", "T (K)", |p| p.temperature_k),
        ("vs speed", "u (m/s)", |p| p.speed_m_s),
    ];
    quantities
        .iter()
        .map(|(title, xl, get)| {
            let mut panel = Panel::new(*title, *xl, "residual (%)");
            for (k, e) in cmp.experiments.iter().enumerate() {
                panel = panel.with_series(
                    Series::markers(
                        e.name.as_str(),
                        e.points
                            .iter()
                            .map(|p| (get(p), 100.0 * p.residual))
                            .collect(),
                    )
                    .with_color(k),
                );
            }
            panel
        })
        .collect()
}

//! Figures of spinning experiments: simulated profiles, measured diameters with the smooth fit
//! and model curves (paper Fig. 2, 3, 5), and the cost landscape (paper Fig. 4).
//!
//! A thin fiber-specific layer over the model-agnostic [`crate::report::plot`]: it converts units
//! for display (positions in m, diameters in µm, `1/d²` in 1/mm², temperatures in °C) and lays out
//! one panel per experiment. Every function renders in memory and returns the file (an
//! [`OutputFile`]: its path and bytes) for the caller to write — a command through its checked
//! outputs, a library user with [`OutputFile::save`]; the format follows the extension (`.png`
//! or `.svg`), and a function given a format renders that format. Residual panels carry the
//! noise band (shaded `±2σ`).

use super::output_files::{OutputError, OutputFile};
use crate::data::smoothing::SmoothFit;
use crate::fit::{Identification, Landscape, Rheometer, RheometerError};
use crate::model::simulate::FiberSolution;
use crate::model::simulate::Profiles;
use crate::report::plot::{
    panels_svg, render_heatmap, render_panels, Band, FigureFormat, Heatmap, Panel, PlotError,
    Series,
};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Writing a figure failed.
#[derive(Debug, Error)]
pub enum FigureError {
    /// The output path is an input, or a directory could not be created.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// Drawing or writing the figure failed.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// The model curves could not be computed (by a caller that computes them for a figure).
    #[error(transparent)]
    Model(#[from] RheometerError),
}

/// Number of points at which smooth curves (the ansatz fit) are drawn.
const CURVE_POINTS: usize = 200;

/// One experiment as shown in a figure panel.
#[derive(Debug, Clone, Copy)]
pub struct ExperimentView<'a> {
    /// Experiment name (panel title).
    pub name: &'a str,
    /// Spin-line length `L` \[m\].
    pub length: f64,
    /// Measurement positions `s` \[m\].
    pub positions: &'a [f64],
    /// Measured diameters \[m\].
    pub diameters: &'a [f64],
    /// The ansatz fit of the measurements, if it is to be drawn.
    pub smooth: Option<&'a SmoothFit>,
}

/// A labelled model curve per experiment (same order as the experiments), drawn as a line
/// (`dashed = false`) or dashed line.
#[derive(Debug, Clone, Copy)]
pub struct ModelCurves<'a> {
    /// Legend label, e.g. `"identified n = 0.80"`.
    pub label: &'a str,
    /// One profile per experiment.
    pub profiles: &'a [Profiles],
    /// Draw dashed.
    pub dashed: bool,
}

/// Which quantity the experiment panels show.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum View {
    /// Diameter `d` in µm (paper Fig. 2 and 3).
    Diameter,
    /// The velocity-like `1/d²` in 1/mm² (paper Fig. 5).
    InverseSquare,
}

impl View {
    fn value(self, d_m: f64) -> f64 {
        match self {
            View::Diameter => d_m * 1e6,
            View::InverseSquare => 1.0 / (d_m * 1e3).powi(2),
        }
    }

    fn label(self) -> &'static str {
        match self {
            View::Diameter => "d / µm",
            View::InverseSquare => "1/d² / mm⁻²",
        }
    }
}

/// Columns of a panel grid for `k` panels (3 for the paper's 9 experiments).
fn columns(k: usize) -> usize {
    match k {
        0..=3 => k.max(1),
        4 => 2,
        _ => 3,
    }
}

/// Figure size for a grid of `k` panels.
fn grid_size(k: usize) -> (u32, u32) {
    let c = columns(k) as u32;
    let r = k.div_ceil(columns(k)).max(1) as u32;
    (420 * c, 320 * r)
}

/// One panel per experiment: measured points, the smooth fit (if given) and `curves`, in the
/// chosen `view`, rendered as the file `path`.
pub(crate) fn experiment_panels(
    path: &Path,
    experiments: &[ExperimentView<'_>],
    curves: &[ModelCurves<'_>],
    view: View,
) -> Result<OutputFile, FigureError> {
    let mut panels = Vec::with_capacity(experiments.len());
    for (k, e) in experiments.iter().enumerate() {
        let mut panel =
            Panel::new(e.name, "s / m", view.label()).with_log_y(view == View::Diameter);
        let data: Vec<(f64, f64)> = e
            .positions
            .iter()
            .zip(e.diameters)
            .map(|(&s, &d)| (s, view.value(d)))
            .collect();
        panel = panel.with_series(Series::markers("measured", data).with_color(7));
        if let Some(f) = e.smooth {
            let pts: Vec<(f64, f64)> = diffbvp::mesh::linspace(0.0, e.length, CURVE_POINTS)
                .into_iter()
                .map(|s| (s, view.value(f.diameter(s))))
                .collect();
            panel = panel.with_series(Series::line("smooth fit (eq. 5)", pts).with_color(2));
        }
        for (c, curve) in curves.iter().enumerate() {
            if let Some(p) = curve.profiles.get(k) {
                // beside the measurements: what the gauge reads (the diameter without gauge
                // effects)
                let pts: Vec<(f64, f64)> = p
                    .position
                    .iter()
                    .zip(p.gauge_reading.as_ref().unwrap_or(&p.diameter))
                    .map(|(&s, &d)| (s, view.value(d)))
                    .collect();
                let series = if curve.dashed {
                    Series::dashed(curve.label, pts)
                } else {
                    Series::line(curve.label, pts)
                };
                panel = panel.with_series(series.with_color(if c == 0 { 0 } else { c + 2 }));
            }
        }
        panels.push(panel);
    }
    let bytes = render_panels(
        path,
        &panels,
        columns(experiments.len()),
        grid_size(experiments.len()),
    )?;
    Ok(OutputFile::new(path, bytes))
}

/// Most experiment panels in one figure file (8 rows of 3: 1260 × 2560 pixels); more are split
/// over several files by [`experiment_panel_pages`].
pub const MAX_PANELS_PER_FIGURE: usize = 24;

/// The file names [`experiment_panel_pages`] writes for `experiments` panels into a figure
/// named `STEM.EXT`: `STEM.EXT` itself up to [`MAX_PANELS_PER_FIGURE`] panels, else
/// `STEM_1.EXT`, `STEM_2.EXT`, … (so that every output can be checked before the work).
pub fn panel_page_names(stem: &str, ext: &str, experiments: usize) -> Vec<String> {
    if experiments <= MAX_PANELS_PER_FIGURE {
        return vec![format!("{stem}.{ext}")];
    }
    (1..=experiments.div_ceil(MAX_PANELS_PER_FIGURE))
        .map(|k| format!("{stem}_{k}.{ext}"))
        .collect()
}

/// Like `experiment_panels`, split into figures of at most [`MAX_PANELS_PER_FIGURE`] panels
/// so that any number of experiments can be drawn: up to that many, `path` itself; beyond,
/// `STEM_1.EXT`, `STEM_2.EXT`, … next to it (see [`panel_page_names`]). Returns the rendered
/// files.
pub fn experiment_panel_pages(
    path: &Path,
    experiments: &[ExperimentView<'_>],
    curves: &[ModelCurves<'_>],
    view: View,
) -> Result<Vec<OutputFile>, FigureError> {
    if experiments.len() <= MAX_PANELS_PER_FIGURE {
        return Ok(vec![experiment_panels(path, experiments, curves, view)?]);
    }
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default();
    let names = panel_page_names(&stem, &ext, experiments.len());
    let mut written = Vec::new();
    for (name, start) in names
        .iter()
        .zip((0..experiments.len()).step_by(MAX_PANELS_PER_FIGURE))
    {
        let end = (start + MAX_PANELS_PER_FIGURE).min(experiments.len());
        let page_curves: Vec<ModelCurves<'_>> = curves
            .iter()
            .map(|c| ModelCurves {
                profiles: c
                    .profiles
                    .get(start..end.min(c.profiles.len()))
                    .unwrap_or(&[]),
                ..*c
            })
            .collect();
        let p = path.with_file_name(name);
        written.push(experiment_panels(
            &p,
            &experiments[start..end],
            &page_curves,
            view,
        )?);
    }
    Ok(written)
}

/// Simulated diameter (log scale) and temperature profiles of all experiments in two panels
/// side by side, one line per experiment, rendered as the file `path`.
pub fn profile_overview(
    path: &Path,
    names: &[&str],
    profiles: &[Profiles],
) -> Result<OutputFile, FigureError> {
    let mut d = Panel::new("diameter", "s / m", "d / µm").with_log_y(true);
    let mut t = Panel::new("temperature", "s / m", "T / °C");
    for (k, (name, p)) in names.iter().zip(profiles).enumerate() {
        let dd: Vec<(f64, f64)> = p
            .position
            .iter()
            .zip(&p.diameter)
            .map(|(&s, &v)| (s, v * 1e6))
            .collect();
        let tt: Vec<(f64, f64)> = p
            .position
            .iter()
            .zip(&p.temperature)
            .map(|(&s, &v)| (s, v - 273.15))
            .collect();
        d = d.with_series(Series::line(*name, dd).with_color(k));
        t = t.with_series(Series::line(*name, tt).with_color(k));
    }
    let bytes = render_panels(path, &[d, t], 2, (1200, 480))?;
    Ok(OutputFile::new(path, bytes))
}

/// The cost landscape as a heat map over `(n, κ)` with a logarithmic colour scale (paper
/// Fig. 4), with `markers` `(n, κ, label)` (e.g. start points and the identified optimum).
/// Missing values (failed simulations) are grey. Rendered as the file `path`.
pub fn landscape_map(
    path: &Path,
    landscape: &Landscape,
    title: &str,
    markers: &[(f64, f64, String)],
) -> Result<OutputFile, FigureError> {
    let map = Heatmap {
        title,
        x_label: "n",
        y_label: "κ = ln(K / 1 Pa)",
        value_label: "J",
        log_color: true,
        markers,
        ..Heatmap::new(&landscape.n, &landscape.kappa, &landscape.cost)
    };
    Ok(OutputFile::new(path, render_heatmap(path, &map)?))
}

/// Stems of the figures of [`identification_figures`].
const IDENTIFICATION_FIGURES: [&str; 3] = [
    "fig2_smoothing",
    "fig3_newtonian_vs_identified",
    "fig5_inverse_square",
];

/// The file names [`identification_figures`] writes for `experiments` experiments with
/// extension `ext`.
pub fn identification_figure_names(ext: &str, experiments: usize) -> Vec<String> {
    IDENTIFICATION_FIGURES
        .iter()
        .flat_map(|stem| panel_page_names(stem, ext, experiments))
        .collect()
}

/// Paper Fig. 2, 3 and 5 for an identification, rendered as files in `dir` with extension `ext`
/// (`"png"` or `"svg"`): `fig2_smoothing` (measured diameters with the smooth fit),
/// `fig3_newtonian_vs_identified` (the Newtonian model `n = 1` at the identified κ with the
/// take-up diameters `d_fit(L)`, and the identified law), and `fig5_inverse_square` (the
/// velocity-like `1/d²` view), each split into `NAME_1`, `NAME_2`, … beyond
/// [`MAX_PANELS_PER_FIGURE`] experiments. Returns the rendered files.
///
/// Draws only: the identified profiles are `id.solutions`, the Newtonian ones `newtonian` (one
/// solution per experiment, from [`Rheometer::newtonian_solutions`] at `id.kappa`).
pub fn identification_figures(
    rh: &Rheometer,
    id: &Identification,
    newtonian: &[diffbvp::Solution],
    dir: &Path,
    ext: &str,
) -> Result<Vec<OutputFile>, FigureError> {
    // the format asked for, or an error before anything is computed
    let ext = FigureFormat::of_path(Path::new(&format!("figure.{ext}")))
        .map_err(|_| PlotError::UnsupportedFormat {
            path: dir.join(format!("fig2_smoothing.{ext}")),
        })?
        .extension();
    let views: Vec<ExperimentView> = rh
        .experiments
        .iter()
        .zip(&rh.measurements)
        .zip(&rh.smoothing)
        .map(|((e, m), f)| ExperimentView {
            name: &e.name,
            length: e.spinline_length,
            positions: &m.positions,
            diameters: &m.diameters,
            smooth: Some(f),
        })
        .collect();
    let profiles = |sols: &[diffbvp::Solution]| -> Vec<crate::model::simulate::Profiles> {
        sols.iter()
            .zip(&rh.models)
            .map(|(s, m)| {
                FiberSolution {
                    solution: s.clone(),
                }
                .uniform_profiles(m, 201)
            })
            .collect()
    };
    let identified = profiles(&id.solutions);
    let newtonian = profiles(newtonian);
    // a law that is not a result (FitSummary::law_not_a_result) is not labelled "identified"
    let (word, note) = match id.summary.law_not_a_result() {
        Some(_) => ("fitted", ": NOT A RESULT (see the report)"),
        None => ("identified", ""),
    };
    let label = format!(
        "{word} n = {:.3}, κ = {:.2}{note}",
        id.law()[0],
        id.law()[1]
    );
    let fitted = ModelCurves {
        label: &label,
        profiles: &identified,
        dashed: false,
    };
    let newt_curves = ModelCurves {
        label: "Newtonian n = 1",
        profiles: &newtonian,
        dashed: true,
    };
    let no_smooth: Vec<ExperimentView> = views
        .iter()
        .map(|v| ExperimentView { smooth: None, ..*v })
        .collect();
    let mut written = Vec::new();
    let f2 = dir.join(format!("{}.{ext}", IDENTIFICATION_FIGURES[0]));
    written.extend(experiment_panel_pages(&f2, &views, &[], View::Diameter)?);
    let f3 = dir.join(format!("{}.{ext}", IDENTIFICATION_FIGURES[1]));
    written.extend(experiment_panel_pages(
        &f3,
        &no_smooth,
        &[fitted, newt_curves],
        View::Diameter,
    )?);
    let f5 = dir.join(format!("{}.{ext}", IDENTIFICATION_FIGURES[2]));
    written.extend(experiment_panel_pages(
        &f5,
        &views,
        &[fitted, newt_curves],
        View::InverseSquare,
    )?);
    Ok(written)
}

/// The relative residuals of one experiment along the spin line, as drawn by
/// [`residual_panels`].
#[derive(Debug, Clone, Copy)]
pub struct ResidualView<'a> {
    /// Experiment name (panel title).
    pub name: &'a str,
    /// Positions `s` \[m\].
    pub positions: &'a [f64],
    /// Relative residuals `(d_model − d_meas)/d_meas` \[-\] (drawn in %), one per position.
    pub residuals: &'a [f64],
}

/// One panel per experiment of the relative residual (in %) along the spin line: `before` as
/// markers, `after` (if given: its label and one view per experiment, same order) as a line,
/// and the noise band `±2σ` shaded around zero when the relative noise level `noise_sigma`
/// \[-\] is given. Rendered as the file `path`; its extension chooses the format.
pub fn residual_panels(
    path: &Path,
    before: &[ResidualView<'_>],
    after: Option<(&str, &[ResidualView<'_>])>,
    noise_sigma: Option<f64>,
) -> Result<OutputFile, FigureError> {
    let panels = residual_panel_list(before, after, noise_sigma);
    if panels.is_empty() {
        return Err(FigureError::Plot(PlotError::InvalidInput {
            path: path.to_path_buf(),
            reason: "no experiments to draw residuals of".into(),
        }));
    }
    let cols = columns(panels.len());
    let bytes = render_panels(path, &panels, cols, grid_size(panels.len()))?;
    Ok(OutputFile::new(path, bytes))
}

/// The figure of [`residual_panels`] (without `after`) as an SVG document in memory, for an
/// HTML report; an error without experiments.
pub(crate) fn residuals_svg(
    views: &[ResidualView<'_>],
    noise_sigma: Option<f64>,
) -> Result<String, PlotError> {
    let panels = residual_panel_list(views, None, noise_sigma);
    if panels.is_empty() {
        return Err(PlotError::InvalidInput {
            path: PathBuf::from("<svg>"),
            reason: "no experiments to draw residuals of".into(),
        });
    }
    panels_svg(&panels, columns(panels.len()), grid_size(panels.len()))
}

/// The panels of [`residual_panels`].
fn residual_panel_list(
    before: &[ResidualView<'_>],
    after: Option<(&str, &[ResidualView<'_>])>,
    noise_sigma: Option<f64>,
) -> Vec<Panel> {
    let percent = |v: &ResidualView<'_>| -> Vec<(f64, f64)> {
        v.positions
            .iter()
            .zip(v.residuals)
            .map(|(&s, &r)| (s, 100.0 * r))
            .collect()
    };
    let mut panels = Vec::with_capacity(before.len());
    for (k, b) in before.iter().enumerate() {
        let mut p = Panel::new(b.name, "s / m", "(d_model − d_meas)/d_meas / %");
        if let Some(sigma) = noise_sigma.filter(|s| s.is_finite() && *s > 0.0) {
            p = p.with_band(Band::noise(
                format!("noise ±2σ (σ = {:.2} %)", 100.0 * sigma),
                200.0 * sigma,
            ));
        }
        let label = if after.is_some() {
            "without"
        } else {
            "residual"
        };
        p = p.with_series(Series::markers(label, percent(b)).with_color(0));
        if let Some((label, views)) = after {
            if let Some(a) = views.get(k) {
                p = p.with_series(Series::line(format!("with {label}"), percent(a)).with_color(3));
            }
        }
        panels.push(p);
    }
    panels
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A path under `target/` for a figure (rendering writes nothing).
    fn scratch(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("target")
            .join("test-figures-unit")
            .join(name)
    }

    #[test]
    fn residual_panels_have_the_noise_band_and_the_requested_format() {
        let dir = scratch("residuals");
        let _ = std::fs::remove_dir_all(&dir);
        let s = [0.0, 0.1, 0.2, 0.3];
        let r = [0.004, -0.006, 0.002, 0.0];
        let a = [0.001, -0.001, 0.0, 0.0005];
        let before = [ResidualView {
            name: "exp <1> & 2",
            positions: &s,
            residuals: &r,
        }];
        let after = [ResidualView {
            residuals: &a,
            ..before[0]
        }];
        for ext in ["svg", "png"] {
            let path = dir.join(format!("residuals.{ext}"));
            let file =
                residual_panels(&path, &before, Some(("drag", &after)), Some(0.005)).unwrap();
            assert_eq!(file.path, path);
            assert!(!path.exists(), "rendered, not written");
            let bytes = file.bytes;
            match ext {
                "svg" => {
                    let svg = String::from_utf8(bytes).unwrap();
                    assert!(svg.starts_with("<svg"));
                    assert!(svg.contains("noise ±2σ (σ = 0.50 %)"), "band label");
                    assert!(svg.contains("exp &lt;1&gt; &amp; 2"), "escaped title");
                    assert!(svg.contains("with drag"));
                }
                _ => assert_eq!(&bytes[..4], b"\x89PNG"),
            }
        }
        let err = residual_panels(&dir.join("r.pdf"), &before, None, None);
        assert!(matches!(
            err,
            Err(FigureError::Plot(PlotError::UnsupportedFormat { .. }))
        ));
    }

    #[test]
    fn writes_panels_for_each_view() {
        let dir = scratch("views");
        let s = [0.0, 0.5, 1.0];
        let d = [1e-3, 3e-4, 1e-4];
        let e = ExperimentView {
            name: "exp",
            length: 1.0,
            positions: &s,
            diameters: &d,
            smooth: None,
        };
        let p = Profiles {
            position: s.to_vec(),
            diameter: d.to_vec(),
            ..Profiles::default()
        };
        let curves = [ModelCurves {
            label: "model",
            profiles: std::slice::from_ref(&p),
            dashed: false,
        }];
        for (view, name) in [(View::Diameter, "d.svg"), (View::InverseSquare, "u.png")] {
            let path = dir.join(name);
            let file = experiment_panels(&path, &[e], &curves, view).unwrap();
            assert_eq!(file.path, path);
            assert!(file.bytes.len() > 100);
            // the bytes are of the format the extension names
            match FigureFormat::of_path(&path).unwrap() {
                FigureFormat::Svg => assert!(file.bytes.starts_with(b"<svg"), "{name}"),
                FigureFormat::Png => assert!(file.bytes.starts_with(b"\x89PNG"), "{name}"),
            }
        }
    }

    #[test]
    fn many_panels_are_split_into_pages_of_their_own_experiments() {
        let dir = scratch("pages");
        let s = [0.0, 0.5, 1.0];
        let d = [1e-3, 3e-4, 1e-4];
        let k = 2 * MAX_PANELS_PER_FIGURE + 1;
        let names: Vec<String> = (0..k).map(|i| format!("e{i}")).collect();
        let views: Vec<ExperimentView> = names
            .iter()
            .map(|n| ExperimentView {
                name: n,
                length: 1.0,
                positions: &s,
                diameters: &d,
                smooth: None,
            })
            .collect();
        let profiles: Vec<Profiles> = (0..k)
            .map(|_| Profiles {
                position: s.to_vec(),
                diameter: d.to_vec(),
                ..Profiles::default()
            })
            .collect();
        let curves = [ModelCurves {
            label: "model",
            profiles: &profiles,
            dashed: false,
        }];
        let path = dir.join("panels.svg");
        let pages = experiment_panel_pages(&path, &views, &curves, View::Diameter).unwrap();
        assert_eq!(pages.len(), 3);
        // 24 panels are 3 × 8 (1260 × 2560 pixels), the last page holds one panel
        let sizes = [
            "width=\"1260\" height=\"2560\"",
            "width=\"1260\" height=\"2560\"",
            "width=\"420\" height=\"320\"",
        ];
        for (i, (p, size)) in pages.iter().zip(sizes).enumerate() {
            assert_eq!(p.path, dir.join(format!("panels_{}.svg", i + 1)));
            let svg = String::from_utf8(p.bytes.clone()).unwrap();
            assert!(
                svg[..svg.len().min(300)].contains(size),
                "{}: {}",
                p.path.display(),
                &svg[..200]
            );
            // page i shows the experiments 24 i … 24 i + 23 (titles as SVG text lines)
            let first = MAX_PANELS_PER_FIGURE * i;
            let last = (first + MAX_PANELS_PER_FIGURE).min(k) - 1;
            for e in [first, last] {
                assert!(
                    svg.contains(&format!("e{e}\n")),
                    "{} lacks e{e}",
                    p.path.display()
                );
            }
            if i > 0 {
                assert!(
                    !svg.contains(&format!("e{}\n", first - 1)),
                    "{}",
                    p.path.display()
                );
            }
        }
        // few experiments: the path itself
        let one = experiment_panel_pages(&path, &views[..3], &curves, View::Diameter).unwrap();
        assert_eq!(one.len(), 1);
        assert_eq!(one[0].path, path);
    }
}

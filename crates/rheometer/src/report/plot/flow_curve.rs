//! The flow-curve figure: a viscosity law `η(ε̇)` on log–log axes with its uncertainty bands,
//! a plateau reference line, the strain-rate range the data cover (the law dashed and marked
//! "extrapolated" outside it) and reference points measured elsewhere ([`FlowCurvePlot`],
//! [`save_flow_curve`], [`flow_curve_svg`]).
//!
//! The input is plain numbers (the curve evaluated by the caller), so the figure knows nothing
//! of how the law was identified.

use std::path::Path;

use super::error::{invalid, PlotError};
use super::panel_draw::{panels_svg, render_panels, save_panels};
use super::panels::{Band, Panel, RefLine, Series};

/// Points measured elsewhere, drawn as markers beside the flow curve: shear data shown as
/// `3η` (Trouton), or other elongational data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferencePoints<'a> {
    /// Legend text, e.g. `"3 × shear viscosity (cone-plate)"`.
    pub label: &'a str,
    /// Strain (or shear) rates \[1/s\].
    pub rates: &'a [f64],
    /// Viscosities \[Pa s\], one per rate.
    pub viscosity: &'a [f64],
}

/// A flow curve `η_E(ε̇)` to draw: all curves are sampled at the same `rates`.
///
/// Build one with [`FlowCurvePlot::new`] and struct-update syntax for the optional parts.
/// Non-finite or non-positive viscosities (and band values) are skipped, as on any
/// logarithmic axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlowCurvePlot<'a> {
    /// Title (default `"Flow curve"`); the temperature is appended (`"…, T = 230.0 °C"`).
    pub title: &'a str,
    /// Temperature of the curve \[K\], shown in °C in the title.
    pub temperature_k: Option<f64>,
    /// Strain rates \[1/s\]: finite, positive and strictly increasing (at least 2).
    pub rates: &'a [f64],
    /// The central curve, elongational viscosity \[Pa s\] at each rate.
    pub viscosity: &'a [f64],
    /// Statistical band (e.g. 95 %): lower and upper viscosity \[Pa s\] at each rate.
    pub statistical: Option<(&'a [f64], &'a [f64])>,
    /// Legend text of the statistical band.
    pub statistical_label: &'a str,
    /// Systematic band (from an error budget): lower and upper viscosity \[Pa s\] at each
    /// rate.
    pub systematic: Option<(&'a [f64], &'a [f64])>,
    /// Legend text of the systematic band.
    pub systematic_label: &'a str,
    /// A horizontal reference line \[Pa s\] and its label, e.g. the Newtonian plateau `3η₀`.
    pub plateau: Option<(f64, &'a str)>,
    /// Strain rates covered by the data \[1/s\] (`lo < hi`): shaded; outside it the curve is
    /// dashed and labelled "extrapolated".
    pub data_range: Option<(f64, f64)>,
    /// Legend text of the central curve (default `"identified law"`).
    pub curve_label: &'a str,
    /// Points measured elsewhere.
    pub points: &'a [ReferencePoints<'a>],
    /// Figure size in pixels (width, height).
    pub size: (u32, u32),
}

impl<'a> FlowCurvePlot<'a> {
    /// A flow curve with no bands, reference line, data range or points, 900 × 650 pixels.
    pub fn new(rates: &'a [f64], viscosity: &'a [f64]) -> Self {
        Self {
            title: "Flow curve",
            temperature_k: None,
            rates,
            viscosity,
            statistical: None,
            statistical_label: "95 % confidence band",
            systematic: None,
            systematic_label: "systematic uncertainty",
            plateau: None,
            data_range: None,
            curve_label: "identified law",
            points: &[],
            size: (900, 650),
        }
    }

    /// Checks the request; the error names what is wrong and where.
    fn validate(&self, path: &Path) -> Result<(), PlotError> {
        let n = self.rates.len();
        if n < 2 {
            return Err(invalid(path, "flow curve: rates needs at least 2 values"));
        }
        if let Some(i) = self.rates.iter().position(|r| !(r.is_finite() && *r > 0.0)) {
            return Err(invalid(
                path,
                format!(
                    "flow curve: rates[{i}] = {} is not a positive finite strain rate",
                    self.rates[i]
                ),
            ));
        }
        if let Some(i) = self.rates.windows(2).position(|w| w[1] <= w[0]) {
            return Err(invalid(
                path,
                format!(
                    "flow curve: rates are not strictly increasing at index {}",
                    i + 1
                ),
            ));
        }
        let same = |name: &str, len: usize| {
            if len == n {
                Ok(())
            } else {
                Err(invalid(
                    path,
                    format!("flow curve: {name} has {len} values, rates has {n}"),
                ))
            }
        };
        same("viscosity", self.viscosity.len())?;
        for (name, band) in [
            ("statistical", self.statistical),
            ("systematic", self.systematic),
        ] {
            if let Some((lo, hi)) = band {
                same(&format!("the {name} band's lower curve"), lo.len())?;
                same(&format!("the {name} band's upper curve"), hi.len())?;
            }
        }
        if let Some((lo, hi)) = self.data_range {
            if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && lo < hi) {
                return Err(invalid(
                    path,
                    format!("flow curve: data range [{lo}, {hi}] 1/s must satisfy 0 < lo < hi"),
                ));
            }
        }
        if let Some(t) = self.temperature_k {
            if !(t.is_finite() && t > 0.0) {
                return Err(invalid(
                    path,
                    format!("flow curve: temperature {t} K is not a positive temperature"),
                ));
            }
        }
        for p in self.points {
            if p.rates.len() != p.viscosity.len() {
                return Err(invalid(
                    path,
                    format!(
                        "flow curve: points {:?} have {} rates and {} viscosities",
                        p.label,
                        p.rates.len(),
                        p.viscosity.len()
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The figure as a panel: log–log axes, bands, plateau, curve (dashed outside the data
    /// range) and points.
    fn panel(&self) -> Panel {
        let title = match self.temperature_k {
            Some(t) => format!("{}, T = {:.1} °C", self.title, t - 273.15),
            None => self.title.to_string(),
        };
        // (no combining dot as in ε̇: the bitmap font renderer cannot place combining marks)
        let mut panel = Panel::new(title, "strain rate / s⁻¹", "elongational viscosity / Pa s")
            .with_log_x(true)
            .with_log_y(true);
        if let Some((lo, hi)) = self.data_range {
            panel = panel.with_band(
                Band::vertical("strain rates of the data", lo, hi)
                    .with_color(7)
                    .with_opacity(0.10),
            );
        }
        let pairs = |v: &[f64]| -> Vec<(f64, f64)> {
            self.rates.iter().copied().zip(v.iter().copied()).collect()
        };
        let bands = [
            (self.systematic, self.systematic_label, 1, 0.22),
            (self.statistical, self.statistical_label, 0, 0.30),
        ];
        for (band, label, color, opacity) in bands {
            if let Some((lo, hi)) = band {
                panel = panel.with_band(
                    Band::between(label, pairs(lo), pairs(hi))
                        .with_color(color)
                        .with_opacity(opacity),
                );
            }
        }
        if let Some((value, label)) = self.plateau {
            panel = panel.with_ref_line(RefLine::new(label, value));
        }
        let curve = pairs(self.viscosity);
        match self.data_range {
            Some((lo, hi)) => {
                let inside: Vec<_> = curve
                    .iter()
                    .copied()
                    .filter(|p| p.0 >= lo && p.0 <= hi)
                    .collect();
                // the dashed parts reach the solid one (the nearest point inside, or the edge)
                let below: Vec<_> = curve.iter().copied().filter(|p| p.0 <= lo).collect();
                let above: Vec<_> = curve.iter().copied().filter(|p| p.0 >= hi).collect();
                let below = extend_to(below, inside.first().copied());
                let above = extend_from(inside.last().copied(), above);
                let label_on_below = below.len() >= 2;
                panel = panel
                    .with_series(Series::line(self.curve_label, inside).with_color(0))
                    .with_series(
                        Series::dashed(if label_on_below { "extrapolated" } else { "" }, below)
                            .with_color(0),
                    )
                    .with_series(
                        Series::dashed(if label_on_below { "" } else { "extrapolated" }, above)
                            .with_color(0),
                    );
            }
            None => panel = panel.with_series(Series::line(self.curve_label, curve).with_color(0)),
        }
        for (k, p) in self.points.iter().enumerate() {
            let pts = p.rates.iter().copied().zip(p.viscosity.iter().copied());
            panel = panel.with_series(Series::markers(p.label, pts.collect()).with_color(k + 2));
        }
        panel
    }
}

/// `points` followed by `next` (if any and not already the last point).
fn extend_to(mut points: Vec<(f64, f64)>, next: Option<(f64, f64)>) -> Vec<(f64, f64)> {
    if let (Some(last), Some(next)) = (points.last(), next) {
        if last.0 != next.0 {
            points.push(next);
        }
    }
    points
}

/// `previous` (if any and not already the first point) followed by `points`.
fn extend_from(previous: Option<(f64, f64)>, points: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    match (previous, points.first()) {
        (Some(p), Some(first)) if p.0 != first.0 => std::iter::once(p).chain(points).collect(),
        _ => points,
    }
}

/// Writes the flow curve to `path` (`.png` or `.svg`).
///
/// Errors (naming the path and the offending input) if fewer than 2 rates are given, a rate is
/// not finite and positive or the rates do not increase, a curve or band has another length
/// than `rates`, the data range is not `0 < lo < hi`, the temperature is not positive, or the
/// size is unusable.
pub fn save_flow_curve(path: &Path, plot: &FlowCurvePlot<'_>) -> Result<(), PlotError> {
    plot.validate(path)?;
    save_panels(path, &[plot.panel()], 1, plot.size)
}

/// The figure of [`save_flow_curve`] rendered in memory as the file `path` would hold it.
pub(crate) fn render_flow_curve(
    path: &Path,
    plot: &FlowCurvePlot<'_>,
) -> Result<Vec<u8>, PlotError> {
    plot.validate(path)?;
    render_panels(path, &[plot.panel()], 1, plot.size)
}

/// The flow curve of [`save_flow_curve`] as an SVG document in memory (e.g. for an HTML page).
pub fn flow_curve_svg(plot: &FlowCurvePlot<'_>) -> Result<String, PlotError> {
    plot.validate(Path::new("<svg>"))?;
    panels_svg(&[plot.panel()], 1, plot.size)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_curve_is_dashed_outside_the_data_range() {
        let rates = [0.1, 1.0, 10.0, 100.0, 1000.0];
        let eta = [3e4, 2.9e4, 2e4, 8e3, 2e3];
        let plot = FlowCurvePlot {
            data_range: Some((1.0, 100.0)),
            ..FlowCurvePlot::new(&rates, &eta)
        };
        let panel = plot.panel();
        let solid = &panel.series[0];
        assert_eq!(solid.points.len(), 3);
        let (below, above) = (&panel.series[1], &panel.series[2]);
        assert_eq!(below.points, vec![(0.1, 3e4), (1.0, 2.9e4)]);
        assert_eq!(above.points, vec![(100.0, 8e3), (1000.0, 2e3)]);
        assert_eq!(below.label, "extrapolated");
        assert!(above.label.is_empty());
        // edges between the samples: the dashed parts reach the nearest point inside
        let plot = FlowCurvePlot {
            data_range: Some((0.5, 50.0)),
            ..plot
        };
        let panel = plot.panel();
        assert_eq!(panel.series[1].points, vec![(0.1, 3e4), (1.0, 2.9e4)]);
        assert_eq!(
            panel.series[2].points,
            vec![(10.0, 2e4), (100.0, 8e3), (1000.0, 2e3)]
        );
    }

    #[test]
    fn bad_requests_are_refused_with_the_reason() {
        let path = Path::new("flow.svg");
        let rates = [1.0, 0.5];
        let eta = [1.0, 1.0];
        let err = FlowCurvePlot::new(&rates, &eta).validate(path).unwrap_err();
        assert!(err.to_string().contains("increasing"), "{err}");
        let rates = [1.0, 2.0];
        let short = [1.0];
        let plot = FlowCurvePlot {
            statistical: Some((&short, &eta)),
            ..FlowCurvePlot::new(&rates, &eta)
        };
        let err = plot.validate(path).unwrap_err();
        assert!(err.to_string().contains("statistical"), "{err}");
        let plot = FlowCurvePlot {
            data_range: Some((5.0, 1.0)),
            ..FlowCurvePlot::new(&rates, &eta)
        };
        assert!(plot.validate(path).is_err());
    }
}

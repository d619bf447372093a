//! The flow-curve figure: `η_E(ε̇)` on log–log axes with the statistical and systematic 95 %
//! bands shaded, the Newtonian plateau (Trouton), the strain rates the data cover shaded and
//! the extrapolated parts dashed; isotherms (if computed) as markers.
//!
//! Drawn by [`crate::report::plot`]'s flow-curve figure ([`FlowCurvePlot`]) from the [`FlowCurve`]
//! value alone, as a file ([`flow_curve_figure`]) or as SVG text for an HTML report
//! (`flow_curve_figure_svg`): the two are the same drawing.

use crate::fit::{BandMethod, FlowCurve, FlowPoint};
use crate::report::format::fmt_g;
use crate::report::output_files::OutputFile;
use crate::report::plot::{
    flow_curve_svg, render_flow_curve, FlowCurvePlot, PlotError, ReferencePoints,
};
use std::path::Path;

/// Size of the figure \[px\].
const SIZE: (u32, u32) = (1000, 700);

/// The numbers of a [`FlowCurve`] as the plot takes them (owned, so the plot can borrow).
struct Drawn {
    rates: Vec<f64>,
    eta: Vec<f64>,
    stat: [Vec<f64>; 2],
    total: [Vec<f64>; 2],
    plateau: String,
    statistical_label: &'static str,
    isotherms: Vec<(String, Vec<f64>)>,
    title: String,
    curve_label: String,
}

impl Drawn {
    fn of(curve: &FlowCurve) -> Self {
        let pts = &curve.points;
        let col = |f: &dyn Fn(&FlowPoint) -> f64| -> Vec<f64> { pts.iter().map(f).collect() };
        Drawn {
            rates: col(&|p| p.strain_rate_per_s),
            eta: col(&|p| p.eta_pa_s),
            stat: [col(&|p| p.stat95_pa_s[0]), col(&|p| p.stat95_pa_s[1])],
            total: [col(&|p| p.total95_pa_s[0]), col(&|p| p.total95_pa_s[1])],
            plateau: format!("Newtonian plateau {} η₀", fmt_g(curve.trouton)),
            statistical_label: match curve.band {
                BandMethod::Profile => "statistical 95 % (profile likelihood)",
                _ => "statistical 95 % (delta method)",
            },
            isotherms: curve
                .isotherms
                .iter()
                .map(|iso| {
                    (
                        format!("{} K", fmt_g(iso.temperature_k)),
                        iso.eta_pa_s.clone(),
                    )
                })
                .collect(),
            // a law that is not a result is never drawn as "the identified law"
            title: match &curve.not_a_result {
                Some(_) => "Elongational viscosity: NOT A RESULT".to_string(),
                None => "Elongational viscosity".to_string(),
            },
            curve_label: match &curve.not_a_result {
                // the reason's head ("n is at its upper bound 1"), the rest in the report
                Some(why) => format!(
                    "fitted law, NOT A RESULT: {}",
                    why.split([',', '(']).next().unwrap_or(why).trim()
                ),
                None => "identified law".to_string(),
            },
        }
    }

    /// The plot of `curve` (whose numbers these are), handed to `f`.
    fn with_plot<R>(&self, curve: &FlowCurve, f: impl FnOnce(&FlowCurvePlot<'_>) -> R) -> R {
        let points: Vec<ReferencePoints<'_>> = self
            .isotherms
            .iter()
            .filter(|(_, eta)| eta.len() == self.rates.len())
            .map(|(label, eta)| ReferencePoints {
                label,
                rates: &self.rates,
                viscosity: eta,
            })
            .collect();
        let [lo, hi] = curve.covered_per_s;
        let plot = FlowCurvePlot {
            title: &self.title,
            temperature_k: Some(curve.temperature_k),
            statistical: (curve.band != BandMethod::None).then_some((&self.stat[0], &self.stat[1])),
            statistical_label: self.statistical_label,
            systematic: curve.systematic.then_some((&self.total[0], &self.total[1])),
            systematic_label: "with systematic 95 % (error budget)",
            plateau: Some((curve.plateau_pa_s, &self.plateau)),
            data_range: (lo.is_finite() && hi.is_finite() && lo > 0.0 && lo < hi)
                .then_some((lo, hi)),
            curve_label: &self.curve_label,
            points: &points,
            size: SIZE,
            ..FlowCurvePlot::new(&self.rates, &self.eta)
        };
        f(&plot)
    }
}

/// The flow-curve figure of `curve`, rendered as the file `path` (PNG or SVG by extension;
/// write it with [`OutputFile::save`] or through a command's checked outputs).
pub fn flow_curve_figure(path: &Path, curve: &FlowCurve) -> Result<OutputFile, PlotError> {
    let bytes = Drawn::of(curve).with_plot(curve, |plot| render_flow_curve(path, plot))?;
    Ok(OutputFile::new(path, bytes))
}

/// The flow-curve figure of `curve` as an SVG document (the drawing of
/// [`flow_curve_figure`]), e.g. for an HTML report.
pub(crate) fn flow_curve_figure_svg(curve: &FlowCurve) -> Result<String, PlotError> {
    Drawn::of(curve).with_plot(curve, flow_curve_svg)
}

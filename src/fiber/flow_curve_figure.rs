//! The flow-curve figure: `η_E(ε̇)` on log–log axes with the statistical and systematic 95 %
//! bands, the Newtonian plateau (Trouton), the strain rates the data cover and the extrapolated
//! parts marked.
//!
//! Drawn with the panel primitives of [`crate::plot`] as they are today (a logarithmic
//! vertical axis, the strain rate as `log10` on a linear axis, bands as dashed bounds). The
//! figure depends only on the [`FlowCurve`] value, so a band primitive can replace the dashed
//! bounds without touching the computation.

use crate::fiber::format::fmt_g;
use crate::fiber::rheometer::{BandMethod, FlowCurve};
use crate::plot::{save_panels, Panel, PlotError, Series, Style};
use std::path::Path;

/// Size of the figure \[px\].
const SIZE: (u32, u32) = (1000, 700);

/// `(log10 ε̇, y)` of the points selected by `keep`, broken (a `NaN` point) where a run ends.
fn runs(
    curve: &FlowCurve,
    keep: impl Fn(usize) -> bool,
    y: impl Fn(usize) -> f64,
) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut open = false;
    for (i, p) in curve.points.iter().enumerate() {
        if keep(i) {
            out.push((p.strain_rate_per_s.log10(), y(i)));
            open = true;
        } else if open {
            out.push((f64::NAN, f64::NAN));
            open = false;
        }
    }
    out
}

/// A band's two bounds as one series (lower, a break, upper).
fn bounds(curve: &FlowCurve, band: impl Fn(usize) -> [f64; 2]) -> Vec<(f64, f64)> {
    let mut pts = runs(curve, |_| true, |i| band(i)[0]);
    pts.push((f64::NAN, f64::NAN));
    pts.extend(runs(curve, |_| true, |i| band(i)[1]));
    pts
}

/// Writes the flow-curve figure of `curve` to `path` (PNG or SVG by extension).
pub fn save_flow_curve_figure(path: &Path, curve: &FlowCurve) -> Result<(), PlotError> {
    let pts = &curve.points;
    let title = format!("Elongational viscosity at {} K", fmt_g(curve.temperature_k));
    let mut panel =
        Panel::new(title, "log10(strain rate / (1/s))", "eta_E / (Pa s)").with_log_y(true);
    panel = panel.with_series(
        Series::line(
            "identified law (data range)",
            runs(curve, |i| !pts[i].extrapolated, |i| pts[i].eta_pa_s),
        )
        .with_color(0),
    );
    panel = panel.with_series(
        Series::dashed(
            "extrapolated",
            runs(curve, |i| pts[i].extrapolated, |i| pts[i].eta_pa_s),
        )
        .with_color(0),
    );
    if curve.band != BandMethod::None {
        let label = match curve.band {
            BandMethod::Profile => "statistical 95 % (profile)",
            _ => "statistical 95 % (delta method)",
        };
        panel = panel.with_series(
            Series::dashed(label, bounds(curve, |i| pts[i].stat95_pa_s)).with_color(1),
        );
    }
    if curve.systematic {
        panel = panel.with_series(
            Series::dashed(
                "with systematic 95 %",
                bounds(curve, |i| pts[i].total95_pa_s),
            )
            .with_color(3),
        );
    }
    let (x0, x1) = match (pts.first(), pts.last()) {
        (Some(a), Some(b)) => (a.strain_rate_per_s.log10(), b.strain_rate_per_s.log10()),
        _ => (0.0, 1.0),
    };
    panel = panel.with_series(
        Series::dashed(
            format!("Newtonian plateau {} eta0", fmt_g(curve.trouton)),
            vec![(x0, curve.plateau_pa_s), (x1, curve.plateau_pa_s)],
        )
        .with_color(2),
    );
    // the strain rates the data cover: their ends as markers on the curve
    let ends: Vec<(f64, f64)> = curve
        .covered_per_s
        .iter()
        .filter_map(|&r| curve.nearest(r).map(|p| (r.log10(), p.eta_pa_s)))
        .collect();
    panel = panel
        .with_series(Series::new("ends of the data's range", ends, Style::Rings).with_color(4));
    for (k, iso) in curve.isotherms.iter().enumerate() {
        let pts: Vec<(f64, f64)> = curve
            .points
            .iter()
            .zip(&iso.eta_pa_s)
            .map(|(p, &e)| (p.strain_rate_per_s.log10(), e))
            .collect();
        panel = panel.with_series(
            Series::line(format!("{} K", fmt_g(iso.temperature_k)), pts).with_color(5 + k),
        );
    }
    save_panels(path, &[panel], 1, SIZE)
}

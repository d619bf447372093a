//! Writes a demonstration HTML page (verdict, tables, warnings, preformatted text and two
//! figures embedded as SVG) and the flow-curve figure as PNG and SVG, for the browser check
//! `.ci/html-check` and for review:
//!
//! ```text
//! cargo run --release --example html_page_demo [-- OUT_DIR]   # default target/html-check
//! ```
//!
//! The numbers are made up for the demonstration (a Carreau-type law with bands of plausible
//! width); the page shows the layout, not a result.

use std::path::PathBuf;

use rheometer::report::html_page::{HtmlPage, Table, Tone};
use rheometer::report::plot::{
    flow_curve_svg, panels_svg, save_flow_curve, save_panels, FlowCurvePlot, Panel,
    ReferencePoints, Series,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("target/html-check"));

    // a Carreau-type law η_E = 3η₀ (1 + (λ ε̇)²)^((n−1)/2) and bands around it
    let (eta0, lambda, n) = (1.9e3, 0.35, 0.6);
    let law = |r: f64| 3.0 * eta0 * (1.0 + (lambda * r).powi(2)).powf(0.5 * (n - 1.0));
    let rates: Vec<f64> = (0..=80)
        .map(|i| 10f64.powf(-2.0 + 0.075 * f64::from(i)))
        .collect();
    let eta: Vec<f64> = rates.iter().map(|&r| law(r)).collect();
    let band = |scale: f64| -> (Vec<f64>, Vec<f64>) {
        let w = |r: f64| scale * (1.0 + 0.25 * (r.log10() - 0.8).powi(2));
        (
            rates
                .iter()
                .zip(&eta)
                .map(|(&r, e)| e / (1.0 + w(r)))
                .collect(),
            rates
                .iter()
                .zip(&eta)
                .map(|(&r, e)| e * (1.0 + w(r)))
                .collect(),
        )
    };
    let (stat_lo, stat_hi) = band(0.025);
    let (sys_lo, sys_hi) = band(0.07);
    let shear_rates = [0.01, 0.02, 0.05, 0.1, 0.2, 0.5];
    let shear: Vec<f64> = shear_rates.iter().map(|&r| 0.97 * law(r)).collect();
    let points = [ReferencePoints {
        label: "3 × shear viscosity (cone–plate)",
        rates: &shear_rates,
        viscosity: &shear,
    }];
    let plateau = format!("3η₀ = {:.0} Pa s", 3.0 * eta0);
    let flow = FlowCurvePlot {
        temperature_k: Some(503.15),
        statistical: Some((&stat_lo, &stat_hi)),
        systematic: Some((&sys_lo, &sys_hi)),
        plateau: Some((3.0 * eta0, &plateau)),
        data_range: Some((0.8, 85.0)),
        points: &points,
        ..FlowCurvePlot::new(&rates, &eta)
    };
    save_flow_curve(&dir.join("flow_curve_demo.png"), &flow)?;
    save_flow_curve(&dir.join("flow_curve_demo.svg"), &flow)?;

    // residuals of three experiments with the noise band
    let sigma = 0.55;
    let panels: Vec<Panel> = ["v0p27_p1", "v0p53_p2", "v1p06 <script>&"]
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let pts: Vec<(f64, f64)> = (0..26)
                .map(|i| {
                    let s = 0.02 * f64::from(i);
                    let phase = 1.7 * f64::from(i) + f64::from(k as u32);
                    (s, sigma * (phase.sin() + 0.5 * (2.3 * phase).cos()))
                })
                .collect();
            Panel::new(*name, "s / m", "residual / %")
                .with_noise_band(format!("noise ±2σ (σ = {sigma:.2} %)"), 2.0 * sigma)
                .with_series(Series::markers("residual", pts).with_color(0))
        })
        .collect();
    save_panels(&dir.join("residuals_demo.png"), &panels, 3, (1260, 340))?;

    let mut page = HtmlPage::new("Elongational rheometer: demo <report> & layout");
    page.subtitle("diffbvp html_page_demo · made-up numbers · inputs: data/demo.toml");
    page.verdict(
        Tone::Good,
        "Strain thinning identified: n = 0.804 ± 0.007, K = 1.13 × 10⁵ Pa sⁿ (95 %)",
        "RMS relative residual 0.61 %, consistent with the measurement noise (0.58 %).\n\
         The law is supported for strain rates 0.8–85 s⁻¹; outside, the curve is extrapolated.",
    );
    page.section("Parameters");
    page.table(
        Table::new(&["parameter", "estimate", "95 % interval", "unit"])
            .row(&["n", "0.804", "0.797 – 0.811", "–"])
            .row(&["κ = ln(K / 1 Pa)", "11.63", "11.58 – 11.68", "–"])
            .row(&["3η₀ (T = 230 °C)", "5700", "5520 – 5880", "Pa s"])
            .numeric(1)
            .with_caption("Identified material law"),
    );
    page.section("Flow curve");
    page.figure_svg(
        "Elongational viscosity against strain rate with the statistical (95 %) and \
         systematic bands; dashed outside the strain rates covered by the data.",
        &flow_curve_svg(&flow)?,
    )?;
    page.section("Residuals");
    page.figure_svg(
        "Relative residual along the spin line, with the ±2σ noise band.",
        &panels_svg(&panels, 3, (1260, 340))?,
    )?;
    page.warnings(&[
        "Experiment \"v1p06 <script>&\": 2 outliers left out of the noise level.",
        "Take-up diameter of v0p27_p1 estimated from the last 3 measurements.",
    ]);
    page.section("Text report");
    page.preformatted(
        "n      = 0.804 ± 0.007\nkappa  = 11.63 ± 0.05\nRMS    = 0.61 %   (noise 0.58 %)\n",
    );
    let html = dir.join("demo.html");
    page.write(&html)?;
    println!("wrote {}", html.display());
    println!("wrote {}", dir.join("flow_curve_demo.png").display());
    Ok(())
}

//! The HTML report of a fit ([`fit_report_page`]): one self-contained page a rheologist can
//! keep, print or mail, rendered from the values of a finished fit (its [`FitSummary`] with
//! the [`FlowCurve`](crate::fit::FlowCurve), the experiments' names, data files
//! and point counts, and optionally the relative residuals); nothing is refitted.
//!
//! The page (built with the generic [`crate::report::html_page`], which escapes every text and
//! forbids loading anything from the network) shows, top to bottom:
//!
//! * the verdict: whether the fit has warnings, the law `n`, `κ` with their 95 % intervals,
//!   the fit against the one noise level of the summary;
//! * the material law table (`n`, `κ = ln(K / 1 Pa)`, `K`, the added effects), with the
//!   numbers exactly as the text report prints them;
//! * the flow curve `η_E(ε̇)` with its statistical and systematic bands (inline SVG);
//! * the relative residuals along the spin line (inline SVG, when given);
//! * one row per experiment: name, data file, points, RMS relative residual, take-up factor;
//! * the warnings, the inputs and the program version, and the full text report.

use std::path::{Path, PathBuf};

use crate::data::input::LoadedExperiments;
use crate::fit::summary::text::{fmt_interval, unit_suffix};
use crate::fit::{BandMethod, Estimate, FitSummary};
use crate::report::figures::{residuals_svg, ResidualView};
use crate::report::flow_curve_figure::flow_curve_figure_svg;
use crate::report::format::{fmt_e, fmt_g, fmt_pm, fmt_sig};
use crate::report::html_page::{HtmlPage, Table, Tone};

/// The name of the report in a `fit --out` directory.
pub const FIT_REPORT_HTML: &str = "fit_report.html";

/// One experiment as the report lists it.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportExperiment {
    /// Its name (`name` in the experiments file).
    pub name: String,
    /// Its measurement file, if any.
    pub data_file: Option<PathBuf>,
    /// Number of measured diameters.
    pub points: usize,
}

impl ReportExperiment {
    /// The experiments of a loaded data set, in its order.
    pub fn of(data: &LoadedExperiments) -> Vec<ReportExperiment> {
        data.set
            .experiments
            .iter()
            .enumerate()
            .map(|(k, e)| ReportExperiment {
                name: e.name.clone(),
                data_file: data.details.get(k).and_then(|d| d.data.clone()),
                points: data
                    .set
                    .measurements
                    .get(k)
                    .and_then(Option::as_ref)
                    .map_or(0, |m| m.positions.len()),
            })
            .collect()
    }
}

/// What the report is made of: values of a finished fit.
#[derive(Debug, Clone, Copy)]
pub struct FitReportInput<'a> {
    /// The outcome of the fit (with its flow curve, if computed).
    pub summary: &'a FitSummary,
    /// The experiments file.
    pub experiments_file: &'a Path,
    /// The experiments, in the order of the summary's.
    pub experiments: &'a [ReportExperiment],
    /// The relative residuals along the spin line, one view per experiment (empty: no
    /// residual figure).
    pub residuals: &'a [ResidualView<'a>],
}

/// The version line of the page: `diffbvp 0.1.0`.
pub(crate) fn program_version() -> String {
    format!("diffbvp {}", env!("CARGO_PKG_VERSION"))
}

/// The HTML report of a fit (see the module doc). A figure that cannot be drawn is replaced
/// by a sentence saying why; the page itself always builds.
pub fn fit_report_page(input: &FitReportInput<'_>) -> HtmlPage {
    let s = input.summary;
    let file_name = input.experiments_file.file_name().map_or_else(
        || input.experiments_file.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let mut page = HtmlPage::new(format!("Elongational viscosity from {file_name}"));
    page.subtitle(format!(
        "rheometer fit · {} · {} estimator · {} experiments · {}",
        law_name(s),
        s.estimator.name(),
        input.experiments.len(),
        program_version()
    ));
    verdict(&mut page, s);
    law_section(&mut page, s);
    flow_curve_section(&mut page, s);
    fit_section(&mut page, input);
    page.warnings(&s.warnings.iter().map(|w| w.to_string()).collect::<Vec<_>>());
    inputs_section(&mut page, input);
    page.section("Text report");
    page.preformatted(s.to_text());
    page
}

fn law_name(s: &FitSummary) -> &'static str {
    match s.law {
        crate::model::effects::LawChoice::Carreau => "Carreau-type law",
        crate::model::effects::LawChoice::Newtonian => "Newtonian law",
    }
}

/// `RMS relative residual 0.61 %, 1.05 times the noise level 0.58 %` (as the text report).
fn fit_against_noise(s: &FitSummary) -> String {
    let rms = 100.0 * s.rms_relative_residual;
    if s.noise.level.is_finite() && s.noise.level > 0.0 {
        format!(
            "RMS relative residual {rms:.3} %, {:.2} times the noise level {:.3} %.",
            s.rms_relative_residual / s.noise.level,
            100.0 * s.noise.level
        )
    } else {
        format!("RMS relative residual {rms:.3} % (no noise level).")
    }
}

fn verdict(page: &mut HtmlPage, s: &FitSummary) {
    let law = if s.law_fitted() {
        let part = |label: &str, e: &Estimate| {
            let (value, ci) = estimate_cells(s, e);
            format!("{label} = {value}{} (95 % CI {ci})", unit_suffix(&e.unit))
        };
        format!("{}; {}", part("n", &s.n), part("κ", &s.kappa))
    } else {
        "the law's parameters were not fitted".to_string()
    };
    let mut details = vec![format!("{}: {law}.", law_name(s)), fit_against_noise(s)];
    let finding = s.law_finding();
    if !finding.is_empty() {
        details.push(sentence(&finding));
    }
    let (tone, headline) = match (s.law_not_a_result(), s.warnings.len()) {
        (Some(why), _) => (
            Tone::Bad,
            format!("NOT A RESULT: {why}; this law is no material property"),
        ),
        (None, 0) => (
            Tone::Good,
            "The model fits the data: no warnings".to_string(),
        ),
        (None, n) => (
            Tone::Caution,
            format!("{n} warning(s): check them (below) before using the estimates"),
        ),
    };
    page.verdict(tone, headline, details.join("\n"));
}

/// `text` as a sentence: its first letter upper case, a full stop at the end.
fn sentence(text: &str) -> String {
    let mut c = text.trim().chars();
    let first: String = c
        .next()
        .map_or_else(String::new, |f| f.to_uppercase().collect());
    let rest = c.as_str().trim_end_matches('.');
    format!("{first}{rest}.")
}

/// The parameter's name as the page shows it (`κ` for `kappa`).
fn shown(parameter: &str) -> &str {
    match parameter {
        "kappa" => "κ",
        p => p,
    }
}

/// The estimate and its 95 % interval as the text report prints them: `("0.804 ± 0.007",
/// "[0.790, 0.818]")`; a fixed value, one at a bound or one without standard error with the
/// reason in place of the interval.
fn estimate_cells(s: &FitSummary, e: &Estimate) -> (String, String) {
    if !e.fitted {
        return (fmt_g(e.value), "fixed".into());
    }
    if let Some(b) = s.bound_of(&e.name) {
        return (
            fmt_sig(e.value, 4),
            format!(
                "none: at the {} bound {} of the search range",
                b.side.name(),
                fmt_g(b.bound)
            ),
        );
    }
    if let Some(side) = e.at_bound {
        return (
            fmt_sig(e.value, 4),
            format!("none: at the {} bound", side.name()),
        );
    }
    if !e.stderr.is_finite() {
        return (
            fmt_sig(e.value, 5),
            "none: no standard error (singular covariance)".into(),
        );
    }
    (fmt_pm(e.value, e.stderr), fmt_interval(e.ci95, e.stderr))
}

/// The unit column: `–` for dimensionless.
fn unit_cell(unit: &str) -> String {
    match unit.trim() {
        "" | "-" => "–".into(),
        u => u.to_string(),
    }
}

fn law_section(page: &mut HtmlPage, s: &FitSummary) {
    page.section("Material law");
    page.paragraph(
        "Carreau-type elongational viscosity η_E = η_E0(T) (1 + (η_E0(T) ε̇ / K)²)^((n − 1)/2) \
         with the power index n and κ = ln(K / 1 Pa); η_E0(T) = Tr η₀(T) is the zero-rate \
         elongational viscosity (Trouton ratio Tr times the VFT shear viscosity of the material \
         data). Estimates ± one standard error; 95 % confidence intervals (normal \
         approximation; K's is the image of κ's).",
    );
    let mut t = Table::new(&["parameter", "estimate", "95 % interval", "unit", "fitted"])
        .numeric(1)
        .with_caption("Identified law");
    let yes = |e: &Estimate| if e.fitted { "yes" } else { "no" };
    for (label, e) in [("n", &s.n), ("κ = ln(K / 1 Pa)", &s.kappa)] {
        let (value, ci) = estimate_cells(s, e);
        t = t.row(&[label, &value, &ci, &unit_cell(&e.unit), yes(e)]);
    }
    let k = &s.k_pa;
    if k.value.is_finite() {
        let (value, ci) = if k.has_interval() {
            let e = |v: f64| fmt_e(v, s.k_digits());
            (e(k.value), format!("[{}, {}]", e(k.ci95[0]), e(k.ci95[1])))
        } else {
            (fmt_sig(k.value, 4), "none".to_string())
        };
        t = t.row(&["K = e^κ", &value, &ci, &unit_cell(&k.unit), yes(k)]);
    }
    for e in &s.effects {
        let (value, ci) = estimate_cells(s, &e.strength);
        t = t.row(&[
            &e.effect,
            &value,
            &ci,
            &unit_cell(&e.strength.unit),
            yes(&e.strength),
        ]);
        for sh in &e.shapes {
            let (value, ci) = estimate_cells(s, sh);
            let label = format!("{}.{}", e.effect, sh.name);
            t = t.row(&[&label, &value, &ci, &unit_cell(&sh.unit), yes(sh)]);
        }
    }
    page.table(t);
    let mut notes = Vec::new();
    if s.correlation_n_kappa.is_finite() {
        notes.push(format!(
            "Correlation of n and κ: {:+.4}.",
            s.correlation_n_kappa
        ));
    }
    if let Some(b) = &s.error_budget {
        let parts: Vec<String> = [("n", b.systematic_n), ("κ", b.systematic_kappa)]
            .into_iter()
            .filter_map(|(l, v)| {
                v.filter(|v| v.is_finite() && *v > 0.0)
                    .map(|v| format!("{l} ± {}", fmt_sig(v, 2)))
            })
            .collect();
        if !parts.is_empty() {
            notes.push(format!(
                "Systematic uncertainty (error budget: process conditions, instrument, material \
                 data; one standard uncertainty): {}.",
                parts.join(", ")
            ));
        }
    }
    if let Some(why) = s.likelihood_skipped() {
        notes.push(format!(
            "Profile-likelihood intervals and the likelihood-ratio test against the Newtonian \
             law not computed: {why}."
        ));
    }
    for i in &s.intervals {
        notes.push(format!(
            "Profile likelihood of {}: {}{}.",
            shown(&i.parameter),
            i.words(),
            if i.linearised_trusted() {
                String::new()
            } else {
                format!(
                    " — the linearised interval is not trusted ({})",
                    i.reasons.join(", ")
                )
            }
        ));
    }
    if !notes.is_empty() {
        page.paragraph(notes.join("\n"));
    }
}

fn flow_curve_section(page: &mut HtmlPage, s: &FitSummary) {
    page.section("Flow curve");
    let Some(c) = &s.flow_curve else {
        page.paragraph("No flow curve: it could not be computed for this fit.");
        return;
    };
    let caption = format!(
        "Elongational viscosity η_E against strain rate at {} K: the identified law (solid where \
         the data cover the strain rates, shaded; dashed where extrapolated), {}{}, and the \
         Newtonian plateau {} η₀.",
        fmt_g(c.temperature_k),
        match c.band {
            BandMethod::Delta => "its statistical 95 % band (delta method)",
            BandMethod::Profile => "its statistical 95 % band (along the likelihood profile)",
            BandMethod::None => crate::fit::summary::text::NO_BAND,
        },
        if c.systematic {
            " and the band with the systematic uncertainty of the error budget"
        } else {
            ""
        },
        fmt_g(c.trouton)
    );
    figure(
        page,
        &caption,
        flow_curve_figure_svg(c).map_err(|e| e.to_string()),
    );
    let mut lines = vec![
        format!(
            "Newtonian plateau {} η₀ = {} Pa s (Trouton ratio times the VFT shear viscosity).",
            fmt_g(c.trouton),
            fmt_sig(c.plateau_pa_s, 3)
        ),
        format!(
            "The data cover strain rates {} to {} 1/s at this temperature (median {} 1/s); \
             beyond, the law is extrapolated.",
            fmt_sig(c.covered_per_s[0], 2),
            fmt_sig(c.covered_per_s[1], 2),
            fmt_sig(c.median_per_s, 2)
        ),
    ];
    if let Some(p) = c.nearest(c.median_per_s) {
        let band = |b: [f64; 2]| format!("[{}, {}]", fmt_sig(b[0], 3), fmt_sig(b[1], 3));
        lines.push(format!(
            "At {} 1/s: η_E = {} Pa s, statistical 95 % band {} Pa s{}.",
            fmt_sig(p.strain_rate_per_s, 2),
            fmt_sig(p.eta_pa_s, 3),
            band(p.stat95_pa_s),
            if c.systematic {
                format!(
                    ", with the systematic uncertainty {} Pa s",
                    band(p.total95_pa_s)
                )
            } else {
                String::new()
            }
        ));
    }
    if !c.finding.is_empty() && c.finding != s.law_finding() {
        lines.push(sentence(&c.finding));
    }
    page.paragraph(lines.join("\n"));
    page.paragraph(
        "The numbers of the curve are in flow_curve.csv and flow_curve.json of `rheometer fit \
         --out DIR`.",
    );
}

/// An SVG figure, or a sentence why it is missing.
fn figure(page: &mut HtmlPage, caption: &str, svg: Result<String, String>) {
    let why = match svg {
        Ok(svg) => match page.figure_svg(caption, &svg) {
            Ok(_) => return,
            Err(e) => e.to_string(),
        },
        Err(e) => e,
    };
    page.paragraph(format!("(Figure not shown: {why}.)"));
}

fn fit_section(page: &mut HtmlPage, input: &FitReportInput<'_>) {
    let s = input.summary;
    page.section("Fit against the noise");
    let mut lines = vec![fit_against_noise(s)];
    lines.push(format!("Noise level: {}.", s.noise.describe()));
    lines.push(format!(
        "{} residuals; {} fitted parameters; the fit ended: {}.",
        s.residuals,
        s.fitted_parameters(),
        s.solver.termination_text()
    ));
    page.paragraph(lines.join("\n"));
    let take_up = s.estimator == crate::fit::Estimator::Principled;
    let mut header = vec!["experiment", "data file", "points", "RMS residual / %"];
    if take_up {
        header.push("take-up factor");
    }
    let mut t = Table::new(&header)
        .numeric(2)
        .numeric(3)
        .numeric(4)
        .with_caption("Experiments");
    for (k, e) in input.experiments.iter().enumerate() {
        let rms = s
            .rms_relative_residual_by_experiment
            .get(k)
            .map_or("–".into(), |v| format!("{:.3}", 100.0 * v));
        let file = e.data_file.as_ref().map_or("–".into(), |p| file_name(p));
        let mut row = vec![e.name.clone(), file, e.points.to_string(), rms];
        if take_up {
            row.push(
                s.take_up_factors
                    .get(k)
                    .map_or("–".into(), |v| format!("{v:.4}")),
            );
        }
        t = t.row(&row);
    }
    page.table(t);
    if !input.residuals.is_empty() {
        let sigma = Some(s.noise.level).filter(|v| v.is_finite() && *v > 0.0);
        figure(
            page,
            "Relative residual (d_model − d_meas)/d_meas along the spin line, one panel per \
             experiment, with the band of ±2 noise levels.",
            residuals_svg(input.residuals, sigma).map_err(|e| e.to_string()),
        );
    }
}

/// The last component of `p` (the whole path if it has none).
fn file_name(p: &Path) -> String {
    p.file_name().map_or_else(
        || p.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

fn inputs_section(page: &mut HtmlPage, input: &FitReportInput<'_>) {
    let s = input.summary;
    page.section("Inputs and program");
    let mut t = Table::new(&["what", "value"]).row(&[
        "experiments file".to_string(),
        input.experiments_file.display().to_string(),
    ]);
    for e in input.experiments {
        if let Some(p) = &e.data_file {
            t = t.row(&[format!("data of {}", e.name), p.display().to_string()]);
        }
    }
    let sv = &s.solver;
    t = t
        .row(&["estimator", s.estimator.name()])
        .row(&["loss", &s.loss.to_string()])
        .row(&[
            "start (n, κ)",
            &format!("({}, {})", fmt_g(s.start[0]), fmt_g(s.start[1])),
        ])
        .row(&[
            "iterations",
            &format!(
                "{} ({} failed BVP trial points)",
                sv.iterations, sv.failed_evaluations
            ),
        ])
        .row(&["BVP tolerance", &format!("{:.0e}", sv.bvp_tolerance)])
        .row(&["program", &program_version()]);
    page.table(t);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::summary::tests::example;
    use crate::fit::{AtBound, BoundSide, FitWarning, FlowCurve, FlowPoint, WarningCode};

    /// A flow curve of five points, the middle three covered by the data.
    fn curve() -> FlowCurve {
        let points = (0..5)
            .map(|i| {
                let rate = 10f64.powi(i - 1);
                let eta = 3e4 / (1.0 + rate).sqrt();
                FlowPoint {
                    strain_rate_per_s: rate,
                    eta_pa_s: eta,
                    stat95_pa_s: [0.95 * eta, 1.05 * eta],
                    sys95_pa_s: [0.9 * eta, 1.1 * eta],
                    total95_pa_s: [0.88 * eta, 1.12 * eta],
                    extrapolated: !(1..=3).contains(&i),
                }
            })
            .collect();
        FlowCurve {
            temperature_k: 513.15,
            trouton: 3.0,
            plateau_pa_s: 3e4,
            covered_per_s: [1.0, 100.0],
            median_per_s: 10.0,
            band: BandMethod::Delta,
            systematic: true,
            points,
            isotherms: Vec::new(),
            finding: String::new(),
            not_a_result: None,
        }
    }

    fn page_of(summary: &FitSummary, name: &str, file: &str, toml: &Path) -> String {
        let experiments = [ReportExperiment {
            name: name.into(),
            data_file: Some(PathBuf::from(file)),
            points: 26,
        }];
        let (pos, res) = ([0.0, 0.1, 0.2], [0.01, -0.005, 0.002]);
        let views = [ResidualView {
            name,
            positions: &pos,
            residuals: &res,
        }];
        fit_report_page(&FitReportInput {
            summary,
            experiments_file: toml,
            experiments: &experiments,
            residuals: &views,
        })
        .render()
    }

    #[test]
    fn user_text_is_escaped_and_the_figures_are_inline() {
        let mut s = example();
        s.flow_curve = Some(curve());
        s.experiments = vec!["<script>alert(1)</script> & co".into()];
        let toml = Path::new("/data/<b>x</b> & y/experiments.toml");
        let h = page_of(&s, &s.experiments[0], "<script>b</script>&.csv", toml);
        assert!(h.contains("<td>&lt;script&gt;alert(1)&lt;/script&gt; &amp; co</td>"));
        assert!(h.contains("&lt;script&gt;b&lt;/script&gt;&amp;.csv"));
        assert!(h.contains("/data/&lt;b&gt;x&lt;/b&gt; &amp; y/experiments.toml"));
        assert!(!h.to_lowercase().contains("<script"), "unescaped user text");
        assert!(!h.contains("<b>"));
        // the flow curve and the residuals, inline
        assert_eq!(h.matches("<figure>").count(), 2, "two figures");
        assert!(!h.contains("Figure not shown"));
        assert!(h.contains("default-src 'none'"));
    }

    #[test]
    fn the_law_is_printed_as_in_the_text_report_and_warnings_change_the_verdict() {
        let mut s = example();
        let h = page_of(&s, "a", "a.csv", Path::new("e.toml"));
        let text = s.to_text();
        // n = 0.8 ± 0.01 and kappa = 11.7 ± 0.1: the same strings in both
        for e in [&s.n, &s.kappa] {
            let pm = fmt_pm(e.value, e.stderr);
            let ci = fmt_interval(e.ci95, e.stderr);
            assert!(text.contains(&format!("{pm}  95% CI {ci}")), "{text}");
            assert!(h.contains(&format!("<td class=\"num\">{pm}</td><td>{ci}</td>")));
        }
        assert!(h.contains("class=\"verdict good\""));
        assert!(h.contains("No flow curve"), "a missing curve is said");
        // the one noise level, as the text report gives it
        assert!(text.contains("the noise level 1.500 %") && h.contains("the noise level 1.500 %"));
        // (a warning that leaves the law a result: a misfit makes it none, see below)
        s.warnings.push(FitWarning::new(
            WarningCode::LargeUncertainty,
            "misfit <here> & there".into(),
        ));
        let h = page_of(&s, "a", "a.csv", Path::new("e.toml"));
        assert!(h.contains("class=\"verdict caution\""));
        assert!(h.contains("Warnings (1)") && h.contains("misfit &lt;here&gt; &amp; there"));
    }

    #[test]
    fn a_law_that_is_not_a_result_is_said_so_in_the_text_the_page_and_the_flow_curve() {
        let mut s = example();
        assert_eq!(s.law_not_a_result(), None);
        assert!(!s.to_text().contains("NOT A RESULT"));
        let plain = flow_curve_figure_svg(&curve()).expect("svg");
        assert!(plain.contains("identified law") && !plain.contains("NOT A RESULT"));
        // an implausible n: the warning's finding is the reason, everywhere the law is shown
        s.warnings.push(FitWarning::new(
            WarningCode::Implausible,
            "n = 0.0027 is implausible for a polymer melt (expected 0.2 to 1): the fit \
             compensates a model error"
                .into(),
        ));
        let why = s.law_not_a_result().expect("not a result");
        assert_eq!(
            why,
            "n = 0.0027 is implausible for a polymer melt (expected 0.2 to 1)"
        );
        assert!(s.to_text().contains(&format!("NOT A RESULT: {why}")));
        let h = page_of(&s, "a", "a.csv", Path::new("e.toml"));
        assert!(h.contains("class=\"verdict bad\"") && h.contains("NOT A RESULT"));
        let flagged = FlowCurve {
            not_a_result: Some(why.clone()),
            ..curve()
        };
        let svg = flow_curve_figure_svg(&flagged).expect("svg");
        assert!(svg.contains("NOT A RESULT") && !svg.contains("identified law"));
        // the CSV a spreadsheet reads: a 0/1 column on every row
        let last_column = |c: &FlowCurve| -> Vec<String> {
            let csv = c.to_csv();
            let mut rows = csv
                .lines()
                .map(|l| l.rsplit(',').next().unwrap_or("").to_string());
            assert_eq!(rows.next().as_deref(), Some("law_is_a_result"));
            rows.collect()
        };
        assert!(last_column(&curve()).iter().all(|v| v == "1"));
        let flagged_rows = last_column(&flagged);
        assert!(!flagged_rows.is_empty() && flagged_rows.iter().all(|v| v == "0"));
        // a misfit far above the noise makes it no result too (the law compensates what the
        // model lacks); a warning of another kind does not; a bound does
        s.warnings.clear();
        s.warnings.push(FitWarning::new(
            WarningCode::Misfit,
            "misfit far above the noise: the RMS relative residual is 4.2 times the noise".into(),
        ));
        assert_eq!(
            s.law_not_a_result().as_deref(),
            Some("misfit far above the noise")
        );
        // and no likelihood intervals nor test of that model, in the text and on the page
        let why = s.likelihood_skipped().expect("skipped under a misfit");
        assert!(why.starts_with("the model misses the data by"), "{why}");
        let flat = |t: &str| t.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(flat(&s.to_text()).contains(&format!("not computed: {why}")));
        let h = page_of(&s, "a", "a.csv", Path::new("e.toml"));
        assert!(flat(&h).contains(&format!(
            "test against the Newtonian law not computed: {why}"
        )));
        s.warnings.clear();
        assert_eq!(s.likelihood_skipped(), None);
        s.warnings.push(FitWarning::new(
            WarningCode::LargeUncertainty,
            "kappa: wide".into(),
        ));
        assert_eq!(s.law_not_a_result(), None);
        s.at_bound.push(AtBound {
            parameter: "kappa".into(),
            side: BoundSide::Lower,
            bound: 7.0,
            value: 7.0,
        });
        let why = s.law_not_a_result().expect("at a bound");
        assert!(why.starts_with("kappa is at its lower bound 7"), "{why}");
        // a fit that did not fit the law has no law to judge
        s.fitted.retain(|p| p != "n" && p != "kappa");
        assert_eq!(s.law_not_a_result(), None);
    }
}

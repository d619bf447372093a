//! Issue 31: what a rheologist takes away. The flow curve `η_E(ε̇)` with its bands (the
//! delta-method band against a Monte Carlo over the covariance), intervals that hold (profile
//! likelihood against the linearised intervals on the shipped data; one-sided bounds and the
//! likelihood-ratio test against the Newtonian law on data of a melt without, or with barely
//! any, strain thinning made by the independent simulator of `tests/independent/`), and the
//! report's text (no warnings on the clean shipped data, lines of at most 100 characters,
//! numbers rounded to their uncertainty).

use crate::independent::rng::Rng;
use crate::independent::scenarios;
use rheometer::data::input::LoadOptions;
use rheometer::data::input::{load_experiments_with, LoadedExperiments};
use rheometer::fit::{BandMethod, FitSummary, IdentifyOptions};
use rheometer::model::LawChoice;
use rheometer::report::flow_curve_figure::flow_curve_figure;
use rheometer::report::format::fmt_pm;

/// The widest line a report prints (the reports' promise, in characters).
const LINE_WIDTH: usize = 100;
use rheometer::workflow::{fit, FitRequest, FitRun};
use std::path::Path;
use std::time::Duration;

fn shipped() -> LoadedExperiments {
    load_experiments_with(
        &crate::probe::repo().join("data/pmma7n_synthetic/experiments.toml"),
        &LoadOptions::default(),
    )
    .unwrap()
}

fn fit_of(data: &LoadedExperiments) -> FitRun {
    let run = fit(data, &FitRequest::new(IdentifyOptions::default())).unwrap();
    assert!(run.profile_error.is_none(), "{:?}", run.profile_error);
    assert!(run.flow_curve_error.is_none(), "{:?}", run.flow_curve_error);
    run
}

/// Every line of `text` fits the report width.
fn assert_lines_fit(text: &str) {
    for l in text.lines() {
        assert!(
            l.chars().count() <= LINE_WIDTH,
            "line of {} characters:\n{l}",
            l.chars().count()
        );
    }
}

#[test]
fn the_band_at_the_median_rate_agrees_with_a_monte_carlo_over_the_covariance() {
    let run = fit_of(&shipped());
    let s = run.summary();
    let curve = s.flow_curve.as_ref().unwrap();
    assert_eq!(curve.band, BandMethod::Delta);
    assert!(curve.systematic);
    let p = curve.nearest(curve.median_per_s).unwrap();
    let delta = (p.stat95_pa_s[1] / p.eta_pa_s).ln();
    // 4000 draws of (n, κ) from the fit's covariance, η_E by the model's own evaluation
    let cov = s.covariance.as_ref().unwrap();
    let (vn, vk, c) = (
        cov.get("n", "n").unwrap(),
        cov.get("kappa", "kappa").unwrap(),
        cov.get("n", "kappa").unwrap(),
    );
    let (l11, l21) = (vn.sqrt(), c / vn.sqrt());
    let l22 = (vk - l21 * l21).sqrt();
    let model = &run.rheometer.models[0];
    let sc = &model.scaling;
    let law = model.param_layout().law();
    let mut params = run.identification.local_params.clone();
    let mut rng = Rng::new(3101);
    let mut ln_eta: Vec<f64> = (0..4000)
        .map(|_| {
            let (z1, z2) = (rng.normal(), rng.normal());
            params[law.start] = s.n.value + l11 * z1;
            params[law.start + 1] = s.kappa.value + l21 * z1 + l22 * z2;
            let mu = model.viscosity_at(
                curve.temperature_k / sc.reference.temperature,
                p.strain_rate_per_s / sc.strain_rate(),
                &params,
            );
            (mu * sc.reference.viscosity).ln()
        })
        .collect();
    ln_eta.sort_by(f64::total_cmp);
    let q = |f: f64| ln_eta[(f * (ln_eta.len() - 1) as f64).round() as usize];
    let mc = 0.5 * (q(0.975) - q(0.025));
    let ratio = delta / mc;
    println!(
        "BAND | median {:.4e} 1/s: delta half-width {delta:.5} (ln), Monte Carlo {mc:.5}, \
         ratio {ratio:.4}",
        p.strain_rate_per_s
    );
    assert!(
        (ratio - 1.0).abs() < 0.10,
        "delta {delta} vs Monte Carlo {mc}"
    );
    // the systematic band is wider than nothing and the total contains the statistical one
    assert!(p.sys95_pa_s[1] > p.eta_pa_s && p.total95_pa_s[1] >= p.stat95_pa_s[1]);
    // the covered range is marked: points inside are not extrapolated, a decade beyond are
    let [lo, hi] = curve.covered_per_s;
    for q in &curve.points {
        let inside = q.strain_rate_per_s >= lo * 0.999 && q.strain_rate_per_s <= hi * 1.001;
        assert_eq!(q.extrapolated, !inside, "{q:?}");
    }
    let first = curve.points.first().unwrap().strain_rate_per_s;
    let last = curve.points.last().unwrap().strain_rate_per_s;
    assert!((first * 10.0 / lo - 1.0).abs() < 1e-9 && (last / 10.0 / hi - 1.0).abs() < 1e-9);
    // the plateau is the Trouton ratio times the VFT shear viscosity at the curve's temperature
    let m = &run.rheometer.material;
    let plateau = m.trouton * m.zero_shear_viscosity(curve.temperature_k);
    assert!((curve.plateau_pa_s / plateau - 1.0).abs() < 1e-12);
}

#[test]
fn profile_intervals_agree_with_the_linearised_ones_on_the_shipped_data() {
    let run = fit_of(&shipped());
    let s = run.summary();
    for e in [&s.n, &s.kappa] {
        let i = s.interval(&e.name).unwrap();
        assert!(i.linearised_trusted(), "{i:?}");
        let lo = (e.value - i.ci95[0]) / (e.value - e.ci95[0]);
        let hi = (i.ci95[1] - e.value) / (e.ci95[1] - e.value);
        println!(
            "PROFILE | {}: profile [{:.5}, {:.5}] linearised [{:.5}, {:.5}]: half-widths {:.4}, \
             {:.4} of the linearised; {} refits",
            e.name,
            i.ci95[0],
            i.ci95[1],
            e.ci95[0],
            e.ci95[1],
            lo,
            hi,
            i.points.len() - 1
        );
        assert!(
            (lo - 1.0).abs() < 0.10 && (hi - 1.0).abs() < 0.10,
            "{lo} {hi}"
        );
    }
    let t = s.newtonian_test.as_ref().unwrap();
    println!("LR | shipped: LR {:.1}, p {:.3e}", t.statistic, t.p_value);
    assert_eq!(t.preferred, LawChoice::Carreau);
    assert!(t.p_value < 1e-6);
    assert!(s
        .law_finding()
        .starts_with("strain thinning detected for strain rates"));
    // the JSON reads back with the new fields
    let back = FitSummary::from_json(&serde_json::to_string(s).unwrap(), "fit.json").unwrap();
    assert_eq!(back.intervals, s.intervals);
    assert_eq!(back.newtonian_test, s.newtonian_test);
    assert_eq!(back.flow_curve, s.flow_curve);
    assert_eq!(back.strain_rates, s.strain_rates);
}

/// Generates `sc`, fits it and checks what the report says about a melt without detectable
/// strain thinning; returns the summary.
fn no_thinning_case(sc: &crate::independent::dataset::Scenario, fig: &Path) -> FitSummary {
    let generated = sc.generate().unwrap();
    let data = load_experiments_with(&generated.toml, &LoadOptions::default()).unwrap();
    let run = fit_of(&data);
    let s = run.summary().clone();
    let text = s.to_text();
    println!("{text}");
    let t = s.newtonian_test.as_ref().unwrap();
    let bound = t.thinning_bound.as_ref();
    println!(
        "LR | {}: n = {:.4} kappa = {:.3}, LR {:.3}, p {:.3}, n > {:?} (K < {:?} Pa), \
         onset above {:?} 1/s, {} refits",
        sc.name,
        s.n.value,
        s.kappa.value,
        t.statistic,
        t.p_value,
        bound.map(|b| b.n_lower95),
        bound.map(|b| b.k_max_pa),
        bound.and_then(|b| b.onset_lower95_per_s),
        s.intervals
            .iter()
            .map(|i| i.points.len() - 1)
            .sum::<usize>()
            + bound.map_or(0, |b| b.points.len() + b.onset_points.len() - 2)
    );
    // n and κ are not estimates where the Newtonian law is preferred: not profiled
    assert!(s.newtonian_on_data() && s.interval("n").is_none());
    // the Newtonian law is preferred by the likelihood-ratio test
    assert_eq!(t.preferred, LawChoice::Newtonian, "p = {}", t.p_value);
    assert!(t.p_value >= 0.05);
    // a one-sided bound on n for thinning within the covered rates, below 1
    let b = bound.unwrap_or_else(|| panic!("no bound on n: {t:?}"));
    assert!(b.n_lower95 > 0.0 && b.n_lower95 < 1.0, "{b:?}");
    // the report says so, in the result section
    let finding = s.law_finding();
    assert!(
        finding.starts_with("no strain thinning detected between"),
        "{finding}"
    );
    assert!(
        finding.contains("thinning, if any, sets in above ")
            && finding.contains("needs n > ")
            && finding.contains("the Newtonian law fits as well"),
        "{finding}"
    );
    let result: String = text.lines().take(10).collect::<Vec<_>>().join("\n");
    assert!(result.contains("no strain thinning detected"), "{result}");
    assert_lines_fit(&text);
    // a flat flow curve over the covered rates, with its band, which contains the plateau
    let c = s.flow_curve.as_ref().unwrap();
    for p in c.points.iter().filter(|p| !p.extrapolated) {
        assert!(
            p.stat95_pa_s[0] <= c.plateau_pa_s * (1.0 + 1e-9)
                && p.stat95_pa_s[1] >= c.plateau_pa_s * (1.0 - 1e-9),
            "{p:?} vs plateau {}",
            c.plateau_pa_s
        );
        assert!(p.stat95_pa_s[1] > p.stat95_pa_s[0], "no band: {p:?}");
    }
    flow_curve_figure(fig, c).unwrap().save().unwrap();
    assert!(std::fs::metadata(fig).unwrap().len() > 10_000);
    s
}

#[test]
fn a_newtonian_melt_gets_a_one_sided_bound_and_the_newtonian_law_preferred() {
    let dir = crate::probe::scratch("fc_newtonian");
    let s = no_thinning_case(
        &scenarios::newtonian(),
        &dir.join("flow_curve_newtonian.png"),
    );
    // the flat curve: within 2 % of the plateau over the covered rates
    let c = s.flow_curve.as_ref().unwrap();
    for p in c.points.iter().filter(|p| !p.extrapolated) {
        assert!((p.eta_pa_s / c.plateau_pa_s - 1.0).abs() < 0.02, "{p:?}");
    }
}

/// A melt with barely any strain thinning (`n = 0.99`): these 234 points at 1.5 % noise detect
/// it (the likelihood-ratio test prefers the Carreau-type law); what must hold is that the
/// report says so with an interval of `n` that contains the truth and lies below 1, and that
/// the finding is not the Newtonian one.
#[test]
fn a_barely_thinning_melt_is_detected_with_the_truth_in_its_interval() {
    let sc = scenarios::slightly_thinning();
    let generated = sc.generate().unwrap();
    let data = load_experiments_with(&generated.toml, &LoadOptions::default()).unwrap();
    let s = fit_of(&data).summary().clone();
    let t = s.newtonian_test.as_ref().unwrap();
    let n = s.interval("n").unwrap();
    println!(
        "LR | {}: n = {:.4} profile {:?}, LR {:.3}, p {:.3e}",
        sc.name, s.n.value, n.ci95, t.statistic, t.p_value
    );
    assert_eq!(t.preferred, LawChoice::Carreau, "p = {}", t.p_value);
    assert!(
        n.ci95[0] <= sc.law.n && sc.law.n <= n.ci95[1] && n.ci95[1] < 1.0,
        "{:?}",
        n.ci95
    );
    assert!(s
        .law_finding()
        .starts_with("strain thinning detected for strain rates"));
    assert_lines_fit(&s.to_text());
}

#[test]
fn the_fit_report_on_the_shipped_data_reads_well_and_writes_the_flow_curve() {
    let (dir, toml, data) = crate::probe::shipped_copy("fc_cli");
    let out = dir.join("out");
    let p = crate::probe::rheometer(
        &[
            "fit",
            crate::probe::s(&toml),
            "--out",
            crate::probe::s(&out),
        ],
        &[&data],
        Duration::from_secs(120),
    );
    p.assert_success();
    println!("{}", p.stdout);
    // no warnings on the clean shipped data (default uncertainties), once nowhere
    assert!(p.stdout.contains("    warnings: none\n"), "{}", p.stdout);
    assert!(
        !p.stdout.contains("WARNING") && !p.stderr.contains("warning"),
        "{}",
        p.stderr
    );
    assert_lines_fit(&p.stdout);
    assert_lines_fit(&std::fs::read_to_string(out.join("fit_report.txt")).unwrap());
    // numbers rounded to their uncertainty: the law as value ± error with the error's digits
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("fit.json")).unwrap()).unwrap();
    for (label, key) in [("n:", "n"), ("kappa:", "kappa")] {
        let e = &v[key];
        let words = fmt_pm(e["value"].as_f64().unwrap(), e["stderr"].as_f64().unwrap());
        let line = p
            .stdout
            .lines()
            .find(|l| l.trim_start().starts_with(label))
            .unwrap();
        assert!(line.contains(&words), "{words:?} not in {line}");
    }
    // and no full-precision float anywhere in the result section
    let result: Vec<&str> = p
        .stdout
        .lines()
        .take_while(|l| !l.starts_with("[[Fit"))
        .collect();
    for l in &result {
        for w in l.split(|c: char| !(c.is_ascii_digit() || c == '.')) {
            let decimals = w.split_once('.').map_or(0, |(_, d)| d.len());
            assert!(decimals <= 4, "{w:?} in {l}");
        }
    }
    // the flow curve: CSV with units in the header, JSON, figure
    let csv = std::fs::read_to_string(out.join("flow_curve.csv")).unwrap();
    assert!(csv.starts_with("strain_rate_per_s,eta_E_Pa_s,stat95_low_Pa_s,stat95_high_Pa_s,"));
    assert!(csv.lines().count() > 30);
    let mut fc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("flow_curve.json")).unwrap())
            .unwrap();
    // the file is the fit's flow curve behind the stamp every JSON report carries
    let stamp = fc.as_object_mut().unwrap();
    assert_eq!(stamp.remove("schema_version"), Some(serde_json::json!(1)));
    assert_eq!(
        stamp.remove("report"),
        Some(serde_json::json!("flow_curve"))
    );
    assert!(stamp.remove("written_by").is_some());
    assert_eq!(fc, v["flow_curve"]);
    assert!(std::fs::metadata(out.join("flow_curve.png")).unwrap().len() > 10_000);
    let _ = std::fs::remove_dir_all(&dir);
}

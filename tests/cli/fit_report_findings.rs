//! The fit report's open rows of `bad-input-findings.md` (issue 28): an effect fixed outside its
//! physical range (G02), a degenerate pair of fitted effects (G18), a per-experiment
//! uncertainty override in the error budget (F41), and a noise level estimated from noiseless
//! rows (c15b). Each test names its finding id; scratch copies live under `target/probes` and
//! are removed at the end.

use std::path::Path;
use std::time::Duration;

use crate::probe::{rheometer, s, shipped_copy};

const LIMIT: Duration = Duration::from_secs(240);

/// `rheometer fit TOML ARGS...`, expected to succeed with the inputs unchanged; its report.
fn fit(toml: &Path, data: &Path, args: &[&str]) -> String {
    let mut all = vec!["fit", s(toml)];
    all.extend_from_slice(args);
    let p = rheometer(&all, &[data], LIMIT);
    p.assert_success();
    p.stdout
}

/// The report's lines that start (after indentation) with `label`.
fn lines_of<'a>(report: &'a str, label: &str) -> Vec<&'a str> {
    report
        .lines()
        .filter(|l| l.trim_start().starts_with(label))
        .collect()
}

#[test]
fn g02_an_effect_fixed_outside_its_physical_range_is_warned() {
    let (dir, toml, data) = shipped_copy("g02_fixed_effect");
    // [G02] emissivity 2 > 1: accepted (inside the search range) but warned in the report
    let report = fit(&toml, &data, &["--with", "radiation=2"]);
    assert!(report.contains("radiation: 2 (fixed)"), "{report}");
    assert!(
        report.contains("WARNING [unphysical] radiation"),
        "{report}"
    );
    assert!(report.contains("physical range [0, 1]"), "{report}");
    assert!(report.contains("ε = 2 > 1"), "{report}");
    // inside the physical range: no such warning
    let report = fit(&toml, &data, &["--with", "radiation=0.9"]);
    assert!(!report.contains("[unphysical]"), "{report}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn g18_a_degenerate_pair_prints_no_zero_width_interval() {
    let (dir, toml, data) = shipped_copy("g18_degenerate_pair");
    // [G18] die swell and inlet velocity have the same physics: the fit cannot tell them
    let report = fit(
        &toml,
        &data,
        &["--with", "inlet_diameter", "--with", "inlet_velocity"],
    );
    assert!(report.contains("[ill_conditioned]"), "{report}");
    for label in ["inlet_diameter:", "inlet_velocity:"] {
        let lines = lines_of(&report, label);
        // the [[Variables]] line: no "± 0" and no interval [x, x]
        let line = lines
            .iter()
            .find(|l| !l.contains("profile ["))
            .unwrap_or_else(|| panic!("no {label} line in\n{report}"));
        // an exactly singular covariance gives no standard error; a nearly singular one (the
        // start from the plain model's optimum ends there) a huge interval marked as such
        assert!(
            line.contains("no standard error: singular covariance")
                || line.contains("(not determined)"),
            "{line}"
        );
        if let Some(ci) = line.split("95% CI [").nth(1) {
            let ends: Vec<&str> = ci.split(']').next().unwrap_or("").split(", ").collect();
            assert!(
                ends.len() == 2 && ends[0] != ends[1],
                "zero-width interval: {line}"
            );
        }
        assert!(!line.contains("± 0"), "{line}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn f41_a_per_experiment_override_is_named_in_the_error_budget() {
    let (dir, toml, data) = shipped_copy("f41_override");
    // [F41] v0p27_p1 declares its own mass-flow uncertainty (5 %); the data set's is the
    // default 1 %: the budget row says both, not "1.00 % (default)" alone
    let text = std::fs::read_to_string(&toml).unwrap();
    let first = "data = \"v0p27_p1.csv\"\n";
    assert!(text.contains(first));
    let text = text.replacen(
        first,
        &format!("{first}[experiment.uncertainty]\nmass_flow_rel = 0.05\n"),
        1,
    );
    std::fs::write(&toml, text).unwrap();
    let report = fit(&toml, &data, &[]);
    let rows: Vec<&str> = report.lines().collect();
    let at = rows
        .iter()
        .position(|l| l.trim_start().starts_with("mass_flow_rel"))
        .unwrap_or_else(|| panic!("no mass_flow_rel row in\n{report}"));
    assert!(rows[at].contains("1.00 % (default)"), "{}", rows[at]);
    assert!(
        rows[at + 1].contains("own value in v0p27_p1: 5.00 %"),
        "{}\n{}",
        rows[at],
        rows[at + 1]
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn c15b_a_noise_level_from_noiseless_rows_is_called_implausible() {
    let (dir, toml, data) = shipped_copy("c15b_noiseless_rows");
    // [c15b] v0p27_p1.csv replaced by 20 000 rows interpolated log-linearly between its
    // points (no noise): they dominate the estimated noise level
    let csv = data.join("v0p27_p1.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    let pts: Vec<(f64, f64)> = text
        .lines()
        .skip(1)
        .map(|l| {
            let (a, b) = l.split_once(',').unwrap();
            (a.parse().unwrap(), b.parse().unwrap())
        })
        .collect();
    let (s0, s1) = (pts[0].0, pts[pts.len() - 1].0);
    let n = 20_000;
    let mut out = String::from("position_m,diameter_m\n");
    for k in 0..n {
        let s = s0 + (s1 - s0) * k as f64 / (n - 1) as f64;
        let i = pts
            .windows(2)
            .position(|w| w[0].0 <= s && s <= w[1].0)
            .unwrap();
        let (a, b) = (pts[i], pts[i + 1]);
        let t = (s - a.0) / (b.0 - a.0);
        let d = (a.1.ln() * (1.0 - t) + b.1.ln() * t).exp();
        out.push_str(&format!("{s:.9},{d:.9e}\n"));
    }
    std::fs::write(&csv, out).unwrap();
    let report = fit(&toml, &data, &[]);
    assert!(report.contains("[misfit]"), "{report}");
    // the level is printed with significant digits, never as "0.000 %"
    assert!(!report.contains("noise level 0.000 %"), "{report}");
    let joined = report.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        joined.contains("the estimated noise level itself is implausibly small"),
        "{report}"
    );
    assert!(joined.contains("declare relative_uncertainty"), "{report}");
    // the shipped (noisy) data: no such words
    std::fs::write(
        &csv,
        std::fs::read(crate::probe::repo().join("data/pmma7n_synthetic/v0p27_p1.csv")).unwrap(),
    )
    .unwrap();
    let report = fit(&toml, &data, &[]);
    assert!(!report.contains("implausibly small"), "{report}");
    std::fs::remove_dir_all(dir).unwrap();
}

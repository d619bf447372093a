//! CLI probes with implausible or singular inputs in modified copies of the shipped data set:
//! each must fail cleanly (exit code 1, no panic) before any work, with a message naming the
//! file, the line, the experiment and the key, and leave every input file unchanged.

use crate::probe;

use std::path::{Path, PathBuf};
use std::time::Duration;

const LIMIT: Duration = Duration::from_secs(60);

/// A scratch copy of the shipped data set with `edit` applied to its TOML text; returns the
/// TOML's path and the data directory.
fn with_toml(name: &str, edit: impl FnOnce(&str) -> String) -> (PathBuf, PathBuf) {
    let dir = probe::scratch(name);
    let toml = probe::copy_data_set("pmma7n_synthetic", &dir);
    let text = std::fs::read_to_string(&toml).unwrap();
    let edited = edit(&text);
    assert_ne!(edited, text, "{name}: the edit changed nothing");
    std::fs::write(&toml, edited).unwrap();
    let data = toml.parent().unwrap().to_path_buf();
    (toml, data)
}

/// Replaces the first occurrence of `from` by `to`.
fn first(from: &'static str, to: &'static str) -> impl FnOnce(&str) -> String {
    move |t: &str| t.replacen(from, to, 1)
}

/// `file:line` of the first line of `path` containing `needle` (1-based).
fn at(path: &Path, needle: &str) -> String {
    let line = probe::line_where(path, |l| l.contains(needle));
    format!("{}:{line}:", path.display())
}

fn run(command: &str, toml: &Path, data: &Path) -> probe::Probe {
    let out = data.parent().unwrap().join("out");
    let toml_s = toml.to_str().unwrap();
    let out_s = out.to_str().unwrap();
    let args: Vec<&str> = match command {
        "fit" => vec!["fit", toml_s],
        other => vec![other, toml_s, "--out", out_s],
    };
    let p = probe::rheometer(&args, &[data], LIMIT);
    assert!(
        !out.exists() || command == "fit",
        "{args:?} created {out:?}"
    );
    p
}

fn expect(command: &str, toml: &Path, data: &Path, needles: &[&str]) -> probe::Probe {
    let p = run(command, toml, data);
    p.assert_clean_failure(needles);
    assert_eq!(p.code, Some(1), "{:?}: {}", p.args, p.stderr);
    assert!(
        p.elapsed < Duration::from_secs(5),
        "{:?} took {:?}: the input should be refused before any work",
        p.args,
        p.elapsed
    );
    p
}

#[test]
fn inlet_diameter_of_a_nanometre_is_refused() {
    let (toml, data) = with_toml(
        "plaus_d_in_1nm",
        first("inlet_diameter_m = 0.001134", "inlet_diameter_m = 1e-9"),
    );
    let line = at(&toml, "inlet_diameter_m = 1e-9");
    expect(
        "fit",
        &toml,
        &data,
        &[
            &line,
            "\"v0p27_p1\"",
            "`inlet_diameter_m` = 1e-9",
            "implausibly small",
            "expected 1e-5 to 0.02 m",
        ],
    );
}

#[test]
fn huge_mass_flow_is_refused_in_simulate() {
    let (toml, data) = with_toml(
        "plaus_q_1e308",
        first("mass_flow_kg_s = 3.08e-05", "mass_flow_kg_s = 1e308"),
    );
    let line = at(&toml, "mass_flow_kg_s = 1e308");
    let p = expect(
        "simulate",
        &toml,
        &data,
        &[
            &line,
            "\"v0p53_p1\"",
            "`mass_flow_kg_s`",
            "implausibly large",
            "kg/s",
        ],
    );
    // not the old, misleading consequence of the overflow
    assert!(!p.stderr.contains("inlet diameter 0 m"), "{}", p.stderr);
}

#[test]
fn overflowing_inlet_velocity_names_the_inputs_that_produce_it() {
    // each value plausible alone; together they need an inlet speed of 46 m/s
    let (toml, data) = with_toml(
        "plaus_u_in_derived",
        first("inlet_diameter_m = 0.001134", "inlet_diameter_m = 2e-5"),
    );
    let q_line = at(&toml, "mass_flow_kg_s = 1.5690566037735852e-05");
    expect(
        "compare",
        &toml,
        &data,
        &[
            &q_line,
            "\"v0p27_p1\"",
            "`mass_flow_kg_s`",
            "`inlet_diameter_m` = 2e-5",
            "inlet velocity",
            "m/s",
            "faster than a melt leaves a spinneret",
            "or the inlet diameter (0.02 mm) is too small",
        ],
    );
}

#[test]
fn inlet_temperature_just_above_the_vogel_temperature_is_refused_in_words() {
    let (toml, data) = with_toml(
        "plaus_t_in_vogel",
        first(
            "inlet_temperature_K = 513.15",
            "inlet_temperature_K = 273.151",
        ),
    );
    let line = at(&toml, "inlet_temperature_K = 273.151");
    let p = expect(
        "simulate",
        &toml,
        &data,
        &[
            &line,
            "[defaults]",
            "\"v0p27_p1\"",
            "`inlet_temperature_K` = 273.151",
            "only 0.0010 K above the Vogel temperature vft_T_VF_K = 273.15 K",
            "infinite zero-shear viscosity",
        ],
    );
    assert!(!p.stderr.contains("right-hand side"), "{}", p.stderr);
}

#[test]
fn inlet_temperature_below_the_glass_transition_is_refused() {
    let (toml, data) = with_toml("plaus_t_in_glass", |t| {
        t.replacen(
            "name = \"v0p53_p2\"",
            "name = \"v0p53_p2\"\ninlet_temperature_K = 300",
            1,
        )
    });
    let line = at(&toml, "inlet_temperature_K = 300");
    expect(
        "landscape",
        &toml,
        &data,
        &[
            &line,
            "[[experiment]] #5 \"v0p53_p2\"",
            "`inlet_temperature_K` = 300",
            "a glass, not a melt",
        ],
    );
}

#[test]
fn air_temperature_below_the_vogel_temperature_is_refused() {
    let (toml, data) = with_toml(
        "plaus_t_air_vogel",
        first("air_temperature_K = 293.15", "air_temperature_K = 250"),
    );
    let line = at(&toml, "air_temperature_K = 250");
    expect(
        "fit",
        &toml,
        &data,
        &[
            &line,
            "\"v0p27_p1\"",
            "(value from [defaults])",
            "`air_temperature_K` = 250",
            "Vogel temperature",
        ],
    );
}

#[test]
fn air_temperature_in_celsius_is_refused() {
    let (toml, data) = with_toml(
        "plaus_t_air_celsius",
        first("air_temperature_K = 293.15", "air_temperature_K = 20"),
    );
    let line = at(&toml, "air_temperature_K = 20");
    expect(
        "fit",
        &toml,
        &data,
        &[
            &line,
            "[defaults]",
            "`air_temperature_K` = 20",
            "implausibly small",
            "check the unit",
        ],
    );
}

#[test]
fn spinline_length_in_millimetres_is_refused() {
    let (toml, data) = with_toml("plaus_length_mm", |t| {
        t.replacen(
            "name = \"v1p06_p3\"",
            "name = \"v1p06_p3\"\nspinline_length_m = 510",
            1,
        )
    });
    let line = at(&toml, "spinline_length_m = 510");
    expect(
        "fit",
        &toml,
        &data,
        &[
            &line,
            "\"v1p06_p3\"",
            "`spinline_length_m` = 510",
            "implausibly large",
            "expected 0.001 to 100 m",
            "`spinline_length_mm = 510` if it is in millimetres",
        ],
    );
}

#[test]
fn take_up_diameter_of_a_nanometre_is_refused() {
    let (toml, data) = with_toml("plaus_d_out_1nm", |t| {
        t.replacen(
            "name = \"v0p27_p3\"",
            "name = \"v0p27_p3\"\ntake_up_diameter_m = 1e-9",
            1,
        )
    });
    let line = at(&toml, "take_up_diameter_m = 1e-9");
    expect(
        "simulate",
        &toml,
        &data,
        &[
            &line,
            "\"v0p27_p3\"",
            "`take_up_diameter_m`",
            "implausibly small",
        ],
    );
}

#[test]
fn take_up_slower_than_the_derived_inlet_velocity_is_refused() {
    let (toml, data) = with_toml("plaus_u_out_slow", |t| {
        t.replacen(
            "name = \"v0p27_p2\"",
            "name = \"v0p27_p2\"\ntake_up_velocity_m_s = 0.001",
            1,
        )
    });
    let line = at(&toml, "take_up_velocity_m_s = 0.001");
    expect(
        "simulate",
        &toml,
        &data,
        &[
            &line,
            "\"v0p27_p2\"",
            "take-up velocity 0.001 m/s must be larger than the inlet velocity",
            "derived from `mass_flow_kg_s` and `inlet_diameter_m`",
        ],
    );
}

#[test]
fn inlet_velocity_giving_a_huge_inlet_diameter_is_refused() {
    let (toml, data) = with_toml(
        "plaus_u_in_tiny",
        first("inlet_diameter_m = 0.001134", "inlet_velocity_m_s = 1e-6"),
    );
    let line = at(&toml, "inlet_velocity_m_s = 1e-6");
    expect(
        "fit",
        &toml,
        &data,
        &[
            &line,
            "\"v0p27_p1\"",
            "`inlet_velocity_m_s`",
            "inlet diameter",
            "outside the plausible range",
        ],
    );
}

#[test]
fn absurd_draw_ratio_is_refused() {
    let (toml, data) = with_toml("plaus_draw_ratio", |t| {
        t.replacen(
            "name = \"v0p53_p3\"",
            "name = \"v0p53_p3\"\ntake_up_diameter_m = 1.1e-6",
            1,
        )
    });
    let line = at(&toml, "take_up_diameter_m = 1.1e-6");
    expect(
        "compare",
        &toml,
        &data,
        &[
            &line,
            "\"v0p53_p3\"",
            "draw ratio",
            "above the plausible 1e6",
        ],
    );
}

#[test]
fn relative_uncertainty_of_two_is_refused() {
    let (toml, data) = with_toml("plaus_rel_unc", |t| {
        format!("relative_uncertainty = 2\n{t}")
    });
    let line = at(&toml, "relative_uncertainty = 2");
    expect(
        "fit",
        &toml,
        &data,
        &[&line, "`relative_uncertainty` = 2", "must lie in (0, 1)"],
    );
}

/// A scratch copy with line `line` (1-based) of CSV `csv` replaced by `row`.
fn with_csv_row(name: &str, csv: &str, line: usize, row: &str) -> (PathBuf, PathBuf, PathBuf) {
    let dir = probe::scratch(name);
    let toml = probe::copy_data_set("pmma7n_synthetic", &dir);
    let data = toml.parent().unwrap().to_path_buf();
    let path = data.join(csv);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    lines[line - 1] = row.to_string();
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    (toml, data, path)
}

#[test]
fn csv_diameter_of_a_nanometre_is_refused() {
    let (toml, data, csv) = with_csv_row("plaus_csv_1nm", "v0p53_p2.csv", 5, "0.06,1e-9");
    expect(
        "fit",
        &toml,
        &data,
        &[
            &format!("{}:5:", csv.display()),
            &at(&toml, "data = \"v0p53_p2.csv\""),
            "\"v0p53_p2\"",
            "diameter 1e-9 m is implausibly small",
        ],
    );
}

#[test]
fn csv_diameter_in_micrometres_is_refused() {
    let (toml, data, csv) = with_csv_row("plaus_csv_um", "v1p06_p1.csv", 3, "0.02,1108.9");
    expect(
        "simulate",
        &toml,
        &data,
        &[
            &format!("{}:3:", csv.display()),
            "\"v1p06_p1\"",
            "implausibly large",
            "millimetres or micrometres",
        ],
    );
}

#[test]
fn digit_separators_are_numbers_and_plausible_inputs_still_fit() {
    // TOML's `1_000`-style separators used to be reported as "not a finite number"
    let (toml, data) = with_toml(
        "plaus_digit_separators",
        first("spinline_length_m = 0.51", "spinline_length_m = 0.5_1"),
    );
    let p = run("fit", &toml, &data);
    p.assert_success();
    assert!(
        p.stdout.contains("kappa") || p.stdout.contains("κ"),
        "{}",
        p.stdout
    );
}

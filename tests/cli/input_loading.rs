//! Loading the TOML + CSV input format: the shipped data set, overrides, and every error.

use rheometer::data::input::LoadOptions;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use rheometer::data::input::{
    load_experiments, load_experiments_with, load_measurements_with, parse_experiments, InputError,
};
use rheometer::model::{Air, ExperimentSet, Inlet, Material, TakeUp};

const SHIPPED: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/data/pmma7n_synthetic/experiments.toml"
);

/// A unique scratch directory under `target/` (never in /tmp), removed on drop.
struct TempDir(PathBuf);

impl TempDir {
    fn new() -> Self {
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("target")
            .join("test-scratch")
            .join(format!("input_loading_{}_{n}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }

    fn write(&self, name: &str, content: &str) -> PathBuf {
        let path = self.0.join(name);
        std::fs::write(&path, content).unwrap();
        path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

const HEAD: &str = r#"
[material]
density_slope_kg_m3_K = -0.964
density_intercept_kg_m3 = 1572.33
heat_capacity_slope_J_kg_K2 = 3.2
heat_capacity_intercept_J_kg_K = 648.22
vft_mu_c_Pa_s = 0.00037074
vft_B_K = 3649.0
vft_T_VF_K = 273.15
air_density_kg_m3 = 1.0
air_heat_capacity_J_kg_K = 1000.0
air_kinematic_viscosity_m2_s = 2e-05
air_heat_conductivity_W_m_K = 0.031

[defaults]
spinline_length_m = 0.51
inlet_temperature_K = 513.15
air_temperature_K = 293.15
"#;

const EXPERIMENT: &str = r#"
[[experiment]]
name = "a"
mass_flow_kg_s = 3.08e-05
inlet_diameter_m = 0.001134
data = "a.csv"
"#;

const GOOD_CSV: &str =
    "position_m,diameter_m\n0.00,1.1e-3\n0.10,5.0e-4\n0.20,3.0e-4\n0.30,2.0e-4\n0.40,1.5e-4\n";

/// Writes `toml` as `exp.toml` and `csv` as `a.csv` into a fresh directory and loads them.
fn load(toml: &str, csv: &str) -> (Result<ExperimentSet, InputError>, TempDir) {
    let dir = TempDir::new();
    dir.write("a.csv", csv);
    let path = dir.write("exp.toml", toml);
    (load_experiments(&path), dir)
}

/// The error message of loading `toml` with a good CSV file.
fn toml_error(toml: &str) -> String {
    let (result, _dir) = load(toml, GOOD_CSV);
    let message = result.unwrap_err().to_string();
    assert!(message.contains("exp.toml"), "file not named: {message}");
    message
}

/// The error message of loading the good TOML with `csv` as data file.
fn csv_error(csv: &str) -> String {
    let (result, _dir) = load(&format!("{HEAD}{EXPERIMENT}"), csv);
    let message = result.unwrap_err().to_string();
    assert!(
        message.contains("exp.toml"),
        "TOML file not named: {message}"
    );
    assert!(message.contains("a.csv"), "CSV file not named: {message}");
    assert!(message.contains("\"a\""), "experiment not named: {message}");
    message
}

fn assert_contains(message: &str, parts: &[&str]) {
    for part in parts {
        assert!(message.contains(part), "`{part}` missing in: {message}");
    }
}

#[test]
fn shipped_data_set_loads() {
    let set = load_experiments(Path::new(SHIPPED)).unwrap();
    assert_eq!(set.material, Material::pmma7n());
    assert_eq!(set.air, Air::paper());
    assert_eq!(set.relative_uncertainty, None);
    assert_eq!(set.experiments.len(), 9);
    assert_eq!(set.measurements.len(), 9);
    let flows = [1.5690566037735852e-05, 3.08e-05, 6.16e-05];
    for (i, (e, m)) in set.experiments.iter().zip(&set.measurements).enumerate() {
        assert_eq!(e.mass_flow, flows[i / 3], "{}", e.name);
        assert_eq!(e.inlet, Inlet::Diameter(0.001134));
        assert_eq!(e.spinline_length, 0.51);
        assert_eq!(e.inlet_temperature, 513.15);
        assert_eq!(e.air_temperature, 293.15);
        assert_eq!(e.take_up, None);
        let m = m.as_ref().unwrap();
        assert_eq!(m.positions.len(), 26);
        assert_eq!(m.diameters.len(), 26);
        assert_eq!(m.positions[0], 0.0);
        assert!((m.positions[25] - 0.50).abs() < 1e-15);
        assert!(m.diameters.iter().all(|&d| d > 0.0 && d < 2e-3));
    }
    assert_eq!(set.experiments[0].name, "v0p27_p1");
    assert_eq!(set.experiments[8].name, "v1p06_p3");
    let m0 = set.measurements[0].as_ref().unwrap();
    assert_eq!(m0.diameters[0], 1.1089323e-03);
    assert_eq!(ExperimentSet::load(Path::new(SHIPPED)).unwrap(), set);
}

#[test]
fn shipped_metadata_is_kept() {
    let loaded =
        load_experiments_with(Path::new(SHIPPED), &LoadOptions::with_min_points(26)).unwrap();
    let d = &loaded.details[4];
    assert_eq!(d.stencil_velocity_mm_s, Some(0.53));
    assert_eq!(d.take_up_pressure_bar, Some(2.0));
    assert!(d.data.as_ref().unwrap().ends_with("v0p53_p2.csv"));
    // more points required than available
    let message = load_experiments_with(Path::new(SHIPPED), &LoadOptions::with_min_points(27))
        .unwrap_err()
        .to_string();
    assert_contains(
        &message,
        &["v0p27_p1.csv", "only 26 measurement point(s); at least 27"],
    );
}

#[test]
fn loading_does_not_modify_files() {
    let dir = Path::new(SHIPPED).parent().unwrap();
    let snapshot = || {
        let mut files: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.is_file())
            .map(|p| {
                let modified = std::fs::metadata(&p).unwrap().modified().unwrap();
                (p.clone(), std::fs::read(&p).unwrap(), modified)
            })
            .collect();
        files.sort();
        files
    };
    let before = snapshot();
    load_experiments(Path::new(SHIPPED)).unwrap();
    assert_eq!(before, snapshot());
}

#[test]
fn csv_loader_min_points_is_a_parameter() {
    let csv = Path::new(SHIPPED).with_file_name("v0p53_p1.csv");
    assert_eq!(
        load_measurements_with(&csv, 0.51, &LoadOptions::with_min_points(26))
            .unwrap()
            .positions
            .len(),
        26
    );
    let message = load_measurements_with(&csv, 0.51, &LoadOptions::with_min_points(40))
        .unwrap_err()
        .to_string();
    assert_contains(&message, &["v0p53_p1.csv", "at least 40"]);
    let message = load_measurements_with(&csv, 0.45, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert_contains(
        &message,
        &["v0p53_p1.csv:25:", "beyond the spin-line length 0.45 m"],
    );
}

#[test]
fn experiment_keys_override_defaults() {
    let toml = format!(
        "{HEAD}{EXPERIMENT}\
         spinline_length_m = 0.6\ninlet_temperature_K = 500\nair_temperature_K = 300\n\
         take_up_diameter_m = 1e-4\n\
         [[experiment]]\nname = \"b\"\nmass_flow_kg_s = 1e-5\ninlet_velocity_m_s = 0.02\n\
         take_up_velocity_m_s = 2.0\n"
    );
    let (result, _dir) = load(&toml, GOOD_CSV);
    let set = result.unwrap();
    let (a, b) = (&set.experiments[0], &set.experiments[1]);
    assert_eq!(a.spinline_length, 0.6);
    assert_eq!(a.inlet_temperature, 500.0);
    assert_eq!(a.air_temperature, 300.0);
    assert_eq!(a.take_up, Some(TakeUp::Diameter(1e-4)));
    assert_eq!(b.spinline_length, 0.51);
    assert_eq!(b.inlet_temperature, 513.15);
    assert_eq!(b.inlet, Inlet::Velocity(0.02));
    assert_eq!(b.take_up, Some(TakeUp::Velocity(2.0)));
    assert!(set.measurements[0].is_some());
    assert!(set.measurements[1].is_none());
}

#[test]
fn inlet_pair_in_experiment_replaces_default_pair() {
    let head = HEAD.replace("[defaults]\n", "[defaults]\ninlet_diameter_m = 1e-3\n");
    let toml = format!(
        "{head}[[experiment]]\nname = \"d\"\nmass_flow_kg_s = 1e-5\n\
         [[experiment]]\nname = \"v\"\nmass_flow_kg_s = 1e-5\ninlet_velocity_m_s = 0.03\n"
    );
    let set = parse_experiments(&toml, Path::new("exp.toml")).unwrap().set;
    assert_eq!(set.experiments[0].inlet, Inlet::Diameter(1e-3));
    assert_eq!(set.experiments[1].inlet, Inlet::Velocity(0.03));
}

#[test]
fn missing_files() {
    let message = load_experiments(Path::new("/nonexistent/dir/exp.toml"))
        .unwrap_err()
        .to_string();
    assert_contains(&message, &["/nonexistent/dir/exp.toml", "cannot read file"]);

    let dir = TempDir::new();
    let path = dir.write("exp.toml", &format!("{HEAD}{EXPERIMENT}"));
    let message = load_experiments(&path).unwrap_err().to_string();
    assert_contains(
        &message,
        &["exp.toml:", "\"a\"", "a.csv", "cannot read file"],
    );
}

#[test]
fn malformed_toml_names_line_and_column() {
    let message = toml_error(&format!("{HEAD}{EXPERIMENT}mass_flow_kg_s 3\n"));
    assert_contains(&message, &["exp.toml:25:16:", "malformed TOML"]);
    let message = toml_error(&format!("{HEAD}{EXPERIMENT}mass_flow_kg_s = 1\n"));
    assert_contains(
        &message,
        &["exp.toml:25:", "malformed TOML", "duplicate key"],
    );
}

#[test]
fn unknown_keys_are_errors() {
    let message = toml_error(&format!(
        "{}{EXPERIMENT}",
        HEAD.replace("vft_B_K", "vft_b_K")
    ));
    assert_contains(
        &message,
        &[
            "exp.toml:8:",
            "unknown key `vft_b_K` in [material]",
            "did you mean `vft_B_K`?",
        ],
    );
    let message = toml_error(&format!("{HEAD}{EXPERIMENT}inlet_temperatur_K = 500\n"));
    assert_contains(
        &message,
        &[
            "exp.toml:25:",
            "unknown key `inlet_temperatur_K` in [[experiment]] #1 \"a\"",
            "`inlet_temperature_K`",
        ],
    );
    let message = toml_error(&format!(
        "{}{EXPERIMENT}",
        HEAD.replace("[defaults]\n", "[defaults]\nvft_B_K = 1\n")
    ));
    assert_contains(
        &message,
        &[
            "unknown key `vft_B_K` in [defaults]",
            "belongs in [material]",
        ],
    );
    let message = toml_error(&format!(
        "{}{EXPERIMENT}",
        HEAD.replace("[defaults]\n", "[defaults]\nname = \"x\"\n")
    ));
    assert_contains(
        &message,
        &["unknown key `name` in [defaults]", "cannot be a default"],
    );
    let message = toml_error(&format!("[extras]\nfoo = 1\n{HEAD}{EXPERIMENT}"));
    assert_contains(
        &message,
        &["exp.toml:1:", "unknown key `extras` in the top level"],
    );
}

#[test]
fn missing_required_keys() {
    let message = toml_error(&format!(
        "{}{EXPERIMENT}",
        HEAD.replace("vft_mu_c_Pa_s = 0.00037074\n", "")
    ));
    assert_contains(
        &message,
        &[
            "exp.toml:2:",
            "[material]",
            "missing required key `vft_mu_c_Pa_s`",
        ],
    );
    let message = toml_error(&format!(
        "{HEAD}{}",
        EXPERIMENT.replace("mass_flow_kg_s = 3.08e-05\n", "")
    ));
    assert_contains(
        &message,
        &[
            "exp.toml:20:",
            "[[experiment]] #1 \"a\"",
            "missing required key `mass_flow_kg_s`",
        ],
    );
    let message = toml_error(&format!(
        "{}{EXPERIMENT}",
        HEAD.replace("spinline_length_m = 0.51\n", "")
    ));
    assert_contains(
        &message,
        &["missing required key `spinline_length_m`", "[defaults]"],
    );
    let message = toml_error(EXPERIMENT);
    assert_contains(&message, &["missing required key `material`"]);
}

#[test]
fn wrong_types_and_non_finite_values() {
    let message = toml_error(&format!(
        "{}{EXPERIMENT}",
        HEAD.replace("= 0.51", "= \"0.51 m\"")
    ));
    assert_contains(
        &message,
        &[
            "exp.toml:16:",
            "[defaults]",
            "`spinline_length_m` must be a number, found a string",
        ],
    );
    let message = toml_error(&format!(
        "{HEAD}{}",
        EXPERIMENT.replace("name = \"a\"", "name = 7")
    ));
    assert_contains(&message, &["`name` must be a string, found an integer"]);
    let message = toml_error(&format!("{}{EXPERIMENT}", HEAD.replace("-0.964", "nan")));
    assert_contains(
        &message,
        &[
            "exp.toml:3:",
            "[material]",
            "`density_slope_kg_m3_K` = nan is not a finite number",
        ],
    );
    let message = toml_error(&format!("{HEAD}{}", EXPERIMENT.replace("3.08e-05", "inf")));
    assert_contains(
        &message,
        &[
            "exp.toml:22:",
            "`mass_flow_kg_s` = inf is not a finite number",
        ],
    );
}

#[test]
fn non_positive_values() {
    let cases = [
        (
            EXPERIMENT.replace("3.08e-05", "0.0"),
            "`mass_flow_kg_s` = 0: must be positive",
        ),
        (
            EXPERIMENT.replace("0.001134", "-1e-3"),
            "`inlet_diameter_m` = -0.001: must be positive",
        ),
        (
            format!("{EXPERIMENT}spinline_length_m = 0\n"),
            "`spinline_length_m` = 0: must be positive",
        ),
        (
            format!("{EXPERIMENT}air_temperature_K = -20\n"),
            "`air_temperature_K` = -20: must be positive",
        ),
        (
            format!("{EXPERIMENT}inlet_temperature_K = 0\n"),
            "`inlet_temperature_K` = 0: must be positive",
        ),
    ];
    for (experiment, expected) in cases {
        let message = toml_error(&format!("{HEAD}{experiment}"));
        assert_contains(&message, &["[[experiment]] #1 \"a\"", expected]);
    }
    let message = toml_error(&format!("{}{EXPERIMENT}", HEAD.replace("= 293.15", "= -1")));
    assert_contains(
        &message,
        &[
            "exp.toml:18:",
            "[defaults]",
            "`air_temperature_K` = -1: must be positive",
        ],
    );
    let message = toml_error(&format!(
        "{HEAD}{}",
        EXPERIMENT.replace("0.001134", "1.134")
    ));
    assert_contains(&message, &["`inlet_diameter_m` = 1.134", "millimetres"]);
}

#[test]
fn inlet_and_take_up_conflicts() {
    let message = toml_error(&format!("{HEAD}{EXPERIMENT}inlet_velocity_m_s = 0.02\n"));
    assert_contains(
        &message,
        &[
            "exp.toml:25:",
            "[[experiment]] #1 \"a\"",
            "either `inlet_diameter_m` or `inlet_velocity_m_s`, not both",
        ],
    );
    let message = toml_error(&format!(
        "{HEAD}{}",
        EXPERIMENT.replace("inlet_diameter_m = 0.001134\n", "")
    ));
    assert_contains(&message, &["exp.toml:20:", "missing inlet condition"]);
    let message = toml_error(&format!(
        "{HEAD}{EXPERIMENT}take_up_diameter_m = 1e-4\ntake_up_velocity_m_s = 2.0\n"
    ));
    assert_contains(
        &message,
        &[
            "exp.toml:26:",
            "either `take_up_diameter_m` or `take_up_velocity_m_s`, not both",
        ],
    );
    let message = toml_error(&format!(
        "{HEAD}{EXPERIMENT}take_up_diameter_m = 0.001134\n"
    ));
    assert_contains(
        &message,
        &[
            "exp.toml:25:",
            "take-up diameter 0.001134 m must be smaller than the inlet diameter 0.001134 m",
        ],
    );
}

#[test]
fn duplicate_experiment_names() {
    let message = toml_error(&format!("{HEAD}{EXPERIMENT}{EXPERIMENT}"));
    assert_contains(
        &message,
        &[
            "exp.toml:27:",
            "[[experiment]] #2 \"a\"",
            "duplicate experiment name \"a\" (first defined at line 21)",
        ],
    );
}

#[test]
fn csv_errors_name_file_and_line() {
    let replace = |from: &str, to: &str| GOOD_CSV.replace(from, to);
    let cases = [
        (
            replace("0.10,5.0e-4", "0.10,abc"),
            "a.csv:3: non-numeric cell `abc` in column `diameter_m`",
        ),
        (
            replace("position_m,diameter_m", "position_in,diameter_m"),
            "a.csv:1: wrong header `position_in,diameter_m`; expected `position_m,diameter_m`",
        ),
        (
            replace("0.20,", "0.05,"),
            "a.csv:4: position 0.05 m is smaller than 0.1 m on line 3",
        ),
        (
            replace("0.20,", "0.10,"),
            "a.csv:4: position 0.10 m repeats the one on line 3",
        ),
        (
            replace("5.0e-4", "-5.0e-4"),
            "a.csv:3: diameter -5.0e-4 m is not positive",
        ),
        (
            replace("5.0e-4", "0"),
            "a.csv:3: diameter 0 m is not positive",
        ),
        (
            replace("5.0e-4", "0.5"),
            "a.csv:3: diameter 0.5 is implausibly large for metres",
        ),
        (
            replace("0.40,", "0.60,"),
            "a.csv:6: position 0.60 m lies beyond the spin-line length 0.51 m",
        ),
        (
            replace("0.00,", "-0.01,"),
            "a.csv:2: position -0.01 m is negative",
        ),
        (
            "position_m,diameter_m\n0.0,1e-3\n0.1,5e-4\n0.2,3e-4\n".to_string(),
            "a.csv: only 3 measurement point(s); at least 4 are required",
        ),
        (
            replace("0.10,5.0e-4", "0.10,5.0e-4,7"),
            "a.csv:3: expected 2 columns",
        ),
    ];
    for (csv, expected) in cases {
        let message = csv_error(&csv);
        assert_contains(&message, &["exp.toml:24:", expected]);
        assert!(!message.contains("look like"), "{message}");
    }
}

#[test]
fn relative_uncertainty_is_read_from_the_top_level() {
    let (result, _dir) = load(
        &format!("\u{feff}relative_uncertainty = 0.015\n{HEAD}{EXPERIMENT}"),
        GOOD_CSV,
    );
    assert_eq!(result.unwrap().relative_uncertainty, Some(0.015));
    let message = toml_error(&format!("relative_uncertainty = 1.5\n{HEAD}{EXPERIMENT}"));
    assert_contains(
        &message,
        &[
            "exp.toml:1:",
            "`relative_uncertainty` = 1.5: must lie in (0, 1)",
        ],
    );
}

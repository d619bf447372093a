//! Messages for the partial cases of `bad-input-findings.md` (issue 28 items 3 and 6): CSV
//! dialects, duplicate keys and tables, files of another kind given as the experiments file,
//! names and paths with stray spaces or too long for file names, missing data, implausible
//! material values, °C in a kelvin key, mass-flow unit slips, the inlet diameter against the
//! data, and a spin line far beyond the measurements. Each test names its finding ids.
//!
//! Scratch copies live under `target/probes` and are removed at the end.

use std::path::{Path, PathBuf};
use std::time::Duration;

use rheometer::data::input::{load_experiments, load_experiments_with, InputError, LoadOptions};

struct Copy {
    dir: PathBuf,
    toml: PathBuf,
    data: PathBuf,
    shipped: String,
}

impl Copy {
    fn new(name: &str) -> Self {
        let (dir, toml, data) = crate::probe::shipped_copy(name);
        let shipped = std::fs::read_to_string(&toml).unwrap();
        Copy {
            dir,
            toml,
            data,
            shipped,
        }
    }

    /// The shipped TOML with the first `from` replaced by `to`.
    fn toml(&self, from: &str, to: &str) -> &Path {
        assert!(self.shipped.contains(from), "{from:?}");
        std::fs::write(&self.toml, self.shipped.replacen(from, to, 1)).unwrap();
        &self.toml
    }

    /// `experiments.toml:LINE:` of the first line containing `needle`.
    fn at(&self, needle: &str) -> String {
        let line = crate::probe::line_where(&self.toml, |l| l.contains(needle));
        format!("{}:{line}:", self.toml.display())
    }

    /// Rewrites CSV `name` line by line.
    fn csv(&self, name: &str, edit: impl Fn(usize, &str) -> String) -> PathBuf {
        let path = self.data.join(name);
        let text = std::fs::read_to_string(
            crate::probe::repo()
                .join("data/pmma7n_synthetic")
                .join(name),
        )
        .unwrap();
        let out: Vec<String> = text
            .lines()
            .enumerate()
            .map(|(i, l)| edit(i + 1, l))
            .collect();
        std::fs::write(&path, out.join("\n") + "\n").unwrap();
        path
    }

    fn restore_csv(&self, name: &str) {
        std::fs::copy(
            crate::probe::repo()
                .join("data/pmma7n_synthetic")
                .join(name),
            self.data.join(name),
        )
        .unwrap();
    }

    fn error(&self) -> String {
        load_experiments(&self.toml).unwrap_err().to_string()
    }
}

impl Drop for Copy {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

fn assert_contains(message: &str, parts: &[&str]) {
    for part in parts {
        assert!(message.contains(part), "`{part}` missing in: {message}");
    }
}

/// A rewrite of one CSV line (1-based line number, text).
type LineEdit = Box<dyn Fn(usize, &str) -> String>;

#[test]
fn csv_dialects_are_named() {
    let c = Copy::new("msg_dialects");
    let csv = "v0p27_p1.csv";
    let data_at = c.at("data = \"v0p27_p1.csv\"");
    let cases: Vec<(&str, LineEdit, Vec<&str>)> = vec![
        // [E41] only the header separated by semicolons
        (
            "E41",
            Box::new(|i, l: &str| {
                if i == 1 {
                    l.replace(',', ";")
                } else {
                    l.into()
                }
            }),
            vec!["v0p27_p1.csv:1:", "semicolons", "expects commas"],
        ),
        // [c04] semicolons throughout
        (
            "c04",
            Box::new(|_, l: &str| l.replace(',', ";")),
            vec!["v0p27_p1.csv:1:", "semicolons", "CSV UTF-8"],
        ),
        // [c05] semicolons and decimal commas (a German Excel export)
        (
            "c05",
            Box::new(|i, l: &str| {
                let l = l.replace(',', ";");
                if i == 1 {
                    l
                } else {
                    l.replace('.', ",")
                }
            }),
            vec![
                "v0p27_p1.csv:1:",
                "semicolons `;`",
                "decimal separator is a comma",
            ],
        ),
        // [c05b] decimal commas with comma separators
        (
            "c05b",
            Box::new(|i, l: &str| {
                if i == 1 {
                    l.into()
                } else {
                    l.replace('.', ",")
                }
            }),
            vec!["v0p27_p1.csv:2:", "found 4", "decimal commas (`0,00`)"],
        ),
        // [c20] a trailing comma on every line
        (
            "c20",
            Box::new(|_, l: &str| format!("{l},")),
            vec!["v0p27_p1.csv:1:", "ends with a comma"],
        ),
        // [c21] Fortran D exponents
        (
            "c21",
            Box::new(|i, l: &str| {
                if i == 1 {
                    l.into()
                } else {
                    l.replace('e', "D")
                }
            }),
            vec!["v0p27_p1.csv:2:", "`D` exponents", "`1.1089323E-03`"],
        ),
        // [c24] tab separators
        (
            "c24",
            Box::new(|_, l: &str| l.replace(',', "\t")),
            vec!["v0p27_p1.csv:1:", "tabs"],
        ),
        // [c22b] positions in millimetres under a metre header
        (
            "c22b",
            Box::new(|i, l: &str| {
                if i == 1 {
                    return l.into();
                }
                let (s, d) = l.split_once(',').unwrap();
                format!("{},{d}", s.parse::<f64>().unwrap() * 1000.0)
            }),
            vec![
                "v0p27_p1.csv:3:",
                "position 20 m lies beyond",
                "millimetres",
                "`position_mm`",
            ],
        ),
    ];
    for (id, edit, needles) in cases {
        c.csv(csv, edit);
        let message = c.error();
        assert!(message.starts_with(&data_at), "{id}: {message}");
        for n in needles {
            assert!(message.contains(n), "{id}: `{n}` missing in: {message}");
        }
        assert!(
            !message.contains("values must be in metres"),
            "{id}: {message}"
        );
    }
    c.restore_csv(csv);
    assert!(load_experiments(&c.toml).is_ok());
}

#[test]
fn duplicate_keys_and_tables_are_named() {
    let c = Copy::new("msg_duplicates");
    // [t07b] a duplicate key
    let toml = c.toml(
        "vft_T_VF_K = 273.15\n",
        "vft_T_VF_K = 273.15\nvft_B_K = 3649.0\n",
    );
    let e = load_experiments(toml).unwrap_err().to_string();
    let first = crate::probe::line_where(toml, |l| l.starts_with("vft_B_K"));
    assert_contains(
        &e,
        &[
            &format!("{}:{}:", toml.display(), first + 2),
            "duplicate key `vft_B_K` in [material]",
            &format!("first on line {first}"),
        ],
    );
    // [F23] [material] defined by a dotted key at the top and by its header
    c.toml("# Synthetic", "material.trouton_ratio = 3\n# Synthetic");
    let e = c.error();
    assert_contains(
        &e,
        &[
            &c.at("[material]"),
            "table `[material]` is defined twice",
            "first on line 1: `material.trouton_ratio = 3`",
        ],
    );
    // [F24] a second [material] table
    let twice = format!("{}\n[material]\ntrouton_ratio = 3\n", c.shipped);
    std::fs::write(&c.toml, twice).unwrap();
    let e = c.error();
    let first = crate::probe::line_where(&c.toml, |l| l == "[material]");
    assert_contains(
        &e,
        &[
            "table `[material]` is defined twice",
            &format!("first on line {first}"),
        ],
    );
    // [F43] an [experiment.uncertainty] table before any [[experiment]]
    c.toml(
        "[defaults]",
        "[experiment.uncertainty]\nmass_flow_rel = 0.05\n\n[defaults]",
    );
    let e = c.error();
    assert_contains(
        &e,
        &[
            &c.at("[[experiment]]"),
            "`[[experiment]]`",
            "`experiment` is already a single table",
            "`[experiment.uncertainty]`",
            "belong after",
        ],
    );
}

#[test]
fn a_csv_or_json_file_is_not_an_experiments_file() {
    let c = Copy::new("msg_not_experiments");
    // [F69] a measurement CSV given as the TOML
    let e = load_experiments(&c.data.join("v0p27_p1.csv")).unwrap_err();
    assert!(matches!(e, InputError::NotExperiments { .. }), "{e}");
    assert_contains(
        &e.to_string(),
        &[
            "v0p27_p1.csv:1: this is not an experiments file",
            "CSV table",
            "data = ",
        ],
    );
    // [F70] a JSON report given as the TOML
    let json = c.data.join("fit.json");
    std::fs::write(&json, "{\n  \"n\": 0.8,\n  \"kappa\": 11.7\n}\n").unwrap();
    let e = load_experiments(&json).unwrap_err().to_string();
    assert_contains(&e, &["fit.json:1: this is not an experiments file", "JSON"]);
    let p = crate::probe::rheometer(
        &["fit", crate::probe::s(&json)],
        &[&c.data],
        Duration::from_secs(30),
    );
    p.assert_clean_failure(&["not an experiments file", "JSON"]);
}

#[test]
fn names_with_stray_spaces_or_only_case_differences_are_refused() {
    let c = Copy::new("msg_names");
    // [F59] "v0p27_p1" and "v0p27_p1 " both accepted before
    c.toml("name = \"v0p27_p2\"", "name = \"v0p27_p1 \"");
    let e = c.error();
    assert_contains(
        &e,
        &[
            &c.at("name = \"v0p27_p1 \""),
            "`name` = \"v0p27_p1 \"",
            "trailing spaces",
        ],
    );
    c.toml("name = \"v0p27_p2\"", "name = \"V0P27_P1\"");
    let e = c.error();
    assert_contains(
        &e,
        &[
            "\"V0P27_P1\" differs from \"v0p27_p1\"",
            "only in upper/lower case",
        ],
    );
}

#[test]
fn names_too_long_for_file_names_are_refused_at_the_toml() {
    // a name becomes file names with suffixes, the longest `_fitted_profile.csv`, and a file
    // name may have 255 bytes
    const MAX_NAME_BYTES: usize = 255 - "_fitted_profile.csv".len();
    let c = Copy::new("msg_long_names");
    // [D06] 255 characters: the output file names would exceed 255 bytes
    let long = "e".repeat(255);
    c.toml("name = \"v0p27_p1\"", &format!("name = \"{long}\""));
    let e = c.error();
    assert_contains(
        &e,
        &[
            &c.at("name = \"eee"),
            "is 255 bytes long",
            &format!("at most {MAX_NAME_BYTES} bytes"),
            "(255 characters)",
        ],
    );
    assert!(e.len() < 600, "{e}");
    // the longest accepted name
    let ok = "e".repeat(MAX_NAME_BYTES);
    c.toml("name = \"v0p27_p1\"", &format!("name = \"{ok}\""));
    assert!(load_experiments(&c.toml).is_ok());
    // [t15] a 1 MB comment line and a 5000-character name: refused before any work, the name cut
    let text = c
        .shipped
        .replacen(
            "name = \"v0p27_p1\"",
            &format!("name = \"{}\"", "n".repeat(5000)),
            1,
        )
        .replacen(
            "[material]",
            &format!("# {}\n[material]", "c".repeat(1 << 20)),
            1,
        );
    std::fs::write(&c.toml, text).unwrap();
    let out = c.dir.join("out");
    let p = crate::probe::rheometer(
        &[
            "simulate",
            crate::probe::s(&c.toml),
            "--take-up-from-data",
            "--out",
            crate::probe::s(&out),
        ],
        &[&c.data],
        Duration::from_secs(30),
    );
    p.assert_clean_failure(&["is 5000 bytes long", "(5000 characters)"]);
    assert!(p.stderr.len() < 2000, "{} bytes of stderr", p.stderr.len());
    assert!(!out.exists(), "the output folder was created");
    assert!(p.elapsed < Duration::from_secs(2), "{:?}", p.elapsed);
}

#[test]
fn a_data_path_with_a_trailing_space_is_quoted() {
    // [D12] "v0p27_p1.csv : cannot read file": the space was easy to miss
    let c = Copy::new("msg_path_space");
    c.toml("data = \"v0p27_p1.csv\"", "data = \"v0p27_p1.csv \"");
    let e = c.error();
    assert_contains(
        &e,
        &[
            &c.at("data = \"v0p27_p1.csv \""),
            "v0p27_p1.csv \": cannot read file",
            "has leading or trailing spaces",
            "\"v0p27_p1.csv\" exists: remove the spaces",
        ],
    );
}

#[test]
fn missing_data_names_the_experiment_and_the_key_to_add() {
    // [t34] "experiment v0p27_p1 has no measurements" without file:line or what to add
    let c = Copy::new("msg_missing_data");
    c.toml("data = \"v0p27_p1.csv\"", "#data = \"v0p27_p1.csv\"");
    let loaded = load_experiments_with(&c.toml, &LoadOptions::default()).unwrap();
    let e = loaded.require_data().unwrap_err().to_string();
    assert_contains(
        &e,
        &[
            &c.at("name = \"v0p27_p1\""),
            "[[experiment]] #1 \"v0p27_p1\"",
            "missing required key `data`",
            "add `data = \"v0p27_p1.csv\"`",
        ],
    );
    let options = LoadOptions {
        require_data: true,
        ..LoadOptions::default()
    };
    let e2 = load_experiments_with(&c.toml, &options)
        .unwrap_err()
        .to_string();
    assert_eq!(e, e2);
}

#[test]
fn implausible_material_values_are_refused() {
    let c = Copy::new("msg_material");
    // [F64] a density slope of +1000 kg/(m³ K): 5e5 kg/m³ at the inlet
    c.toml(
        "density_slope_kg_m3_K = -0.964",
        "density_slope_kg_m3_K = 1000",
    );
    let e = c.error();
    assert_contains(
        &e,
        &[
            &c.at("density_slope_kg_m3_K"),
            "[material]: the density line (`density_slope_kg_m3_K` = 1000",
            "ρ = 5.147e5 kg/m³ at 513.15 K (`inlet_temperature_K` = 513.15 (line",
            "300 to 3500 kg/m³",
        ],
    );
    // [F66] an air heat conductivity of 1e9 W/(m K)
    c.toml(
        "air_heat_conductivity_W_m_K = 0.031",
        "air_heat_conductivity_W_m_K = 1e9",
    );
    let e = c.error();
    assert_contains(
        &e,
        &[
            &c.at("air_heat_conductivity_W_m_K"),
            "`air_heat_conductivity_W_m_K` = 1e9",
            "implausibly large",
            "0.001 to 1 W/(m K)",
        ],
    );
}

#[test]
fn degrees_celsius_in_a_kelvin_key_get_a_hint() {
    // [F06] inlet_temperature_K = 240: accurate, but no unit hint
    let c = Copy::new("msg_celsius");
    c.toml("inlet_temperature_K = 513.15", "inlet_temperature_K = 240");
    let e = c.error();
    assert_contains(
        &e,
        &[
            &c.at("inlet_temperature_K = 240"),
            "Vogel temperature",
            "if 240 is in degrees Celsius, write `inlet_temperature_C = 240` (= 513.15 K)",
        ],
    );
    c.toml("air_temperature_K = 293.15", "air_temperature_K = 20");
    let e = c.error();
    assert_contains(
        &e,
        &["`air_temperature_C = 20` if it is in degrees Celsius"],
    );
    // the other way round: kelvin in a Celsius key is accepted with a warning
    c.toml(
        "inlet_temperature_K = 513.15",
        "inlet_temperature_C = 513.15",
    );
    let loaded = load_experiments_with(&c.toml, &LoadOptions::default()).unwrap();
    let w: Vec<String> = loaded.warnings.iter().map(ToString::to_string).collect();
    assert!(
        w.iter()
            .any(|w| w.contains("if the value is in kelvin, write `inlet_temperature_K = 513.15`")),
        "{w:?}"
    );
}

#[test]
fn mass_flow_unit_slips_are_blamed_on_the_mass_flow_before_any_work() {
    let c = Copy::new("msg_mass_flow");
    for (id, typed, units) in [
        // [F10, t39] g/s typed as kg/s: 1000 times the mass flow
        (
            "F10",
            "1.5690566037735852e-02",
            vec!["`mass_flow_g_s = 1.5690566037735852e-02` if it is in g/s"],
        ),
        // [F11] kg/h typed as kg/s
        (
            "F11",
            "0.0565",
            vec!["`mass_flow_kg_h = 0.0565` if it is in kg/h"],
        ),
    ] {
        c.toml("1.5690566037735852e-05", typed);
        let e = c.error();
        let line = c.at(&format!("mass_flow_kg_s = {typed}"));
        let mut needles = vec![
            line.as_str(),
            "\"v0p27_p1\"",
            "give an inlet velocity",
            "faster than a melt leaves a spinneret",
            "the mass flow is probably in another unit",
        ];
        needles.extend(units.iter().copied());
        for n in needles {
            assert!(e.contains(n), "{id}: `{n}` missing in: {e}");
        }
        let out = c.dir.join("out");
        let p = crate::probe::rheometer(
            &[
                "simulate",
                crate::probe::s(&c.toml),
                "--take-up-from-data",
                "--out",
                crate::probe::s(&out),
            ],
            &[&c.data],
            Duration::from_secs(60),
        );
        p.assert_clean_failure(&["mass flow is probably in another unit"]);
        assert!(p.elapsed < Duration::from_secs(1), "{id}: {:?}", p.elapsed);
        assert!(!p.stderr.contains("take-up"), "{id}: {}", p.stderr);
    }
}

#[test]
fn the_inlet_diameter_is_checked_against_the_first_measured_diameter() {
    // [t09b] an inlet of 11.3 mm with a first measured diameter of 1.1 mm
    let c = Copy::new("msg_inlet_vs_data");
    c.toml("inlet_diameter_m = 0.001134", "inlet_diameter_m = 0.01134");
    let e = c.error();
    assert_contains(
        &e,
        &[
            &c.at("inlet_diameter_m = 0.01134"),
            "\"v0p27_p1\"",
            "the inlet diameter 11.34 mm is 10.23 times the first measured diameter 1.109 mm",
            "within a factor of 2",
        ],
    );
    // an inlet diameter smaller than a downstream measurement
    c.toml("inlet_diameter_m = 0.001134", "inlet_diameter_m = 0.0002");
    let e = c.error();
    assert_contains(&e, &["is 1/5.545 of the first measured diameter"]);
}

#[test]
fn a_spin_line_far_beyond_the_data_is_refused_and_a_little_beyond_warned() {
    let c = Copy::new("msg_spinline");
    // [F09] 51 m (a cm slip) with data ending at 0.5 m
    c.toml("spinline_length_m = 0.51", "spinline_length_m = 51");
    let e = c.error();
    assert_contains(
        &e,
        &[
            &c.at("spinline_length_m = 51"),
            "`spinline_length_m` = 51",
            "cover s = 0 to 0.5 m",
            "extrapolated 50.5 m beyond",
            "101 times the measured span",
            "spinline_length_cm",
            "take_up_diameter_m",
        ],
    );
    // [S21] 5 m
    c.toml("spinline_length_m = 0.51", "spinline_length_m = 5");
    assert_contains(&c.error(), &["9 times the measured span"]);
    // [c30] data ending at 3 mm, L = 0.51 m
    c.toml("spinline_length_m = 0.51", "spinline_length_m = 0.51");
    let rows = [
        "position_m,diameter_m",
        "0.000,1.1089323e-03",
        "0.001,1.0e-03",
        "0.002,9.5e-04",
        "0.003,9.0e-04",
    ];
    std::fs::write(c.data.join("v0p27_p1.csv"), rows.join("\n") + "\n").unwrap();
    assert_contains(
        &c.error(),
        &["cover s = 0 to 0.003 m", "169 times the measured span"],
    );
    // the same data with the take-up given by the caller: no check
    let options = LoadOptions {
        take_up_from_data: false,
        ..LoadOptions::default()
    };
    assert!(load_experiments_with(&c.toml, &options).is_ok());
    // data to 0.35 m of 0.51 m: a warning, not an error
    c.csv("v0p27_p1.csv", |_, l| l.to_string());
    let text = std::fs::read_to_string(c.data.join("v0p27_p1.csv")).unwrap();
    let cut: Vec<&str> = text
        .lines()
        .filter(|l| {
            l.split(',')
                .next()
                .and_then(|s| s.parse::<f64>().ok())
                .is_none_or(|s| s <= 0.35)
        })
        .collect();
    std::fs::write(c.data.join("v0p27_p1.csv"), cut.join("\n") + "\n").unwrap();
    let loaded = load_experiments_with(&c.toml, &LoadOptions::default()).unwrap();
    let warnings: Vec<String> = loaded.warnings.iter().map(ToString::to_string).collect();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert_contains(
        &warnings[0],
        &[
            &c.at("spinline_length_m"),
            "\"v0p27_p1\"",
            "0.17 m beyond",
            "an extrapolation",
        ],
    );
    // the command line shows it once, and not when the take-up diameter is given
    let out = c.dir.join("out");
    let args = [
        "simulate",
        crate::probe::s(&c.toml),
        "--out",
        crate::probe::s(&out),
    ];
    let p = crate::probe::rheometer(
        &[&args[..], &["--take-up-from-data"]].concat(),
        &[],
        Duration::from_secs(60),
    );
    p.assert_success();
    assert_eq!(p.stderr.matches("warning:").count(), 1, "{}", p.stderr);
    assert_contains(&p.stderr, &["warning:", "0.17 m beyond"]);
    let p = crate::probe::rheometer(
        &[&args[..], &["--take-up-diameter", "1e-4"]].concat(),
        &[],
        Duration::from_secs(60),
    );
    p.assert_success();
    assert!(!p.stderr.contains("beyond"), "{}", p.stderr);
    // the shipped data (0.5 of 0.51 m): neither
    std::fs::write(&c.toml, &c.shipped).unwrap();
    c.restore_csv("v0p27_p1.csv");
    assert!(load_experiments_with(&c.toml, &LoadOptions::default())
        .unwrap()
        .warnings
        .is_empty());
}

#[test]
fn metres_in_a_micrometre_uncertainty_key_are_refused() {
    // [F38] gauge_offset_um = 2e-6 (metres) was accepted
    let c = Copy::new("msg_gauge_offset");
    c.toml(
        "[material]",
        "[uncertainty]\ngauge_offset_um = 2e-6\n\n[material]",
    );
    let e = c.error();
    assert_contains(
        &e,
        &[
            &c.at("gauge_offset_um"),
            "`gauge_offset_um` = 2e-6",
            "implausibly small",
            "was it given in metres? then write `gauge_offset_um = 2`",
        ],
    );
}

/// Finding D36: two experiments reading one data file (a copied table whose `data` was not
/// changed) are warned about at the second's `data` key, whatever the path's spelling.
#[test]
fn two_experiments_reading_one_data_file_are_warned_about() {
    let (dir, toml, data) = crate::probe::shipped_copy("shared_data_file");
    let (out, out2) = (dir.join("out"), dir.join("out2"));
    let v = crate::probe::variant(
        &toml,
        "shared.toml",
        "data = \"v0p27_p2.csv\"",
        "data = \"./v0p27_p1.csv\"",
    );
    let line = crate::probe::line_where(&v, |l| l.contains("./v0p27_p1.csv"));
    let p = crate::probe::rheometer(
        &[
            "simulate",
            crate::probe::s(&v),
            "--n",
            "0.8",
            "--kappa",
            "11.71",
            "--take-up-from-data",
            "--out",
            crate::probe::s(&out),
        ],
        &[&data],
        std::time::Duration::from_secs(60),
    );
    p.assert_success();
    assert!(
        p.stderr.contains(&format!(
            "shared.toml:{line}: experiments v0p27_p1 and v0p27_p2 read the same data file"
        )),
        "{}",
        p.stderr
    );
    // the shipped data set, every experiment with its own file: no such warning
    let p = crate::probe::rheometer(
        &[
            "simulate",
            crate::probe::s(&toml),
            "--n",
            "0.8",
            "--kappa",
            "11.71",
            "--take-up-from-data",
            "--out",
            crate::probe::s(&out2),
        ],
        &[&data],
        std::time::Duration::from_secs(60),
    );
    p.assert_success();
    assert!(
        !p.stderr.contains("read the same data file"),
        "{}",
        p.stderr
    );
}

/// Finding D37: an experiments file reached through a symbolic link in another folder resolves
/// its relative `data` paths from the link's folder; the missing CSV's error says so and names
/// the file beside the link's target.
#[cfg(unix)]
#[test]
fn a_linked_experiments_file_explains_where_data_paths_are_resolved() {
    let (dir, toml, data) = crate::probe::shipped_copy("linked_experiments_file");
    let other = dir.join("elsewhere");
    std::fs::create_dir_all(&other).expect("scratch folder");
    let link = other.join("experiments.toml");
    std::os::unix::fs::symlink(&toml, &link).expect("symlink");
    let p = crate::probe::rheometer(
        &["fit", crate::probe::s(&link)],
        &[&data],
        std::time::Duration::from_secs(60),
    );
    p.assert_clean_failure(&[
        "v0p27_p1.csv: cannot read file",
        "is a symbolic link",
        "resolved from the folder it was given in",
        &format!("{} exists", data.join("v0p27_p1.csv").display()),
    ]);
}

//! Units people type (issue 31 item 2): TOML keys and CSV headers in lab units (g/min, °C, mm,
//! cm, µm), converted once at load to the SI `ExperimentSet`. The converted copy of the shipped
//! data set in `tests/data/pmma7n_units` was made by `make.py` there (exact decimal arithmetic
//! in Python, not by the loader under test); it must load to the same SI values as the shipped
//! files and give the same fit. A quantity given twice in different units is refused, and a
//! value in the wrong unit is still caught with its line.
//!
//! Scratch files live under `target/probes` and are removed at the end.

use std::path::{Path, PathBuf};

use rheometer::data::input::{load_experiments, parse_experiments, parse_measurements};
use rheometer::fit::{IdentifyOptions, Rheometer};
use rheometer::model::{ExperimentSet, Inlet};

fn shipped() -> PathBuf {
    crate::probe::repo().join("data/pmma7n_synthetic/experiments.toml")
}

fn lab_units() -> PathBuf {
    crate::probe::repo().join("tests/data/pmma7n_units/experiments.toml")
}

/// |a − b| ≤ 1e-12 |b| (values loaded from decimal text in two units may differ in the last
/// binary digit).
fn close(a: f64, b: f64, what: &str) {
    assert!(
        (a - b).abs() <= 1e-12 * b.abs(),
        "{what}: {a:e} vs {b:e} (relative {:e})",
        (a - b).abs() / b.abs()
    );
}

fn assert_same_set(a: &ExperimentSet, b: &ExperimentSet) {
    assert_eq!(a.material, b.material);
    assert_eq!(a.air, b.air);
    assert_eq!(a.relative_uncertainty, b.relative_uncertainty);
    assert_eq!(a.experiments.len(), b.experiments.len());
    for (x, y) in a.experiments.iter().zip(&b.experiments) {
        let n = &x.name;
        assert_eq!(x.name, y.name);
        close(x.mass_flow, y.mass_flow, &format!("{n} mass flow"));
        close(
            x.inlet_temperature,
            y.inlet_temperature,
            &format!("{n} T_in"),
        );
        close(x.air_temperature, y.air_temperature, &format!("{n} T_air"));
        close(x.spinline_length, y.spinline_length, &format!("{n} L"));
        match (x.inlet, y.inlet) {
            (Inlet::Diameter(p), Inlet::Diameter(q)) => close(p, q, &format!("{n} d_in")),
            other => panic!("{n}: inlets differ: {other:?}"),
        }
        assert_eq!(x.take_up, y.take_up);
    }
    for (k, (x, y)) in a.measurements.iter().zip(&b.measurements).enumerate() {
        let (x, y) = (x.as_ref().unwrap(), y.as_ref().unwrap());
        assert_eq!(x.positions.len(), y.positions.len());
        for i in 0..x.positions.len() {
            close(x.positions[i], y.positions[i], &format!("#{k} s[{i}]"));
            close(x.diameters[i], y.diameters[i], &format!("#{k} d[{i}]"));
        }
    }
}

#[test]
fn lab_units_load_to_the_shipped_si_values() {
    let si = load_experiments(&shipped()).unwrap();
    let lab = load_experiments(&lab_units()).unwrap();
    assert_same_set(&lab, &si);
    // the exactly representable conversions are exact
    assert_eq!(lab.experiments[0].inlet_temperature, 513.15);
    assert_eq!(lab.experiments[0].air_temperature, 293.15);
    assert_eq!(lab.material.vft_t_vf, 273.15);
    assert_eq!(lab.experiments[0].spinline_length, 0.51);
    // the converted copy really is in other units
    let text = std::fs::read_to_string(lab_units()).unwrap();
    for key in [
        "mass_flow_g_min",
        "inlet_temperature_C",
        "inlet_diameter_mm",
        "spinline_length_cm",
    ] {
        assert!(text.contains(key), "{key}");
    }
    assert!(
        !text.contains("_kg_s ="),
        "SI mass flow left in the lab-unit copy"
    );
    let csv = std::fs::read_to_string(lab_units().with_file_name("v0p27_p1.csv")).unwrap();
    assert!(csv.starts_with("position_mm,diameter_um\n"), "{csv}");
}

#[test]
fn lab_units_give_the_same_fit_as_si() {
    let fit = |path: &Path| {
        let set = load_experiments(path).unwrap();
        let rh = Rheometer::new(&set).unwrap();
        rh.identify([0.7, 11.0], &IdentifyOptions::default())
            .unwrap()
    };
    let (si, lab) = (fit(&shipped()), fit(&lab_units()));
    close(lab.summary.n.value, si.summary.n.value, "n");
    close(lab.summary.kappa.value, si.summary.kappa.value, "kappa");
    for (a, b) in lab.take_up_factors().iter().zip(si.take_up_factors()) {
        close(*a, *b, "take-up factor");
    }
    close(
        lab.summary.rms_relative_residual,
        si.summary.rms_relative_residual,
        "RMS",
    );
}

const MATERIAL: &str = "[material]\ndensity_slope_kg_m3_K = -0.964\ndensity_intercept_kg_m3 = \
    1572.33\nheat_capacity_slope_J_kg_K2 = 3.2\nheat_capacity_intercept_J_kg_K = 648.22\n\
    vft_mu_c_Pa_s = 0.00037074\nvft_B_K = 3649.0\nvft_T_VF_K = 273.15\nair_density_kg_m3 = 1.0\n\
    air_heat_capacity_J_kg_K = 1000.0\nair_kinematic_viscosity_m2_s = 2e-05\n\
    air_heat_conductivity_W_m_K = 0.031\n";

fn experiment(keys: &str) -> Result<ExperimentSet, String> {
    let text = format!("{MATERIAL}\n[[experiment]]\nname = \"a\"\n{keys}");
    parse_experiments(&text, Path::new("u.toml"))
        .map(|l| l.set)
        .map_err(|e| e.to_string())
}

const BASE: &str = "spinline_length_m = 0.51\ninlet_temperature_K = 513.15\n\
    air_temperature_K = 293.15\nmass_flow_kg_s = 3e-5\ninlet_diameter_m = 1e-3\n";

#[test]
fn every_unit_of_every_key_converts() {
    let cases: &[(&str, &str, f64)] = &[
        ("mass_flow_kg_s = 3e-5", "mass_flow_g_s = 0.03", 3e-5),
        ("mass_flow_kg_s = 3e-5", "mass_flow_g_min = 1.8", 3e-5),
        ("mass_flow_kg_s = 3e-5", "mass_flow_g_h = 108", 3e-5),
        ("mass_flow_kg_s = 3e-5", "mass_flow_kg_h = 0.108", 3e-5),
        ("inlet_diameter_m = 1e-3", "inlet_diameter_mm = 1", 1e-3),
        ("inlet_diameter_m = 1e-3", "inlet_diameter_um = 1000", 1e-3),
        ("spinline_length_m = 0.51", "spinline_length_cm = 51", 0.51),
        ("spinline_length_m = 0.51", "spinline_length_mm = 510", 0.51),
        (
            "inlet_temperature_K = 513.15",
            "inlet_temperature_C = 240",
            513.15,
        ),
        (
            "air_temperature_K = 293.15",
            "air_temperature_C = 20",
            293.15,
        ),
        (
            "air_temperature_K = 293.15",
            "air_temperature_C = 5",
            278.15,
        ),
    ];
    for (from, to, si) in cases {
        let set = experiment(&BASE.replace(from, to)).unwrap_or_else(|e| panic!("{to}: {e}"));
        let e = &set.experiments[0];
        let got = match to.split(" =").next().unwrap().rsplit_once('_').unwrap().0 {
            k if k.starts_with("mass_flow") => e.mass_flow,
            k if k.starts_with("inlet_diameter") => match e.inlet {
                Inlet::Diameter(d) => d,
                Inlet::Velocity(_) => f64::NAN,
            },
            k if k.starts_with("spinline") => e.spinline_length,
            k if k.starts_with("inlet_temperature") => e.inlet_temperature,
            _ => e.air_temperature,
        };
        close(got, *si, to);
    }
    // speeds, and the take-up keys
    let set = experiment(
        &BASE
            .replace("inlet_diameter_m = 1e-3", "inlet_velocity_mm_s = 20")
            .replace("mass_flow", "take_up_velocity_m_min = 60\nmass_flow"),
    )
    .unwrap();
    assert_eq!(set.experiments[0].inlet, Inlet::Velocity(0.02));
    assert_eq!(
        set.experiments[0].take_up,
        Some(rheometer::model::TakeUp::Velocity(1.0))
    );
    let set = experiment(&format!("{BASE}take_up_diameter_um = 90\n")).unwrap();
    assert_eq!(
        set.experiments[0].take_up,
        Some(rheometer::model::TakeUp::Diameter(9e-5))
    );
    // the Vogel temperature in °C
    let text = format!(
        "{}\n[[experiment]]\nname = \"a\"\n{BASE}",
        MATERIAL.replace("vft_T_VF_K = 273.15", "vft_T_VF_C = 0")
    );
    let set = parse_experiments(&text, Path::new("u.toml")).unwrap().set;
    assert_eq!(set.material.vft_t_vf, 273.15);
    // CSV columns
    let m = parse_measurements(
        "position_cm,diameter_mm\n0,1.1\n10,0.5\n",
        Path::new("m.csv"),
        0.51,
        2,
    )
    .unwrap();
    assert_eq!(m.positions, vec![0.0, 0.1]);
    assert_eq!(m.diameters, vec![1.1e-3, 5e-4]);
}

#[test]
fn a_quantity_given_twice_in_different_units_is_refused() {
    let e = experiment(&format!("{BASE}mass_flow_g_min = 1.8\n")).unwrap_err();
    assert!(
        e.starts_with("u.toml:21:")
            && e.contains(
                "`mass_flow_kg_s` (line 19) and `mass_flow_g_min` (line 21) give the same quantity \
                 twice"
            ),
        "{e}"
    );
    let e = parse_measurements("position_m,position_mm\n0,0\n", Path::new("m.csv"), 0.51, 1)
        .unwrap_err()
        .to_string();
    assert!(e.contains("names the same quantity twice"), "{e}");
    // one unit in [defaults], another in the experiment: the experiment's value is used
    let text = format!(
        "{MATERIAL}[defaults]\nmass_flow_kg_h = 0.108\n\n[[experiment]]\nname = \"a\"\n{}",
        BASE.replace("mass_flow_kg_s = 3e-5", "mass_flow_g_min = 3.6")
    );
    let set = parse_experiments(&text, Path::new("u.toml")).unwrap().set;
    close(
        set.experiments[0].mass_flow,
        6e-5,
        "experiment overrides defaults",
    );
}

#[test]
fn a_value_in_the_wrong_unit_is_still_refused_with_its_line() {
    // millimetres under a metre key
    let e = experiment(&BASE.replace("inlet_diameter_m = 1e-3", "inlet_diameter_m = 1.134"))
        .unwrap_err();
    assert!(e.starts_with("u.toml:20:"), "{e}");
    assert!(
        e.contains("`inlet_diameter_m` = 1.134: implausibly large for a diameter in metres"),
        "{e}"
    );
    assert!(
        e.contains("write `inlet_diameter_mm = 1.134` if it is in millimetres"),
        "{e}"
    );
    let e = experiment(&BASE.replace("spinline_length_m = 0.51", "spinline_length_m = 510"))
        .unwrap_err();
    assert!(
        e.starts_with("u.toml:16:") && e.contains("`spinline_length_mm = 510`"),
        "{e}"
    );
    // metres under a millimetre key
    let e = experiment(&BASE.replace("inlet_diameter_m = 1e-3", "inlet_diameter_mm = 0.001134"))
        .unwrap_err();
    assert!(e.starts_with("u.toml:20:"), "{e}");
    assert!(
        e.contains("implausibly small") && e.contains("`inlet_diameter_m = 0.001134`"),
        "{e}"
    );
    // kg/s under a g/min key: the inlet velocity gives it away
    let e =
        experiment(&BASE.replace("mass_flow_kg_s = 3e-5", "mass_flow_g_min = 1.8e3")).unwrap_err();
    assert!(
        e.starts_with("u.toml:19:") && e.contains("faster than a melt"),
        "{e}"
    );
    // kelvin under a Celsius key that makes it implausible
    let e = experiment(&BASE.replace("air_temperature_K = 293.15", "air_temperature_C = 1500"))
        .unwrap_err();
    assert!(
        e.contains("implausibly large") && e.contains("`air_temperature_K = 1500`"),
        "{e}"
    );
    // below absolute zero
    let e = experiment(&BASE.replace("air_temperature_K = 293.15", "air_temperature_C = -300"))
        .unwrap_err();
    assert!(e.contains("at or below absolute zero"), "{e}");
    // a CSV in metres under a micrometre header
    let e = parse_measurements(
        "position_m,diameter_um\n0,1.1e-3\n",
        Path::new("m.csv"),
        0.51,
        1,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("m.csv:2:") && e.contains("`diameter_m` (metres)"),
        "{e}"
    );
}

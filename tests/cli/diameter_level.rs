//! Outputs of the model that was fitted (issue 65, item 6): with diameter-level effects in the
//! model (`mass_flow_scale`, `gauge_scale`, `gauge_offset`), the fitted profiles show the
//! diameter that model predicts, a `gauge_reading_m` column what its gauge reads, and
//! `compare` sets the gauge's reading against the measurements, as the fit's residuals do.

use std::fs;
use std::path::Path;
use std::time::Duration;

use crate::probe::{rheometer, s, shipped_copy};

const LIMIT: Duration = Duration::from_secs(240);

/// The die's diameter of every experiment of the shipped set \[m\].
const DIE_M: f64 = 1.134e-3;

/// A CSV file as (header, rows of numbers; the first column is skipped where it is a name).
fn csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = fs::read_to_string(path).expect("csv");
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap_or("")
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| l.split(',').filter_map(|v| v.parse().ok()).collect())
        .collect();
    (header, rows)
}

/// `rheometer fit --with EFFECT --out`: the fitted profiles, by file name.
fn fitted_profiles(name: &str, effect: &str) -> Vec<(String, Vec<String>, Vec<Vec<f64>>)> {
    let (dir, toml, data) = shipped_copy(name);
    let out = dir.join("out");
    let p = rheometer(
        &["fit", s(&toml), "--with", effect, "--out", s(&out)],
        &[&data],
        LIMIT,
    );
    p.assert_success();
    let mut files: Vec<_> = fs::read_dir(&out)
        .expect("out")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.to_string_lossy().ends_with("_fitted_profile.csv"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 9, "one fitted profile per experiment");
    files
        .iter()
        .map(|f| {
            let (h, rows) = csv(f);
            (f.display().to_string(), h, rows)
        })
        .collect()
}

fn column(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

#[test]
fn a_scaled_mass_flow_starts_the_fitted_profile_at_the_die() {
    for (file, header, rows) in fitted_profiles("diameter_level_mass_flow", "mass_flow_scale=-0.05")
    {
        let d = column(&header, "diameter_m");
        // the diameter of the mass flow the model has, at the die: the die's diameter (the
        // nominal mass flow would give 1.1635 mm)
        let d0 = rows[0][d];
        assert!((d0 / DIE_M - 1.0).abs() < 1e-9, "{file}: d(0) = {d0} m");
        assert!(
            !header.iter().any(|h| h == "gauge_reading_m"),
            "{file}: no gauge effect, no gauge column"
        );
    }
}

#[test]
fn gauge_effects_add_what_the_gauge_reads() {
    for (effect, reading) in [
        ("gauge_offset=1.5", (|d: f64| d + 1.5e-6) as fn(f64) -> f64),
        ("gauge_scale=0.02", |d: f64| 1.02 * d),
    ] {
        let name = format!("diameter_level_{}", &effect[..12]);
        for (file, header, rows) in fitted_profiles(&name, effect) {
            let (d, g) = (
                column(&header, "diameter_m"),
                column(&header, "gauge_reading_m"),
            );
            assert!(
                (rows[0][d] / DIE_M - 1.0).abs() < 1e-9,
                "{file}: the true diameter at 0"
            );
            for r in &rows {
                let want = reading(r[d]);
                assert!(
                    (r[g] - want).abs() < 1e-9 * want,
                    "{file} ({effect}): reads {} m for a diameter of {} m",
                    r[g],
                    r[d]
                );
            }
        }
    }
}

#[test]
fn compare_sets_the_gauge_reading_against_the_measurements() {
    let (dir, toml, data) = shipped_copy("diameter_level_compare");
    let out = dir.join("out");
    let p = rheometer(
        &[
            "compare",
            s(&toml),
            "--n",
            "0.8",
            "--kappa",
            "11.71",
            "--take-up-from-data",
            "--with",
            "gauge_offset=1.5",
            "--out",
            s(&out),
        ],
        &[&data],
        LIMIT,
    );
    p.assert_success();
    let (header, rows) = csv(&out.join("compare_points.csv"));
    // the first column is the experiment's name, dropped by `csv`
    let pos = column(&header, "position_m") - 1;
    let model = column(&header, "d_model_m") - 1;
    let at_die: Vec<f64> = rows
        .iter()
        .filter(|r| r[pos] == 0.0)
        .map(|r| r[model])
        .collect();
    assert_eq!(at_die.len(), 9, "a point at the die per experiment");
    for d in at_die {
        assert!(
            (d - (DIE_M + 1.5e-6)).abs() < 1e-12,
            "model value at the die {d} m"
        );
    }
}

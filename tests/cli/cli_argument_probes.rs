//! Bad or extreme command-line values and inputs whose simulation fails: every probe runs on a
//! copy of the shipped data set and asserts the exit code, no panic, a message naming the flag
//! and value (or the experiment and its TOML line) and unchanged inputs; values refused up
//! front must be refused quickly.

use crate::probe;
use rheometer::data::input::LoadOptions;

use probe::{s, variant, Probe};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Refused-up-front probes must end within this time.
const QUICK: Duration = Duration::from_secs(2);
/// Time limit of probes that solve something.
const LIMIT: Duration = Duration::from_secs(120);

/// "FILE:LINE" of the experiment `name` (its `name = "..."` line) in `toml`.
fn place(toml: &Path, name: &str) -> String {
    let key = format!("name = \"{name}\"");
    let line = probe::line_where(toml, |l| l.trim() == key);
    format!("{}:{line}", toml.display())
}

/// Runs `rheometer ARGS` watching the data dir.
fn run(args: &[&str], data_dir: &Path, limit: Duration) -> Probe {
    probe::rheometer(args, &[data_dir], limit)
}

/// A probe refused up front: clean failure naming every needle, within [`QUICK`].
fn refused(args: &[&str], data_dir: &Path, needles: &[&str]) -> Probe {
    let p = run(args, data_dir, LIMIT);
    p.assert_clean_failure(needles);
    assert!(
        p.elapsed < QUICK,
        "{args:?} took {:?} to refuse (limit {QUICK:?})",
        p.elapsed
    );
    p
}

// ---------------------------------------------------------------- simulate

#[test]
fn simulate_points_zero_one_and_huge_are_refused() {
    let (dir, toml, dd) = probe::shipped_copy("args_points");
    let out = dir.join("out");
    for v in ["0", "1", "50000000"] {
        refused(
            &[
                "simulate",
                s(&toml),
                "--take-up-from-data",
                "--points",
                v,
                "--out",
                s(&out),
            ],
            &dd,
            &["--points", &format!("'{v}'"), "2 to 100000"],
        );
    }
    assert!(!out.join("v0p27_p1_profile.csv").exists());
}

#[test]
fn simulate_negative_n_is_a_value_and_refused_by_domain() {
    let (dir, toml, dd) = probe::shipped_copy("args_neg_n");
    let out = dir.join("out");
    // both spellings reach the value check (no "use -- -0" tip)
    for args in [
        vec![
            "simulate",
            s(&toml),
            "--n=-0.1",
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
        vec![
            "simulate",
            s(&toml),
            "--n",
            "-0.1",
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
    ] {
        let p = refused(&args, &dd, &["--n", "-0.1", ">= 0"]);
        assert!(!p.stderr.contains("tip:"), "{}", p.stderr);
    }
}

#[test]
fn simulate_n_zero_names_experiment_line_and_cause() {
    let (dir, toml, dd) = probe::shipped_copy("args_n_zero");
    let out = dir.join("out");
    let p = run(
        &[
            "simulate",
            s(&toml),
            "--n",
            "0",
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
        &dd,
        LIMIT,
    );
    p.assert_clean_failure(&[
        "experiment v0p27_p1",
        &place(&toml, "v0p27_p1"),
        "(n, kappa) = (0, 11.71)",
        "continuation stopped", // the original cause stays in the chain
        "hint: n = 0 is strong strain thinning",
        "--take-up-from-data",
    ]);
}

#[test]
fn simulate_kappa_out_of_range_and_non_numbers_are_refused() {
    let (dir, toml, dd) = probe::shipped_copy("args_kappa");
    let out = dir.join("out");
    refused(
        &[
            "simulate",
            s(&toml),
            "--kappa",
            "1000",
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
        &dd,
        &["--kappa", "'1000'", "700"],
    );
    refused(
        &[
            "simulate",
            s(&toml),
            "--kappa",
            "-1e4",
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
        &dd,
        &["--kappa", "'-1e4'"],
    );
    refused(
        &[
            "simulate",
            s(&toml),
            "--n",
            "nan",
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
        &dd,
        &["--n", "'nan'", "finite"],
    );
}

#[test]
fn simulate_take_up_diameter_out_of_range_is_refused() {
    let (dir, toml, dd) = probe::shipped_copy("args_take_up");
    let out = dir.join("out");
    for v in ["-1e-4", "1e-9", "0.5"] {
        refused(
            &[
                "simulate",
                s(&toml),
                "--take-up-diameter",
                v,
                "--out",
                s(&out),
            ],
            &dd,
            &["--take-up-diameter", &format!("'{v}'"), "metres"],
        );
    }
}

#[test]
fn max_nodes_out_of_range_is_refused_on_every_subcommand() {
    let (dir, toml, dd) = probe::shipped_copy("args_max_nodes");
    let out = dir.join("out");
    for (cmd, extra) in [
        ("simulate", vec!["--take-up-from-data", "--out", s(&out)]),
        ("fit", vec![]),
        ("diagnose", vec!["--out", s(&out)]),
        ("landscape", vec!["--out", s(&out)]),
        (
            "compare",
            vec!["--n", "0.8", "--kappa", "11.71", "--out", s(&out)],
        ),
    ] {
        for v in ["0", "10", "99999999"] {
            let mut args = vec![cmd, s(&toml), "--max-nodes", v];
            args.extend(&extra);
            refused(&args, &dd, &["--max-nodes", &format!("'{v}'"), "20000"]);
        }
    }
}

#[test]
fn small_max_nodes_fails_naming_experiment_line_and_flag() {
    let (dir, toml, dd) = probe::shipped_copy("args_small_max_nodes");
    let out = dir.join("out");
    let p = run(
        &[
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--max-nodes",
            "50",
            "--out",
            s(&out),
        ],
        &dd,
        LIMIT,
    );
    p.assert_clean_failure(&[
        "experiment v0p27_p1",
        &place(&toml, "v0p27_p1"),
        "max_nodes = 50",
        "raise the limit with --max-nodes",
    ]);
    // the same run with the default limit succeeds: the limit, not the input, failed
    let p = run(
        &[
            "simulate",
            s(&toml),
            "--take-up-from-data",
            "--points",
            "2",
            "--out",
            s(&out),
        ],
        &dd,
        LIMIT,
    );
    p.assert_success();
}

#[test]
fn extreme_thin_take_up_names_the_experiment() {
    // a valid but extreme take-up (1 µm from a 1.1 mm inlet) with a small mesh limit
    let (dir, toml, dd) = probe::shipped_copy("args_thin_take_up");
    let out = dir.join("out");
    let p = run(
        &[
            "simulate",
            s(&toml),
            "--take-up-diameter",
            "1e-6",
            "--max-nodes",
            "200",
            "--out",
            s(&out),
        ],
        &dd,
        LIMIT,
    );
    p.assert_clean_failure(&[
        "experiment v0p27_p1",
        &place(&toml, "v0p27_p1"),
        "hint:",
        "times thinner than the inlet",
    ]);
}

#[test]
fn simulate_overflowing_mass_flow_is_refused_with_experiment() {
    // refused by the reader (plausible range of the key), before any derived value overflows
    let (dir, toml, dd) = probe::shipped_copy("args_mass_flow");
    let out = dir.join("out");
    let bad = variant(
        &toml,
        "huge_flow.toml",
        "mass_flow_kg_s = 1.5690566037735852e-05",
        "mass_flow_kg_s = 1e308",
    );
    let p = run(
        &["simulate", s(&bad), "--take-up-from-data", "--out", s(&out)],
        &dd,
        LIMIT,
    );
    p.assert_clean_failure(&[
        "\"v0p27_p1\"",
        &format!("{}:", bad.display()),
        "`mass_flow_kg_s` = 1e308",
        "implausibly large",
        "kg/s",
    ]);
    assert!(!p.stderr.contains("inlet diameter 0 m"), "{}", p.stderr);
    assert!(!out.exists(), "nothing written for a refused input");
}

/// The data set with the melt entering at 273.151 K, just above the VFT temperature.
fn cold(toml: &Path) -> PathBuf {
    variant(
        toml,
        "cold.toml",
        "inlet_temperature_K = 513.15",
        "inlet_temperature_K = 273.151",
    )
}

#[test]
fn cold_melt_names_experiment_and_vft_in_simulate_compare_fit_landscape_diagnose() {
    // refused by the reader in every subcommand, before a solver meets the infinite viscosity
    let (dir, toml, dd) = probe::shipped_copy("args_cold");
    let bad = cold(&toml);
    let at = format!("{}:", bad.display());
    let out = dir.join("out");
    let runs: Vec<Vec<&str>> = vec![
        vec!["simulate", s(&bad), "--take-up-from-data", "--out", s(&out)],
        vec![
            "compare",
            s(&bad),
            "--n",
            "0.8",
            "--kappa",
            "11.71",
            "--take-up-from-data",
            "--out",
            s(&out),
        ],
        vec!["fit", s(&bad)],
        vec!["landscape", s(&bad), "--grid", "3x3", "--out", s(&out)],
        vec!["diagnose", s(&bad), "--out", s(&out)],
    ];
    for args in runs {
        let p = run(&args, &dd, LIMIT);
        p.assert_clean_failure(&[
            "\"v0p27_p1\"",
            &at,
            "`inlet_temperature_K` = 273.151",
            "vft_T_VF_K = 273.15 K",
            "infinite zero-shear viscosity",
        ]);
    }
}

// ---------------------------------------------------------------- landscape

#[test]
fn landscape_huge_and_degenerate_grids_are_refused() {
    let (dir, toml, dd) = probe::shipped_copy("args_grid");
    let out = dir.join("out");
    for (v, needle) in [
        ("100000x100000", "too large"),
        ("1001x2", "too large"),
        ("400x400", "100000 points"),
        ("1x5", "at least 2"),
        ("5", "NxM"),
    ] {
        refused(
            &["landscape", s(&toml), "--grid", v, "--out", s(&out)],
            &dd,
            &["--grid", &format!("'{v}'"), needle],
        );
    }
    assert!(!out.exists());
}

#[test]
fn landscape_reversed_and_out_of_bounds_ranges_are_refused() {
    let (dir, toml, dd) = probe::shipped_copy("args_ranges");
    let out = dir.join("out");
    for (flag, v, needle) in [
        ("--n-range", "1,0", "did you mean 0,1"),
        ("--n-range", "0.5,0.5", "MIN < MAX"),
        ("--n-range", "-0.1,1", "[0, 1]"),
        ("--n-range", "0,1.5", "[0, 1]"),
        ("--kappa-range", "16,9", "did you mean 9,16"),
        ("--kappa-range", "5,30", "[7, 20]"),
    ] {
        refused(
            &["landscape", s(&toml), flag, v, "--out", s(&out)],
            &dd,
            &[flag, v, needle],
        );
    }
    assert!(!out.exists());
}

#[test]
fn landscape_tol_and_max_nodes_out_of_range_are_refused() {
    let (dir, toml, dd) = probe::shipped_copy("args_tol");
    let out = dir.join("out");
    for v in ["0", "2", "-1e-4", "1e-20"] {
        refused(
            &["landscape", s(&toml), "--tol", v, "--out", s(&out)],
            &dd,
            &["--tol", &format!("'{v}'"), "[1e-12, 0.1]"],
        );
    }
    refused(
        &[
            "landscape",
            s(&toml),
            "--max-nodes",
            "5000",
            "--out",
            s(&out),
        ],
        &dd,
        &["--max-nodes 5000", "at most 1000"],
    );
}

#[test]
fn landscape_prints_a_measured_time_estimate_up_front() {
    let (dir, toml, dd) = probe::shipped_copy("args_estimate");
    let out = dir.join("out");
    let p = run(
        &["landscape", s(&toml), "--grid", "4x3", "--out", s(&out)],
        &dd,
        LIMIT,
    );
    p.assert_success();
    let est = p
        .stderr
        .lines()
        .position(|l| l.starts_with("landscape: 12 points on") && l.contains("about"))
        .unwrap_or_else(|| panic!("no estimate line:\n{}", p.stderr));
    let done = p
        .stderr
        .lines()
        .position(|l| l.starts_with("12 points in"))
        .unwrap_or_else(|| panic!("no summary line:\n{}", p.stderr));
    assert!(
        est < done,
        "the estimate comes after the work:\n{}",
        p.stderr
    );
    // --quiet prints no estimate
    let q = run(
        &[
            "landscape",
            s(&toml),
            "--grid",
            "3x3",
            "--quiet",
            "--out",
            s(&out),
        ],
        &dd,
        LIMIT,
    );
    q.assert_success();
    assert!(!q.stderr.contains("about"), "{}", q.stderr);
}

// ---------------------------------------------------------------- fit, compare, diagnose

#[test]
fn fit_start_outside_the_bounds_is_refused() {
    let (_dir, toml, dd) = probe::shipped_copy("args_start");
    for v in ["1.5,11", "-0.1,11", "0.5,25", "0.5,-3"] {
        refused(
            &["fit", s(&toml), "--start", v],
            &dd,
            &["--start", v, "bounds"],
        );
    }
}

#[test]
fn compare_relative_uncertainty_outside_zero_one_is_refused() {
    let (dir, toml, dd) = probe::shipped_copy("args_sigma");
    let out = dir.join("out");
    for v in ["2", "0", "1", "-0.01", "inf"] {
        refused(
            &[
                "compare",
                s(&toml),
                "--n",
                "0.8",
                "--kappa",
                "11.71",
                "--take-up-from-data",
                "--relative-uncertainty",
                v,
                "--out",
                s(&out),
            ],
            &dd,
            &["--relative-uncertainty", &format!("'{v}'")],
        );
    }
}

#[test]
fn compare_negative_n_is_a_value_and_refused() {
    let (dir, toml, dd) = probe::shipped_copy("args_compare_n");
    let out = dir.join("out");
    refused(
        &[
            "compare",
            s(&toml),
            "--n",
            "-0.5",
            "--kappa",
            "11.71",
            "--out",
            s(&out),
        ],
        &dd,
        &["--n", "'-0.5'", ">= 0"],
    );
}

/// A fit file as `rheometer fit --json` writes it (the fields `compare` reads).
fn fit_json(dir: &Path, n: f64, kappa: f64, factor: f64) -> PathBuf {
    let factors: Vec<String> = (0..9)
        .map(|k| if k == 4 { factor } else { 1.0 })
        .map(|v| format!("{v}"))
        .collect();
    let text = format!(
        "{{\"schema_version\": 1, \"report\": \"fit\", \"written_by\": \"rheometer\", \
         \"estimator\": \"Principled\", \"n\": {n}, \"kappa\": {kappa}, \
         \"experiments\": [{}], \"take_up_factors\": [{}]}}",
        [
            "v0p27_p1", "v0p27_p2", "v0p27_p3", "v0p53_p1", "v0p53_p2", "v0p53_p3", "v1p06_p1",
            "v1p06_p2", "v1p06_p3"
        ]
        .map(|n| format!("\"{n}\""))
        .join(", "),
        factors.join(", ")
    );
    let path = dir.join(format!("fit_{n}_{kappa}_{factor}.json"));
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn compare_fit_file_values_are_checked() {
    let (dir, toml, dd) = probe::shipped_copy("args_fit_values");
    let out = dir.join("out");
    for (n, kappa, factor, needles) in [
        (-0.5, 11.71, 1.0, vec!["field \"n\"", "-0.5", "[0, 1]"]),
        (0.8, 1000.0, 1.0, vec!["field \"kappa\"", "1000"]),
        (
            0.8,
            11.71,
            7.0,
            vec!["\"take_up_factors\"[4]", "take-up factor 7", "[0.5, 1.5]"],
        ),
    ] {
        let f = fit_json(&dir, n, kappa, factor);
        let mut all = vec![s(&f)];
        all.extend(needles);
        let p = probe::rheometer(
            &["compare", s(&toml), "--fit", s(&f), "--out", s(&out)],
            &[&dd, &f],
            LIMIT,
        );
        p.assert_clean_failure(&all);
        assert!(p.elapsed < QUICK, "{:?}", p.elapsed);
    }
}

#[test]
fn diagnose_refit_top_zero_or_huge_is_refused() {
    let (dir, toml, dd) = probe::shipped_copy("args_refit_top");
    let out = dir.join("out");
    for v in ["0", "1000", "-1"] {
        refused(
            &["diagnose", s(&toml), "--refit-top", v, "--out", s(&out)],
            &dd,
            &["--refit-top", &format!("'{v}'")],
        );
    }
}

#[test]
fn loaded_experiments_know_their_toml_line() {
    let (_dir, toml, _dd) = probe::shipped_copy("args_lines");
    let loaded =
        rheometer::data::input::load_experiments_with(&toml, &LoadOptions::default()).unwrap();
    assert_eq!(loaded.details.len(), loaded.set.experiments.len());
    for (e, d) in loaded.set.experiments.iter().zip(&loaded.details) {
        let want = place(&toml, &e.name);
        let got = format!("{}:{}", toml.display(), d.line.unwrap_or(0));
        assert_eq!(got, want, "{}", e.name);
    }
}

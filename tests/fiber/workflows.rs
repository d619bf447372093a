//! The library's workflows reproduce the `rheometer` subcommands' numbers (each test runs the
//! program, reads what it wrote, and compares with the library call), and one fit outcome
//! carries one noise level through `fit`, `compare` and `diagnose`.

use crate::probe;
use rheometer::data::input::LoadOptions;

use rheometer::data::input::{load_experiments_with, LoadedExperiments};
use rheometer::data::take_up::MissingTakeUp;
use rheometer::diagnostics::DiagnoseOptions;
use rheometer::fit::{Estimator, FitSummary, IdentifyOptions};
use rheometer::model::ModelSpec;
use rheometer::model::SimulateOptions;
use rheometer::workflow::{self, CompareRequest, FitRequest, LandscapeRequest, SimulateRequest};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn data_set(set: &str) -> (PathBuf, LoadedExperiments) {
    let toml = probe::repo()
        .join("data")
        .join(set)
        .join("experiments.toml");
    let loaded = load_experiments_with(&toml, &LoadOptions::default()).unwrap();
    (toml, loaded)
}

fn run_ok(args: &[&str]) -> String {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rheometer"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) || (a.is_nan() && b.is_nan())
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `rheometer fit --json` and `workflow::fit`: the same estimates, uncertainties and noise
/// level (to 1e-12), read back from the file as the same value.
#[test]
fn fit_reproduces_the_program() {
    let dir = probe::scratch("wf_fit");
    let (toml, data) = data_set("pmma7n_synthetic");
    let file = dir.join("fit.json");
    run_ok(&["--quiet", "fit", s(&toml), "--json", s(&file)]);
    let cli = FitSummary::from_json(&std::fs::read_to_string(&file).unwrap(), "fit.json").unwrap();
    let lib = workflow::fit(&data, &FitRequest::new(IdentifyOptions::default())).unwrap();
    let lib = lib.summary();
    for (a, b) in lib.parameters().iter().zip(cli.parameters()) {
        assert_eq!(a.name, b.name);
        assert!(
            close(a.value, b.value, 1e-12),
            "{} {} {}",
            a.name,
            a.value,
            b.value
        );
        assert!(
            close(a.stderr, b.stderr, 1e-9),
            "{} {} {}",
            a.name,
            a.stderr,
            b.stderr
        );
    }
    assert!(close(lib.cost, cli.cost, 1e-12));
    assert!(close(lib.noise.level, cli.noise.level, 1e-12));
    assert_eq!(lib.noise.source, cli.noise.source);
    assert_eq!(lib.warnings, cli.warnings);
    for (a, b) in lib.take_up_factors.iter().zip(&cli.take_up_factors) {
        assert!(close(*a, *b, 1e-12));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `rheometer compare --fit` and `workflow::compare` with the fit read back: the same χ², RMS
/// and the fit's own noise level.
#[test]
fn compare_reproduces_the_program_and_keeps_the_fits_noise_level() {
    let dir = probe::scratch("wf_compare");
    let (toml, data) = data_set("hidden_radiation");
    let file = dir.join("fit.json");
    run_ok(&["--quiet", "fit", s(&toml), "--json", s(&file)]);
    let out = dir.join("cmp");
    run_ok(&[
        "--quiet",
        "compare",
        s(&toml),
        "--fit",
        s(&file),
        "--out",
        s(&out),
    ]);
    let cli = json(&out.join("compare.json"));
    let fit = FitSummary::from_json(&std::fs::read_to_string(&file).unwrap(), "fit.json").unwrap();
    let lib = workflow::compare(&data, &CompareRequest::of_fit(fit.clone(), "fit.json")).unwrap();
    assert!(close(lib.chi2, cli["chi2"].as_f64().unwrap(), 1e-12));
    assert!(close(lib.rms, cli["rms"].as_f64().unwrap(), 1e-12));
    assert_eq!(lib.dof as u64, cli["dof"].as_u64().unwrap());
    // one noise level: the comparison of a fit reports the fit's
    assert_eq!(lib.noise.level, fit.noise.level);
    assert_eq!(cli["noise"]["level"].as_f64().unwrap(), fit.noise.level);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `rheometer simulate` and `workflow::simulate_experiments`: the same profiles.
#[test]
fn simulate_reproduces_the_program() {
    let dir = probe::scratch("wf_simulate");
    let (toml, data) = data_set("pmma7n_synthetic");
    let out = dir.join("sim");
    run_ok(&[
        "--quiet",
        "simulate",
        s(&toml),
        "--n",
        "0.8",
        "--kappa",
        "11.71",
        "--take-up-from-data",
        "--points",
        "11",
        "--out",
        s(&out),
    ]);
    let request = SimulateRequest {
        law: [0.8, 11.71],
        missing_take_up: MissingTakeUp::FromData,
        points: 11,
        simulate: SimulateOptions::default(),
        source: toml.clone(),
        ..SimulateRequest::new([0.8, 11.71], PathBuf::new())
    };
    let lib =
        workflow::simulate_experiments(&data, &request, |_, _| std::ops::ControlFlow::Continue(()))
            .unwrap();
    assert_eq!(lib.len(), data.set.experiments.len());
    for p in &lib {
        let csv = std::fs::read_to_string(out.join(format!("{}_profile.csv", p.name))).unwrap();
        let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
        let col = header
            .iter()
            .position(|h| h.starts_with("diameter"))
            .unwrap();
        let from_file: Vec<f64> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
            .collect();
        assert_eq!(from_file.len(), p.profiles.diameter.len());
        for (a, b) in from_file.iter().zip(&p.profiles.diameter) {
            assert!(close(*a, *b, 1e-9), "{}: {a} vs {b}", p.name);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `rheometer landscape` and `workflow::landscape`: the same costs on a small grid.
#[test]
fn landscape_reproduces_the_program() {
    let dir = probe::scratch("wf_landscape");
    let (toml, data) = data_set("pmma7n_synthetic");
    let out = dir.join("ls");
    run_ok(&[
        "--quiet",
        "landscape",
        s(&toml),
        "--grid",
        "3x2",
        "--n-range",
        "0.6,0.9",
        "--kappa-range",
        "11,12",
        "--out",
        s(&out),
    ]);
    let csv = std::fs::read_to_string(out.join("landscape.csv")).unwrap();
    let from_file: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(2).unwrap().parse().unwrap())
        .collect();
    let mut identify = IdentifyOptions::with_estimator(Estimator::Paper);
    identify.simulate.tol = 1e-4;
    identify.simulate.max_nodes = 1000;
    let request = LandscapeRequest {
        n: vec![0.6, 0.75, 0.9],
        kappa: vec![11.0, 12.0],
        identify,
        far: None,
    };
    let lib = workflow::landscape(&data, &request, |_| {}, &AtomicBool::new(false)).unwrap();
    // both in the order n fastest
    assert_eq!(lib.landscape.cost.len(), from_file.len());
    for (a, b) in lib.landscape.cost.iter().zip(&from_file) {
        assert!(close(*a, *b, 1e-6), "{a} vs {b}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `rheometer diagnose --json` and `workflow::diagnose`: the same ranking and numbers, and the
/// diagnosis' noise level is the user's fit's (the same as `rheometer fit` prints), on the
/// shipped data with radiation and a noisier take-up region.
#[test]
fn diagnose_reproduces_the_program_with_the_fits_noise_level() {
    let dir = probe::scratch("wf_diagnose");
    let (toml, data) = data_set("hidden_radiation");
    let file = dir.join("d.json");
    run_ok(&[
        "--quiet",
        "diagnose",
        s(&toml),
        "--refit-top",
        "2",
        "--json",
        s(&file),
    ]);
    let cli = json(&file);
    let options = DiagnoseOptions {
        refit_top: 2,
        ..DiagnoseOptions::default()
    };
    let lib = workflow::diagnose(&data, &ModelSpec::default(), &options).unwrap();
    let d = &lib.diagnosis;
    assert_eq!(
        d.most_likely_missing.as_deref(),
        cli["most_likely_missing"].as_str()
    );
    let cands = cli["candidates"].as_array().unwrap();
    assert_eq!(cands.len(), d.candidates.len());
    for (a, b) in d.candidates.iter().zip(cands) {
        assert_eq!(a.effect, b["effect"].as_str().unwrap());
        assert!(close(a.delta_bic, b["delta_bic"].as_f64().unwrap(), 1e-9));
    }
    // the same noise level in fit and diagnose
    let fitfile = dir.join("fit.json");
    run_ok(&["--quiet", "fit", s(&toml), "--json", s(&fitfile)]);
    let fit = json(&fitfile);
    assert_eq!(
        cli["base_fit"]["noise"]["level"].as_f64().unwrap(),
        fit["noise"]["level"].as_f64().unwrap()
    );
    assert_eq!(d.noise_level(), fit["noise"]["level"].as_f64().unwrap());
    let text = d.to_text();
    let level = format!("{:.3} %", 100.0 * d.noise_level());
    assert!(text.contains(&level), "{text}");
    // where the time went: every stage timed, the stages add up to the wall time, and the
    // CLI's JSON carries them
    let t = &d.stage_times;
    let stages = [
        t.fits_s,
        t.linearised_s,
        t.scans_s,
        t.refits_s,
        t.pairs_s,
        t.rest_s,
    ];
    assert!(stages.iter().all(|v| v.is_finite() && *v >= 0.0), "{t:?}");
    assert!(
        t.fits_s > 0.0 && t.scans_s > 0.0 && t.refits_s > 0.0,
        "{t:?}"
    );
    let sum: f64 = stages.iter().sum();
    assert!(
        (sum - d.wall_time_s).abs() <= 1e-6 * d.wall_time_s.max(1.0),
        "stages {sum} s, wall {} s",
        d.wall_time_s
    );
    assert!(text.contains(" s (fits "), "{text}");
    assert!(cli["stage_times"]["scans_s"]
        .as_f64()
        .is_some_and(|v| v > 0.0));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The printed noise level of the shipped clean data is the same number in the three reports.
#[test]
fn one_noise_level_is_printed_by_fit_compare_and_diagnose() {
    let dir = probe::scratch("wf_noise");
    let (toml, _) = data_set("pmma7n_synthetic");
    let file = dir.join("fit.json");
    let fit_text = run_ok(&["--quiet", "fit", s(&toml), "--json", s(&file)]);
    let level = json(&file)["noise"]["level"].as_f64().unwrap();
    let words = format!("{:.3} %", 100.0 * level);
    assert!(fit_text.contains(&words), "{fit_text}");
    let out = dir.join("cmp");
    let cmp_text = run_ok(&[
        "--quiet",
        "compare",
        s(&toml),
        "--fit",
        s(&file),
        "--out",
        s(&out),
    ]);
    assert!(cmp_text.contains(&words), "{cmp_text}");
    let diag_text = run_ok(&["--quiet", "diagnose", s(&toml), "--refit-top", "1"]);
    assert!(diag_text.contains(&words), "{diag_text}");
    // and no other percentage is called a noise level: every "noise level" followed by a
    // number gives this one
    for t in [&fit_text, &cmp_text, &diag_text] {
        for l in t.lines() {
            let Some(at) = l.find("noise level") else {
                continue;
            };
            let after = &l[at..];
            let number = after
                .find(|c: char| c.is_ascii_digit())
                .is_some_and(|d| after[d..].find('%').is_some_and(|p| p < 12));
            if number {
                assert!(after.contains(&words), "{l}");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

//! Model vs measurement comparison: residual statistics, systematic segments, the CLI's error
//! paths and the shipped hidden-effect data set.

use rheometer::data::input::load_experiments;
use rheometer::data::statistics::RunsTest;
use rheometer::data::NoiseSource;
use rheometer::diagnostics::{
    compare, compare_set, simulate_experiments, CompareOptions, Comparison, ModelSetup,
    SimulatedExperiment,
};
use rheometer::model::{ExperimentSet, TakeUp};
use rheometer::model::{Physics, SimulateOptions};
use std::path::Path;
use std::process::Command;
use std::sync::OnceLock;

/// True take-up diameters (m) of `data/pmma7n_synthetic/TRUTH.md` (also those of
/// `data/hidden_radiation`), in experiment order.
const TAKE_UP_M: [f64; 9] = [
    110e-6, 70e-6, 55e-6, 140e-6, 90e-6, 70e-6, 180e-6, 120e-6, 95e-6,
];
const TRUTH: [f64; 2] = [0.8, 11.71];

fn paper() -> Physics {
    Physics::paper()
}

/// A shipped data set with the true take-up diameters filled in.
fn with_true_take_up(dir: &str) -> ExperimentSet {
    let mut set = load_experiments(&Path::new(dir).join("experiments.toml")).unwrap();
    for (e, d) in set.experiments.iter_mut().zip(TAKE_UP_M) {
        e.take_up = Some(TakeUp::Diameter(d));
    }
    set
}

/// The paper model at the truth, simulated at the measurement positions of the shipped set
/// (tolerance 1e-8); the "measured" diameters are still the shipped noisy ones.
fn truth_runs() -> &'static Vec<SimulatedExperiment> {
    static RUNS: OnceLock<Vec<SimulatedExperiment>> = OnceLock::new();
    RUNS.get_or_init(|| {
        let set = with_true_take_up("data/pmma7n_synthetic");
        let physics = paper;
        let mut setup = ModelSetup::carreau(TRUTH, &physics);
        setup.simulate = SimulateOptions::with_tol(1e-8);
        setup.curve_points = 0;
        simulate_experiments(&set, &setup).unwrap()
    })
}

/// A small seeded normal generator (SplitMix64 + Box–Muller).
struct Normal(u64);
impl Normal {
    fn next(&mut self) -> f64 {
        let mut u = [0.0; 2];
        for v in &mut u {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            *v = ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
        }
        (-2.0 * u[0].ln()).sqrt() * (2.0 * std::f64::consts::PI * u[1]).cos()
    }
}

/// The truth runs with "measured" = model × (1 + noise) / (1 + bias(s)) so that the relative
/// residual is ≈ bias(s) − noise.
fn synthetic(bias: impl Fn(f64) -> f64, noise: f64, seed: u64) -> Vec<SimulatedExperiment> {
    let mut rng = Normal(seed);
    truth_runs()
        .iter()
        .map(|r| {
            let mut r = r.clone();
            r.measured = r
                .positions
                .iter()
                .zip(&r.at_measurements.diameter)
                .map(|(&s, &d)| d * (1.0 + noise * rng.next()) / (1.0 + bias(s)))
                .collect();
            r
        })
        .collect()
}

fn estimated() -> CompareOptions {
    CompareOptions::default()
}

#[test]
fn noise_free_simulated_data_give_zero_residuals_and_no_segment() {
    // measurements = the simulator itself at tolerance 1e-8; the model solved at 1e-6
    let mut set = with_true_take_up("data/pmma7n_synthetic");
    for (m, r) in set.measurements.iter_mut().zip(truth_runs()) {
        m.as_mut().unwrap().diameters = r.at_measurements.diameter.clone();
    }
    set.relative_uncertainty = Some(0.015);
    let physics = paper;
    let setup = ModelSetup::carreau(TRUTH, &physics);
    let cmp = compare_set(&set, &setup, &CompareOptions::default()).unwrap();
    let max = cmp
        .experiments
        .iter()
        .flat_map(|e| e.points.iter().map(|p| p.residual.abs()))
        .fold(0.0, f64::max);
    eprintln!(
        "noise-free: max |r| = {max:.2e}, chi2/dof = {:.2e}",
        cmp.chi2_per_dof
    );
    // data at tol 1e-8, model at 1e-6 (measured: max |r| 1.2e-8, chi2/dof 2e-14)
    assert!(max < 1e-6, "max |r| = {max}");
    assert_eq!(cmp.noise.source, NoiseSource::Declared);
    assert!(cmp.chi2_per_dof < 1e-8, "chi2/dof = {}", cmp.chi2_per_dof);
    assert!(cmp.segments.is_empty(), "{:?}", cmp.segments);
    assert!(cmp.experiments.iter().all(|e| e.segments.is_empty()));
    assert!(cmp.to_text().contains("no systematic segment"));
    assert_eq!(cmp.points, 9 * 26);
}

#[test]
fn white_noise_is_white_and_has_no_segment() {
    let mut worst_runs: f64 = 0.0;
    for seed in [1, 2, 3, 4, 5] {
        let cmp = compare(&synthetic(|_| 0.0, 0.015, seed), None, &estimated()).unwrap();
        eprintln!(
            "seed {seed}: sigma_est = {:.4}, chi2/dof = {:.3}, runs z = {:.2}, lag1 z = {:.2}, segments {}",
            cmp.noise.level, cmp.chi2_per_dof, cmp.runs.z, cmp.lag1_z, cmp.segments.len()
        );
        assert!(
            (cmp.noise.level / 0.015 - 1.0).abs() < 0.15,
            "estimated sigma {}",
            cmp.noise.level
        );
        assert!((cmp.chi2_per_dof - 1.0).abs() < 0.3, "{}", cmp.chi2_per_dof);
        assert!(cmp.segments.is_empty(), "seed {seed}: {:?}", cmp.segments);
        assert!(cmp.lag1_z.abs() < 3.0, "lag-1 z {}", cmp.lag1_z);
        worst_runs = worst_runs.max(cmp.runs.z.abs());
    }
    assert!(worst_runs < 3.0, "runs |z| up to {worst_runs}");
}

#[test]
fn runs_test_flags_a_smooth_residual() {
    let wave = |s: f64| 0.02 * (2.0 * std::f64::consts::PI * s / 0.5).sin();
    let cmp = compare(&synthetic(wave, 0.01, 7), None, &estimated()).unwrap();
    eprintln!(
        "smooth: runs z = {:.2}, lag1 = {:.2} (z {:.1}), sigma_est = {:.4}",
        cmp.runs.z, cmp.lag1, cmp.lag1_z, cmp.noise.level
    );
    assert!(cmp.runs.z < -4.0, "runs z = {}", cmp.runs.z);
    assert!(cmp.lag1_z > 4.0, "lag-1 z = {}", cmp.lag1_z);
    // the noise estimate is not inflated by the smooth part
    assert!(
        (cmp.noise.level / 0.01 - 1.0).abs() < 0.2,
        "sigma {}",
        cmp.noise.level
    );
    assert!(cmp.to_text().contains("NOT white"));
    // the basic statistic on a plain sequence
    let t = RunsTest::of(&[1.0, 1.0, 1.0, 1.0, 1.0, -1.0, -1.0, -1.0, -1.0, -1.0]);
    assert_eq!(t.runs, 2);
    assert!(t.z < -2.5, "{}", t.z);
}

#[test]
fn injected_bias_is_located_with_sign_and_size() {
    // model 4 % too thick on 0.10 ≤ s ≤ 0.20 m, 1.5 % noise
    let bias = |s: f64| {
        if (0.099..=0.201).contains(&s) {
            0.04
        } else {
            0.0
        }
    };
    let cmp = compare(&synthetic(bias, 0.015, 11), None, &estimated()).unwrap();
    println!("{}", cmp.to_text());
    assert_eq!(cmp.segments.len(), 1, "{:?}", cmp.segments);
    let seg = &cmp.segments[0];
    assert_eq!(seg.direction(), "thick");
    assert!((seg.start_m - 0.10).abs() < 0.021, "start {}", seg.start_m);
    assert!((seg.end_m - 0.20).abs() < 0.021, "end {}", seg.end_m);
    assert!((seg.mean - 0.04).abs() < 0.01, "mean {}", seg.mean);
    assert!(seg.same_sign >= 8, "same sign in {}", seg.same_sign);
    let text = cmp.to_text();
    assert!(text.contains("model too thick by"), "{text}");
    // the opposite sign: model too thin
    let cmp = compare(&synthetic(|s| -bias(s), 0.015, 12), None, &estimated()).unwrap();
    assert_eq!(cmp.segments.len(), 1, "{:?}", cmp.segments);
    assert_eq!(cmp.segments[0].direction(), "thin");
    assert!((cmp.segments[0].mean + 0.04).abs() < 0.01);
}

#[test]
fn given_uncertainty_is_used_and_chi2_scales() {
    let runs = synthetic(|_| 0.0, 0.015, 3);
    let cmp = compare(&runs, Some(0.03), &estimated()).unwrap();
    assert_eq!(cmp.noise.source, NoiseSource::Declared);
    assert_eq!(cmp.noise.level, 0.03);
    assert!(
        (cmp.chi2_per_dof - 0.25).abs() < 0.08,
        "{}",
        cmp.chi2_per_dof
    );
    let opts = CompareOptions {
        relative_uncertainty: Some(-1.0),
        ..Default::default()
    };
    assert!(compare(&runs, None, &opts).is_err());
    assert!(compare(&[], None, &estimated()).is_err());
}

fn summary(cmp: &Comparison) -> String {
    let segs: Vec<String> = cmp
        .segments
        .iter()
        .map(|s| {
            format!(
                "{:.2}-{:.2} m {:+.2}% z={:.1} ({} of 9)",
                s.start_m,
                s.end_m,
                100.0 * s.mean,
                s.z,
                s.same_sign
            )
        })
        .collect();
    format!(
        "chi2/dof = {:.2}, sigma = {:.4}, runs z = {:.1}, lag1 z = {:.1}, segments: [{}]",
        cmp.chi2_per_dof,
        cmp.noise.level,
        cmp.runs.z,
        cmp.lag1_z,
        segs.join("; ")
    )
}

#[test]
fn shipped_pmma7n_at_truth_is_consistent_with_noise() {
    // control: the model that made the data, at its truth, with the true take-up diameters
    let set = with_true_take_up("data/pmma7n_synthetic");
    let physics = paper;
    let cmp = compare_set(&set, &ModelSetup::carreau(TRUTH, &physics), &estimated()).unwrap();
    eprintln!("pmma7n at truth: {}", summary(&cmp));
    assert!(cmp.segments.is_empty(), "{}", summary(&cmp));
    assert!(cmp.runs.z > -3.0, "{}", summary(&cmp));
}

#[test]
fn hidden_radiation_at_truth_shows_systematic_misfit() {
    let set = with_true_take_up("data/hidden_radiation");
    let physics = paper;
    let cmp = compare_set(&set, &ModelSetup::carreau(TRUTH, &physics), &estimated()).unwrap();
    println!("{}", cmp.to_text());
    eprintln!("hidden radiation at truth: {}", summary(&cmp));
    assert!(!cmp.segments.is_empty(), "{}", summary(&cmp));
    assert!(cmp.chi2_per_dof > 2.0, "{}", summary(&cmp));
    assert!(cmp.runs.z < -3.0, "{}", summary(&cmp));
}

fn rheometer(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_rheometer"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn cli_errors_are_clear() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("diffbvp-compare-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let toml = "data/pmma7n_synthetic/experiments.toml";
    let out = dir.join("out");
    let out = out.to_str().unwrap();
    let missing = dir.join("missing.json");
    let (ok, err) = rheometer(&[
        "compare",
        toml,
        "--fit",
        missing.to_str().unwrap(),
        "--out",
        out,
    ]);
    assert!(!ok);
    assert!(
        err.contains("--fit") && err.contains("cannot read file") && err.contains("missing.json"),
        "{err}"
    );

    let bad = dir.join("bad.json");
    std::fs::write(&bad, "{ \"n\": 0.8, \"kappa\": ").unwrap();
    let (ok, err) = rheometer(&[
        "compare",
        toml,
        "--fit",
        bad.to_str().unwrap(),
        "--out",
        out,
    ]);
    assert!(!ok);
    assert!(
        err.contains("bad.json") && err.contains("the file ends early (truncated?)"),
        "{err}"
    );

    let short = dir.join("short.json");
    std::fs::write(
        &short,
        r#"{"schema_version": 1, "report": "fit", "written_by": "rheometer",
            "estimator": "Principled", "n": 0.8, "kappa": 11.7, "experiments": [],
            "take_up_factors": [1.0, 1.0]}"#,
    )
    .unwrap();
    let (ok, err) = rheometer(&[
        "compare",
        toml,
        "--fit",
        short.to_str().unwrap(),
        "--out",
        out,
    ]);
    assert!(!ok);
    assert!(err.contains("2 take-up factors for 9 experiments"), "{err}");

    let (ok, err) = rheometer(&["compare", toml, "--out", out]);
    assert!(!ok);
    assert!(err.contains("--fit FIT.json"), "{err}");

    // no take-up condition in the TOML and none from the data
    let (ok, err) = rheometer(&[
        "compare", toml, "--n", "0.8", "--kappa", "11.71", "--out", out,
    ]);
    assert!(!ok);
    assert!(
        err.contains("no take-up condition") && err.contains("v0p27_p1"),
        "{err}"
    );
    assert!(!Path::new(out).exists());
}

#[test]
fn cli_writes_summary_json_and_figures() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("diffbvp-compare-run-{}", std::process::id()));
    let fit = dir.join("fit.json");
    std::fs::create_dir_all(&dir).unwrap();
    // a fit report as this version writes it (the paper's estimator: n and kappa fitted)
    let (ok, err) = rheometer(&[
        "fit",
        "data/hidden_radiation/experiments.toml",
        "--estimator",
        "paper",
        "--json",
        fit.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let out = dir.join("cmp");
    let (ok, err) = rheometer(&[
        "compare",
        "data/hidden_radiation/experiments.toml",
        "--fit",
        fit.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--format",
        "svg",
    ]);
    assert!(ok, "{err}");
    for f in [
        "compare_summary.txt",
        "compare.json",
        "compare_points.csv",
        "compare_diameters.svg",
        "compare_inverse_d2.svg",
        "compare_residuals.svg",
        "compare_residual_trends.svg",
    ] {
        assert!(out.join(f).is_file(), "missing {f}");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("compare.json")).unwrap()).unwrap();
    assert_eq!(json["experiments"].as_array().unwrap().len(), 9);
    assert_eq!(json["fitted_parameters"], 2);
    let csv = std::fs::read_to_string(out.join("compare_points.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 9 * 26);
}

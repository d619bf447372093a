//! The missing-physics story on the shipped data set `data/hidden_radiation/` (9 PMMA-like
//! experiments made by the simulator with grey-body radiation ε = 0.9 switched on, 1.5%
//! multiplicative noise and a larger disturbance near the take-up; see its TRUTH.md):
//!
//! 1. fit the paper's model (no radiation) with the principled estimator;
//! 2. compare it with the measurements: where does it miss, by how much, above the noise?
//! 3. diagnose: which candidate effect explains the misfit?
//! 4. add the winner, refit, compare again, and watch the error fall.
//!
//! Figures and reports go to `target/missing_physics/` (or the directory given as argument).
//!
//! `cargo run --release --example missing_physics [-- OUT_DIR]`

use diffbvp::fiber::diagnostics::compare::{
    compare_set, CompareOptions, FigureFormat, FitParameters, ModelSetup,
};
use diffbvp::fiber::diagnostics::diagnose::{diagnose, DiagnoseOptions};
use diffbvp::fiber::effects::{physics_with, Effect, EffectSetting, ModelSpec};
use diffbvp::fiber::input::load_experiments;
use diffbvp::fiber::rheometer::{FitReport, Identification, IdentifyOptions, Rheometer};
use diffbvp::fiber::setup::ExperimentSet;
use diffbvp::fiber::Physics;
use std::error::Error;
use std::path::{Path, PathBuf};

/// Compares the model of a fit with the measurements and writes the summary and figures into
/// `dir`; returns the comparison's text summary.
fn compare_fit(
    set: &ExperimentSet,
    id: &Identification,
    physics: &(dyn Fn() -> Physics + Sync),
    dir: &Path,
    inputs: &[PathBuf],
) -> Result<String, Box<dyn Error>> {
    let report = FitReport::new(id);
    let params = FitParameters::from_json(&serde_json::to_string(&report)?, "the fit")?;
    let mut setup = ModelSetup::carreau([id.n, id.kappa], physics);
    params.apply(&mut setup, set.experiments.len(), "the fit")?;
    let options = CompareOptions {
        fitted_parameters: params.fitted_parameters(),
        ..Default::default()
    };
    let cmp = compare_set(set, &setup, &options)?;
    cmp.write(dir, FigureFormat::Png, inputs)?;
    Ok(cmp.to_text())
}

fn main() -> Result<(), Box<dyn Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let data = root.join("data/hidden_radiation/experiments.toml");
    let out: PathBuf = match std::env::args_os().nth(1) {
        Some(dir) => dir.into(),
        None => root.join("target/missing_physics"),
    };
    std::fs::create_dir_all(&out)?;
    let inputs: Vec<PathBuf> = std::fs::read_dir(data.parent().unwrap_or(root))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    // ANCHOR: story
    let set = load_experiments(&data)?;
    let opts = IdentifyOptions::default(); // principled estimator

    // 1. the paper's model, fitted
    let rh = Rheometer::new(&set)?;
    let start = rh.start_heuristic(&opts)?.start;
    let id0 = rh.identify(start, &opts)?;
    println!("{}", FitReport::new(&id0).to_text());

    // 2. where does it miss?
    let paper = || Physics::paper();
    let before = compare_fit(&set, &id0, &paper, &out.join("compare_before"), &inputs)?;
    println!("{before}");

    // 3. which effect is missing?
    let run = diagnose(&set, &ModelSpec::default(), &DiagnoseOptions::default())?;
    println!("{}", run.diagnosis.to_text());
    run.save_figure(&out.join("residuals_before_after.png"))?;

    // 4. add it, refit, compare again
    let Some(best) = run.diagnosis.most_likely_missing.clone() else {
        println!("no candidate earns its place; nothing to add");
        return Ok(());
    };
    let setting: EffectSetting = best.parse()?;
    let spec = ModelSpec::default().with(setting);
    let rh1 = Rheometer::with_spec(&set, spec.clone())?;
    let id1 = rh1.identify([id0.n, id0.kappa], &opts)?;
    println!("{}", FitReport::new(&id1).to_text());
    let report1 = FitReport::new(&id1);
    let effects = report1
        .effects
        .iter()
        .map(|e| Ok((e.effect.parse::<Effect>()?, e.strength)))
        .collect::<Result<Vec<_>, String>>()?;
    physics_with(&effects)?; // validated once; the closure rebuilds it per experiment
    let with_effect = || physics_with(&effects).unwrap_or_else(|_| Physics::paper());
    let after = compare_fit(
        &set,
        &id1,
        &with_effect,
        &out.join("compare_after"),
        &inputs,
    )?;
    println!("{after}");
    println!(
        "RMS relative residual: {:.3} % (paper model) -> {:.3} % (with {best}); noise level {:.3} % ({})",
        100.0 * id0.rms_relative_residual,
        100.0 * id1.rms_relative_residual,
        100.0 * run.diagnosis.noise_level,
        run.diagnosis.noise_source
    );
    // ANCHOR_END: story
    println!("figures in {}", out.display());
    Ok(())
}

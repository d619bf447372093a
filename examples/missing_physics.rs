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

use rheometer::data::input::{load_experiments_with, LoadOptions};
use rheometer::diagnostics::DiagnoseOptions;
use rheometer::fit::IdentifyOptions;
use rheometer::model::{EffectSetting, ModelSpec};
use rheometer::report::output_files::{OutputFile, OutputPlan};
use rheometer::report::plot::FigureFormat;
use rheometer::workflow::{self, CompareRequest, FitRequest};
use std::error::Error;
use std::path::{Path, PathBuf};

fn main() -> Result<(), Box<dyn Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let toml = root.join("data/hidden_radiation/experiments.toml");
    let out: PathBuf = match std::env::args_os().nth(1) {
        Some(dir) => dir.into(),
        None => root.join("target/missing_physics"),
    };
    std::fs::create_dir_all(&out)?;
    let inputs: Vec<PathBuf> = std::fs::read_dir(toml.parent().unwrap_or(root))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    // ANCHOR: story
    let data = load_experiments_with(&toml, &LoadOptions::default())?;
    // principled estimator
    let request = FitRequest::new(IdentifyOptions::default());

    // 1. the paper's model, fitted
    let fit0 = workflow::fit(&data, &request)?;
    println!("{}", fit0.summary().to_text());

    // 2. where does it miss?
    let before = CompareRequest::of_fit(fit0.summary().clone(), "the paper's fit");
    let cmp0 = workflow::compare(&data, &before)?;
    let dir = out.join("compare_before");
    write_checked(&dir, &cmp0.files(&dir, FigureFormat::Png)?, &inputs)?;
    println!("{}", cmp0.to_text());

    // 3. which effect is missing?
    let run = workflow::diagnose(&data, &ModelSpec::default(), &DiagnoseOptions::default())?;
    println!("{}", run.diagnosis.to_text());
    let figure = run.residual_figure(&out.join("residuals_before_after.png"))?;
    write_checked(&out, std::slice::from_ref(&figure), &inputs)?;

    // 4. add it, refit from the paper's fit, compare again
    let Some(best) = run.diagnosis.most_likely_missing.clone() else {
        println!("no candidate earns its place; nothing to add");
        return Ok(());
    };
    let setting: EffectSetting = best.parse()?;
    let with_effect = FitRequest {
        model: ModelSpec::default().with(setting),
        start: Some(fit0.summary().law_params()),
        ..request
    };
    let fit1 = workflow::fit(&data, &with_effect)?;
    println!("{}", fit1.summary().to_text());
    let after = CompareRequest::of_fit(fit1.summary().clone(), "the fit with the effect");
    let cmp1 = workflow::compare(&data, &after)?;
    let dir = out.join("compare_after");
    write_checked(&dir, &cmp1.files(&dir, FigureFormat::Png)?, &inputs)?;
    println!("{}", cmp1.to_text());
    println!(
        "RMS relative residual: {:.3} % (paper model) -> {:.3} % (with {best}); noise level {}",
        100.0 * fit0.summary().rms_relative_residual,
        100.0 * fit1.summary().rms_relative_residual,
        run.diagnosis.base_fit.noise.describe()
    );
    // ANCHOR_END: story
    println!("figures in {}", out.display());
    Ok(())
}

/// Writes `files` (all in `dir`) after checking, before any is written, that none replaces one
/// of the `inputs`.
fn write_checked(
    dir: &Path,
    files: &[OutputFile],
    inputs: &[PathBuf],
) -> Result<(), Box<dyn std::error::Error>> {
    let names: Vec<String> = files
        .iter()
        .filter_map(|f| f.path.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .collect();
    let mut plan = OutputPlan::new();
    plan.inputs(inputs).dir(dir, "OUT_DIR", &names);
    let outputs = plan.check()?;
    outputs.create_dirs()?;
    for f in files {
        outputs.write_output(f)?;
    }
    Ok(())
}

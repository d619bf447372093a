//! The fit that `diffbvp.fit(dataset)` runs, called from Rust, timed in-process: the reference
//! of the Python-vs-Rust benchmark (`python/benchmarks/fit_overhead.py`).
//!
//! `cargo run --release -p diffbvp-python --example fit_timing -- [RUNS] [EXPERIMENTS.toml]`
//! prints one wall time per run (s) and the median, then `n kappa` of the last fit.

use rheometer::data::input::{load_experiments_with, LoadOptions};
use rheometer::fit::IdentifyOptions;
use rheometer::model::FiberSolution;
use rheometer::workflow::{fit, FitRequest};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let runs: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(20);
    let path = args
        .next()
        .unwrap_or_else(|| "data/pmma7n_synthetic/experiments.toml".into());
    let loaded = load_experiments_with(std::path::Path::new(&path), &LoadOptions::default())?;
    let mut times = Vec::with_capacity(runs);
    let mut last = None;
    for _ in 0..runs {
        let t0 = Instant::now();
        // what `diffbvp.fit(dataset)` runs: the fit workflow, the fitted profiles on 101
        // positions, the summary as JSON
        let run = fit(&loaded, &FitRequest::new(IdentifyOptions::default()))?;
        let profiles: Vec<_> = run
            .identification
            .solutions
            .iter()
            .zip(&run.rheometer.models)
            .map(|(s, m)| {
                FiberSolution {
                    solution: s.clone(),
                }
                .uniform_profiles(m, 101)
            })
            .collect();
        let json = serde_json::to_value(run.summary())?;
        times.push(t0.elapsed().as_secs_f64());
        println!("run {:>3}: {:.4} s", times.len(), times[times.len() - 1]);
        last = Some((json, profiles.len()));
    }
    times.sort_by(f64::total_cmp);
    let median = if runs % 2 == 1 {
        times[runs / 2]
    } else {
        0.5 * (times[runs / 2 - 1] + times[runs / 2])
    };
    println!("median {median:.4} s over {runs} runs");
    if let Some((json, _)) = last {
        println!(
            "n = {}, kappa = {}",
            json["n"]["value"], json["kappa"]["value"]
        );
    }
    Ok(())
}

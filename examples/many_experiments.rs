//! Joint fits of many experiments: the shipped experiments of `data/pmma7n_synthetic`
//! replicated with fresh measurement noise, fitted with the principled estimator (one take-up
//! factor per experiment, eliminated through the Schur complement).
//!
//! ```text
//! cargo run --release --example many_experiments -- M [seed]
//! /usr/bin/time -f '%e s %M kB' target/release/examples/many_experiments 1000
//! ```
//!
//! Experiment `k` repeats the conditions of shipped experiment `k mod 9`; its diameters are the
//! noise-free diameters of `data/pmma7n_synthetic/truth` (an independent scipy model) times
//! `1 + noise` with the shipped noise model (1.5 % plus the aspirator disturbance beyond 0.35 m)
//! from a SplitMix64 stream seeded with `seed` (default 1). Prints the planned cost, the
//! progress on stderr, then the estimate with its standard errors and the time of each phase.

use rheometer::data::input::load_experiments;
use rheometer::data::synthetic::{SplitMix64, SyntheticNoise};
use rheometer::fit::{FitProgress, IdentifyOptions, ProgressHook, Rheometer};
use rheometer::model::{ExperimentSet, Measurements};
use std::error::Error;
use std::path::Path;
use std::time::Instant;

/// The shipped set with `m` experiments: replicated conditions, fresh noise.
fn replicated(m: usize, seed: u64) -> Result<ExperimentSet, Box<dyn Error>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/pmma7n_synthetic");
    let shipped = load_experiments(&dir.join("experiments.toml"))?;
    let text = std::fs::read_to_string(dir.join("truth/noise_free_diameters_m.csv"))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().ok_or("empty truth file")?.split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split(',').map(str::parse).collect::<Result<_, _>>())
        .collect::<Result<_, _>>()?;
    let positions: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let clean: Vec<Vec<f64>> = shipped
        .experiments
        .iter()
        .map(|e| {
            let c = header
                .iter()
                .position(|h| *h == e.name)
                .ok_or_else(|| format!("no truth column for {}", e.name))?;
            Ok(rows.iter().map(|r| r[c]).collect())
        })
        .collect::<Result<_, Box<dyn Error>>>()?;
    let noise = SyntheticNoise::pmma7n_synthetic();
    let mut rng = SplitMix64::new(seed);
    let mut set = ExperimentSet {
        experiments: Vec::with_capacity(m),
        measurements: Vec::with_capacity(m),
        ..shipped.clone()
    };
    for k in 0..m {
        let base = k % shipped.experiments.len();
        let mut e = shipped.experiments[base].clone();
        e.name = format!("{}_r{}", e.name, k / shipped.experiments.len());
        // the take-up condition comes from each replicate's own data
        e.take_up = None;
        let diameters = noise.apply(&positions, &clean[base], &mut rng)?;
        set.experiments.push(e);
        set.measurements.push(Some(Measurements {
            positions: positions.clone(),
            diameters,
        }));
    }
    Ok(set)
}

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().collect();
    let m: usize = args.get(1).map_or(Ok(100), |s| s.parse())?;
    let seed: u64 = args.get(2).map_or(Ok(1), |s| s.parse())?;
    let t0 = Instant::now();
    let set = replicated(m, seed)?;
    let rh = Rheometer::new(&set)?;
    let t_data = t0.elapsed().as_secs_f64();
    let start = [0.5, 11.51];
    let mut opts = IdentifyOptions::default();
    let plan = rh.plan(start, &opts)?;
    println!(
        "plan: {} experiments, {} residuals, {} parameters ({} shared), {} threads: \
         about {:.1} s and {:.0} MB (probe: {} nodes, cold start {:.1} ms, evaluation {:.1} ms)",
        plan.experiments,
        plan.residuals,
        plan.parameters,
        plan.shared_parameters,
        plan.threads,
        plan.seconds,
        plan.bytes as f64 / 1e6,
        plan.nodes,
        1e3 * plan.cold_start_s,
        1e3 * plan.evaluation_s
    );
    // progress on stderr for a fit of more than a few seconds (as a program would draw a bar)
    let t1 = Instant::now();
    if plan.seconds > 3.0 {
        let every = (m / 10).max(1);
        opts.progress = Some(ProgressHook::new(move |event| match event {
            FitProgress::Simulated { done, total } if done % every == 0 || done == total => {
                eprintln!(
                    "[{:6.1} s] simulated {done}/{total}",
                    t1.elapsed().as_secs_f64()
                )
            }
            FitProgress::Iteration(it) => eprintln!(
                "[{:6.1} s] step {}: cost {:.6e} {}",
                t1.elapsed().as_secs_f64(),
                it.iteration,
                it.cost.unwrap_or(f64::NAN),
                if it.accepted { "accepted" } else { "rejected" }
            ),
            _ => {}
        }));
    }
    let id = rh.identify(start, &opts)?;
    let t_fit = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let se = id.fit.standard_errors().ok_or("singular covariance")?;
    let t_se = t2.elapsed().as_secs_f64();
    let ns = id.names.len();
    println!(
        "experiments {m}: residuals {}, parameters {} ({ns} shared), {} iterations ({} loose), {}",
        id.fit.num_residuals(),
        id.fit.p.len(),
        id.fit.iterations,
        id.fit.loose_iterations,
        id.fit.termination
    );
    println!(
        "n = {:.6} +/- {:.6}, kappa = {:.5} +/- {:.5}, RMS {:.4} %",
        id.summary.n.value,
        se[0],
        id.summary.kappa.value,
        se[1],
        100.0 * id.summary.rms_relative_residual
    );
    let solver = &id.summary.solver;
    println!(
        "accuracy: BVP tolerance {:.0e}, discretisation shift {:.4} standard errors (checked on \
         the halved meshes), nodes per experiment {}–{}",
        solver.bvp_tolerance,
        solver.discretisation_shift_se,
        solver.nodes.iter().min().unwrap_or(&0),
        solver.nodes.iter().max().unwrap_or(&0)
    );
    println!("time: data {t_data:.2} s, fit {t_fit:.2} s, standard errors {t_se:.3} s");
    Ok(())
}

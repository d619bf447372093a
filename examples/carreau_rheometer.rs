//! The rheometer end to end on the shipped synthetic PMMA7N-like data set (truth
//! (n, κ) = (0.8, 11.71)): smoothing, start heuristic, identification with the principled and
//! the paper's estimator, uncertainty report, and the paper's Table 3 sweep.
//!
//! Figures like the paper's Fig. 2, 3, 4 and 5 are written into `OUT_DIR` (default
//! `target/carreau_rheometer/`).
//!
//! Run with `cargo run --release --example carreau_rheometer [-- OUT_DIR]`.

use diffbvp::mesh::linspace;
use indicatif::{ProgressBar, ProgressStyle};
use rheometer::data::input::load_experiments;
use rheometer::fit::{Estimator, IdentifyOptions, Rheometer, PAPER_TABLE3_STARTS};
use rheometer::report::figures::{
    identification_figure_names, identification_figures, landscape_map,
};
use rheometer::report::output_files::OutputPlan;
use std::path::{Path, PathBuf};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let data = root.join("data/pmma7n_synthetic/experiments.toml");
    let out: PathBuf = match std::env::args_os().nth(1) {
        Some(dir) => dir.into(),
        None => root.join("target/carreau_rheometer"),
    };
    let inputs: Vec<PathBuf> = std::fs::read_dir(data.parent().unwrap_or(root))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    // ANCHOR: identify
    let set = load_experiments(&data)?;
    let rheometer = Rheometer::new(&set)?;
    println!("Smoothing (paper eq. 5), u0 = d_meas(0)^-2:");
    for (e, f) in rheometer.experiments.iter().zip(&rheometer.smoothing) {
        println!(
            "  {:<9} b = {:.4}, c = {:.5} m, v = {:.4e} 1/m², RMS {:.2}%, d_fit(L) = {:.2} µm",
            e.name,
            f.b,
            f.c,
            f.v,
            100.0 * f.rms,
            1e6 * f.diameter(e.spinline_length)
        );
    }
    let principled = IdentifyOptions::with_estimator(Estimator::Principled);
    let heuristic = rheometer.start_heuristic(&principled)?;
    let start = heuristic.start;
    println!(
        "\nStart heuristic (paper Algorithm 2): (n, κ) = ({}, {}) after {} cost evaluations",
        start[0],
        start[1],
        heuristic.trace.len() + 1
    );
    let id = rheometer.identify(start, &principled)?;
    let report = id.summary.clone();
    println!("\n{}", report.to_text());
    // ANCHOR_END: identify
    // every figure is checked before the rest of the run: none may replace a data file
    let mut names = identification_figure_names("png", set.experiments.len());
    names.push("fig4_landscape.png".into());
    let mut plan = OutputPlan::new();
    plan.inputs(&inputs).dir(&out, "OUT_DIR", &names);
    let outputs = plan.check()?;
    let paper = IdentifyOptions::with_estimator(Estimator::Paper);
    let id_paper = rheometer.identify(start, &paper)?;
    println!("{}", id_paper.summary.clone().to_text());
    println!(
        "truth (0.8, 11.71): principled estimator lands at ({:.4}, {:.4}), paper's at ({:.4}, {:.4}) (bias of the smoothing step)",
        id.law()[0], id.law()[1], id_paper.law()[0], id_paper.law()[1]
    );

    println!("\nPaper Table 3: identification from 11 starting points");
    println!(
        "{:>5} {:>6} | {:>8} {:>8} {:>5} {:>8} | {:>8} {:>8} {:>5} {:>8}",
        "n0", "κ0", "n", "κ", "it", "time[s]", "n", "κ", "it", "time[s]"
    );
    println!("{:>13} | {:^32} | {:^32}", "", "principled", "paper");
    let starts = PAPER_TABLE3_STARTS;
    // progress on stderr (nothing is drawn when stderr is not a terminal)
    let sweep = ProgressBar::new(starts.len() as u64);
    sweep.set_style(
        ProgressStyle::with_template("Table 3 [{bar:40}] {pos}/{len}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    for [n0, k0] in starts {
        sweep.inc(1);
        let a = rheometer.identify([n0, k0], &principled);
        let b = rheometer.identify([n0, k0], &paper);
        let cell = |r: &Result<rheometer::fit::Identification, _>| match r {
            Ok(i) => format!(
                "{:>8.4} {:>8.4} {:>5} {:>8.3}",
                i.law()[0],
                i.law()[1],
                i.fit.iterations,
                i.summary.solver.wall_time_s
            ),
            Err(e) => format!("failed: {e}"),
        };
        sweep.suspend(|| println!("{:>5} {:>6} | {} | {}", n0, k0, cell(&a), cell(&b)));
    }
    sweep.finish_and_clear();

    // Figures: paper Fig. 2, 3, 5 for the principled fit, and Fig. 4, the cost landscape.
    outputs.create_dirs()?;
    let newtonian = rheometer.newtonian_solutions(id.law()[1], &principled)?;
    for figure in identification_figures(&rheometer, &id, &newtonian, &out, "png")? {
        outputs.write_output(&figure)?;
        println!("wrote {}", figure.path.display());
    }
    let (ns, kappas) = (linspace(0.0, 1.0, 41), linspace(9.0, 16.0, 41));
    let mut landscape_opts = paper.clone();
    landscape_opts.simulate.tol = 1e-4; // a picture, not a fit
    let bar = ProgressBar::new((ns.len() * kappas.len()) as u64);
    bar.set_style(
        ProgressStyle::with_template("landscape [{bar:40}] {pos}/{len} ({eta} left)")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let t0 = std::time::Instant::now();
    let landscape = rheometer.landscape(&ns, &kappas, &landscape_opts, |done| {
        bar.set_position(done as u64)
    })?;
    bar.finish_and_clear();
    let mut markers: Vec<(f64, f64, String)> = starts
        .iter()
        .map(|&[n, k]| (n, k, "Table 3 start".to_string()))
        .collect();
    markers.push((
        id_paper.law()[0],
        id_paper.law()[1],
        "identified (paper J)".to_string(),
    ));
    let path = out.join("fig4_landscape.png");
    let figure = landscape_map(&path, &landscape, "J(n, κ), paper's cost", &markers)?;
    outputs.write_output(&figure)?;
    println!(
        "wrote {} ({}×{} grid in {:.1} s)",
        path.display(),
        ns.len(),
        kappas.len(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}

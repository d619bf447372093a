//! The rheometer end to end on the shipped synthetic PMMA7N-like data set (truth
//! (n, κ) = (0.8, 11.71)): smoothing, start heuristic, identification with the principled and
//! the paper's estimator, uncertainty report, and the paper's Table 3 sweep.
//!
//! Run with `cargo run --release --example carreau_rheometer [-- OUT_DIR]`.

use diffbvp::fiber::input::load_experiments;
use diffbvp::fiber::rheometer::{Estimator, FitReport, IdentifyOptions, Rheometer};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/pmma7n_synthetic/experiments.toml");
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
    let report = FitReport::new(&id);
    println!("\n{}", report.to_text());
    // ANCHOR_END: identify
    let paper = IdentifyOptions::with_estimator(Estimator::Paper);
    let id_paper = rheometer.identify(start, &paper)?;
    println!("{}", FitReport::new(&id_paper).to_text());
    println!(
        "truth (0.8, 11.71): principled estimator lands at ({:.4}, {:.4}), paper's at ({:.4}, {:.4}) (bias of the smoothing step)",
        id.n, id.kappa, id_paper.n, id_paper.kappa
    );

    println!("\nPaper Table 3: identification from 11 starting points");
    println!(
        "{:>5} {:>6} | {:>8} {:>8} {:>5} {:>8} | {:>8} {:>8} {:>5} {:>8}",
        "n0", "κ0", "n", "κ", "it", "time[s]", "n", "κ", "it", "time[s]"
    );
    println!("{:>13} | {:^32} | {:^32}", "", "principled", "paper");
    let starts = [
        (0.5, 9.21),
        (0.7, 9.21),
        (0.9, 9.21),
        (0.3, 11.51),
        (0.5, 11.51),
        (0.7, 11.51),
        (0.9, 11.51),
        (0.3, 13.82),
        (0.5, 13.82),
        (0.7, 13.82),
        (0.9, 13.82),
    ];
    for (n0, k0) in starts {
        let a = rheometer.identify([n0, k0], &principled);
        let b = rheometer.identify([n0, k0], &paper);
        let cell = |r: &Result<diffbvp::fiber::rheometer::Identification, _>| match r {
            Ok(i) => format!(
                "{:>8.4} {:>8.4} {:>5} {:>8.3}",
                i.n, i.kappa, i.fit.iterations, i.wall_time_s
            ),
            Err(e) => format!("failed: {e}"),
        };
        println!("{:>5} {:>6} | {} | {}", n0, k0, cell(&a), cell(&b));
    }
    Ok(())
}

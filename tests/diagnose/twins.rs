//! Issue 65 item 1: a near-twin inside a pair. A die colder than declared with an aspirator
//! co-flow: the die offset's near-twin, the Nusselt factor, can be named beside the co-flow,
//! and the result with the twin swapped must be tried before its law is printed as a result.
//! Data by the independent simulator of `tests/independent/`, fresh noise per replicate.
//!
//! Slow and ignored; run with
//! `cargo test --release --test diagnose twins -- --ignored --nocapture`. `TWIN_SETS`
//! replicates (default 20).

use crate::few_runs::law_outcome;
use crate::independent;
use crate::shared;

use independent::rng::Rng;
use independent::scenarios;
use rheometer::diagnostics::diagnose::DiagnoseOptions;

/// A die 10–20 K colder than declared with an aspirator of 40–100 m/s and decay length
/// 0.05–0.15 m (drawn per replicate), nine runs: how the reported law stands and what is named.
#[test]
#[ignore = "a study: one diagnosis per replicate (about two minutes for 20 sets)"]
fn cold_die_with_a_coflow_study() {
    let sets: u64 = std::env::var("TWIN_SETS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let (mut holds, mut flagged, mut wrong, mut both) = (0, 0, 0, 0);
    let mut seconds = Vec::new();
    for k in 0..sets {
        let mut rng = Rng::new(9900 + k);
        let die = -10.0 - 10.0 * rng.uniform();
        let speed = 40.0 + 60.0 * rng.uniform();
        let length = 0.05 + 0.1 * rng.uniform();
        let sc = scenarios::die_offset_and_coflow(die, speed, length, 9950 + k);
        let d = shared::diagnose_with(&sc, &DiagnoseOptions::default());
        let g = &d.run.diagnosis;
        let outcome = law_outcome(&d.run, &sc);
        match outcome {
            "holds" => holds += 1,
            "WRONG" => wrong += 1,
            _ => flagged += 1,
        }
        let has = |e: &str| g.found.iter().any(|f| f == e);
        both += usize::from(has("air_coflow") && has("die_temperature_offset"));
        seconds.push(d.seconds);
        let f = g.law_fit();
        println!(
            "TWIN | {k:2} | die {die:5.1} K, V {speed:5.1} m/s, l {length:.3} m | found {:?} | \
             pair {:?} | {} | n {:.3} [{:.3}, {:.3}] kappa {:.2} [{:.2}, {:.2}] | {} | {:.1} s",
            g.found,
            g.pair.as_ref().map(|p| (&p.effects, p.replaces)),
            g.verdict.kind(),
            f.n.value,
            f.n.ci95[0],
            f.n.ci95[1],
            f.kappa.value,
            f.kappa.ci95[0],
            f.kappa.ci95[1],
            outcome,
            d.seconds
        );
    }
    seconds.sort_by(f64::total_cmp);
    println!(
        "TWIN SUMMARY | {sets} sets | both named {both} | law holds {holds}, not a result \
         {flagged}, WRONG {wrong} | median {:.1} s, max {:.1} s",
        seconds[seconds.len() / 2],
        seconds[seconds.len() - 1]
    );
}

//! Issue 65's "no confident wrong law" over further scenario classes: strong strain thinning
//! (`n` = 0.45) with a process or instrument fault, and two physics effects at once. Data by
//! the independent simulator of `tests/independent/`, strengths drawn per replicate, fresh
//! noise each; each set's reported law is classed as in `few_runs::law_outcome`.
//!
//! Slow and ignored; run with
//! `cargo test --release --test diagnose classes -- --ignored --nocapture`. `CLASS_SETS`
//! replicates per class (default 20).

use crate::few_runs::law_outcome;
use crate::independent;
use crate::shared;

use independent::dataset::{Faults, Scenario};
use independent::rng::Rng;
use independent::scenarios;
use rheometer::diagnostics::diagnose::DiagnoseOptions;

/// Diagnoses `sets` scenarios of `make(replicate, rng)` and prints one row per set and a
/// summary under `label`.
fn study(label: &str, make: impl Fn(u64, &mut Rng) -> (Scenario, String)) {
    let sets: u64 = std::env::var("CLASS_SETS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let (mut holds, mut flagged, mut wrong, mut failed) = (0, 0, 0, 0);
    let mut seconds = Vec::new();
    for k in 0..sets {
        let mut rng = Rng::new(0xC1A5 + 97 * k);
        let (sc, what) = make(k, &mut rng);
        let generated = match sc.generate() {
            Ok(g) => g,
            Err(e) => {
                // the independent simulator has no solution at these conditions: no data set
                println!("{label} | {k:2} | {what} | not generated: {e}");
                failed += 1;
                continue;
            }
        };
        let d = shared::diagnose_generated(&generated, &DiagnoseOptions::default());
        let g = &d.run.diagnosis;
        let outcome = law_outcome(&d.run, &sc);
        match outcome {
            "holds" => holds += 1,
            "WRONG" => wrong += 1,
            _ => flagged += 1,
        }
        seconds.push(d.seconds);
        let f = g.law_fit();
        println!(
            "{label} | {k:2} | {what} | found {:?} | {} | n {:.3} [{:.3}, {:.3}] kappa {:.2} \
             [{:.2}, {:.2}] | {} | {:.1} s",
            g.found,
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
    let at = |q: f64| {
        seconds
            .get(((seconds.len() as f64 - 1.0) * q) as usize)
            .copied()
    };
    println!(
        "{label} SUMMARY | {sets} sets ({failed} not generated) | law holds {holds}, not a \
         result {flagged}, WRONG {wrong} | median {:.1} s, max {:.1} s",
        at(0.5).unwrap_or(f64::NAN),
        at(1.0).unwrap_or(f64::NAN)
    );
}

/// `n` = 0.45 with one fault drawn per replicate: a die 10–20 K off, a mass flow 5–15 % off,
/// or a gauge reading 2–6 % high (in turn).
#[test]
#[ignore = "a study: one diagnosis per replicate (minutes for 20 sets)"]
fn strong_thinning_with_a_fault_study() {
    study("STRONG THINNING", |k, rng| {
        let size = rng.uniform();
        let (faults, what) = match k % 3 {
            0 => {
                let dk = -(10.0 + 10.0 * size);
                (
                    Faults {
                        die_offset_k: dk,
                        ..Faults::none()
                    },
                    format!("die {dk:+.1} K"),
                )
            }
            1 => {
                let f = 1.0 - (0.05 + 0.1 * size);
                (
                    Faults {
                        mass_flow_factor: f,
                        ..Faults::none()
                    },
                    format!("mass flow x{f:.3}"),
                )
            }
            _ => {
                let f = 1.0 + (0.02 + 0.04 * size);
                (
                    Faults {
                        gauge_factor: f,
                        ..Faults::none()
                    },
                    format!("gauge x{f:.3}"),
                )
            }
        };
        (scenarios::strongly_thinning_with(faults, 0x5100 + k), what)
    });
}

/// Radiation (emissivity 0.3–0.9) with warm air near the die (50–200 K over 0.03–0.1 m).
#[test]
#[ignore = "a study: one diagnosis per replicate (minutes for 20 sets)"]
fn two_physics_effects_study() {
    study("TWO PHYSICS", |k, rng| {
        let emissivity = 0.3 + 0.6 * rng.uniform();
        let excess = 50.0 + 150.0 * rng.uniform();
        let length = 0.03 + 0.07 * rng.uniform();
        let sc = scenarios::radiation_with_warm_air(emissivity, excess, length, 0x5200 + k);
        (
            sc,
            format!("eps {emissivity:.2}, warm {excess:.0} K over {length:.3} m"),
        )
    });
}

//! The diagnose tests in one binary (one link instead of 7): each file is a module
//! named after its former test binary; run one with `cargo test --release --test diagnose NAME::`.

#[path = "../independent/mod.rs"]
mod independent;

mod ci_coverage;
mod classes;
mod detection_limits;
mod diagnose_candidates;
mod diagnose_hidden_effects;
mod diagnose_realistic;
mod diagnose_scan;
mod diagnose_separability;
mod few_runs;
mod global;
mod newtonian_effects;
mod noise_rates;
mod shared;
mod studies;
mod twins;
mod user_effect_descriptor;

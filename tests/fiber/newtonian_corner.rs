//! Issue 65 item 2: the Carreau-type law's two Newtonian corners (`n = 1`, and `n → 0` with
//! `K` beyond the data's stresses) are one answer on data of a Newtonian melt. Data made by the
//! independent simulator of `tests/independent/` (truth `n = 1`, no effect, 1.5 % noise), each
//! replicate with fresh noise, fitted as `rheometer fit` fits them.
//!
//! * (fast) on two seeds: the report says the data show no strain thinning, prints no `n` or
//!   `κ` as an estimate (the JSON says so), warns of no implausible law or bound, and the fit
//!   is quick;
//! * (slow, ignored) over `NEWTONIAN_SEEDS` replicates (default 100): how often strain thinning
//!   is claimed (target ≤ 5 %), how often the Newtonian finding is reported (≥ 90 %) and the
//!   fit's wall time (median, max). Run with
//!   `cargo test --release --test fiber newtonian_corner -- --ignored --nocapture`.
//!
//! Each fit prints one `CORNER` row.

use crate::independent::dataset::Scenario;
use crate::independent::scenarios;
use rheometer::effects::LawChoice;
use rheometer::fit::{FitSummary, IdentifyOptions};
use rheometer::input::load_experiments_with;
use rheometer::workflow::{fit, FitRequest};
use std::time::Instant;

/// A Newtonian melt with the noise of `seed`.
fn newtonian(seed: u64) -> Scenario {
    Scenario {
        seed,
        ..scenarios::newtonian()
    }
}

/// What one replicate's report says.
struct Row {
    seed: u64,
    /// The likelihood-ratio test rejects the Newtonian law.
    thinning: bool,
    /// The finding is "no strain thinning detected".
    newtonian: bool,
    seconds: f64,
    summary: FitSummary,
}

/// Generates `sc`, fits it as `rheometer fit` does and prints its `CORNER` row.
fn replicate(sc: &Scenario) -> Row {
    let generated = sc.generate().unwrap();
    let data = load_experiments_with(&generated.toml, 4).unwrap();
    let t0 = Instant::now();
    let run = fit(&data, &FitRequest::new(IdentifyOptions::default())).unwrap();
    let seconds = t0.elapsed().as_secs_f64();
    let s = run.summary().clone();
    let finding = s.law_finding();
    let row = Row {
        seed: sc.seed,
        thinning: (s.newtonian_test.as_ref()).is_some_and(|t| t.preferred == LawChoice::Carreau),
        newtonian: finding.starts_with("no strain thinning detected"),
        seconds,
        summary: s,
    };
    let s = &row.summary;
    let t = s.newtonian_test.as_ref();
    println!(
        "CORNER | seed {} | n {:.4} κ {:.3} | LR {:.3} p {:.4} | thinning {} newtonian {} | \
         warnings {:?} | profile {:?} | {:.2} s | {}",
        row.seed,
        s.n.value,
        s.kappa.value,
        t.map_or(f64::NAN, |t| t.statistic),
        t.map_or(f64::NAN, |t| t.p_value),
        row.thinning,
        row.newtonian,
        s.warnings
            .iter()
            .map(|w| w.code.name())
            .collect::<Vec<_>>(),
        run.profile_error,
        row.seconds,
        finding
    );
    row
}

/// The median and the largest of `v`.
fn median_max(v: &mut [f64]) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let median = if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    };
    (median, v.last().copied().unwrap_or(f64::NAN))
}

#[test]
#[ignore = "slow: 100 fits of fresh-noise Newtonian data (about 2 min on 2 cores)"]
fn newtonian_replicates_report_no_thinning() {
    let seeds: u64 = std::env::var("NEWTONIAN_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100);
    let rows: Vec<Row> = (0..seeds).map(|k| replicate(&newtonian(6500 + k))).collect();
    let m = rows.len() as f64;
    let thinning = rows.iter().filter(|r| r.thinning).count();
    let newtonian = rows.iter().filter(|r| r.newtonian).count();
    let (median, max) = median_max(&mut rows.iter().map(|r| r.seconds).collect::<Vec<_>>());
    println!(
        "CORNER SUMMARY | {} replicates | thinning claimed {} ({:.0} %) | Newtonian reported {} \
         ({:.0} %) | fit time median {:.2} s max {:.2} s",
        rows.len(),
        thinning,
        100.0 * thinning as f64 / m,
        newtonian,
        100.0 * newtonian as f64 / m,
        median,
        max
    );
    assert!(thinning as f64 <= 0.05 * m, "thinning claimed in {thinning}");
    assert!(newtonian as f64 >= 0.90 * m, "Newtonian reported in {newtonian}");
}

//! How well the data of issue 11's `gauge_scale` scenario (the diameter gauge reads 3 % high,
//! independent model of `tests/independent/`) can separate the true cause `gauge_scale` from
//! `inlet_diameter` (die swell), the one the diagnosis names on the acceptance test's noise.
//!
//! With the take-up diameter a fitted nuisance per experiment (the aspirator line has no known
//! take-up speed; the paper takes `d_out` from the measurements), a gauge reading `(1 + g) d`
//! and a die swell `δ = g` differ only where the fiber's balances are not invariant under
//! `d → a d, u → u/a²` at fixed mass flow: gravity (∝ a²), inertia and drag (∝ a⁻²), the
//! Nusselt number through `Re ∝ a⁻¹`, radiation. The test measures that difference:
//!
//! - on **noise-free** data the true cause must win, with its factor recovered and a residual
//!   far below the noise (this fails if the gauge candidate were parametrised wrongly);
//! - the **non-centrality** `λ = (J_inlet − J_gauge)/σ²` of the noise-free refits is the
//!   expected margin in `χ²` by which the truth wins; with noise the margin is about
//!   `N(λ, 4λ)`, so the truth ranks first with probability `Φ(√λ/2)`, and a gauge error needs
//!   `|g| ≥ 0.03 √(λ₉₅/λ)` (`λ₉₅ = (2 · 1.645)²`) to be ranked first 95 % of the time;
//! - a few noise realisations (seeds other than the acceptance test's) show the ranking.
//!
//! Run: `cargo test --release --test diagnose_separability -- --ignored --nocapture`.

use crate::independent;
use crate::shared;

use independent::dataset::Scenario;
use independent::scenarios::{self, NOISE_SD};
use rheometer::diagnostics::{DiagnoseOptions, Diagnosis};
use rheometer::model::Effect;

/// Diagnoses `sc` with the two rival candidates only.
fn rivals(sc: &Scenario) -> Diagnosis {
    let options = DiagnoseOptions {
        candidates: vec![Effect::InletDiameter, Effect::GaugeScale],
        ..DiagnoseOptions::default()
    };
    shared::diagnose_with(sc, &options).run.diagnosis
}

/// `(J after, strength)` of candidate `name`.
fn refit(d: &Diagnosis, name: &str) -> (f64, f64) {
    let c = d
        .candidates
        .iter()
        .find(|c| c.effect == name)
        .expect("candidate listed");
    assert!(c.refitted(), "{name} not refitted");
    (c.cost_after, c.strength())
}

/// Standard normal CDF (Abramowitz–Stegun 7.1.26 for erf, |error| < 1.5e-7).
fn normal_cdf(x: f64) -> f64 {
    let z = x.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * z);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let erf = 1.0 - poly * (-z * z).exp();
    if x >= 0.0 {
        0.5 * (1.0 + erf)
    } else {
        0.5 * (1.0 - erf)
    }
}

#[test]
#[ignore = "measurement (about 1 min): prints the separability of gauge_scale and inlet_diameter"]
fn gauge_scale_against_die_swell() {
    let truth = scenarios::gauge_scale();
    let g = 0.03;
    let clean = rivals(&Scenario {
        noise_sd: 0.0,
        ..truth.clone()
    });
    let (j_gauge, s_gauge) = refit(&clean, "gauge_scale");
    let (j_inlet, s_inlet) = refit(&clean, "inlet_diameter");
    let n = clean.base_fit.rms_relative_residual; // noise-free base misfit
    let sigma2 = NOISE_SD * NOISE_SD;
    let lambda = (j_inlet - j_gauge) / sigma2;
    let lambda95 = (2.0f64 * 1.645).powi(2);
    println!(
        "SEPARABILITY noise-free | base RMS {:.4} % | gauge_scale g = {s_gauge:.5} J = {j_gauge:.3e} ({:.4} σ²) | inlet_diameter δ = {s_inlet:.5} J = {j_inlet:.3e} ({:.4} σ²) | λ = {lambda:.2} | P(truth first at σ = {:.1} %) = {:.2} | |g| for 95 %: {:.3}",
        100.0 * n,
        j_gauge / sigma2,
        j_inlet / sigma2,
        100.0 * NOISE_SD,
        normal_cdf(lambda.max(0.0).sqrt() / 2.0),
        g * (lambda95 / lambda.max(1e-12)).sqrt()
    );
    // the true cause wins on noise-free data, recovered, with a residual far below the noise
    assert!(
        j_gauge < j_inlet,
        "noise-free: gauge_scale J {j_gauge} ≥ inlet_diameter J {j_inlet}"
    );
    assert!((s_gauge - g).abs() < 0.1 * g, "noise-free g = {s_gauge}");
    let points: usize = truth.experiments.iter().map(|e| e.positions.len()).sum();
    assert!(
        (j_gauge / points as f64).sqrt() < 0.2 * NOISE_SD,
        "noise-free gauge_scale RMS {}",
        (j_gauge / points as f64).sqrt()
    );

    // noise realisations (not the acceptance test's seed 110)
    let mut first = 0;
    let seeds = 201..=206u64;
    let total = seeds.clone().count();
    for seed in seeds {
        let d = rivals(&Scenario {
            seed,
            ..truth.clone()
        });
        let (jg, _) = refit(&d, "gauge_scale");
        let (ji, _) = refit(&d, "inlet_diameter");
        if jg < ji {
            first += 1;
        }
        println!(
            "SEPARABILITY seed {seed} | (J_inlet − J_gauge)/σ² = {:+.2} | first {}",
            (ji - jg) / sigma2,
            d.candidates[0].effect
        );
    }
    println!("SEPARABILITY gauge_scale ranked first in {first} of {total} noise realisations");
}

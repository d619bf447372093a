//! Issue 65 item 2: a real effect on a Newtonian melt. The refit with the right effect may end
//! at the Carreau-type law's other Newtonian corner (`n → 0` with `K` beyond the data's
//! stresses): that is a Newtonian melt with that effect, not an implausible law, and the
//! diagnosis must name the effect. Data by the independent simulator of `tests/independent/`
//! (truth `n = 1`), radiation at twice its 95 % detection limit on a Newtonian melt (the
//! limit read from the diagnosis of a Newtonian control), fresh noise per replicate.
//!
//! Slow and ignored (one diagnosis per replicate); run with
//! `cargo test --release --test diagnose newtonian_effects -- --ignored --nocapture`.
//! `NEWTONIAN_EFFECT_SEEDS` replicates (default 20). Each prints one `NEWTONIAN EFFECT` row and
//! a summary; the target is the effect named in at least 80 %.

use crate::independent;
use crate::shared;

use independent::dataset::Scenario;
use independent::model::Law;
use independent::scenarios;
use rheometer::diagnostics::DiagnoseOptions;

/// Radiation of emissivity `emissivity` on a Newtonian melt with the noise of `seed`.
fn newtonian_radiating(emissivity: f64, seed: u64) -> Scenario {
    Scenario {
        name: "newtonian_radiating",
        law: Law {
            n: 1.0,
            kappa: 11.71,
        },
        ..scenarios::radiating(emissivity, seed)
    }
}

/// The diagnosis of a Newtonian melt (independent model, no effect) reports its law as the fit
/// does: Newtonian within the data's strain rates, `n` and `κ` not estimates (the fit's test
/// attached to the base fit, no warnings about them as estimates), in the text and the JSON;
/// nothing named. A melt that thins (the independent model's default `n = 0.8`) keeps its law
/// as an estimate.
#[test]
fn a_newtonian_melt_is_reported_newtonian_by_the_diagnosis() {
    for seed in [115, 6701] {
        let sc = Scenario {
            seed,
            ..scenarios::newtonian()
        };
        let d = shared::diagnosed(&sc);
        let g = &d.run.diagnosis;
        assert!(g.found.is_empty(), "seed {seed}: named {:?}", g.found);
        let b = &g.base_fit;
        assert!(b.newtonian_on_data(), "seed {seed}: {:?}", b.newtonian_test);
        let about_the_law = |m: &str| {
            [
                "the standard error of n",
                "the standard error of kappa",
                "the 95% interval of n",
            ]
            .iter()
            .any(|p| m.starts_with(p))
                || m.contains("leaves the law undetermined")
        };
        assert!(
            !b.warnings.iter().any(|w| about_the_law(&w.message)),
            "seed {seed}: {:?}",
            b.warnings
        );
        let text = g.to_text();
        assert!(
            text.contains("Its law is Newtonian within the data's strain rates"),
            "seed {seed}:\n{text}"
        );
        // no shifts of n and kappa counted in standard errors of non-estimates
        assert!(g.detection.shifts_withheld.is_some(), "seed {seed}");
        assert!(g
            .detection
            .limits
            .iter()
            .all(|l| l.shift_n_se.is_none() && l.shift_kappa_se.is_none()));
        let json = serde_json::to_string(&g.json()).unwrap();
        assert!(json.contains("\"law_not_estimated\""), "seed {seed}");
    }
    let thinning = shared::diagnosed(&scenarios::control());
    let b = &thinning.run.diagnosis.base_fit;
    assert!(!b.newtonian_on_data() && b.newtonian_test.is_none());
    assert!(thinning.run.diagnosis.detection.shifts_withheld.is_none());
    assert!(!thinning
        .run
        .diagnosis
        .to_text()
        .contains("Its law is Newtonian"));
}

#[test]
#[ignore = "slow: one diagnosis per replicate (minutes on 2 cores)"]
fn radiation_on_a_newtonian_melt_is_named() {
    let seeds: u64 = std::env::var("NEWTONIAN_EFFECT_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let control = Scenario {
        seed: 6700,
        ..scenarios::newtonian()
    };
    let c = shared::diagnose_with(&control, &DiagnoseOptions::default());
    let limit = c
        .run
        .diagnosis
        .detection
        .limits
        .iter()
        .find(|l| l.effect == "radiation")
        .map(|l| l.s95)
        .expect("a detection limit for radiation");
    let emissivity = (2.0 * limit).min(1.0);
    println!(
        "NEWTONIAN EFFECT | control seed {} named {:?}; radiation s95 {limit:.3}: emissivity \
         {emissivity:.3}",
        control.seed, c.run.diagnosis.most_likely_missing
    );
    let mut named = 0;
    let mut seconds = Vec::new();
    for k in 0..seeds {
        let sc = newtonian_radiating(emissivity, 6800 + k);
        let d = shared::diagnose_with(&sc, &DiagnoseOptions::default());
        let r = &d.run.diagnosis;
        let rad = r.candidate("radiation");
        if r.most_likely_missing.as_deref() == Some("radiation") {
            named += 1;
        }
        seconds.push(d.seconds);
        println!(
            "NEWTONIAN EFFECT | seed {} | named {:?} | radiation {:.3} ± {:.3} status {} ΔBIC \
             {:.1} n {:.4} κ {:.3} | base n {:.4} κ {:.3} | {:.1} s",
            sc.seed,
            r.most_likely_missing,
            rad.map_or(f64::NAN, |c| c.strength()),
            rad.map_or(f64::NAN, |c| c.stderr_strength()),
            rad.map_or("-", |c| c.status.name()),
            rad.map_or(f64::NAN, |c| c.delta_bic),
            rad.map_or(f64::NAN, |c| c.n()),
            rad.map_or(f64::NAN, |c| c.kappa()),
            r.base_fit.n.value,
            r.base_fit.kappa.value,
            d.seconds
        );
    }
    seconds.sort_by(f64::total_cmp);
    let m = seeds.max(1) as f64;
    println!(
        "NEWTONIAN EFFECT SUMMARY | {seeds} replicates, emissivity {emissivity:.3} | radiation \
         named {named} ({:.0} %) | diagnosis median {:.1} s max {:.1} s",
        100.0 * named as f64 / m,
        seconds.get(seconds.len() / 2).copied().unwrap_or(f64::NAN),
        seconds.last().copied().unwrap_or(f64::NAN)
    );
    assert!(
        named as f64 >= 0.8 * m,
        "radiation named in {named} of {seeds}"
    );
}

/// The rate behind `a_newtonian_melt_is_reported_newtonian_by_the_diagnosis`: over
/// `NEWTONIAN_DIAGNOSIS_SEEDS` (default 100) Newtonian melts from the independent model (seeds
/// 6500 on, fresh noise), how often the diagnosis reports the law as Newtonian within the
/// data's strain rates (target ≥ 90 %), names an effect (false alarm, target ≤ 5 %) or
/// presents a thinning law as a result (target ≤ 5 %).
#[test]
#[ignore = "slow: one diagnosis per replicate (minutes on 2 cores)"]
fn newtonian_melts_are_reported_newtonian_by_the_diagnosis() {
    let seeds: u64 = std::env::var("NEWTONIAN_DIAGNOSIS_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100);
    let (mut newtonian, mut named, mut thinning) = (0, 0, 0);
    for k in 0..seeds {
        let sc = Scenario {
            seed: 6500 + k,
            ..scenarios::newtonian()
        };
        let d = shared::diagnose_with(&sc, &DiagnoseOptions::default());
        let g = &d.run.diagnosis;
        let law = g.law_fit();
        let is_newtonian = law.newtonian_on_data();
        let claims_thinning = g.law_is_a_result() && !is_newtonian && law.n.ci95[1] < 1.0;
        newtonian += usize::from(is_newtonian);
        named += usize::from(!g.found.is_empty());
        thinning += usize::from(claims_thinning);
        println!(
            "NEWTONIAN DIAGNOSIS | seed {} | newtonian {is_newtonian} | named {:?} | thinning \
             claimed {claims_thinning} | n {:.4} [{:.4}, {:.4}] | {:.1} s",
            sc.seed, g.found, law.n.value, law.n.ci95[0], law.n.ci95[1], d.seconds
        );
    }
    let pct = |a: usize| 100.0 * a as f64 / seeds as f64;
    println!(
        "NEWTONIAN DIAGNOSIS SUMMARY | {seeds} sets | Newtonian reported {newtonian} ({:.1} %) | \
         named {named} ({:.1} %) | thinning claimed {thinning} ({:.1} %)",
        pct(newtonian),
        pct(named),
        pct(thinning)
    );
    assert!(pct(newtonian) >= 90.0 && pct(named) <= 5.0 && pct(thinning) <= 5.0);
}

//! Detection limits of `diagnose` (issue 11) checked on data of the independent simulator of
//! `tests/independent/` (its own model of the spin line; nothing of the candidates' code path
//! makes the data):
//!
//! * the control's limits say the faults the diagnosis cannot see (−4 % mass flow, a 3 µm gauge
//!   offset: the ignored tests of `tests/diagnose_realistic.rs`) could be missed, and place the
//!   10 K cold die between the 50 % and 95 % limits (it is named on one seed of three);
//! * a fault generated at 1.5 × the control's `s95` is detected with its strength within 3
//!   standard errors of the truth, and named first (the mass flow: or tied with `nusselt_scale`,
//!   whose signature is nearly parallel);
//! * the bias the limits predict for an undetected fault (the error budget's exact propagation)
//!   is the bias of the user's fit on the same noise realisation;
//! * the cold die that goes unnamed (seed 2108) is covered by what the report says: its 95 %
//!   limit is above 10 K and the stated bias at that limit covers the fit's actual error;
//! * (slow, ignored) over five seeds, a fault at `s95` is detected in at least four.
//!
//! Each run prints one `DETECTION` line (run with `--nocapture`).

use crate::independent;
use crate::shared;

use independent::dataset::{Expected, Faults, Scenario};
use independent::scenarios;
use rheometer::diagnostics::DetectionLimit;
use rheometer::diagnostics::{earns_its_place, DiagnoseOptions, Diagnosis};
use rheometer::fit::FitSummary;
use std::sync::OnceLock;

/// Generates, loads and diagnoses `sc`.
/// (Made once per test binary and shared by the tests that ask for the same scenario,
/// [`shared::diagnosed`].)
fn run(sc: &Scenario) -> Diagnosis {
    let d = shared::diagnosed(sc).run.diagnosis.clone();
    let top = &d.candidates[0];
    println!(
        "DETECTION | {} seed {} | base n {:.4} κ {:.4} | named {:?} | top {} = {:.4} ± {:.4} {} ΔBIC {:.1}",
        sc.name,
        sc.seed,
        d.base_fit.n.value,
        d.base_fit.kappa.value,
        d.most_likely_missing,
        top.effect,
        top.strength(),
        top.stderr_strength(),
        top.unit,
        top.delta_bic
    );
    d
}

/// Generates, loads and fits `sc` as a diagnosis fits the user's model (its base fit, the
/// noise model's weights included), without searching any candidate: the same fit, bit for
/// bit, at 0.03 s instead of a whole diagnosis' 0.75 s.
fn base_fit(sc: &Scenario) -> FitSummary {
    let options = DiagnoseOptions {
        candidates: Vec::new(),
        ..DiagnoseOptions::default()
    };
    shared::diagnose_with(sc, &options).run.diagnosis.base_fit
}

/// The control's diagnosis (the shared one, [`shared::diagnosed`], held here as a `'static`
/// borrow for the limit lookups; its detection limits printed once).
fn control() -> &'static Diagnosis {
    static C: OnceLock<Diagnosis> = OnceLock::new();
    C.get_or_init(|| {
        let d = run(&scenarios::control());
        println!("{}", d.detection.to_text());
        d
    })
}

fn limit<'a>(d: &'a Diagnosis, effect: &str) -> &'a DetectionLimit {
    d.detection
        .limits
        .iter()
        .find(|l| l.effect == effect)
        .unwrap_or_else(|| panic!("no detection limit for {effect}"))
}

/// A scenario with the control's truth and `faults`, on the seed `seed`.
fn faulty(name: &'static str, faults: Faults, expected: Expected, seed: u64) -> Scenario {
    let acceptable = vec![match expected {
        Expected::DieOffsetK(_) => "die_temperature_offset",
        Expected::MassFlowFactor(_) => "mass_flow_scale",
        Expected::GaugeOffsetM(_) => "gauge_offset",
        Expected::GaugeFactor(_) => "gauge_scale",
        Expected::Emissivity(_) => "radiation",
    }];
    Scenario {
        name,
        faults,
        acceptable: acceptable.clone(),
        expected: Some((acceptable[0], expected)),
        seed,
        ..scenarios::control()
    }
}

fn mass_flow(factor: f64, seed: u64) -> Scenario {
    let f = Faults {
        mass_flow_factor: factor,
        ..Faults::none()
    };
    faulty("mass_flow", f, Expected::MassFlowFactor(factor), seed)
}

fn gauge_offset(metres: f64, seed: u64) -> Scenario {
    let f = Faults {
        gauge_offset_m: metres,
        ..Faults::none()
    };
    faulty("gauge_offset", f, Expected::GaugeOffsetM(metres), seed)
}

fn die_offset(kelvin: f64, seed: u64) -> Scenario {
    let f = Faults {
        die_offset_k: kelvin,
        ..Faults::none()
    };
    faulty("die_offset", f, Expected::DieOffsetK(kelvin), seed)
}

/// The expected cause is detected: it earns its place (`ΔBIC` below the threshold, a credible
/// strength) with its strength within 3 standard errors of the truth; and it is named and ranked
/// first, or (where `allow_tie`) the candidate ranked above it is one the diagnosis itself lists
/// as indistinguishable from it, within 2 of its `ΔBIC` (a tie the data cannot break).
fn assert_detected(sc: &Scenario, d: &Diagnosis, allow_tie: bool) {
    let (name, truth) = sc.expected.unwrap();
    let ranking: Vec<(&String, f64)> = d
        .candidates
        .iter()
        .map(|c| (&c.effect, c.delta_bic))
        .collect();
    let pos = d.candidates.iter().position(|c| c.effect == name).unwrap();
    let c = &d.candidates[pos];
    assert!(
        earns_its_place(c, DiagnoseOptions::default().earn_threshold),
        "{}: {name} does not earn its place: {ranking:?}",
        sc.name
    );
    let t = truth.in_unit(&c.unit, c.strength()).unwrap();
    assert!(
        (c.strength() - t).abs() <= 3.0 * c.stderr_strength(),
        "{}: {} = {} ± {} {}, truth {t}",
        sc.name,
        c.effect,
        c.strength(),
        c.stderr_strength(),
        c.unit
    );
    if pos == 0 {
        assert_eq!(d.most_likely_missing.as_deref(), Some(name));
        return;
    }
    assert!(
        allow_tie,
        "{}: {name} not ranked first: {ranking:?}",
        sc.name
    );
    let first = &d.candidates[0];
    let listed = d
        .indistinguishable
        .iter()
        .any(|p| p.effects.contains(&first.effect) && p.effects.iter().any(|e| e == name));
    assert!(
        listed && c.delta_bic - first.delta_bic < 2.0 && pos == 1,
        "{}: {} ranked above {name} without a listed tie: {ranking:?}",
        sc.name,
        first.effect
    );
}

#[test]
fn the_control_says_which_faults_it_could_miss() {
    let d = control();
    assert!(d.most_likely_missing.is_none());
    let mf = limit(d, "mass_flow_scale");
    let go = limit(d, "gauge_offset");
    let die = limit(d, "die_temperature_offset");
    for l in [mf, go, die] {
        assert!(0.0 < l.s50 && l.s50 < l.s95, "{l:?}");
    }
    // the ignored scenarios' truths are below even the 50 % limit: the report correctly says
    // they could be missed
    assert!(0.04 < mf.s50, "mass flow s50 = {}", mf.s50);
    assert!(3.0 < go.s50, "gauge offset s50 = {} µm", go.s50);
    // the cold die (10 K, named on one seed of three) lies between the two limits
    assert!(die.s50 < 10.0 && 10.0 < die.s95, "{die:?}");
    // the words of a diagnosis that names nothing
    let text = d.to_text();
    assert!(text.contains("No candidate earns its place"), "{text}");
    assert!(
        text.contains("These data would reveal (95 %): ")
            && text.contains(&format!("mass_flow_scale >= {}", mf.strength_words(mf.s95)))
            && text.contains("What these data could have missed"),
        "{text}"
    );
    // JSON round trip (as written, with its derived reasons) keeps the limits and the rule
    let js = serde_json::to_string(&d.json()).unwrap();
    let back: Diagnosis = serde_json::from_str(&js).unwrap();
    assert_eq!(back.detection.limits.len(), d.detection.limits.len());
    assert_eq!(back.law_not_a_result(), d.law_not_a_result());
    // nothing named: the user's fit is the reported one, and both reasons are the same
    let v: serde_json::Value = serde_json::from_str(&js).unwrap();
    assert_eq!(v["law_not_a_result"], v["base_law_not_a_result"]);
    assert_eq!(v["law_not_a_result"].is_null(), d.law_is_a_result());
}

/// A mass-flow error of 1.5 × `s95` (−14.5 %) is detected; `nusselt_scale`, whose signature is
/// nearly parallel (cosine −0.997, listed as indistinguishable), may tie with it.
#[test]
fn a_mass_flow_error_of_one_and_a_half_s95_is_detected() {
    let s95 = limit(control(), "mass_flow_scale").s95;
    let sc = mass_flow(1.0 - 1.5 * s95, 209);
    assert_detected(&sc, &run(&sc), true);
}

#[test]
#[ignore = "issue 11: detected but not separable: at 1.5 s95 (-14.5 % mass flow, seed 209) mass_flow_scale earns its place (dBIC -67.2) but nusselt_scale ranks first by 0.8 (signature cosine -0.997)"]
fn a_mass_flow_error_of_one_and_a_half_s95_is_ranked_first() {
    let s95 = limit(control(), "mass_flow_scale").s95;
    let sc = mass_flow(1.0 - 1.5 * s95, 209);
    assert_detected(&sc, &run(&sc), false);
}

#[test]
fn a_gauge_offset_of_one_and_a_half_s95_is_named_first() {
    let s95 = limit(control(), "gauge_offset").s95;
    let sc = gauge_offset(1.5 * s95 * 1e-6, 211);
    assert_detected(&sc, &run(&sc), false);
}

#[test]
fn a_die_offset_of_one_and_a_half_s95_is_named_first() {
    let s95 = limit(control(), "die_temperature_offset").s95;
    let sc = die_offset(-1.5 * s95, 208);
    assert_detected(&sc, &run(&sc), false);
}

/// The bias an undetected fault causes, as the limits predict it (`dκ/ds`, `dn/ds` from the
/// control's fit), against the fit's actual change on the same noise realisation (seed 101),
/// for faults below the 50 % limit (the ignored scenarios' −4 % mass flow and 3 µm offset, a
/// 5 K cold die). The prediction is first order: its error grows as the strength squared (a
/// 10 K cold die, at the limit, is shifted 17 % more than predicted: κ −0.516 against −0.440).
#[test]
fn the_predicted_bias_of_an_undetected_fault_is_the_fits() {
    let c = control();
    let seed = scenarios::control().seed;
    for (sc, effect, strength) in [
        (mass_flow(0.96, seed), "mass_flow_scale", -0.04),
        (gauge_offset(3e-6, seed), "gauge_offset", 3.0),
        (die_offset(-5.0, seed), "die_temperature_offset", -5.0),
    ] {
        let fit = base_fit(&sc);
        let l = limit(c, effect);
        let dk = fit.kappa.value - c.base_fit.kappa.value;
        let dn = fit.n.value - c.base_fit.n.value;
        let pk = l.dkappa_per_unit.unwrap() * strength;
        let pn = l.dn_per_unit.unwrap() * strength;
        println!(
            "BIAS | {effect} {strength}: κ {dk:+.4} predicted {pk:+.4}; n {dn:+.4} predicted {pn:+.4}"
        );
        // first order: the misprediction is second order in the strength, small against the
        // statistical standard error
        let (sk, sn) = (c.base_fit.kappa.stderr, c.base_fit.n.stderr);
        assert!(
            (dk - pk).abs() < 0.5 * sk,
            "{effect}: Δκ {dk} vs {pk} (se {sk})"
        );
        assert!(
            (dn - pn).abs() < 0.5 * sn,
            "{effect}: Δn {dn} vs {pn} (se {sn})"
        );
    }
}

/// The 95 % claim over five seeds: a fault at exactly the control's `s95` is detected (its own
/// refit earns its place) in at least four (probability 0.977 if the claim holds). How often it
/// is also named first (it may lose to a rival listed as indistinguishable) is printed.
#[test]
#[ignore = "slow (ten diagnoses, about 2 min on 2 cores); issue 11 open: mass flow at s95 (9.6 %) detected in 5 of 5 seeds (named first in 2: radiation, nusselt_scale, die_temperature_offset win the others), gauge offset (13.4 um) in 3 of 5 (fitted 8.7 and 7.6 um on the two misses): the linearised 95 % limit is optimistic for gauge_offset, whose undetected shift of n is 8 se"]
fn faults_at_s95_are_detected_over_seeds() {
    let c = control();
    let mf = limit(c, "mass_flow_scale").s95;
    let go = limit(c, "gauge_offset").s95;
    let seeds = [301u64, 302, 303, 304, 305];
    let threshold = DiagnoseOptions::default().earn_threshold;
    for (label, make) in [
        (
            "mass_flow_scale",
            Box::new(|seed| mass_flow(1.0 - mf, seed)) as Box<dyn Fn(u64) -> Scenario>,
        ),
        (
            "gauge_offset",
            Box::new(|seed| gauge_offset(go * 1e-6, seed)),
        ),
    ] {
        let (mut detected, mut first) = (0, 0);
        for &seed in &seeds {
            let d = run(&make(seed));
            let c = d.candidates.iter().find(|c| c.effect == label).unwrap();
            detected += usize::from(earns_its_place(c, threshold));
            first += usize::from(d.most_likely_missing.as_deref() == Some(label));
        }
        println!(
            "SEEDS | {label} at s95: detected in {detected} of {}, named first in {first}",
            seeds.len()
        );
        assert!(detected >= 4, "{label} at s95 detected in {detected} of 5");
    }
}

/// The inlet-temperature case of issue 11 where the diagnosis names nothing (the 10 K cold die
/// of `tests/diagnose_realistic.rs` on seed 2108, between its 50 % and 95 % limits): either the
/// offset is identified (strength within 3 standard errors of −10 K), or the report says in
/// words that a die offset of this size could be missed (its 95 % limit above 10 K) and the bias
/// it states for an undetected offset at that limit, plus two statistical standard errors,
/// covers the actual error of the user's κ and n.
#[test]
fn an_unnamed_cold_die_is_covered_by_the_reported_limits() {
    let base = scenarios::die_colder();
    let sc = Scenario {
        seed: base.seed + 2000,
        ..base.clone()
    };
    let d = run(&sc);
    let truth_k = 10.0;
    if d.most_likely_missing.as_deref() == Some("die_temperature_offset") {
        let c = &d.candidates[0];
        assert!((c.strength() + truth_k).abs() <= 3.0 * c.stderr_strength());
        return;
    }
    let l = limit(&d, "die_temperature_offset");
    assert!(l.s95 >= truth_k, "s95 = {} K below the unnamed 10 K", l.s95);
    let text = d.to_text();
    assert!(
        text.contains("These data would reveal (95 %)")
            && text.contains("die_temperature_offset >="),
        "{text}"
    );
    let b = &d.base_fit;
    let (err_k, err_n) = (
        (b.kappa.value - sc.law.kappa).abs(),
        (b.n.value - sc.law.n).abs(),
    );
    let cover_k = l.shift_kappa_at_s95.unwrap().abs() + 2.0 * b.kappa.stderr;
    let cover_n = l.shift_n_at_s95.unwrap().abs() + 2.0 * b.n.stderr;
    println!(
        "COLD DIE UNNAMED | s50 {:.1} K s95 {:.1} K | κ error {err_k:.4} covered by {cover_k:.4} | n error {err_n:.4} covered by {cover_n:.4}",
        l.s50, l.s95
    );
    assert!(err_k <= cover_k, "κ error {err_k} > {cover_k}");
    assert!(err_n <= cover_n, "n error {err_n} > {cover_n}");
}

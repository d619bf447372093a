//! Issue 26's acceptance tests: never a wrong viscosity with confidence. Data from the
//! independent model of `tests/independent/` (Lorentzian aspirator jets, inverse-square warm
//! air, radiation, strain hardening — an effect no candidate describes —, outliers, a take-up
//! region three times as noisy), diagnosed with the default options. For each: the causes found
//! (or "none of the candidates"), the final fit's RMS within 20 % of the noise where explained,
//! the true (n, κ) inside its 95 % intervals, and the global check: the final fit's `J` no
//! higher than a local refit of the same model started at the truth (+0.1 %).
//! Each prints one `GLOBAL` line (run with `--nocapture`).

use crate::independent;
use crate::shared;

use independent::dataset::{Faults, Scenario};
use independent::model::AirHeat;
use independent::scenarios;
use rheometer::diagnostics::earns_its_place;
use rheometer::diagnostics::Verdict;
use rheometer::diagnostics::{DiagnoseOptions, DiagnosisRun};
use rheometer::fit::{FitStart, Rheometer};
use rheometer::model::ExperimentSet;
use rheometer::model::{Effect, EffectSetting, LawChoice, ModelSpec};
use std::time::Instant;

/// What a scenario must give.
struct Expect {
    /// Effects that must all be found (in any order).
    found: &'static [&'static str],
    /// Effects that may be found besides.
    allowed: &'static [&'static str],
    /// Whether the verdict must be "explained" (else "none of the candidates" or "adequate").
    explained: bool,
    /// Start strengths of the local refit from the truth, by effect or shape parameter.
    truth_strengths: Vec<(&'static str, f64)>,
}

/// The scenario's data set, diagnosed with the default options, not cached (the studies).
fn diagnosed(sc: &Scenario) -> (ExperimentSet, DiagnosisRun) {
    let d = shared::diagnose_with(sc, &DiagnoseOptions::default());
    (d.set, d.run)
}

/// The scenario's diagnosis with the default options, made once per test binary and shared by
/// the tests that ask for the same scenario ([`shared::diagnosed`]; the studies, which diagnose
/// hundreds of sets once each, call [`diagnosed`]), with its wall time \[s\].
fn run(sc: &Scenario) -> (ExperimentSet, DiagnosisRun, f64) {
    let d = shared::diagnosed(sc);
    println!("{}", d.run.diagnosis.to_text());
    (d.set.clone(), d.run.clone(), d.seconds)
}

/// `J` of the model with the found effects, refitted locally from the truth.
fn local_from_truth(set: &ExperimentSet, r: &DiagnosisRun, sc: &Scenario, e: &Expect) -> f64 {
    let mut spec = ModelSpec::new(LawChoice::Carreau);
    for name in &r.diagnosis.found {
        let effect: Effect = name.parse().unwrap();
        spec = spec.with(EffectSetting::fitted(effect));
    }
    let rh = Rheometer::with_spec(set, spec).unwrap();
    let start = FitStart {
        strengths: e
            .truth_strengths
            .iter()
            .map(|(n, v)| (n.to_string(), *v))
            .collect(),
        ..FitStart::at([sc.law.n, sc.law.kappa])
    };
    let id = rh.identify_from(&start, &r.fit_options).unwrap();
    id.summary.cost
}

fn check(sc: &Scenario, e: &Expect) -> (ExperimentSet, DiagnosisRun) {
    let (set, r, t) = run(sc);
    let d = &r.diagnosis;
    let fit = d.law_fit();
    let verdict = d.verdict.kind();
    let local = if d.found.is_empty() {
        f64::NAN
    } else {
        local_from_truth(&set, &r, sc, e)
    };
    println!(
        "GLOBAL | {} | found {:?} | verdict {verdict} | n {} κ {} | RMS {:.3} % noise {:.3} % | \
         J {:.6e} local from truth {:.6e} | {:.1} s",
        sc.name,
        d.found,
        shared::with_interval(&fit.n, 4),
        shared::with_interval(&fit.kappa, 4),
        100.0 * fit.rms_relative_residual,
        100.0 * d.base_fit.noise.level,
        fit.cost,
        local,
        t
    );
    // under "none of the candidates" no law is printed as a result
    if matches!(d.verdict, Verdict::NoneOfTheCandidates { .. }) {
        let text = d.to_text();
        assert!(
            !text.contains("With it: n ="),
            "{}: a law printed as a result under none of the candidates",
            sc.name
        );
    }
    // the named candidate's refit is global: several starts, the report says how many reached
    // the kept optimum
    if let Some(c) = d.named() {
        let [ran, reached] = c.refit_starts;
        assert!(
            ran >= 2 && (1..=ran).contains(&reached),
            "{}: {:?}",
            sc.name,
            c.refit_starts
        );
        let flat = d.to_text().split_whitespace().collect::<Vec<_>>().join(" ");
        let words = format!("({reached} of {ran} refit starts reached this optimum)");
        assert!(
            flat.contains(&words),
            "{}: no '{words}' in the report",
            sc.name
        );
    }
    // one noise level: a warning of the user's fit that names the noise names the fit's own
    let level = d.base_fit.noise.describe();
    for w in &d.base_fit.warnings {
        if w.message.contains("noise level") && w.message.contains("estimated") {
            assert!(w.message.contains(&level), "{}: {w} vs {level}", sc.name);
        }
    }
    for f in e.found {
        assert!(
            d.found.iter().any(|x| x == f),
            "{}: {f} not found: {:?}",
            sc.name,
            d.found
        );
    }
    for f in &d.found {
        assert!(
            e.found.contains(&f.as_str()) || e.allowed.contains(&f.as_str()),
            "{}: {f} found but not expected",
            sc.name
        );
    }
    if e.explained {
        assert!(
            matches!(d.verdict, Verdict::Explained { .. }),
            "{}: verdict {verdict}",
            sc.name
        );
        // the RMS without the points the fit leaves out as outliers
        let rms = fit
            .noise
            .model
            .as_ref()
            .map_or(fit.rms_relative_residual, |m| m.rms);
        let ratio = rms / sc.noise_sd;
        assert!((ratio - 1.0).abs() <= 0.2, "{}: RMS/noise {ratio}", sc.name);
    } else {
        assert!(
            !matches!(d.verdict, Verdict::Explained { .. }),
            "{}: explained by {:?}",
            sc.name,
            d.found
        );
    }
    if !d.found.is_empty() || e.explained {
        assert!(
            fit.covers(sc.law.n, sc.law.kappa),
            "{}: truth ({}, {}) outside n {:?}, κ {:?}",
            sc.name,
            sc.law.n,
            sc.law.kappa,
            fit.n.ci95,
            fit.kappa.ci95
        );
    }
    if local.is_finite() {
        assert!(
            fit.cost <= local * 1.001,
            "{}: the diagnosis' fit J = {} is above the local refit from the truth {local}",
            sc.name,
            fit.cost
        );
    }
    // never an implausible law printed as the answer
    assert!(fit.n.value >= 0.2, "{}: n = {}", sc.name, fit.n.value);
    (set, r)
}

#[test]
fn strong_coflow_with_a_long_decay() {
    check(
        &scenarios::aspirator(40.0, 0.15, 2601),
        &Expect {
            found: &["air_coflow"],
            allowed: &[
                "air_coflow_line",
                "air_temperature_profile",
                "nusselt_scale",
            ],
            explained: true,
            truth_strengths: vec![("air_coflow", 40.0), ("air_coflow.decay_length", 0.15)],
        },
    );
}

#[test]
fn coflow_corners_fast_and_short_slow_and_long() {
    for (v, l, seed) in [(300.0, 0.03, 2602), (30.0, 0.3, 2603)] {
        check(
            &scenarios::aspirator(v, l, seed),
            &Expect {
                found: &["air_coflow"],
                allowed: &[
                    "air_coflow_line",
                    "air_temperature_profile",
                    "nusselt_scale",
                ],
                explained: true,
                truth_strengths: vec![("air_coflow", v), ("air_coflow.decay_length", l)],
            },
        );
    }
}

/// Warm air (+150 K, inverse square over 8 cm) and an aspirator jet (60 m/s, Lorentzian over
/// 10 cm) together: the shipped `data/two_effects`.
///
/// The user's fit sits at n = 0.18. Until stop 46 the search lost the co-flow's basin: the scan
/// walked each side outwards from that law and followed its branch towards n = 0, every
/// co-flow grid point above the neutral value ended above the user's `J`, and the named
/// refit stayed at −2.2 m/s, n = 0.33 (J 0.135; the co-flow alone reaches J ≈ 0.10 with a
/// plausible law). Three things now find both effects: the sides are walked inwards again
/// from the diagnosis' start law where the user's law is implausible (the co-flow at 75 m/s,
/// n = 0.77); a refit that moves an implausible plain law into the plausible range is not
/// judged a "law jump" from it; and the second step fits the named co-flow with its decay
/// length free and starts its scans from the step's own strengths (before, it fixed the decay
/// at the grid's value and started every fit at zero co-flow, and ended at 18 m/s, J 0.32).
#[test]
fn warm_air_and_coflow_together() {
    let sc = scenarios::warm_air_and_coflow();
    let (_, r) = check(
        &sc,
        &Expect {
            found: &["air_temperature_profile", "air_coflow"],
            allowed: &["air_coflow_line"],
            explained: true,
            truth_strengths: vec![
                ("air_temperature_profile", 150.0),
                ("air_temperature_profile.decay_length", 0.08),
                ("air_coflow", 60.0),
                ("air_coflow.decay_length", 0.10),
            ],
        },
    );
    // the second step fits the named co-flow's decay length again (the refit's shape, not the
    // grid's), and its fit starts no worse than that refit (within the change of the noise
    // weights, which it refits with its own)
    let d = &r.diagnosis;
    let step2 = &d.further_steps[0];
    assert!(
        step2
            .base_fit
            .fitted
            .iter()
            .any(|p| p == "air_coflow.decay_length"),
        "{:?}",
        step2.base_fit.fitted
    );
    let named = d.candidate("air_coflow").and_then(|c| c.refit.as_ref());
    let named = named.expect("the named co-flow's refit");
    assert!(
        step2.base_fit.cost <= 1.1 * named.cost,
        "step 2 starts at J = {} after the refit's {}",
        step2.base_fit.cost,
        named.cost
    );
}

/// Radiation (emissivity 0.6) and warm air (+100 K, inverse square over 5 cm): the shipped
/// `data/radiation_warm_air`.
fn radiation_and_warm_air() -> Scenario {
    Scenario {
        name: "radiation_and_warm_air",
        air_heat: AirHeat::InverseSquare {
            excess: 100.0,
            length: 0.05,
        },
        ..scenarios::radiating(0.6, 2605)
    }
}

/// Whatever is named on the radiation-and-warm-air set, no law the truth is far from is
/// printed as a result: either the final fit's 95 % intervals hold the truth, or the law is
/// marked not a result and the two explanations' envelope holds it.
#[test]
fn radiation_and_warm_air_never_a_wrong_law() {
    let sc = radiation_and_warm_air();
    let (_, r, t) = run(&sc);
    let d = &r.diagnosis;
    let fit = d.law_fit();
    let holds = |ci: [f64; 2], v: f64| ci[0] <= v && v <= ci[1];
    let flagged = fit.warnings.iter().any(|w| {
        w.message.contains("not a result") || w.message.contains("neither law is a result")
    });
    println!(
        "GLOBAL | radiation_and_warm_air | found {:?} | pair {:?} | n {:.4} {:?} | flagged \
         {flagged} | {t:.1} s",
        d.found,
        d.pair
            .as_ref()
            .map(|p| (&p.effects, p.delta_bic, p.replaces)),
        fit.n.value,
        fit.n.ci95
    );
    if holds(fit.n.ci95, sc.law.n) && holds(fit.kappa.ci95, sc.law.kappa) {
        return;
    }
    assert!(flagged, "a wrong law printed as a result: {:?}", fit.n);
    let pair = d.pair.as_ref().expect("the disagreeing explanation");
    let pf = pair.fit.as_ref().expect("the pair's fit beside the result");
    // the union of the two fits' 95 % intervals
    let n = [
        pf.n.ci95[0].min(fit.n.ci95[0]),
        pf.n.ci95[1].max(fit.n.ci95[1]),
    ];
    let k = [
        pf.kappa.ci95[0].min(fit.kappa.ci95[0]),
        pf.kappa.ci95[1].max(fit.kappa.ci95[1]),
    ];
    assert!(holds(n, sc.law.n) && holds(k, sc.law.kappa), "{n:?} {k:?}");
    // the pair beside the result is the truth's
    let mut effects = pair.effects.to_vec();
    effects.sort();
    assert_eq!(effects, ["air_temperature_profile", "radiation"]);
    // the verdict is of its own kind, with the range both laws span
    let Verdict::Ambiguous {
        alternatives,
        n_range,
        kappa_range,
        ..
    } = &d.verdict
    else {
        panic!("verdict {:?}", d.verdict)
    };
    assert!(
        alternatives.contains(&pair.effects.to_vec()),
        "{alternatives:?}"
    );
    assert!(
        n_range[0] <= n[0] && n[1] <= n_range[1],
        "{n_range:?} {n:?}"
    );
    assert!(kappa_range[0] <= k[0] && k[1] <= kappa_range[1]);
    assert!(!d.law_is_a_result());
    // and so does the JSON, for the law with the found effects and for the user's model
    let js: serde_json::Value = serde_json::to_value(d.json()).unwrap();
    let why = js["law_not_a_result"]
        .as_str()
        .expect("a reason in the JSON");
    assert!(why.contains("disagrees on the law"), "{why}");
    let base = js["base_law_not_a_result"]
        .as_str()
        .expect("a reason for the base fit");
    assert!(d.found.iter().all(|e| base.contains(e.as_str())), "{base}");
    // the report says so (its lines wrapped at 100 characters)
    let text = d.to_text().split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(text.contains("neither law is a result"), "{text}");
    assert!(text.contains("VERDICT: AMBIGUOUS"), "{text}");
    // with what decides between them: a measurement for each (the air along the line, the
    // fiber's temperature), and no explanation called the most likely one
    let decides = text
        .split("What decides: ")
        .nth(1)
        .and_then(|t| t.split(". ").next())
        .unwrap_or_else(|| panic!("no 'What decides' in {text}"));
    for e in ["air_temperature_profile", "radiation"] {
        assert!(decides.contains(&format!("(for {e}")), "{decides}");
    }
    assert!(decides.contains("pyrometer"), "{decides}");
    assert!(!text.contains("Most likely missing"), "{text}");
}

/// Two effects that hide each other: warm air heats where radiation cools. Alone, radiation
/// barely changes the fit and the best single candidate (a sharp line co-flow) reaches the
/// noise with n = 0.758 [0.744, 0.772]. The true pair is better by 10.1 in ΔBIC, not beyond
/// the margin corrected for the 36 pairs tried (13.2), so it is reported beside the single
/// one and the law is no result (see `radiation_and_warm_air_never_a_wrong_law`).
#[test]
#[ignore = "known shortfall (issue 26): air_coflow_line stays named (the true pair's ΔBIC gap \
            10.1 is inside the look-elsewhere margin 13.2); the law is marked not a result"]
fn radiation_and_warm_air_together() {
    let sc = radiation_and_warm_air();
    check(
        &sc,
        &Expect {
            found: &["air_temperature_profile"],
            allowed: &["radiation", "nusselt_scale"],
            explained: true,
            truth_strengths: vec![
                ("air_temperature_profile", 100.0),
                ("air_temperature_profile.decay_length", 0.05),
                ("radiation", 0.6),
            ],
        },
    );
}

/// Radiation (0.51) brings this hardening's residuals to the noise (RMS/noise 1.02) with a law
/// 3.3 standard errors off (n = 0.863 against 0.8): only the consistency stage tells, since the
/// radiation it needs grows with the throughput and the draw-down.
#[test]
fn strain_hardening_is_none_of_the_candidates() {
    let sc = Scenario {
        name: "strain_hardening",
        hardening: 0.15,
        acceptable: vec![],
        expected: None,
        ..scenarios::control()
    };
    let (_, r, _) = run(&sc);
    let d = &r.diagnosis;
    println!(
        "GLOBAL | strain_hardening | found {:?} | verdict {:?}",
        d.found,
        match &d.verdict {
            Verdict::NoneOfTheCandidates { helps, .. } =>
                format!("none of the candidates {helps:?}"),
            v => format!("{v:?}"),
        }
    );
    assert!(
        matches!(d.verdict, Verdict::NoneOfTheCandidates { .. }),
        "{:?}",
        d.verdict
    );
    // the named effect is a stand-in: its strength differs between the experiments
    assert!(
        d.consistency.iter().any(|c| !c.consistent()),
        "{:?}",
        d.consistency
    );
    assert!(!d.law_is_a_result());
    // nothing named that removes less than half the excess misfit
    for c in d.candidates.iter().filter(|c| d.found.contains(&c.effect)) {
        assert!(
            c.share_of_excess >= 0.5,
            "{} named at {}",
            c.effect,
            c.share_of_excess
        );
    }
    let text = d.to_text();
    assert!(text.contains("NONE OF THE CANDIDATES"), "{text}");
    assert!(!text.contains("With it: n ="), "{text}");
    // the named candidate is a stand-in, not the cause: the report does not call it the most
    // likely missing effect
    let flat = text.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(!flat.contains("Most likely missing"), "{text}");
    // the best single candidate is called a stand-in, or a pair replaces it (the stand-in's
    // result settles nothing, so every pair challenges it) and the pair's law is no result
    // for the same reason
    assert!(
        flat.contains("Best candidate, a stand-in (not the cause")
            || (flat.contains("Best single candidate (a pair explains the data better")
                && flat.contains("(NOT A RESULT: the effect's strength differs between the experiments: a stand-in")),
        "{text}"
    );
}

/// Strong hardening (β = 0.3, seed 12002 of `hardening_study`): the Nusselt factor's refit
/// removes most of the excess misfit only by driving `n` to the lower bound of its range
/// (n ≈ 1e-4). It was named "most likely missing" with that law, and step 2 (with it in the
/// model) then scanned every candidate at n ≈ 0, where the fiber's strain rate explodes: 17 s
/// of the 18 s diagnosis. A refit whose `n` is below the plausible range is not credible
/// whether or not `n` sits at its bound: nothing is named, no further step runs, and the
/// verdict is "none of the candidates" without calling the model adequate. (A further step's
/// start from the weights of the step before is checked by `warm_air_and_coflow_together`.)
#[test]
fn a_refit_that_drives_n_to_its_lower_bound_is_not_named() {
    let sc = Scenario {
        name: "strong_hardening",
        hardening: 0.3,
        seed: 12_002,
        acceptable: vec![],
        expected: None,
        ..scenarios::control()
    };
    let (_, r) = diagnosed(&sc);
    let d = &r.diagnosis;
    let text = d.to_text();
    println!(
        "GLOBAL | strong_hardening | found {:?} | verdict {} | stopped {:?} | {:.1} s",
        d.found,
        d.verdict.kind(),
        d.stopped,
        d.wall_time_s
    );
    assert!(
        matches!(d.verdict, Verdict::NoneOfTheCandidates { .. }),
        "{text}"
    );
    assert!(!d.law_is_a_result());
    assert_eq!(d.stopped, None, "{text}");
    // the candidates whose refits reach n < 0.2 are flagged and not named
    let low_n: Vec<&str> = d
        .candidates
        .iter()
        .filter(|c| c.refit.as_ref().is_some_and(|f| f.n.value < 0.2))
        .map(|c| c.effect.as_str())
        .collect();
    assert!(
        !low_n.is_empty(),
        "the premise: some refit runs to n ~ 0\n{text}"
    );
    for name in &low_n {
        assert!(!d.found.iter().any(|f| f == name), "{name} named\n{text}");
        let c = d.candidate(name).expect("listed");
        assert!(
            !earns_its_place(c, DiagnoseOptions::default().earn_threshold),
            "{name} credible\n{text}"
        );
    }
    assert!(d.most_likely_missing.is_none(), "{text}");
    assert!(d.further_steps.is_empty(), "{text}");
    assert!(text.contains("No candidate earns its place"), "{text}");
    assert!(!text.contains("the model is adequate"), "{text}");
}

#[test]
fn outliers_on_top_of_a_real_effect() {
    let sc = Scenario {
        name: "outliers_with_coflow",
        faults: Faults {
            outliers: 8,
            ..Faults::none()
        },
        ..scenarios::aspirator(80.0, 0.1, 2606)
    };
    let generated = sc.generate().unwrap();
    let (set, r) = check(
        &sc,
        &Expect {
            found: &["air_coflow"],
            allowed: &[
                "air_coflow_line",
                "air_temperature_profile",
                "nusselt_scale",
            ],
            explained: true,
            truth_strengths: vec![("air_coflow", 80.0), ("air_coflow.decay_length", 0.1)],
        },
    );
    // every planted outlier flagged by the final fit, at most one false flag per 1000 points
    let flagged: Vec<(usize, usize)> = r
        .diagnosis
        .outliers()
        .iter()
        .map(|o| (o.experiment_index, o.point_index))
        .collect();
    for o in &generated.outliers {
        assert!(
            flagged.contains(o),
            "outlier {o:?} missed; flagged {flagged:?}"
        );
    }
    let points: usize = set
        .measurements
        .iter()
        .flatten()
        .map(|m| m.positions.len())
        .sum();
    let false_flags = flagged.len() - generated.outliers.len();
    assert!(
        (false_flags as f64) <= 1.0 + points as f64 / 1000.0,
        "{false_flags} false flags over {points} points"
    );
}

#[test]
fn control_with_a_noisy_take_up_names_nothing() {
    let sc = Scenario {
        name: "control_noisy_take_up",
        take_up_noise: 3.0,
        ..scenarios::control()
    };
    let (_, r, _) = run(&sc);
    let d = &r.diagnosis;
    println!("GLOBAL | control_noisy_take_up | found {:?}", d.found);
    assert!(d.found.is_empty(), "{:?}", d.found);
    assert!(
        !matches!(d.verdict, Verdict::Explained { .. }),
        "{:?}",
        d.verdict
    );
}

/// What the diagnosis says of the material law against the truth: `"flagged"` where the law is
/// marked not a result (an `implausible` warning on the fit it reports; `"flagged, range
/// misses"` where an ambiguous verdict's range of the laws misses the truth), else `"holds"` where
/// both `n` and `κ` lie within 3 standard errors of the truth, else `"WRONG"`: a wrong law
/// printed with confidence (the number issue 26 must keep at zero). Also the larger of the two
/// distances in standard errors.
fn law_outcome(r: &DiagnosisRun, sc: &Scenario) -> (&'static str, f64) {
    let d = &r.diagnosis;
    let fit = d.law_fit();
    let z = |e: &rheometer::fit::Estimate, truth: f64| (e.value - truth).abs() / e.stderr;
    let worst = z(&fit.n, sc.law.n).max(z(&fit.kappa, sc.law.kappa));
    let flagged = !d.law_is_a_result()
        || fit
            .warnings
            .iter()
            .any(|w| w.code == rheometer::fit::WarningCode::Implausible);
    if let Verdict::Ambiguous {
        n_range,
        kappa_range,
        ..
    } = &d.verdict
    {
        let holds = |r: &[f64; 2], v: f64| r[0] <= v && v <= r[1];
        if !(holds(n_range, sc.law.n) && holds(kappa_range, sc.law.kappa)) {
            return ("flagged, range misses", worst);
        }
    }
    if flagged {
        ("flagged", worst)
    } else if worst <= 3.0 {
        ("holds", worst)
    } else {
        ("WRONG", worst)
    }
}

/// The outcomes [`law_outcome`] gives, in the order the studies count them.
const LAW_OUTCOMES: [&str; 4] = ["holds", "flagged", "WRONG", "flagged, range misses"];

/// How many of `sets` laws may lie more than 3 standard errors from the truth by chance where
/// the model is right: `n` and `κ` each miss by that with probability 0.27 %, a set at most
/// 0.54 %; 2 % of the sets (at least 2) is beyond that by a binomial tail of about 2 % at 100
/// sets.
fn chance_wrong_laws(sets: usize) -> usize {
    (sets / 50).max(2)
}

/// The false-alarm rate of the whole diagnosis on effect-free data (issue 26): `N` data sets of
/// the independent model without any effect (`DIFFBVP_FALSE_ALARM_SETS`, default 100), seeds
/// and noise levels (0.8 %, 1.5 %, 3 %; take-up region 1× or 2× as noisy) varied, every
/// fourth set with six gross outliers. Counts the sets where any effect is named (and, printed
/// beside, those with the verdict "none of the candidates"); the search is calibrated to a false-alarm probability of
/// 5 % per set, so more than 10 of 100 (a binomial tail of 1 % at 5 %) fails. The law reported
/// is checked against the truth as in the power study ([`law_outcome`]). Takes ~10 s per
/// set: `cargo test --release --test diagnose global::false_alarm_rate -- --ignored --nocapture`
/// (`DIFFBVP_FALSE_ALARM_FIRST` continues a study at that set's index).
#[test]
#[ignore = "a study: ~15 min for 100 sets"]
fn false_alarm_rate_on_effect_free_sets() {
    let var = |name: &str, default: usize| -> usize {
        std::env::var(name)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(default)
    };
    let sets = var("DIFFBVP_FALSE_ALARM_SETS", 100);
    // the first set's index (to continue a study in parts: seeds 7000 + index)
    let first = var("DIFFBVP_FALSE_ALARM_FIRST", 0);
    let mut alarms = Vec::new();
    let mut nones = Vec::new();
    let mut wrong = 0;
    let t0 = Instant::now();
    for k in first..first + sets {
        let name: &'static str = Box::leak(format!("false_alarm_{k}").into_boxed_str());
        let sc = Scenario {
            name,
            seed: 7_000 + k as u64,
            noise_sd: [0.008, 0.015, 0.03][k % 3],
            take_up_noise: [1.0, 2.0][(k / 3) % 2],
            // every fourth set with gross outliers (+15 … +35 %), which are no missing effect
            faults: Faults {
                outliers: if k % 4 == 3 { 6 } else { 0 },
                ..Faults::none()
            },
            ..scenarios::control()
        };
        let (_, r) = diagnosed(&sc);
        let (law, z) = law_outcome(&r, &sc);
        // crying wolf without naming anything: "none of the candidates" on effect-free data
        if matches!(r.diagnosis.verdict, Verdict::NoneOfTheCandidates { .. }) {
            println!(
                "NONE OF THE CANDIDATES | set {k} | noise {} | outliers {} | RMS/noise {:.2}",
                sc.noise_sd,
                sc.faults.outliers,
                r.diagnosis.rms_over_noise()
            );
            nones.push(k);
        }
        if law == "WRONG" {
            println!("WRONG LAW | set {k} | {z:.1} se from the truth");
            wrong += 1;
        }
        // a pair reported beside the result is an alarm too
        let pair = r.diagnosis.pair.as_ref().map(|p| p.effects.clone());
        if !r.diagnosis.found.is_empty() || pair.is_some() {
            println!(
                "FALSE ALARM | set {k} | noise {} | {:?} | pair {pair:?}",
                sc.noise_sd, r.diagnosis.found
            );
            alarms.push(k);
        }
    }
    let rate = alarms.len() as f64 / sets as f64;
    println!(
        "FALSE ALARMS | {} of {sets} effect-free sets ({:.1} %) | verdict none of the \
         candidates {} | wrong laws printed as a result {wrong} | {:.0} s",
        alarms.len(),
        100.0 * rate,
        nones.len(),
        t0.elapsed().as_secs_f64()
    );
    assert!(
        wrong <= chance_wrong_laws(sets),
        "{wrong} wrong laws printed with confidence in {sets} sets"
    );
    assert!(
        alarms.len() * 10 <= sets,
        "{} false alarms in {sets} sets",
        alarms.len()
    );
}

/// The power of the diagnosis at twice each candidate's detection limit (issue 26), for the
/// candidates the independent model produces in their own parametrisation: radiation, a die
/// temperature offset, a mass-flow error, a gauge scale and a gauge offset. The 95 % detection
/// strength `s95` of each on the effect-free control (the diagnosis' own detection table),
/// then `N` data sets of the independent model with the effect at `2 s95`
/// (`DIFFBVP_POWER_SETS`, default 20; seeds varied, the control's noise level;
/// `DIFFBVP_POWER_EFFECTS`, a comma-separated subset; `DIFFBVP_POWER_TEXT` prints the report
/// of each miss and wrong law; `DIFFBVP_POWER_FIRST` starts at that set;
/// `DIFFBVP_POWER_TIMES` another multiple of `s95`; radiation is capped at its physical
/// limit 1). Counts the sets where
/// the effect is found, and those where it is reported in a tie with the named cause (an
/// alternative as consistent with the data, within the tie margin, with the measurement that
/// decides: a mass-flow error and a Nusselt scale have signatures with cosine −0.997 on these
/// data, and issue 26 asks for ties to be reported as ties, with no "first"; or an explanation
/// the ambiguous verdict puts beside the result, with its decisive measurement, as a gauge
/// offset beyond its physical range of ±20 µm); 80 % of the two
/// together is the target, both counts are printed. In every set, found or missed, the law the diagnosis
/// reports is checked against the truth ([`law_outcome`]): a law more than 3 standard errors
/// off and not marked as no result is a wrong law printed with confidence, allowed only as
/// often as chance gives it ([`chance_wrong_laws`]).
/// `cargo test --release --test diagnose global::power -- --ignored --nocapture`.
#[test]
#[ignore = "a study, ~20 min for 5 x 20 sets; measured (stop 36, sets 0-39): radiation \
            39/40, die_temperature_offset 40/40, mass_flow_scale 26/40 (the misses name \
            nusselt_scale; the law is no result in all 40: the twins disagree on it), \
            gauge_scale 27/40 (they name inlet_diameter; the law holds in all 40), \
            gauge_offset 17/40 (2 x s95 = 26.9 um lies beyond its +-20 um physical range; the \
            law is no result in 25): short of 80 % for three; wrong laws printed with \
            confidence 0 of 200 (12 of the first 100 before the ambiguity stage); stop 37, \
            same sets and counts: the true effect called a stand-in 0 of 149 times it was \
            found, 6 proxies named for a gauge error rejected as stand-ins; stop 42, sets \
            0-25, found + in a reported tie: mass_flow_scale 16 + 9 of 26, gauge_scale 18 + 7 \
            of 26, gauge_offset 11 + 0 of 26, WRONG 0 of 78; stop 53, sets 0-99 \
            (DIFFBVP_POWER_SETS=100, 46 min beside other work): radiation 96 + 4 tied, \
            die_temperature_offset 100 + 0, mass_flow_scale 60 + 39, gauge_scale 79 + 20, \
            gauge_offset 35 + 0 (the misses name air_temperature_profile in 33; its law no \
            result in 71), WRONG 0 of 500, the true effect a stand-in 0 times; stop 54, the \
            gauge offset with the ambiguous verdict's explanations counted as reported ties: \
            35 + 46 of 100 at 2 x s95 (26.9 um; the 19 misses all with the law no result), \
            98 + 1 at its physical limit 20 um (1.49 x s95; DIFFBVP_POWER_TIMES=1.489), WRONG 0"]
fn power_at_twice_the_detection_limit() {
    let sets: usize = std::env::var("DIFFBVP_POWER_SETS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20);
    let all = [
        "radiation",
        "die_temperature_offset",
        "mass_flow_scale",
        "gauge_scale",
        "gauge_offset",
    ];
    // the first set's index (to continue a study or look at one set: seeds 9000 + index)
    let first: usize = std::env::var("DIFFBVP_POWER_FIRST")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);
    // the strength as a multiple of s95 (2: the target; e.g. 1.49 puts the gauge
    // offset at its physical limit 20 µm)
    let times: f64 = std::env::var("DIFFBVP_POWER_TIMES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(2.0);
    let chosen: Vec<String> = std::env::var("DIFFBVP_POWER_EFFECTS")
        .map(|v| v.split(',').map(|s| s.trim().to_string()).collect())
        .unwrap_or_else(|_| all.iter().map(|s| s.to_string()).collect());
    let (_, control, _) = run(&scenarios::control());
    let mut short = Vec::new();
    let mut wrong = 0;
    let mut all_stand_ins = 0;
    for effect in all.iter().filter(|e| chosen.iter().any(|c| c == *e)) {
        let limit = control
            .diagnosis
            .detection
            .limits
            .iter()
            .find(|l| l.effect == *effect)
            .unwrap();
        // the candidate's unit: a relative change as a fraction or in per cent, µm, K, -
        let per_unit = match limit.unit.trim() {
            "%" => 0.01,
            "µm" | "um" | "μm" => 1e-6,
            _ => 1.0,
        };
        let s = times * limit.s95 * per_unit;
        let scenario = |seed: u64| match *effect {
            "radiation" => scenarios::radiating(s.min(1.0), seed),
            "die_temperature_offset" => scenarios::with_faults(
                Faults {
                    die_offset_k: s,
                    ..Faults::none()
                },
                seed,
            ),
            "mass_flow_scale" => scenarios::with_faults(
                Faults {
                    mass_flow_factor: 1.0 + s,
                    ..Faults::none()
                },
                seed,
            ),
            "gauge_scale" => scenarios::with_faults(
                Faults {
                    gauge_factor: 1.0 + s,
                    ..Faults::none()
                },
                seed,
            ),
            _ => scenarios::with_faults(
                Faults {
                    gauge_offset_m: s,
                    ..Faults::none()
                },
                seed,
            ),
        };
        let mut found = 0;
        let mut tied = 0;
        let mut stand_ins = 0;
        let mut correlated = 0;
        let mut laws = [0usize; 4];
        let t0 = Instant::now();
        for k in first..first + sets {
            let sc = scenario(9_000 + k as u64);
            let (_, r) = diagnosed(&sc);
            let (law, z) = law_outcome(&r, &sc);
            laws[LAW_OUTCOMES.iter().position(|l| *l == law).unwrap()] += 1;
            let hit = r.diagnosis.found.iter().any(|f| f == effect);
            if hit {
                found += 1;
            }
            // named in a tie: an alternative the report lists beside the named cause, as about
            // as consistent with the data, with the measurement that decides between them
            // (a tied candidate, or an explanation the ambiguous verdict puts beside the
            // result: e.g. a gauge offset whose strength lies beyond its physical range)
            let in_verdict = match &r.diagnosis.verdict {
                Verdict::Ambiguous { alternatives, .. } => {
                    alternatives.iter().any(|a| a.iter().any(|e| e == effect))
                }
                _ => false,
            };
            // the noise model took the noise for correlated along the line (issue 65 item 3):
            // elsewhere the diagnosis runs exactly as for white noise
            if r.diagnosis.base_fit.noise.correlation() > 0.0 {
                correlated += 1;
            }
            let tie = !hit
                && (in_verdict || r.diagnosis.alternatives.iter().any(|a| a.effect == *effect));
            if tie {
                tied += 1;
            }
            // a found effect called a stand-in by the consistency stage: the true one (a false
            // rejection) or another in its place (a proxy, rightly rejected)
            let rejected: Vec<&str> = r
                .diagnosis
                .consistency
                .iter()
                .filter(|c| !c.consistent())
                .map(|c| c.effect.as_str())
                .collect();
            if rejected.contains(effect) {
                stand_ins += 1;
            }
            if !rejected.is_empty() {
                println!(
                    "STAND-IN | {effect} | set {k} | {:?}",
                    r.diagnosis
                        .consistency
                        .iter()
                        .map(|c| (c.effect.as_str(), c.f_statistic, c.p_value))
                        .collect::<Vec<_>>()
                );
            }
            let odd = !hit || law == "WRONG" || law == "flagged, range misses";
            if odd && std::env::var_os("DIFFBVP_POWER_TEXT").is_some() {
                println!("{}", r.diagnosis.to_text());
            }
            if odd {
                println!(
                    "{} | {effect} | set {k} | found {:?} | most likely {:?} | law {law} ({z:.1} \
                     se from the truth)",
                    if hit {
                        "FOUND"
                    } else if tie {
                        "TIED"
                    } else {
                        "MISSED"
                    },
                    r.diagnosis.found,
                    r.diagnosis.most_likely_missing
                );
            }
        }
        println!(
            "POWER | {effect} at {times} x s95 = {times} x {:.4} {}: found in {found} of {sets} sets, in a \
             reported tie with the named cause in {tied} more | law holds {} flagged {} (range \
             misses the truth {}) WRONG {} | the true effect called a stand-in {stand_ins} | \
             noise taken for correlated in {correlated} | {:.0} s",
            limit.s95,
            limit.unit,
            laws[0],
            laws[1] + laws[3],
            laws[3],
            laws[2],
            t0.elapsed().as_secs_f64()
        );
        wrong += laws[2];
        all_stand_ins += stand_ins;
        if (found + tied) * 10 < sets * 8 {
            short.push(format!("{effect}: {found} + {tied} tied of {sets}"));
        }
    }
    let all_sets = sets
        * all
            .iter()
            .filter(|e| chosen.iter().any(|c| c == *e))
            .count();
    assert!(
        wrong <= chance_wrong_laws(all_sets),
        "{wrong} wrong laws printed with confidence in {all_sets} sets"
    );
    // the consistency test rejects a true effect with probability 1 % (its level)
    assert!(
        all_stand_ins <= chance_stand_ins(all_sets),
        "the true effect called a stand-in in {all_stand_ins} of {all_sets} sets"
    );
    assert!(short.is_empty(), "power below 80 %: {short:?}");
}

/// How many of `sets` true effects the consistency stage may call stand-ins by chance: its
/// level is 1 %; 4 % of the sets (at least 3) is beyond that by a binomial tail of 0.4 % at 100
/// sets.
fn chance_stand_ins(sets: usize) -> usize {
    (sets / 25).max(3)
}

/// Strain hardening, an effect no candidate describes, at several strengths and seeds
/// (`DIFFBVP_HARDENING_SETS` per strength, default 10; strengths `β` = 0.1, 0.15, 0.3 in
/// `η₀ exp(β ε_H)`): how often the diagnosis says "none of the candidates" (directly, or because
/// the effect it would name is a stand-in whose strength differs between the experiments), how
/// often it names a candidate, and whether the law it reports holds ([`law_outcome`]); wrong
/// laws printed with confidence are allowed only as often as chance gives them.
/// `cargo test --release --test diagnose global::hardening_study -- --ignored --nocapture`.
#[test]
#[ignore = "a study, ~8 min for 3 x 10 sets; measured (stop 37): beta 0.1 stand-in 9/10 \
            (1 ambiguous), 0.15 stand-in 9/10 (1 none of the candidates), 0.3 none of the \
            candidates 10/10; no law printed as a result in the 30"]
fn hardening_study() {
    let sets: usize = std::env::var("DIFFBVP_HARDENING_SETS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(10);
    let mut wrong = 0;
    for beta in [0.1, 0.15, 0.3] {
        let (mut none, mut stand_in, mut named) = (0, 0, 0);
        let mut laws = [0usize; 4];
        let t0 = Instant::now();
        for k in 0..sets {
            let sc = Scenario {
                name: "hardening_study",
                hardening: beta,
                seed: 12_000 + k as u64,
                acceptable: vec![],
                expected: None,
                ..scenarios::control()
            };
            let (_, r) = diagnosed(&sc);
            let d = &r.diagnosis;
            let (law, z) = law_outcome(&r, &sc);
            laws[LAW_OUTCOMES.iter().position(|l| *l == law).unwrap()] += 1;
            match &d.verdict {
                Verdict::NoneOfTheCandidates { stand_ins, .. } if !stand_ins.is_empty() => {
                    stand_in += 1
                }
                Verdict::NoneOfTheCandidates { .. } => none += 1,
                Verdict::Explained { .. } | Verdict::Ambiguous { .. } => named += 1,
                Verdict::Adequate => {}
            }
            println!(
                "HARDENING | beta {beta} | set {k} | verdict {} | found {:?} | consistency {:?} | \
                 law {law} ({z:.1} se from the truth)",
                d.verdict.kind(),
                d.found,
                d.consistency
                    .iter()
                    .map(|c| (c.effect.as_str(), c.f_statistic, c.p_value))
                    .collect::<Vec<_>>()
            );
        }
        println!(
            "HARDENING | beta {beta}: none of the candidates {none}, by a stand-in {stand_in}, \
             a candidate named {named}, adequate {} of {sets} | law holds {} flagged {} WRONG {} \
             | {:.0} s",
            sets - none - stand_in - named,
            laws[0],
            laws[1] + laws[3],
            laws[2],
            t0.elapsed().as_secs_f64()
        );
        wrong += laws[2];
    }
    assert!(
        wrong <= chance_wrong_laws(3 * sets),
        "{wrong} wrong laws printed with confidence in {} sets",
        3 * sets
    );
}

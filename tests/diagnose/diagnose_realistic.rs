//! Issue 11's acceptance tests for `diagnose`, on data made by the independent model of
//! `tests/independent/` (not the project's simulator or candidate terms): hidden effects of
//! realistic strengths and shapes unlike the candidates' defaults, process and instrument faults,
//! outliers, two effects at once, another material, and a control. Each test loads the
//! generated TOML + CSV with the crate's loader, runs `diagnose` with the default options and
//! checks: the cause ranked first is an acceptable name, its strength within 3 standard errors of
//! the truth (where its parametrisation is the truth's), RMS after within 20 % of the noise σ,
//! the true (n, κ) inside the reported 95 % CIs after adding it, nothing named without an effect,
//! and never a strength at a bound or outside the physical range.
//! Tests the project cannot pass yet are `#[ignore]`d with the reason; each prints one
//! `BASELINE` line (run with `--nocapture`).

use crate::independent;
use crate::shared;

use diffbvp::least_squares::Loss;
use independent::dataset::{Faults, Scenario};
use independent::model::AirHeat;
use independent::scenarios::{self, NOISE_SD};
use rheometer::data::noise_model::NoiseModel;
use rheometer::diagnostics::Verdict;
use rheometer::diagnostics::{Candidate, DiagnoseOptions, DiagnosisRun};

/// The diagnosis of `sc` with the default options (made once per test binary and shared by
/// the tests that ask for the same scenario, [`shared::diagnosed`]), printing the baseline line.
fn run(sc: &Scenario) -> DiagnosisRun {
    let d = shared::diagnosed(sc);
    print_baseline(sc, &d.run, d.seconds);
    d.run.clone()
}

/// [`run`] with the diagnosis' `options` (not shared).
fn run_with(sc: &Scenario, options: &DiagnoseOptions) -> DiagnosisRun {
    let d = shared::diagnose_with(sc, options);
    print_baseline(sc, &d.run, d.seconds);
    d.run
}

/// Prints the diagnosis `r` of `sc` (made in `t_diag` seconds) and its `BASELINE` and
/// `ALTERNATIVES` lines.
fn print_baseline(sc: &Scenario, r: &DiagnosisRun, t_diag: f64) {
    let d = &r.diagnosis;
    println!("{}", d.to_text());
    let b = &d.base_fit;
    let top = d.candidates.first();
    println!(
        "BASELINE | {} | base n {:.3} κ {:.3} RMS {:.2} % noise {:.2} % ({}) sys {} | named {:?} | top {} = {:.4} ± {:.4} {} at_bound {:?} ΔBIC {:.1} RMS after {:.2} % n {:.3} κ {:.3} | diagnose {:.1} s",
        sc.name,
        b.n.value,
        b.kappa.value,
        100.0 * b.rms_relative_residual,
        100.0 * d.noise_level(),
        d.base_fit.noise.estimator,
        d.systematic,
        d.most_likely_missing,
        top.map_or("-", |c| c.effect.as_str()),
        top.map_or(f64::NAN, |c| c.strength()),
        top.map_or(f64::NAN, |c| c.stderr_strength()),
        top.map_or("", |c| c.unit.as_str()),
        top.map(|c| c.at_bound().iter().map(|a| a.parameter.clone()).collect::<Vec<_>>()),
        top.map_or(f64::NAN, |c| c.delta_bic),
        100.0 * top.map_or(f64::NAN, |c| c.rms_relative_residual_after()),
        top.map_or(f64::NAN, |c| c.n()),
        top.map_or(f64::NAN, |c| c.kappa()),
        t_diag
    );
    println!(
        "ALTERNATIVES | {} | named {:?} | {}",
        sc.name,
        d.most_likely_missing,
        if d.alternatives.is_empty() {
            "none".to_string()
        } else {
            d.alternatives
                .iter()
                .map(|a| {
                    format!(
                        "{} (gap {:.1}, cos {:+.3}, n {:.4} κ {:.4}, shifts {:+.2}/{:+.2} se, robust {})",
                        a.effect,
                        a.delta_bic_gap,
                        a.signature_cosine,
                        d.candidate(&a.effect).map_or(f64::NAN, |c| c.n()),
                        d.candidate(&a.effect).map_or(f64::NAN, |c| c.kappa()),
                        a.n_shift_se,
                        a.kappa_shift_se,
                        a.material_robust
                    )
                })
                .collect::<Vec<_>>()
                .join("; ")
        }
    );
}

/// A named effect is never one whose strength sits at a bound or outside the physical range,
/// except where the range is within 1.96 standard errors: at a search bound beyond the physical
/// range, a strength the data do not bound on that side (a short co-flow's speed trades off
/// against its decay length) is consistent with a physical value.
fn assert_named_is_credible(r: &DiagnosisRun) {
    let d = &r.diagnosis;
    let Some(named) = &d.most_likely_missing else {
        return;
    };
    let c = d
        .candidates
        .iter()
        .find(|c| &c.effect == named)
        .expect("the named candidate is listed");
    let effect: rheometer::model::Effect = named.parse().unwrap();
    let (plo, phi) = effect.physical_range();
    for a in c.at_bound().iter().filter(|a| &a.parameter == named) {
        let beyond = (a.bound - phi).max(plo - a.bound);
        assert!(
            beyond > 0.0 && beyond <= 1.96 * c.stderr_strength(),
            "{named} named with its strength at a bound inside its physical range [{plo}, {phi}] \
             or too far beyond it: {a:?}, standard error {}",
            c.stderr_strength()
        );
    }
    if named == "radiation" {
        // inside [0, 1], or beyond by less than 1.96 standard errors (consistent with it: a
        // true ε near 1 is estimated beyond it half the time)
        let beyond = (c.strength() - 1.0).max(-c.strength()).max(0.0);
        assert!(
            beyond <= 1.96 * c.stderr_strength(),
            "radiation named with ε = {} ± {}",
            c.strength(),
            c.stderr_strength()
        );
    }
}

/// The acceptance criteria for a scenario with a hidden cause.
fn assert_found(sc: &Scenario, r: &DiagnosisRun) {
    assert_found_but_ci(sc, r);
    assert_truth_in_ci(sc, &r.diagnosis.candidates[0]);
}

/// The true (n, κ) inside the 95 % CIs of refit `c`.
fn assert_truth_in_ci(sc: &Scenario, c: &Candidate) {
    let (n, k) = (sc.law.n, sc.law.kappa);
    assert!(
        c.ci95_n()[0] <= n && n <= c.ci95_n()[1],
        "{}: n = {n} outside {:?} with {}",
        sc.name,
        c.ci95_n(),
        c.effect
    );
    assert!(
        c.ci95_kappa()[0] <= k && k <= c.ci95_kappa()[1],
        "{}: κ = {k} outside {:?} with {}",
        sc.name,
        c.ci95_kappa(),
        c.effect
    );
}

/// Refit `c` recovers the truth: its strength within 3 standard errors of `expected` (in its
/// unit, where known) and its RMS after within 20 % of the noise.
fn assert_refit_recovers(sc: &Scenario, c: &Candidate, expected: Option<f64>) {
    if let Some(truth) = expected {
        assert!(
            (c.strength() - truth).abs() <= 3.0 * c.stderr_strength(),
            "{}: {} = {} ± {} {}, truth {truth}",
            sc.name,
            c.effect,
            c.strength(),
            c.stderr_strength(),
            c.unit
        );
    }
    let ratio = c.rms_relative_residual_after() / NOISE_SD;
    assert!(
        (ratio - 1.0).abs() <= 0.2,
        "{}: RMS after / noise = {ratio}",
        sc.name
    );
}

/// The acceptance criteria for a scenario with a hidden cause, except the true (n, κ) inside
/// the CIs after adding it.
fn assert_found_but_ci(sc: &Scenario, r: &DiagnosisRun) {
    let d = &r.diagnosis;
    assert_named_is_credible(r);
    let named = d.most_likely_missing.as_deref();
    assert!(
        named.is_some_and(|n| sc.acceptable.contains(&n)),
        "{}: named {named:?}, acceptable {:?}; ranking {:?}",
        sc.name,
        sc.acceptable,
        d.candidates.iter().map(|c| &c.effect).collect::<Vec<_>>()
    );
    let c = &d.candidates[0];
    assert_eq!(Some(c.effect.as_str()), named, "named is not ranked first");
    let expected = sc
        .expected
        .filter(|(name, _)| *name == c.effect)
        .and_then(|(_, e)| e.in_unit(&c.unit, c.strength()));
    assert_refit_recovers(sc, c, expected);
}

/// Whether the true (n, κ) lie inside the 95 % CIs reported with the cause ranked first.
fn truth_in_ci(sc: &Scenario, r: &DiagnosisRun) -> bool {
    let c = &r.diagnosis.candidates[0];
    let (n, k) = (sc.law.n, sc.law.kappa);
    c.ci95_n()[0] <= n && n <= c.ci95_n()[1] && c.ci95_kappa()[0] <= k && k <= c.ci95_kappa()[1]
}

/// The acceptance criteria where the data cannot separate the truth from another cause: the
/// truth (the scenario's expected candidate) is named, or listed among the alternatives (a tie
/// with the named one, `ΔBIC` gap below the tie margin); its own refit then meets the criteria
/// of [`assert_found`]: strength within 3 standard errors of the truth, RMS after within 20 %
/// of the noise, the true (n, κ) inside its 95 % CIs.
fn assert_named_or_tied(sc: &Scenario, r: &DiagnosisRun) {
    let d = &r.diagnosis;
    assert_named_is_credible(r);
    let (truth, strength) = sc.expected.expect("the scenario has an expected candidate");
    let named = d.most_likely_missing.as_deref();
    let tied = d.alternatives.iter().find(|a| a.effect == truth);
    assert!(
        named == Some(truth) || tied.is_some(),
        "{}: {truth} neither named ({named:?}) nor an alternative ({:?})",
        sc.name,
        d.alternatives.iter().map(|a| &a.effect).collect::<Vec<_>>()
    );
    let c = d
        .candidates
        .iter()
        .find(|c| c.effect == truth)
        .expect("the truth is a candidate");
    if let (Some(a), Some(n)) = (tied, named) {
        let best = &d.candidates[0];
        assert_eq!(best.effect, n, "named is not ranked first");
        let margin = DiagnoseOptions::default().tie_margin;
        assert!(
            c.delta_bic - best.delta_bic < margin,
            "{}: {truth} listed with a gap {} ≥ {margin}",
            sc.name,
            c.delta_bic - best.delta_bic
        );
        assert_eq!(a.effect, c.effect, "the alternative is its candidate");
    }
    let expected = strength
        .in_unit(&c.unit, c.strength())
        .expect("the truth's unit");
    assert_refit_recovers(sc, c, Some(expected));
    assert_truth_in_ci(sc, c);
}

/// The criteria without a physical cause: nothing named, the base fit covers the truth, the
/// noise is estimated within 20 %.
fn assert_nothing_missing(sc: &Scenario, r: &DiagnosisRun) {
    let d = &r.diagnosis;
    assert_named_is_credible(r);
    assert!(
        d.most_likely_missing.is_none(),
        "{}: named {:?}",
        sc.name,
        d.most_likely_missing
    );
    assert!(
        d.alternatives.is_empty(),
        "{}: alternatives {:?}",
        sc.name,
        d.alternatives
    );
    let b = &d.base_fit;
    let (n, k) = (sc.law.n, sc.law.kappa);
    assert!(
        b.n.ci95[0] <= n && n <= b.n.ci95[1],
        "n {n} outside {:?}",
        b.n.ci95
    );
    assert!(
        b.kappa.ci95[0] <= k && k <= b.kappa.ci95[1],
        "κ {k} outside {:?}",
        b.kappa.ci95
    );
    // the second-difference estimator of the noise level; where the noise model reads the
    // white noise of a draw as correlated along the line (the outliers' seed 112: ρ̂ = 0.29,
    // 2.9 standard errors; 3 of 100 clean white sets in `noise_rates`), the level it reports is
    // that estimate times the AR(1) factor, printed with the correlation, and is not checked
    // here
    let rho = d.base_fit.noise.correlation();
    let ratio = d.noise_level() / NoiseModel::level_factor(rho) / NOISE_SD;
    assert!((ratio - 1.0).abs() <= 0.2, "noise estimate / σ = {ratio}");
}

#[test]
fn control_names_nothing() {
    let sc = scenarios::control();
    assert_nothing_missing(&sc, &run(&sc));
}

/// Also: the exponential and the inverse-square tail fit these data about equally well (the
/// truth's decay is neither); the report keeps the exponential and gives the other's estimate
/// as the shape's systematic uncertainty (ignored from the global refits until stop 52, when the
/// other tail was no longer within the tie margin; measured at stop 53: 42.96 ± 8.14 m/s,
/// ΔBIC −865.4, RMS after 1.45 %, the inverse-square tail as the shape alternative).
#[test]
fn strong_aspirator_coflow_is_found() {
    let sc = scenarios::aspirator_strong();
    let r = run(&sc);
    assert_found(&sc, &r);
    let c = &r.diagnosis.candidates[0];
    let tail = |shape: &[rheometer::diagnostics::ShapeParameter]| {
        shape.iter().find(|p| p.name == "tail").map(|p| p.value)
    };
    let a = c
        .shape_alternative
        .as_ref()
        .expect("the other tail as a shape alternative");
    let margin = DiagnoseOptions::default().tie_margin;
    assert!(a.delta_bic_gap.abs() < margin, "gap {}", a.delta_bic_gap);
    assert_eq!(tail(&c.shape()), Some(0.0));
    let other = a.refit.effect(&c.effect).expect("the effect in its refit");
    let other_shape: Vec<_> = other
        .shapes
        .iter()
        .map(|sh| rheometer::diagnostics::ShapeParameter {
            name: sh.name.clone(),
            value: sh.value,
            unit: sh.unit.clone(),
        })
        .collect();
    assert_eq!(tail(&other_shape), Some(0.5));
    assert!(r
        .diagnosis
        .to_text()
        .contains("SHAPE: these data cannot choose the shape of air_coflow"));
}

#[test]
fn short_aspirator_coflow_is_found() {
    let sc = scenarios::aspirator_short();
    assert_found(&sc, &run(&sc));
}

#[test]
fn coflow_along_the_line_is_found() {
    let sc = scenarios::coflow_line();
    assert_found(&sc, &run(&sc));
}

#[test]
fn warm_air_inverse_square_is_found() {
    let sc = scenarios::warm_air_inverse_square();
    assert_found(&sc, &run(&sc));
}

#[test]
fn warm_air_linear_is_found() {
    let sc = scenarios::warm_air_linear();
    assert_found(&sc, &run(&sc));
}

#[test]
fn radiation_is_found() {
    let sc = scenarios::radiation();
    assert_found(&sc, &run(&sc));
}

#[test]
#[ignore = "chance miss of this seed: die_temperature_offset named (-9.97 ± 2.30 K, truth -10 K), n's CI [0.7805, 0.7997] misses 0.8 by 2.0 se; over 40 seeds the CIs hold n in 39, κ in 39 (tests/ci_coverage.rs); see cold_die_is_found_over_seeds"]
fn cold_die_is_found() {
    let sc = scenarios::die_colder();
    assert_found(&sc, &run(&sc));
}

/// The cold die over three noise realisations (the scenario's seed and two more): every
/// criterion but the CI on each, and the true (n, κ) inside the reported CIs on at least two of
/// the three. With the 95 % CIs' measured joint miss rate (2 of 40 seeds, tests/ci_coverage.rs),
/// two misses of three happen by chance with probability 3 p² − 2 p³ ≈ 0.7 % at p = 0.05.
#[test]
#[ignore = "issue 11 open: detection of a 10 K cold die is itself marginal: it lies between the control's detection limits s50 = 9.1 K and s95 = 13.1 K (tests/detection_limits.rs), so it is named on average, not with 95 %: seed 2108 names nothing (mass_flow_scale first, dBIC -8.5 > -10), so 1 of 3 seeds passes (108 misses n's CI by chance, 1108 passes)"]
fn cold_die_is_found_over_seeds() {
    let base = scenarios::die_colder();
    let held = [0u64, 1000, 2000]
        .iter()
        .filter(|&&k| {
            let sc = Scenario {
                seed: base.seed + k,
                ..base.clone()
            };
            let r = run(&sc);
            assert_found_but_ci(&sc, &r);
            truth_in_ci(&sc, &r)
        })
        .count();
    assert!(held >= 2, "true (n, κ) inside the CIs in {held} of 3 seeds");
}

#[test]
#[ignore = "issue 11 open: a 4 % low mass flow is below the detection limit: the control reports s50 = 6.7 %, s95 = 9.6 % (tests/detection_limits.rs; RMS 1.33 % < noise, nothing named; the report says a mass-flow error below 9.6 % could be missed and the error budget covers it)"]
fn low_mass_flow_is_found() {
    let sc = scenarios::mass_flow_low();
    assert_found(&sc, &run(&sc));
}

/// Its premise, the truth ranked first, is out of reach of these data (a tie with
/// `inlet_diameter`); `gauge_scale_is_named_or_tied` tests the tie.
#[test]
#[ignore = "issue 11: not separable by these data: inlet_diameter (0.034 ± 0.005) is named, gauge_scale (0.033 ± 0.005) second by dBIC 2.1; noise-free the truth wins by only lambda = 1.22 chi2 (first with p = 0.71 at 1.5 % noise; 95 % needs |g| >= 8.9 %), see tests/diagnose_separability.rs"]
fn gauge_scale_is_found() {
    let sc = scenarios::gauge_scale();
    assert_found(&sc, &run(&sc));
}

/// The gauge reading 3 % high, judged as the tie it is: `gauge_scale` named or listed as an
/// alternative to the named cause (here `inlet_diameter`, signatures cos ≈ +0.99), and its own
/// refit recovering the truth.
#[test]
fn gauge_scale_is_named_or_tied() {
    let sc = scenarios::gauge_scale();
    let r = run(&sc);
    assert_named_or_tied(&sc, &r);
    // the report says so in words
    let text = r.diagnosis.to_text();
    if r.diagnosis.most_likely_missing.as_deref() != Some("gauge_scale") {
        assert!(
            text.contains("or, about as consistent with these data, gauge_scale"),
            "{text}"
        );
        assert!(text.contains("calibrate the diameter gauge"), "{text}");
    }
}

#[test]
#[ignore = "issue 11 open: a 3 um gauge offset is below the detection limit: the control reports s50 = 9.3 um, s95 = 13.4 um (tests/detection_limits.rs; gauge_offset 5.3 ± 2.4 um, dBIC +0.4); 1.5 s95 is named"]
fn gauge_offset_is_found() {
    let sc = scenarios::gauge_offset();
    assert_found(&sc, &run(&sc));
}

#[test]
fn outliers_name_no_physics() {
    let sc = scenarios::outliers();
    let r = run(&sc);
    assert_nothing_missing(&sc, &r);
    assert_outliers_are_only_outliers(&sc, &r);
    // left out of the fits: the diagnosis weights them by its noise model, not a loss
    assert!(r.diagnosis.robust.is_none());
}

#[test]
fn outliers_under_a_robust_loss_name_no_physics() {
    let sc = Scenario {
        seed: 2611,
        ..scenarios::outliers()
    };
    let mut options = DiagnoseOptions::default();
    options.identify.loss = Loss::Huber;
    let r = run_with(&sc, &options);
    assert_nothing_missing(&sc, &r);
    assert_outliers_are_only_outliers(&sc, &r);
    let w = r
        .diagnosis
        .robust
        .as_ref()
        .expect("the weights of the huber loss");
    assert_eq!(w.loss, Loss::Huber);
    let planted = sc.generate().unwrap().outliers.len();
    assert!(w.down_weighted >= planted, "{w:?}");
    // huber weighs a point by C/|r| against its local margin: a planted outlier (a reading
    // 15–35 % high, a relative residual of at most −13 %) weighs at most C/0.13, twice that
    // where the local noise (and so the margin) is up to twice the level
    assert!(w.smallest_weight <= 2.0 * w.f_scale / 0.13, "{w:?}");
    assert!(r
        .diagnosis
        .to_text()
        .contains("Loss huber: the points are weighted"));
}

/// Gross outliers on a correct model: the residuals are noise once they are left out (the fit
/// the diagnosis judges is not bent by them), the verdict "adequate" with the law a result,
/// and every planted outlier flagged.
fn assert_outliers_are_only_outliers(sc: &Scenario, r: &DiagnosisRun) {
    let d = &r.diagnosis;
    assert!(!d.systematic, "{}", d.to_text());
    assert!(matches!(d.verdict, Verdict::Adequate), "{}", d.to_text());
    assert!(d.law_is_a_result());
    let flagged: Vec<(usize, usize)> = d
        .outliers()
        .iter()
        .map(|o| (o.experiment_index, o.point_index))
        .collect();
    for o in &sc.generate().unwrap().outliers {
        assert!(
            flagged.contains(o),
            "outlier {o:?} missed; flagged {flagged:?}"
        );
    }
}

#[test]
fn radiation_and_gauge_scale_together() {
    let sc = scenarios::radiation_and_gauge();
    assert_found(&sc, &run(&sc));
}

#[test]
fn other_material_with_radiation() {
    let sc = scenarios::other_material();
    assert_found(&sc, &run(&sc));
}

// The corners of issue 11's ranges (co-flow 30–300 m/s with decay lengths 0.03–0.3 m, warm air
// 50–200 K, radiation ε 0.3–0.95, die 5–15 K off, gauge 2–5 % off, 5–10 outliers), each on its
// own seed: found where the data carry the effect above its detection limit, covered by the
// reported detection limits where they do not.

/// A 300 m/s aspirator over 0.3 m: air_coflow is named and the verdict is "explained" (RMS/noise
/// 1.08), but the data hardly bound the jet's speed (measured: 600 ± 3100 m/s at its search
/// bound, 0.4 standard errors beyond the physical limit 400 m/s, which the report notes) and the
/// law is wide (n = 0.63 ± 0.24, κ = 10 ± 40). It meets the acceptance criteria: the strength
/// within 3 standard errors of the truth, RMS after within 20 % of the noise, the truth inside
/// the intervals. And what the diagnosis must never do while the refit's `κ` may end at a bound
/// (until stop 51 it ended at its lower bound 7 with the verdict "explained"): print that law as
/// a result. Its law either holds the truth in its intervals, or is at a bound and marked "NOT A
/// RESULT" (text, and `Diagnosis::law_is_a_result` false). One diagnosis for both checks.
#[test]
fn aspirator_300_m_s_long_is_found_and_never_gives_a_law_at_a_bound_as_a_result() {
    let sc = scenarios::aspirator(300.0, 0.3, 121);
    let r = run(&sc);
    let d = &r.diagnosis;
    match d.law_at_bound() {
        Some(b) => {
            assert!(!d.law_is_a_result(), "{:?}", d.verdict);
            let text = d.to_text();
            let mark = format!(
                "NOT A RESULT: {} is at its {} bound",
                b.parameter,
                b.side.name()
            );
            assert!(text.contains(&mark), "no '{mark}' in:\n{text}");
        }
        None if d.law_is_a_result() => assert_truth_in_ci(&sc, &d.candidates[0]),
        None => {}
    }
    assert_found(&sc, &r);
}

#[test]
fn aspirator_30_m_s_long_is_found() {
    let sc = scenarios::aspirator(30.0, 0.3, 122);
    assert_found(&sc, &run(&sc));
}

#[test]
fn aspirator_30_m_s_short_is_found() {
    let sc = scenarios::aspirator(30.0, 0.03, 133);
    assert_found(&sc, &run(&sc));
}

#[test]
fn aspirator_300_m_s_short_is_found() {
    let sc = scenarios::aspirator(300.0, 0.03, 123);
    assert_found(&sc, &run(&sc));
}

#[test]
fn warm_air_200_k_is_found() {
    let sc = scenarios::warm_air(
        AirHeat::InverseSquare {
            excess: 200.0,
            length: 0.03,
        },
        124,
    );
    assert_found(&sc, &run(&sc));
}

#[test]
fn warm_air_50_k_linear_is_found() {
    let sc = scenarios::warm_air(
        AirHeat::Linear {
            excess: 50.0,
            end: 0.15,
        },
        125,
    );
    assert_found(&sc, &run(&sc));
}

#[test]
fn weak_radiation_is_found() {
    let sc = scenarios::radiating(0.3, 126);
    assert_found(&sc, &run(&sc));
}

/// ε = 0.95: the estimate may land beyond 1 by noise (1.02 ± 0.09 here); within 1.96 standard
/// errors it is consistent with physics and named, with a note.
#[test]
fn near_black_radiation_is_found() {
    let sc = scenarios::radiating(0.95, 127);
    let r = run(&sc);
    assert_found(&sc, &r);
    let c = &r.diagnosis.candidates[0];
    if c.strength() > 1.0 {
        let text = r.diagnosis.to_text();
        assert!(text.contains("beyond its physical limit 1 by"), "{text}");
    }
}

#[test]
fn die_15_k_colder_is_found() {
    let sc = scenarios::with_faults(
        Faults {
            die_offset_k: -15.0,
            ..Faults::none()
        },
        128,
    );
    assert_found(&sc, &run(&sc));
}

#[test]
fn gauge_5_percent_high_is_named_or_tied() {
    let sc = scenarios::with_faults(
        Faults {
            gauge_factor: 1.05,
            ..Faults::none()
        },
        129,
    );
    assert_named_or_tied(&sc, &run(&sc));
}

#[test]
fn ten_outliers_name_no_physics() {
    let sc = scenarios::with_faults(
        Faults {
            outliers: 10,
            ..Faults::none()
        },
        131,
    );
    assert_nothing_missing(&sc, &run(&sc));
}

/// A fault below the data's detection limit: if nothing is named, the report's 95 % detection
/// limit of the fault's candidate must exceed the fault (so its words say such a fault could
/// be missed); if it is named, the criteria of a found effect.
fn assert_found_or_below_limit(sc: &Scenario, r: &DiagnosisRun) {
    let d = &r.diagnosis;
    let (truth, expected) = sc.expected.expect("the scenario has an expected candidate");
    if d.most_likely_missing.is_some() {
        assert_found(sc, r);
        return;
    }
    let l = d
        .detection
        .limits
        .iter()
        .find(|l| l.effect == truth)
        .expect("a detection limit for the fault's candidate");
    let size = expected
        .in_unit(&l.unit, 0.0)
        .expect("the truth's unit")
        .abs();
    println!(
        "LIMIT | {} | {truth}: fault {size} {}, s50 {} s95 {}",
        sc.name, l.unit, l.s50, l.s95
    );
    assert!(
        l.s95 > size,
        "{}: nothing named, but the reported 95 % limit {} {} of {truth} does not cover the \
         fault {size}",
        sc.name,
        l.s95,
        l.unit
    );
    assert!(d.detection.words().is_some_and(|w| w.contains(truth)));
}

#[test]
fn die_5_k_warmer_is_found_or_below_the_limit() {
    let sc = scenarios::with_faults(
        Faults {
            die_offset_k: 5.0,
            ..Faults::none()
        },
        132,
    );
    assert_found_or_below_limit(&sc, &run(&sc));
}

#[test]
fn gauge_2_percent_low_is_found_or_below_the_limit() {
    let sc = scenarios::with_faults(
        Faults {
            gauge_factor: 0.98,
            ..Faults::none()
        },
        130,
    );
    assert_found_or_below_limit(&sc, &run(&sc));
}

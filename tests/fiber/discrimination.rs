//! Design for discrimination validated by simulation (issue 30): a real mass-flow error of
//! −8 % on the shipped set's nine experiments, data made by the independent model of
//! `tests/independent` (not the crate's simulator), 1.5 % noise. On these conditions the
//! mass-flow error ties with a scaled Nusselt law (nearly parallel signatures). The rivals
//! (base model + `mass_flow_scale`, base model + `nusselt_scale`) are fitted to one realisation
//! (the user's data) and the design ranks a grid of candidate experiments by how well each
//! tells them apart. Then, over noise replicates, each data set is refitted with the base model
//! and both rivals (a) as it is, (b) with the top-ranked candidate added and (c) with a
//! uniformly drawn feasible candidate added, every new experiment simulated with noise by the
//! independent model at the true (−8 %) mass flow.
//!
//! Success on a replicate is diagnose's verdict for the true cause: `mass_flow_scale` ranked
//! first of the two rivals (lower BIC; same number of parameters) and earning its place,
//! `ΔBIC = N ln(J/J_base) + ln N < −10` against the base model. The stricter "separated" also
//! needs the rival beaten by more than 10: `N ln(J_mf/J_nu) < −10`. Each run prints one
//! `DISCRIMINATION` line per arm (`--nocapture`).

use crate::independent::dataset::{Faults, Scenario};
use crate::independent::model::Line;
use crate::independent::rng::Rng;
use crate::independent::scenarios::with_faults;
use crate::independent::solve::diameters;
use crate::noisy_data::noisy_set;
use rayon::prelude::*;
use rheometer::data::input::load_experiments_with;
use rheometer::data::input::LoadOptions;
use rheometer::design::{
    design_for_discrimination, CandidateGrid, Discrimination, DiscriminationRequest, Rival,
    TakeUpAxis,
};
use rheometer::fit::{FitStart, Identification, IdentifyOptions, Rheometer};
use rheometer::model::{simulate_params, SimulateOptions};
use rheometer::model::{Effect, EffectSetting, LawChoice, ModelSpec};
use rheometer::model::{Experiment, ExperimentSet};
use std::time::Instant;

/// True mass flow over the nominal one.
const MASS_FLOW_FACTOR: f64 = 0.92;
/// The effects of the two rivals; the first is the truth.
const RIVALS: [&str; 2] = ["mass_flow_scale", "nusselt_scale"];
/// diagnose's earn threshold and the separation margin.
const DBIC: f64 = -10.0;

fn scenario() -> Scenario {
    with_faults(
        Faults {
            mass_flow_factor: MASS_FLOW_FACTOR,
            ..Faults::none()
        },
        4101,
    )
}

/// The base model (index 0) and the two rivals.
fn specs() -> Vec<ModelSpec> {
    let base = ModelSpec::new(LawChoice::Carreau);
    let mut v = vec![base.clone()];
    for r in RIVALS {
        let e: Effect = r.parse().unwrap();
        v.push(base.clone().with(EffectSetting::fitted(e)));
    }
    v
}

fn options() -> IdentifyOptions {
    IdentifyOptions {
        max_discretisation_shift: None,
        ..IdentifyOptions::default()
    }
}

/// The user's data (the generated realisation), the noise-free truth and the fits of the
/// three models to it.
struct Reference {
    scenario: Scenario,
    clean: Vec<Vec<f64>>,
    set: ExperimentSet,
    rheometers: Vec<Rheometer>,
    fits: Vec<Identification>,
}

fn reference() -> Reference {
    let scenario = scenario();
    let generated = scenario.generate().unwrap();
    let set = load_experiments_with(&generated.toml, &LoadOptions::default())
        .unwrap()
        .set;
    let rheometers: Vec<Rheometer> = specs()
        .into_iter()
        .map(|s| Rheometer::with_spec(&set, s).unwrap())
        .collect();
    let start = rheometers[0].start_heuristic(&options()).unwrap().start;
    let fits = rheometers
        .iter()
        .map(|rh| rh.identify(start, &IdentifyOptions::default()).unwrap())
        .collect();
    Reference {
        scenario,
        clean: generated.clean,
        set,
        rheometers,
        fits,
    }
}

fn grid(set: &ExperimentSet) -> CandidateGrid {
    let q: Vec<f64> = set.experiments.iter().map(|e| e.mass_flow).collect();
    let (qlo, qhi) = (
        q.iter().copied().fold(f64::INFINITY, f64::min),
        q.iter().copied().fold(0.0, f64::max),
    );
    CandidateGrid {
        template: 4,
        mass_flows: diffbvp::mesh::linspace(0.5 * qlo, 2.0 * qhi, 6),
        take_up: TakeUpAxis::Diameter(diffbvp::mesh::linspace(35e-6, 230e-6, 6)),
        positions: None,
    }
}

/// A candidate added to the current experiments: its nominal experiment and noise-free true
/// diameters (independent model, true mass flow).
#[derive(Clone)]
struct Added {
    experiment: Experiment,
    positions: Vec<f64>,
    clean: Vec<f64>,
}

fn added(r: &Reference, d: &Discrimination, index: usize) -> Result<Added, String> {
    let c = &d.candidates[index].candidate;
    let template = d.grid.template;
    let positions = r.scenario.experiments[template].positions.clone();
    let line = Line {
        mass_flow: c.mass_flow * MASS_FLOW_FACTOR,
        take_up_diameter: c.take_up,
        ..r.scenario.line(template)
    };
    let clean = diameters(&line, &positions)?;
    Ok(Added {
        experiment: Experiment {
            name: "added".into(),
            mass_flow: c.mass_flow,
            take_up: None,
            ..r.set.experiments[template].clone()
        },
        positions,
        clean,
    })
}

/// A noisy data set: the current experiments and `extra`, noise of replicate `seed`.
fn data_set(r: &Reference, extra: Option<&Added>, seed: u64) -> ExperimentSet {
    let mut rng = Rng::new(seed);
    let mut experiments = r.set.experiments.clone();
    let mut clean = r.clean.clone();
    let mut positions: Vec<Vec<f64>> = r
        .scenario
        .experiments
        .iter()
        .map(|e| e.positions.clone())
        .collect();
    if let Some(a) = extra {
        experiments.push(a.experiment.clone());
        clean.push(a.clean.clone());
        positions.push(a.positions.clone());
    }
    noisy_set(&r.set, experiments, &clean, &positions, &mut rng)
}

/// The outcome of one replicate: `(ranked first and earns its place, separated, gap)` with
/// `gap = BIC_mf − BIC_nu = N ln(J_mf/J_nu)`.
type Verdict = (bool, bool, f64);

/// Fits the three models to `set`, warm-started from the reference fits (the added
/// experiment's start solution simulated by the model itself at the reference fit).
fn verdict(r: &Reference, set: &ExperimentSet) -> Option<Verdict> {
    let mut costs = Vec::with_capacity(3);
    for (spec, fit) in specs().into_iter().zip(&r.fits) {
        let rh = Rheometer::with_spec(set, spec).ok()?;
        let mut warm = fit.solutions.clone();
        if rh.len() > warm.len() {
            let mut p = fit.local_params.clone();
            p[rh.models[0].take_up_factor_index()] = 1.0;
            let last = rh.models.last()?;
            let s = simulate_params(last, &p, None, &SimulateOptions::default()).ok()?;
            warm.push(s.solution);
        }
        let start = FitStart {
            law: fit.law(),
            free_candidates: Vec::new(),
            strengths: fit.fitted_strengths(),
            warm: Some(warm),
        };
        costs.push(rh.identify_from(&start, &options()).ok()?.fit.cost);
    }
    let n: usize = set
        .measurements
        .iter()
        .map(|m| m.as_ref().map_or(0, |m| m.positions.len()))
        .sum();
    let n = n as f64;
    let dbic = |j: f64| n * (j / costs[0]).ln() + n.ln();
    let first = costs[1] < costs[2] && dbic(costs[1]) < DBIC;
    let gap = n * (costs[1] / costs[2]).ln();
    let separated = gap < DBIC && dbic(costs[1]) < DBIC;
    Some((first, separated, gap))
}

struct Arm {
    label: &'static str,
    first: f64,
    separated: f64,
    replicates: usize,
    /// Mean and standard error of the mean of the realised `BIC_mf − BIC_nu`.
    gap: (f64, f64),
}

fn arm(
    label: &'static str,
    r: &Reference,
    replicates: usize,
    extra: impl Fn(u64) -> Option<Added> + Sync,
) -> Arm {
    let verdicts: Vec<Option<Verdict>> = (0..replicates)
        .into_par_iter()
        .map(|i| {
            let seed = 50_000 + i as u64;
            let set = data_set(r, extra(seed).as_ref(), seed);
            verdict(r, &set)
        })
        .collect();
    let ok: Vec<Verdict> = verdicts.into_iter().flatten().collect();
    assert!(
        ok.len() * 20 >= replicates * 19,
        "{label}: {} of {replicates} replicate fits failed",
        replicates - ok.len()
    );
    let frac =
        |f: &dyn Fn(&Verdict) -> bool| ok.iter().filter(|v| f(v)).count() as f64 / ok.len() as f64;
    let m = ok.len() as f64;
    let mean = ok.iter().map(|v| v.2).sum::<f64>() / m;
    let var = ok.iter().map(|v| (v.2 - mean).powi(2)).sum::<f64>() / (m - 1.0);
    let a = Arm {
        label,
        first: frac(&|v| v.0),
        separated: frac(&|v| v.1),
        replicates: ok.len(),
        gap: (mean, (var / m).sqrt()),
    };
    println!(
        "DISCRIMINATION | {label} | {} replicates | mass_flow_scale ranked first with dBIC < -10: \
         {:.3} | separated from nusselt_scale by dBIC < -10: {:.3} | BIC_mf - BIC_nu {:.2} ± {:.2}",
        a.replicates, a.first, a.separated, a.gap.0, a.gap.1
    );
    a
}

/// The three arms over `replicates` noise replicates and the design's prediction for the top
/// candidate: `(current, top, uniform, expected BIC_mf − BIC_nu)`.
fn study(replicates: usize) -> (Arm, Arm, Arm, f64) {
    let t0 = Instant::now();
    let r = reference();
    let rivals: Vec<Rival> = RIVALS
        .iter()
        .enumerate()
        .map(|(i, name)| Rival {
            name,
            rheometer: &r.rheometers[i + 1],
            fit: &r.fits[i + 1],
        })
        .collect();
    let d = design_for_discrimination(&rivals, &DiscriminationRequest::new(grid(&r.set))).unwrap();
    println!("{}", d.to_text());
    let t_design = t0.elapsed().as_secs_f64();
    // the current data tie: the rivals' BICs within diagnose's tie margin (6)
    let n: usize = r.rheometers[0]
        .measurements
        .iter()
        .map(|m| m.positions.len())
        .sum();
    let gap = (r.fits[1].fit.cost / r.fits[2].fit.cost).ln().abs() * n as f64;
    println!("current data: |dBIC| between the rivals {gap:.2}");
    // every feasible candidate's truth, for the top and the uniform draws
    let feasible: Vec<usize> = d.ranking.clone();
    let truths: Vec<Option<Added>> = feasible
        .par_iter()
        .map(|&i| added(&r, &d, i).ok())
        .collect();
    let top = truths[0]
        .clone()
        .expect("the top candidate solves in the independent model");
    let solvable: Vec<usize> = (0..feasible.len())
        .filter(|&k| truths[k].is_some())
        .collect();
    let t1 = Instant::now();
    let current = arm("current data", &r, replicates, |_| None);
    let top_arm = arm("top-ranked candidate added", &r, replicates, |_| {
        Some(top.clone())
    });
    let uniform = arm("uniformly drawn candidate added", &r, replicates, |seed| {
        let mut rng = Rng::new(seed ^ 0x5eed);
        let k =
            solvable[((rng.uniform() * solvable.len() as f64) as usize).min(solvable.len() - 1)];
        truths[k].clone()
    });
    println!(
        "time: fits and design {t_design:.1} s, replicates {:.1} s",
        t1.elapsed().as_secs_f64()
    );
    let predicted = d
        .best()
        .and_then(|b| b.separations.iter().find(|p| p.truth == RIVALS[0]))
        .map(|p| p.expected_delta_bic)
        .unwrap();
    println!("top candidate: expected BIC_mf - BIC_nu {predicted:.2} (design)");
    (current, top_arm, uniform, predicted)
}

/// Replicates of the on-demand study (≥ 200; `DISCRIMINATION_REPLICATES` overrides).
fn replicates() -> usize {
    std::env::var("DISCRIMINATION_REPLICATES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(200)
}

/// The design's prediction holds: adding the top-ranked experiment moves the realised mean of
/// `BIC_mf − BIC_nu` below the current data's, to the predicted value within three standard
/// errors of the mean.
fn check_prediction(current: &Arm, top: &Arm, predicted: f64) {
    assert!(
        top.gap.0 < current.gap.0,
        "top {:?} vs current {:?}",
        top.gap,
        current.gap
    );
    assert!(
        (top.gap.0 - predicted).abs() <= 3.0 * top.gap.1,
        "realised {:?}, predicted {predicted}",
        top.gap
    );
}

#[test]
fn the_top_discriminating_experiment_separates_as_predicted() {
    let (c, t, u, predicted) = study(50);
    check_prediction(&c, &t, predicted);
    // the recommended experiment names the cause more often than the current data and than a
    // uniformly chosen one
    assert!(t.first > c.first, "{} vs {}", t.first, c.first);
    assert!(t.first >= u.first, "{} vs {}", t.first, u.first);
}

/// The target: with the recommended experiment, the true cause is named (ranked first,
/// earning its place) in at least 80 % of replicates, more often than with the current data or
/// a uniformly chosen experiment.
#[test]
#[ignore = "slow (200 replicates x 3 arms x 3 fits, about 2 min on 2 busy cores); run on demand with --ignored --nocapture"]
fn the_top_discriminating_experiment_names_the_cause_in_80_percent() {
    let (c, t, u, predicted) = study(replicates());
    check_prediction(&c, &t, predicted);
    assert!(t.first >= 0.8, "{}: {}", t.label, t.first);
    assert!(t.first > c.first && t.first >= u.first);
}

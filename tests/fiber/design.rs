//! Design for estimation validated by simulation (issue 30): the data are made by the
//! independent model of `tests/independent` (not the crate's), the truth far from the shipped
//! set's (`n = 0.72`, `κ = 12.1`), three experiments at one mass flow. The design ranks a grid
//! of candidate experiments; the top-ranked and the worst one are then simulated with noise by
//! the independent model, many replicates, each refitted with the new experiment added, and the
//! realised standard errors of `(n, κ)` are compared with the predicted ones.

use crate::independent::dataset::{ExperimentSpec, Scenario};
use crate::independent::model::{Law, Line};
use crate::independent::rng::Rng;
use crate::independent::scenarios::control;
use crate::independent::solve::diameters;
use crate::noisy_data::noisy_set;
use rayon::prelude::*;
use rheometer::data::input::load_experiments_with;
use rheometer::data::input::LoadOptions;
use rheometer::design::{
    design_for_estimation, CandidateGrid, CandidateOutcome, Criterion, Design, DesignRequest,
    TakeUpAxis,
};
use rheometer::fit::{FitStart, Identification, IdentifyOptions, Rheometer};
use rheometer::model::{Experiment, ExperimentSet};
use std::time::Instant;

/// Replicates of each simulated design (≥ 200 for the criterion; `DESIGN_REPLICATES`
/// overrides).
fn replicates() -> usize {
    std::env::var("DESIGN_REPLICATES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(200)
}

const TRUTH: Law = Law {
    n: 0.72,
    kappa: 12.1,
};

/// Stencil 0.53 mm/s (3.08e-5 kg/s), three take-up diameters.
fn scenario() -> Scenario {
    let positions: Vec<f64> = (0..26).map(|i| 0.02 * i as f64).collect();
    let spec = |name: &str, bar: f64, d_out: f64| ExperimentSpec {
        name: name.into(),
        stencil_velocity_mm_s: 0.53,
        take_up_pressure_bar: bar,
        mass_flow: 3.08e-5,
        take_up_diameter: d_out,
        positions: positions.clone(),
    };
    Scenario {
        name: "design_base",
        law: TRUTH,
        experiments: vec![
            spec("b1", 1.0, 150e-6),
            spec("b2", 2.0, 100e-6),
            spec("b3", 3.0, 75e-6),
        ],
        seed: 3001,
        ..control()
    }
}

/// Fit options of the replicates: the default principled fit without the discretisation
/// check (the replicates compare with each other, not with a tolerance).
fn replicate_options() -> IdentifyOptions {
    IdentifyOptions {
        max_discretisation_shift: None,
        ..IdentifyOptions::default()
    }
}

struct Base {
    scenario: Scenario,
    clean: Vec<Vec<f64>>,
    set: ExperimentSet,
    rh: Rheometer,
    id: Identification,
}

fn base() -> Base {
    let scenario = scenario();
    let generated = scenario.generate().unwrap();
    let loaded = load_experiments_with(&generated.toml, &LoadOptions::default()).unwrap();
    let rh = Rheometer::new(&loaded.set).unwrap();
    let id = rh
        .identify([0.6, 11.5], &IdentifyOptions::default())
        .unwrap();
    Base {
        scenario,
        clean: generated.clean,
        set: loaded.set,
        rh,
        id,
    }
}

fn grid() -> CandidateGrid {
    CandidateGrid {
        template: 0,
        mass_flows: [0.35, 0.7, 1.4, 2.8].iter().map(|f| f * 3.08e-5).collect(),
        // 1.5 mm is wider than the inlet: infeasible, reported as such
        take_up: TakeUpAxis::Diameter(vec![45e-6, 70e-6, 110e-6, 170e-6, 1.5e-3]),
        positions: None,
    }
}

/// Estimates `(n, κ)` of `replicates` noisy data sets: the base experiments and, if given,
/// the candidate, all simulated by the independent model, each refitted from the base fit.
fn realise(b: &Base, candidate: Option<&CandidateOutcome>, replicates: usize) -> Vec<[f64; 2]> {
    let mut experiments = b.set.experiments.clone();
    let mut clean = b.clean.clone();
    let mut positions: Vec<Vec<f64>> = b
        .scenario
        .experiments
        .iter()
        .map(|e| e.positions.clone())
        .collect();
    if let Some(c) = candidate {
        let line = Line {
            mass_flow: c.candidate.mass_flow,
            take_up_diameter: c.candidate.take_up,
            ..b.scenario.line(0)
        };
        let s = positions[0].clone();
        clean.push(diameters(&line, &s).unwrap());
        positions.push(s);
        experiments.push(Experiment {
            name: "candidate".into(),
            mass_flow: c.candidate.mass_flow,
            take_up: None,
            ..experiments[0].clone()
        });
    }
    let set_of = |seed: u64| {
        let mut rng = Rng::new(seed);
        noisy_set(&b.set, experiments.clone(), &clean, &positions, &mut rng)
    };
    let opts = replicate_options();
    let first = Rheometer::new(&set_of(1)).unwrap();
    let warm = first.identify(b.id.law(), &opts).unwrap().solutions;
    let fits: Vec<Option<[f64; 2]>> = (0..replicates)
        .into_par_iter()
        .map(|r| {
            let rh = Rheometer::new(&set_of(10_000 + r as u64)).ok()?;
            let start = FitStart {
                warm: Some(warm.clone()),
                ..FitStart::at(b.id.law())
            };
            rh.identify_from(&start, &opts).ok().map(|id| id.law())
        })
        .collect();
    let ok: Vec<[f64; 2]> = fits.into_iter().flatten().collect();
    assert!(
        ok.len() * 20 >= replicates * 19,
        "{} of {replicates} replicate fits failed",
        replicates - ok.len()
    );
    ok
}

fn sd(v: &[[f64; 2]], i: usize) -> f64 {
    let m = v.iter().map(|x| x[i]).sum::<f64>() / v.len() as f64;
    (v.iter().map(|x| (x[i] - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
}

fn se_of(d: &Design, c: &CandidateOutcome, name: &str) -> f64 {
    c.prediction.as_ref().unwrap().stderr[d.index_of(name).unwrap()]
}

#[test]
fn predicted_standard_errors_match_refits_of_independent_simulations() {
    let t0 = Instant::now();
    let b = base();
    let t_fit = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let design =
        design_for_estimation(&b.rh, &b.id, &DesignRequest::new(grid(), Criterion::D)).unwrap();
    let t_design = t1.elapsed().as_secs_f64();
    println!("{}", design.to_text());
    // the infeasible column is reported, not crashed on, and never ranked
    let infeasible: Vec<&CandidateOutcome> = design
        .candidates
        .iter()
        .filter(|c| c.infeasible.is_some())
        .collect();
    assert_eq!(infeasible.len(), 4, "the 1.5 mm take-up column");
    assert!(infeasible
        .iter()
        .all(|c| c.rank.is_none() && c.candidate.take_up > 1e-3));
    assert!(infeasible[0]
        .infeasible
        .as_deref()
        .unwrap()
        .contains("inlet diameter"));
    assert_eq!(design.ranking.len(), 16);
    // the current prediction agrees with the fit's own standard errors (the same data, the
    // noise estimated two ways)
    for (i, p) in design.parameters.iter().enumerate() {
        let r = design.current.stderr[i] / design.fit_stderr[i];
        println!(
            "current se({p}): predicted {:.4e}, fit {:.4e} (ratio {r:.3})",
            design.current.stderr[i], design.fit_stderr[i]
        );
        assert!((0.9..1.1).contains(&r), "se({p}) ratio {r}");
    }
    let top = design.best().unwrap();
    let worst = design.worst().unwrap();
    // a uniformly chosen candidate: the mean predicted κ standard error over the feasible set
    let feasible: Vec<&CandidateOutcome> = design
        .ranking
        .iter()
        .map(|&i| &design.candidates[i])
        .collect();
    let mean_se_kappa = feasible
        .iter()
        .map(|c| se_of(&design, c, "kappa"))
        .sum::<f64>()
        / feasible.len() as f64;
    let mut rng = Rng::new(77);
    let uniform = feasible[(rng.uniform() * feasible.len() as f64) as usize];
    let t2 = Instant::now();
    let realised_top = realise(&b, Some(top), replicates());
    let realised_worst = realise(&b, Some(worst), replicates());
    let realised_uniform = realise(&b, Some(uniform), replicates());
    let t_mc = t2.elapsed().as_secs_f64();
    let now_kappa = design.current.stderr[design.index_of("kappa").unwrap()];
    let mut lines = Vec::new();
    for (label, c, real) in [
        ("top", top, &realised_top),
        ("worst", worst, &realised_worst),
        ("uniform", uniform, &realised_uniform),
    ] {
        for (i, p) in ["n", "kappa"].iter().enumerate() {
            let pred = se_of(&design, c, p);
            let got = sd(real, i);
            lines.push((label, *p, pred, got));
            println!(
                "{label} ({}, rank {:?}): se({p}) predicted {pred:.4e}, realised {got:.4e} over {} \
                 replicates (ratio {:.3})",
                c.name,
                c.rank,
                real.len(),
                got / pred
            );
        }
    }
    println!(
        "se(kappa): now {now_kappa:.4e}, top {:.4e}, mean over the candidates {mean_se_kappa:.4e}, \
         uniform pick {:.4e}, worst {:.4e}",
        se_of(&design, top, "kappa"),
        se_of(&design, uniform, "kappa"),
        se_of(&design, worst, "kappa")
    );
    println!(
        "time: base fit {t_fit:.1} s, design of 20 candidates {t_design:.2} s, refits {t_mc:.1} s"
    );
    // the criterion: predicted and realised within 20 % (the top design; the worst
    // and the uniform pick too)
    for &(label, p, pred, got) in &lines {
        assert!(
            (got / pred - 1.0).abs() < 0.2,
            "{label} design: se({p}) predicted {pred:.4e}, realised {got:.4e}"
        );
    }
    // the top design shrinks κ's standard error more than a uniformly chosen one
    assert!(se_of(&design, top, "kappa") < mean_se_kappa);
    assert!(sd(&realised_top, 1) < sd(&realised_uniform, 1) || top.name == uniform.name);
    assert!(sd(&realised_top, 1) < sd(&realised_worst, 1));
}

/// The timing target: a 50×50 design grid on the shipped 9 experiments (run by hand:
/// `cargo test --release --test fiber design::grid_50x50 -- --ignored --nocapture`).
#[test]
#[ignore]
fn grid_50x50_on_the_shipped_data_timing() {
    let loaded = load_experiments_with(
        std::path::Path::new("data/pmma7n_synthetic/experiments.toml"),
        &LoadOptions::default(),
    )
    .unwrap();
    let rh = Rheometer::new(&loaded.set).unwrap();
    let id = rh
        .identify([0.7, 11.5], &IdentifyOptions::default())
        .unwrap();
    let q0 = 3.08e-5;
    let grid = CandidateGrid {
        template: 4,
        mass_flows: diffbvp::mesh::linspace(0.4 * q0, 2.5 * q0, 50),
        take_up: TakeUpAxis::Diameter(diffbvp::mesh::linspace(40e-6, 220e-6, 50)),
        positions: None,
    };
    let mut times = Vec::new();
    for _ in 0..3 {
        let t = Instant::now();
        let d = design_for_estimation(&rh, &id, &DesignRequest::new(grid.clone(), Criterion::D))
            .unwrap();
        times.push(t.elapsed().as_secs_f64());
        println!(
            "{} candidates, {} feasible, best {}",
            d.candidates.len(),
            d.ranking.len(),
            d.best().map_or("-", |c| c.name.as_str())
        );
    }
    times.sort_by(f64::total_cmp);
    println!("50x50 design grid: median {:.2} s of {times:?}", times[1]);
}

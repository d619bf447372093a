//! Agreement with the noise-free reference profiles of an independent scipy implementation
//! (`tests/data/reference_profiles/`, solve_bvp tol 1e-8 with every output point a node).

use rheometer::model::simulate_from;
use rheometer::model::{Air, Experiment, Material};
use rheometer::{
    model::simulate, model::CarreauLike, model::FiberModel, model::Newtonian, model::Physics,
    model::SimulateOptions, model::ViscosityLaw,
};
use std::time::Instant;

/// Columns: position, velocity, force, temperature, strain rate, diameter.
fn read_reference(file: &str) -> Vec<[f64; 6]> {
    let path = format!(
        "{}/tests/data/reference_profiles/{file}",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    text.lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|s| s.trim().parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3], v[4], v[5]]
        })
        .collect()
}

/// Max relative deviations (velocity, force, temperature, strain rate / max, diameter).
fn compare<L: ViscosityLaw>(
    model: &FiberModel<L>,
    params: &[f64],
    file: &str,
) -> ([f64; 5], usize, f64) {
    let reference = read_reference(file);
    let positions: Vec<f64> = reference.iter().map(|r| r[0]).collect();
    let opts = SimulateOptions::with_tol(1e-8);
    let t0 = Instant::now();
    let sol = simulate(model, params, &opts).unwrap_or_else(|e| panic!("{file}: {e}"));
    let secs = t0.elapsed().as_secs_f64();
    let prof = sol.profiles(model, &positions);
    let rate_max = reference.iter().fold(0.0f64, |a, r| a.max(r[4].abs()));
    let force_max = reference.iter().fold(0.0f64, |a, r| a.max(r[2].abs()));
    let mut dev = [0.0f64; 5];
    for (i, r) in reference.iter().enumerate() {
        let rel = |a: f64, b: f64| ((a - b) / b).abs();
        dev[0] = dev[0].max(rel(prof.velocity[i], r[1]));
        // force relative to the local value where not near zero, else to the maximum
        dev[1] = dev[1].max((prof.force[i] - r[2]).abs() / r[2].abs().max(1e-2 * force_max));
        dev[2] = dev[2].max(rel(prof.temperature[i], r[3]));
        dev[3] = dev[3].max((prof.strain_rate[i] - r[4]).abs() / rate_max);
        dev[4] = dev[4].max(rel(prof.diameter[i], r[5]));
    }
    (dev, sol.nodes(), secs)
}

fn check_all<L: ViscosityLaw + Clone>(law: L, params: &[f64], suffix: &str) {
    let mut worst = [0.0f64; 5];
    for experiment in Experiment::pmma7n_synthetic_truth() {
        let file = format!("{}_{suffix}.csv", experiment.name);
        // every experiment has its reference profile: a missing file fails in read_reference
        let model = FiberModel::new(
            &Material::pmma7n(),
            &Air::paper(),
            &experiment,
            law.clone(),
            Physics::paper(),
        )
        .unwrap();
        let (dev, nodes, secs) = compare(&model, params, &file);
        eprintln!(
            "{file}: nodes {nodes}, {secs:.3} s, max rel dev u {:.2e} N {:.2e} T {:.2e} epsdot {:.2e} d {:.2e}",
            dev[0], dev[1], dev[2], dev[3], dev[4]
        );
        for k in 0..5 {
            worst[k] = worst[k].max(dev[k]);
        }
    }
    eprintln!(
        "{suffix}: worst u {:.2e} N {:.2e} T {:.2e} epsdot {:.2e} d {:.2e}",
        worst[0], worst[1], worst[2], worst[3], worst[4]
    );
    for (k, w) in worst.iter().enumerate() {
        assert!(*w < 1e-4, "component {k}: max relative deviation {w:e}");
    }
}

#[test]
fn carreau_matches_reference_profiles() {
    check_all(CarreauLike::new(), &[0.8, 11.71], "carreau");
}

#[test]
fn newtonian_matches_reference_profiles() {
    check_all(Newtonian, &[], "newtonian");
}

#[test]
fn warm_start_from_nearby_parameters_gives_the_same_solution() {
    let model = FiberModel::new(
        &Material::pmma7n(),
        &Air::paper(),
        &Experiment::pmma7n_v0p53_p2(),
        CarreauLike::new(),
        Physics::paper(),
    )
    .unwrap();
    let opts = SimulateOptions::with_tol(1e-8);
    let near = simulate(&model, &[0.79, 11.70], &opts).unwrap();
    let warm = simulate_from(&model, &[0.8, 11.71], &near, &opts).unwrap();
    let cold = simulate(&model, &[0.8, 11.71], &opts).unwrap();
    let pos: Vec<f64> = (0..=50).map(|i| 0.51 * i as f64 / 50.0).collect();
    let (a, b) = (warm.profiles(&model, &pos), cold.profiles(&model, &pos));
    for i in 0..pos.len() {
        assert!((a.diameter[i] / b.diameter[i] - 1.0).abs() < 1e-6);
        assert!((a.temperature[i] / b.temperature[i] - 1.0).abs() < 1e-7);
    }
}

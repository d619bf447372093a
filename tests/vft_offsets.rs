//! The material-data effects `vft_b_offset` and `vft_t_vf_offset`: with the strength as a model
//! parameter the model equals the one built from **changed material data** (VFT `B` or `T_VF`
//! changed and `μ_c` rescaled so that the zero-rate viscosity at the reference temperature
//! `T_o` stays), their derivatives are exact, and the VFT sources of the error budget now have
//! numbers.

use diffbvp::fiber::effects::{Category, Effect};
use diffbvp::fiber::setup::{Air, Experiment, Material};
use diffbvp::fiber::simulate::simulate_params;
use diffbvp::fiber::{CarreauLike, FiberModel, Physics, SimulateOptions};
use diffbvp::sensitivity::Sensitivities;
use diffbvp::{Guess, SolveOptions, Solver};

const TRUTH: [f64; 2] = [0.8, 11.71];

fn experiment() -> Experiment {
    Experiment::pmma7n_synthetic_truth().swap_remove(3)
}

fn model(material: &Material, physics: Physics) -> FiberModel<CarreauLike> {
    FiberModel::new(
        material,
        &Air::paper(),
        &experiment(),
        CarreauLike::new(),
        physics,
    )
    .unwrap()
}

fn opts() -> SimulateOptions {
    SimulateOptions {
        tol: 1e-8,
        factor_at_solution: true,
        ..SimulateOptions::default()
    }
}

/// Fiber diameters \[m\] at 26 positions and the temperatures \[K\] there.
fn profile(m: &FiberModel<CarreauLike>, p: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let sol = simulate_params(m, p, None, &opts()).unwrap().solution;
    let lo = m.scaling.reference.length;
    (0..26)
        .map(|i| {
            let y = sol.eval(0.02 * i as f64 / lo);
            (
                m.fiber_diameter(&y, &sol.params) * m.scaling.diameter(),
                y[2] * m.scaling.reference.temperature,
            )
        })
        .unzip()
}

fn max_rel_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x / y - 1.0).abs())
        .fold(0.0, f64::max)
}

#[test]
fn vft_offsets_are_the_model_of_changed_material_data() {
    let nominal = Material::pmma7n();
    let t_o = model(&nominal, Physics::paper())
        .scaling
        .reference
        .temperature;
    // far from neutral: B + 250 K, T_VF − 12 K; μ_c rescaled so that μ_s0(T_o) stays
    let cases = [(Effect::VftBOffset, 250.0), (Effect::VftTvfOffset, -12.0)];
    for (effect, strength) in cases {
        assert_eq!(effect.category(), Category::Material);
        let mut changed = nominal.clone();
        match effect {
            Effect::VftBOffset => changed.vft_b += strength,
            _ => changed.vft_t_vf += strength,
        }
        changed.vft_mu_c *= (nominal.vft_b / (t_o - nominal.vft_t_vf)
            - changed.vft_b / (t_o - changed.vft_t_vf))
            .exp();
        let level = |m: &Material| m.vft_mu_c * (m.vft_b / (t_o - m.vft_t_vf)).exp();
        assert!((level(&changed) / level(&nominal) - 1.0).abs() < 1e-12);

        let m = model(&nominal, effect.apply(Physics::paper()).unwrap());
        let mut p = m.parameters(1.0, &TRUTH).unwrap();
        p[m.param_index(effect.model_param()).unwrap()] = strength;
        let (with_param, temps) = profile(&m, &p);
        let direct_model = model(&changed, Physics::paper());
        let (direct, _) = profile(
            &direct_model,
            &direct_model.parameters(1.0, &TRUTH).unwrap(),
        );
        let plain = model(&nominal, Physics::paper());
        let (base, _) = profile(&plain, &plain.parameters(1.0, &TRUTH).unwrap());
        // the neutral strength is the nominal model
        let (neutral, _) = profile(&m, &m.parameters(1.0, &TRUTH).unwrap());
        let diff = max_rel_diff(&with_param, &direct);
        let change = max_rel_diff(&direct, &base);
        let t_min = temps.iter().copied().fold(f64::INFINITY, f64::min);
        println!(
            "{}: parameter vs changed material data {diff:.2e}, change {change:.2e}, \
             neutral vs nominal {:.2e}, fiber temperature down to {t_min:.1} K",
            effect.name(),
            max_rel_diff(&neutral, &base)
        );
        assert!(diff < 1e-6, "{}: {diff:e}", effect.name());
        assert!(
            change > 1e-3,
            "{}: no visible change ({change:e})",
            effect.name()
        );
        assert!(max_rel_diff(&neutral, &base) < 1e-9, "{}", effect.name());
    }
}

#[test]
fn vft_offset_derivatives_match_finite_differences() {
    let physics = [Effect::VftBOffset, Effect::VftTvfOffset]
        .iter()
        .try_fold(Physics::paper(), |p, e| e.apply(p))
        .unwrap();
    let m = model(&Material::pmma7n(), physics);
    let mut p = m.parameters(1.0, &TRUTH).unwrap();
    p[m.param_index("vft_b_offset").unwrap()] = 120.0;
    p[m.param_index("vft_t_vf_offset").unwrap()] = -7.0;
    let s = simulate_params(&m, &p, None, &opts()).unwrap().solution;
    let sens = Sensitivities::compute(&m, &s).unwrap();
    let xs: Vec<f64> = (1..=10).map(|i| m.length() * i as f64 / 10.0).collect();
    for (name, h) in [("vft_b_offset", 0.05), ("vft_t_vf_offset", 0.005)] {
        let j = m.param_index(name).unwrap();
        let solve_at = |dv: f64| {
            let mut q = p.clone();
            q[j] += dv;
            let sol = Solver::new(&m, SolveOptions::fixed_mesh())
                .solve(&q, &Guess::from(&s))
                .unwrap();
            xs.iter().map(|&x| sol.eval(x)).collect::<Vec<Vec<f64>>>()
        };
        let (up, dn) = (solve_at(h), solve_at(-h));
        // velocity (state 0) and temperature (state 2)
        for state in [0usize, 2] {
            let q = sens.num_params();
            let col = |x: f64| sens.at(x)[state * q + j];
            let scale = xs.iter().map(|&x| col(x).abs()).fold(0.0, f64::max);
            assert!(scale > 0.0, "{name}: zero sensitivity of state {state}");
            let worst = xs
                .iter()
                .enumerate()
                .map(|(i, &x)| (col(x) - (up[i][state] - dn[i][state]) / (2.0 * h)).abs() / scale)
                .fold(0.0, f64::max);
            println!("{name}, state {state}: max |dual - FD| / max |dual| = {worst:.2e}");
            assert!(worst <= 1e-6, "{name}, state {state}: {worst:.2e}");
        }
    }
}

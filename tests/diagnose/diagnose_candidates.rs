//! Candidate effects: neutral strengths reproduce the base model exactly, dual-number
//! derivatives with respect to a strength agree with finite differences, CLI parsing.

use diffbvp::sensitivity::Sensitivities;
use diffbvp::{DualNum, Guess, SolveOptions, Solver};
use rheometer::model::simulate_params;
use rheometer::model::{Air, Experiment, Material};
use rheometer::model::{
    Category, Effect, EffectSetting, LawChoice, ModelSpec, STRAIN_THINNING_REFERENCE_KAPPA,
};
use rheometer::{
    model::Balance, model::CarreauLike, model::FiberModel, model::FiberTerm, model::SiState,
    model::SimulateOptions,
};

fn experiment() -> Experiment {
    Experiment::pmma7n_v0p53_p2()
}

/// A user-written effect: natural convection near the nozzle, a heat loss
/// `−h π d (T − T_air) exp(−s/0.03 m)` with `h` = 10 W/(m² K) at unit strength.
#[derive(Clone)]
struct NozzleConvection;

impl FiberTerm for NozzleConvection {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, st: &SiState<D>) -> D {
        -(st.temperature - st.air_temperature)
            * st.diameter
            * (10.0 * std::f64::consts::PI * (-st.s / 0.03).exp())
    }
}

fn all_effects() -> Vec<Effect> {
    let mut v = Effect::builtin();
    v.push(Effect::custom(
        "nozzle_convection",
        Balance::Energy,
        NozzleConvection,
    ));
    v
}

fn model(spec: &ModelSpec) -> FiberModel<CarreauLike> {
    FiberModel::new(
        &Material::pmma7n(),
        &Air::paper(),
        &experiment(),
        CarreauLike::new(),
        spec.physics().unwrap(),
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

fn diameters(m: &FiberModel<CarreauLike>, sol: &diffbvp::Solution, xs: &[f64]) -> Vec<f64> {
    xs.iter()
        .map(|&x| {
            let y = sol.eval(x);
            m.diameter(y[0], m.density(y[2]))
        })
        .collect()
}

#[test]
fn neutral_strengths_reproduce_the_base_model_exactly() {
    let base = model(&ModelSpec::default());
    let p0 = base.parameters(1.0, &[0.8, 11.71]).unwrap();
    let s0 = simulate_params(&base, &p0, None, &opts()).unwrap().solution;
    let xs: Vec<f64> = (0..=50).map(|i| base.length() * i as f64 / 50.0).collect();
    let d0 = diameters(&base, &s0, &xs);
    let spec = ModelSpec::default().with_candidates(&all_effects());
    let m = model(&spec);
    // one strength per effect (strain thinning lives in the law) plus the shape parameters
    let expected: usize = all_effects()
        .iter()
        .filter(|e| !matches!(e, Effect::StrainThinning))
        .map(|e| 1 + e.shape_parameters().len())
        .sum();
    assert_eq!(
        m.physics.num_strength_params(),
        expected,
        "{:?}",
        m.param_names()
    );
    let p = m.parameters(1.0, &[0.8, 11.71]).unwrap();
    let s = simulate_params(&m, &p, None, &opts()).unwrap().solution;
    assert_eq!(s.x.len(), s0.x.len());
    let d = diameters(&m, &s, &xs);
    for (a, b) in d.iter().zip(&d0) {
        assert!((a / b - 1.0).abs() <= 1e-14, "{a} vs {b}");
    }
}

#[test]
fn strength_derivatives_match_finite_differences() {
    // Newtonian base so that strain_thinning is a candidate (derivative wrt n at n = 1)
    let spec = ModelSpec::new(LawChoice::Newtonian).with_candidates(&all_effects());
    let m = model(&spec);
    let p = m
        .parameters(1.0, &[1.0, STRAIN_THINNING_REFERENCE_KAPPA])
        .unwrap();
    let s = simulate_params(&m, &p, None, &opts()).unwrap().solution;
    let sens = Sensitivities::compute(&m, &s).unwrap();
    let xs: Vec<f64> = (1..=10).map(|i| m.length() * i as f64 / 10.0).collect();
    // relative steps in strength units
    let steps = [
        ("strain_thinning", 1e-4),
        ("radiation", 1e-4),
        ("air_coflow", 1e-4),
        ("air_temperature_profile", 1e-2),
        ("inlet_velocity", 1e-4),
        ("nusselt_scale", 1e-4),
        ("nozzle_convection", 1e-3),
        ("air_coflow_line", 1e-4),
        ("inlet_diameter", 1e-4),
        ("die_temperature_offset", 1e-2),
        ("mass_flow_scale", 1e-4),
    ];
    // fixed mesh: agreement to 1e-7 relative (measured: at most 1.4e-8)
    const TOL: f64 = 1e-7;
    // instrument effects do not change the fiber (their residual derivatives are checked in
    // tests/effects_families.rs)
    for e in all_effects()
        .into_iter()
        .filter(|e| e.category() != Category::Instrument)
    {
        let h = steps.iter().find(|s| s.0 == e.name()).unwrap().1;
        let j = m.param_index(e.model_param()).unwrap();
        let per = e.param_per_strength();
        // re-solves on the solution's own mesh: the discrete sensitivities are exact
        // derivatives of this discrete system, so only the FD truncation error remains
        let solve_at = |sv: f64| {
            let mut q = p.clone();
            q[j] = e.param_value(sv);
            let sol = Solver::new(&m, SolveOptions::fixed_mesh())
                .solve(&q, &Guess::from(&s))
                .unwrap();
            xs.iter().map(|&x| sol.eval(x)[0]).collect::<Vec<f64>>()
        };
        let (up, dn) = (solve_at(h), solve_at(-h));
        let scale = xs
            .iter()
            .map(|&x| (sens.at(x)[j] * per).abs())
            .fold(0.0, f64::max);
        assert!(scale > 0.0, "{}: zero sensitivity", e.name());
        // ∂u/∂strength (row 0 of the n × q block) against central differences
        let worst = xs
            .iter()
            .enumerate()
            .map(|(i, &x)| (sens.at(x)[j] * per - (up[i] - dn[i]) / (2.0 * h)).abs() / scale)
            .fold(0.0, f64::max);
        assert!(
            worst <= TOL,
            "{}: max |dual - FD| / max |dual| = {worst:.2e}",
            e.name()
        );
    }
}

#[test]
fn settings_parse_names_and_values() {
    for name in rheometer::model::BUILTIN_NAMES {
        let s: EffectSetting = name.parse().unwrap();
        assert_eq!(s.effect.name(), name);
        assert!(s.value.is_none());
    }
    let s: EffectSetting = "radiation=0.9".parse().unwrap();
    assert_eq!(s.value, Some(0.9));
    assert!("radiation=abc".parse::<EffectSetting>().is_err());
    assert!("radiation=7".parse::<EffectSetting>().is_err());
    let e = "magnetism".parse::<EffectSetting>().unwrap_err();
    assert!(e.contains("air_coflow"), "{e}");
    assert!("carreau".parse::<LawChoice>().is_ok());
    let bad = ModelSpec::new(LawChoice::Carreau)
        .with(EffectSetting::fitted(Effect::StrainThinning))
        .validate();
    assert!(bad.is_err());
}

#[test]
fn a_user_effect_named_like_a_builtin_strength_is_an_error_not_a_panic() {
    // a user effect named after a base-model term or a built-in effect would set the other
    // strength: the spec refuses it, naming the effect
    for name in [
        "convection",
        "nusselt_scale",
        "radiation",
        "air_coflow",
        "kappa",
    ] {
        let spec = ModelSpec::default().with_candidates(&[Effect::custom(
            name,
            Balance::Energy,
            NozzleConvection,
        )]);
        let e = spec.validate().unwrap_err();
        assert!(e.contains(name) && e.contains("taken"), "{name}: {e}");
    }
    // a fresh name is accepted and its strength exists in the physics
    let spec = ModelSpec::default().with_candidates(&all_effects());
    spec.validate().unwrap();
    let physics = spec.physics().unwrap();
    assert!(physics
        .strength_parameters()
        .iter()
        .any(|(n, _)| *n == "nozzle_convection"));
}

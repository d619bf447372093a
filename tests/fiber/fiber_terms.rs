//! Inputs, errors, named contributions, user terms and optional effects.

use diffbvp::DualNum;
use rheometer::model::simulate_params;
use rheometer::model::{Air, Experiment, Inlet, Material, TakeUp};
use rheometer::{
    model::simulate, model::Balance, model::CarreauLike, model::FiberModel, model::FiberTerm,
    model::InclinedChurchillBernstein, model::Newtonian, model::Physics, model::SiState,
    model::SimulateOptions, model::Strength, FiberError,
};

fn experiment() -> Experiment {
    Experiment::pmma7n_v0p53_p2()
}

fn build(e: &Experiment, physics: Physics) -> Result<FiberModel<CarreauLike>, FiberError> {
    FiberModel::new(
        &Material::pmma7n(),
        &Air::paper(),
        e,
        CarreauLike::new(),
        physics,
    )
}

#[test]
fn bad_inputs_are_errors_not_panics() {
    let cases: Vec<(&str, Experiment)> = vec![
        (
            "negative mass flow",
            Experiment {
                mass_flow: -1.0,
                ..experiment()
            },
        ),
        (
            "NaN mass flow",
            Experiment {
                mass_flow: f64::NAN,
                ..experiment()
            },
        ),
        (
            "zero inlet diameter",
            Experiment {
                inlet: Inlet::Diameter(0.0),
                ..experiment()
            },
        ),
        (
            "NaN temperature",
            Experiment {
                inlet_temperature: f64::NAN,
                ..experiment()
            },
        ),
        (
            "take-up too thick",
            Experiment {
                take_up: Some(TakeUp::Diameter(2e-3)),
                ..experiment()
            },
        ),
        (
            "take-up too slow",
            Experiment {
                take_up: Some(TakeUp::Velocity(1e-3)),
                ..experiment()
            },
        ),
        (
            "negative length",
            Experiment {
                spinline_length: -0.5,
                ..experiment()
            },
        ),
    ];
    for (what, e) in cases {
        match build(&e, Physics::paper()) {
            Err(FiberError::InvalidInput(msg)) => eprintln!("{what}: {msg}"),
            other => panic!("{what}: expected InvalidInput, got {other:?}"),
        }
    }
    let missing = Experiment {
        take_up: None,
        ..experiment()
    };
    assert!(matches!(
        build(&missing, Physics::paper()),
        Err(FiberError::MissingTakeUp(_))
    ));
    let m = build(&experiment(), Physics::paper()).unwrap();
    let opts = SimulateOptions::default();
    assert!(matches!(
        simulate(&m, &[0.8], &opts),
        Err(FiberError::InvalidInput(_))
    ));
    assert!(matches!(
        simulate(&m, &[-0.1, 11.0], &opts),
        Err(FiberError::InvalidInput(_))
    ));
    assert!(matches!(
        simulate(&m, &[0.8, f64::NAN], &opts),
        Err(FiberError::InvalidInput(_))
    ));
}

/// Gravity written by a user in SI: ρ A g = Q g/u [N/m].
struct UserGravity;
impl FiberTerm for UserGravity {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, st: &SiState<D>) -> D {
        st.velocity.recip() * (3.08e-5 * 9.81)
    }
}

#[test]
fn user_term_reproduces_builtin_gravity() {
    let opts = SimulateOptions::with_tol(1e-8);
    let reference = build(&experiment(), Physics::paper()).unwrap();
    let user = build(
        &experiment(),
        Physics::paper()
            .strength("gravity", Strength::Off)
            .unwrap()
            .with_custom("user_gravity", Balance::Momentum, UserGravity),
    )
    .unwrap();
    let a = simulate(&reference, &[0.8, 11.71], &opts).unwrap();
    let b = simulate(&user, &[0.8, 11.71], &opts).unwrap();
    let pos = [0.0, 0.1, 0.3, 0.51];
    let (pa, pb) = (a.profiles(&reference, &pos), b.profiles(&user, &pos));
    for i in 0..pos.len() {
        assert!((pa.diameter[i] / pb.diameter[i] - 1.0).abs() < 1e-9);
        // reported SI values agree: built-in gravity vs the user's term
        let g_builtin = pa.terms.iter().find(|t| t.0 == "gravity").unwrap().2[i];
        let g_user = pb.terms.iter().find(|t| t.0 == "user_gravity").unwrap().2[i];
        let expected = 3.08e-5 * 9.81 / pa.velocity[i];
        assert!(
            (g_builtin / expected - 1.0).abs() < 1e-12,
            "{g_builtin} {expected}"
        );
        assert!((g_user / g_builtin - 1.0).abs() < 1e-8);
        let off = pb.terms.iter().find(|t| t.0 == "gravity").unwrap().2[i];
        assert_eq!(off, 0.0);
    }
}

#[test]
fn term_report_units_and_signs() {
    let m = build(&experiment(), Physics::paper()).unwrap();
    let sol = simulate(&m, &[0.8, 11.71], &SimulateOptions::with_tol(1e-6)).unwrap();
    let p = sol.profiles(&m, &[0.1]);
    let get = |n: &str| p.terms.iter().find(|t| t.0 == n).unwrap().2[0];
    // Stokes drag in still air: −μ_* r u [N/m]
    let drag = -2e-5 * rheometer::model::stokes_tangential_resistance(1e-3) * p.velocity[0];
    assert!((get("air_drag") / drag - 1.0).abs() < 1e-12);
    // convection: −π d α (T − T_air) with α = λ_*/d · ½ Nu_CB(d u/ν_*)
    let re = p.diameter[0] * p.velocity[0] / 2e-5;
    let pr: f64 = 1000.0 * 1.0 * 2e-5 / 0.031;
    let nu_cb = 0.3
        + 0.62
            * re.sqrt()
            * pr.cbrt()
            * (1.0 + (0.4 / pr).powf(2.0 / 3.0)).powf(-0.25)
            * (1.0 + (re / 282000.0).powf(0.625)).powf(0.8);
    let conv = -std::f64::consts::PI * 0.031 * 0.5 * nu_cb * (p.temperature[0] - 293.15);
    assert!(
        (get("convection") / conv - 1.0).abs() < 1e-5,
        "{} {conv}",
        get("convection")
    );
    // viscous heating N u' [W/m]
    let vh = p.force[0] * p.strain_rate[0];
    assert!((get("viscous_heating") / vh - 1.0).abs() < 1e-12);
    // viscosity: μ_e = 3 μ_s0(T) (1 + (μ_e0 ε̇/K)²)^((n−1)/2) [Pa s]
    let mu0 = 3.0 * Material::pmma7n().zero_shear_viscosity(p.temperature[0]);
    let mu = mu0 * (1.0 + (mu0 * p.strain_rate[0] / 11.71f64.exp()).powi(2)).powf(-0.1);
    assert!((p.viscosity[0] / mu - 1.0).abs() < 1e-9);
    // constitutive law N = A μ_e u'
    let area = std::f64::consts::PI * p.diameter[0].powi(2) / 4.0;
    assert!((area * p.viscosity[0] * p.strain_rate[0] / p.force[0] - 1.0).abs() < 1e-6);
}

#[test]
fn strength_parameters_extend_p_and_are_neutral_at_default() {
    let physics = Physics::paper()
        .strength("convection", Strength::Parameter(1.0))
        .unwrap();
    let m = build(&experiment(), physics).unwrap();
    assert_eq!(
        m.param_names(),
        vec!["c", "n", "kappa", "nusselt_scale", "take_up_factor"]
    );
    let p = m.parameters(1.0, &[0.8, 11.71]).unwrap();
    assert_eq!(p, vec![1.0, 0.8, 11.71, 1.0, 1.0]);
    assert_eq!(m.param_index("nusselt_scale"), Some(3));
    let opts = SimulateOptions::with_tol(1e-8);
    let a = simulate_params(&m, &p, None, &opts).unwrap();
    let r = build(&experiment(), Physics::paper()).unwrap();
    let b = simulate(&r, &[0.8, 11.71], &opts).unwrap();
    let (pa, pb) = (a.uniform_profiles(&m, 11), b.uniform_profiles(&r, 11));
    for i in 0..11 {
        assert!((pa.temperature[i] / pb.temperature[i] - 1.0).abs() < 1e-9);
    }
    // a stronger cooling (strength 1.1) gives a colder fiber at the take-up
    let mut p2 = p.clone();
    p2[3] = 1.1;
    let c = simulate_params(&m, &p2, Some(&a.solution), &opts).unwrap();
    assert!(c.uniform_profiles(&m, 11).temperature[10] < pa.temperature[10] - 1.0);
}

#[test]
fn optional_effects_solve_and_change_the_fiber() {
    let opts = SimulateOptions::with_tol(1e-6);
    let base = build(&experiment(), Physics::paper()).unwrap();
    let tb = simulate(&base, &[0.8, 11.71], &opts)
        .unwrap()
        .uniform_profiles(&base, 11);
    // radiation cools
    let rad = build(&experiment(), Physics::paper().with_radiation(0.9)).unwrap();
    let sol = simulate(&rad, &[0.8, 11.71], &opts).unwrap();
    let tr = sol.uniform_profiles(&rad, 11);
    assert!(tr.temperature[10] < tb.temperature[10] - 1.0);
    let q_rad = tr.terms.iter().find(|t| t.0 == "radiation").unwrap().2[0];
    let expected = -std::f64::consts::PI
        * tr.diameter[0]
        * 0.9
        * 5.670374419e-8
        * (513.15f64.powi(4) - 293.15f64.powi(4));
    assert!((q_rad / expected - 1.0).abs() < 1e-10, "{q_rad} {expected}");
    // warm air near the nozzle heats
    let warm = build(&experiment(), Physics::paper().with_warm_air(100.0, 0.05)).unwrap();
    let tw = simulate(&warm, &[0.8, 11.71], &opts)
        .unwrap()
        .uniform_profiles(&warm, 11);
    assert!(tw.temperature[10] > tb.temperature[10] + 0.1);
    // an aspirator co-flow (smoothed inclination factor) pulls on the fiber near the take-up
    let physics = Physics::with_nusselt(InclinedChurchillBernstein {
        re_regularisation: 1e-3,
        inclination_regularisation: 0.05,
    })
    .with_coflow(8.0, 0.05); // take-up speed ≈ 4 m/s
    let co = FiberModel::new(
        &Material::pmma7n(),
        &Air::paper(),
        &experiment(),
        CarreauLike::new(),
        physics,
    )
    .unwrap();
    let sol = simulate(&co, &[0.8, 11.71], &opts).unwrap();
    let pc = sol.uniform_profiles(&co, 11);
    let drag_end = pc.terms.iter().find(|t| t.0 == "air_drag").unwrap().2[10];
    assert!(
        drag_end > 0.0,
        "co-flow drag at the take-up should pull: {drag_end}"
    );
    eprintln!(
        "co-flow drag at L {drag_end:e} N/m; N(0) {:e} vs {:e}; T(L) {} vs {}",
        pc.force[0], tb.force[0], pc.temperature[10], tb.temperature[10]
    );
    // less relative speed near the take-up: less convective cooling there
    assert!(pc.temperature[10] > tb.temperature[10] + 1.0);
    eprintln!(
        "co-flow: {} nodes, N(0) {:.4e} N vs {:.4e} N still air",
        sol.nodes(),
        pc.force[0],
        tb.force[0]
    );
}

#[test]
fn velocity_take_up_and_newtonian_law_work() {
    let e = Experiment {
        take_up: Some(TakeUp::Velocity(3.0)),
        ..experiment()
    };
    let m = FiberModel::new(
        &Material::pmma7n(),
        &Air::paper(),
        &e,
        Newtonian,
        Physics::paper(),
    )
    .unwrap();
    let sol = simulate(&m, &[], &SimulateOptions::with_tol(1e-8)).unwrap();
    let p = sol.profiles(&m, &[0.51]);
    assert!((p.velocity[0] / 3.0 - 1.0).abs() < 1e-9);
}

#[test]
fn unknown_or_absent_strengths_are_errors() {
    // one name per effect: the old internal names are not strengths
    assert!(Physics::paper().strength("coflow", Strength::Off).is_err());
    assert!(Physics::paper()
        .strength("warm_air", Strength::Off)
        .is_err());
    assert!(Physics::paper()
        .strength("no_such_term", Strength::Off)
        .is_err());
    // an air profile that is not there cannot get a strength
    assert!(Physics::paper()
        .strength("air_coflow", Strength::Off)
        .is_err());
    assert!(Physics::paper()
        .strength("air_temperature_profile", Strength::Off)
        .is_err());
    // the effect names
    let p = Physics::paper()
        .with_coflow(1.0, 0.1)
        .with_warm_air(10.0, 0.05)
        .strength("air_coflow", Strength::Parameter(0.0))
        .and_then(|p| p.strength("air_temperature_profile", Strength::Parameter(0.0)))
        .and_then(|p| p.strength("nusselt_scale", Strength::Parameter(1.0)))
        .and_then(|p| p.strength("inlet_velocity", Strength::Parameter(0.0)))
        .unwrap();
    let names: Vec<&str> = p.strength_parameters().iter().map(|(n, _)| *n).collect();
    assert_eq!(
        names,
        [
            "nusselt_scale",
            "air_coflow",
            "air_temperature_profile",
            "inlet_velocity"
        ]
    );
}

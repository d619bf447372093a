//! The candidate families of `fiber::effects`: process parameters are exactly the model of the
//! changed experiment, shape parameters have exact derivatives, a co-flow faster than the fiber
//! stays physical, the gauge enters the residuals as `(1 + g) d + o`, settings parse and
//! round-trip, unphysical strengths are named, and fits recover a die-temperature offset and a
//! gauge scale from data made *without* the candidate code paths (the experiment's inlet
//! temperature changed, the measured diameters scaled). The material-data effects
//! `vft_b_offset` and `vft_t_vf_offset` are the model built from changed VFT data (with `μ_c`
//! rescaled so that the zero-rate viscosity at `T_o` stays), with exact derivatives.

use diffbvp::sensitivity::{residual_jacobian, Sensitivities};
use diffbvp::{Guess, SolveOptions, Solver};
use rheometer::data::synthetic::{SplitMix64, SyntheticNoise};
use rheometer::fit::RelativeResidual;
use rheometer::fit::{FitStart, FitSummary, IdentifyOptions, Layout, Rheometer};
use rheometer::model::simulate_params;
use rheometer::model::{Air, Experiment, ExperimentSet, Inlet, Material, Measurements};
use rheometer::model::{Category, Effect, EffectSetting, ModelSpec, ALL_NAMES, BUILTIN_NAMES};
use rheometer::{
    model::Balance, model::CarreauLike, model::FiberModel, model::Physics, model::SimulateOptions,
};

const TRUTH: [f64; 2] = [0.8, 11.71];

fn experiment(i: usize) -> Experiment {
    Experiment::pmma7n_synthetic_truth().swap_remove(i)
}

fn model_for(e: &Experiment, physics: Physics) -> FiberModel<CarreauLike> {
    model_with(&Material::pmma7n(), e, physics)
}

fn model_with(material: &Material, e: &Experiment, physics: Physics) -> FiberModel<CarreauLike> {
    FiberModel::new(material, &Air::paper(), e, CarreauLike::new(), physics).unwrap()
}

fn opts() -> SimulateOptions {
    SimulateOptions {
        tol: 1e-8,
        factor_at_solution: true,
        ..SimulateOptions::default()
    }
}

fn positions() -> Vec<f64> {
    (0..26).map(|i| 0.02 * i as f64).collect()
}

/// True fiber diameters \[m\] of `m` at parameters `p` at `positions()`.
fn diameters_m(m: &FiberModel<CarreauLike>, p: &[f64]) -> Vec<f64> {
    let sol = simulate_params(m, p, None, &opts()).unwrap().solution;
    let lo = m.scaling.reference.length;
    positions()
        .iter()
        .map(|&s| {
            let y = sol.eval(s / lo);
            m.fiber_diameter(&y, &sol.params) * m.scaling.diameter()
        })
        .collect()
}

fn max_rel_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x / y - 1.0).abs())
        .fold(0.0, f64::max)
}

#[test]
fn process_parameters_are_the_model_of_the_changed_experiment() {
    let e = experiment(3);
    let Inlet::Diameter(d_in) = e.inlet else {
        panic!("the synthetic experiments give the inlet diameter")
    };
    // (effect, strength, the experiment changed directly)
    let mut hot = e.clone();
    hot.inlet_temperature += 10.0;
    let mut more = e.clone();
    more.mass_flow *= 1.05;
    let mut swollen = e.clone();
    swollen.inlet = Inlet::Diameter(1.1 * d_in);
    let cases = [
        (Effect::DieTemperatureOffset, 10.0, hot),
        (Effect::MassFlowScale, 0.05, more),
        (Effect::InletDiameter, 0.1, swollen),
    ];
    for (effect, strength, changed) in cases {
        let m = model_for(&e, effect.apply(Physics::paper()).unwrap());
        let mut p = m.parameters(1.0, &TRUTH).unwrap();
        p[m.param_index(effect.model_param()).unwrap()] = effect.param_value(strength);
        let with_param = diameters_m(&m, &p);
        let direct_model = model_for(&changed, Physics::paper());
        let direct = diameters_m(
            &direct_model,
            &direct_model.parameters(1.0, &TRUTH).unwrap(),
        );
        let nominal_model = model_for(&e, Physics::paper());
        let nominal = diameters_m(
            &nominal_model,
            &nominal_model.parameters(1.0, &TRUTH).unwrap(),
        );
        let diff = max_rel_diff(&with_param, &direct);
        let change = max_rel_diff(&direct, &nominal);
        println!(
            "{}: parameter vs changed experiment {diff:.2e}, change {change:.2e}",
            effect.name()
        );
        // both solved to tol 1e-8 on their own meshes
        assert!(diff < 1e-6, "{}: {diff:e}", effect.name());
        assert!(
            change > 1e-3,
            "{}: no visible change ({change:e})",
            effect.name()
        );
    }
}

/// Physics with all three environment families switched on at non-neutral strengths and
/// shapes (far from the defaults).
fn profiled_model() -> (FiberModel<CarreauLike>, Vec<f64>) {
    let effects = [
        Effect::AirCoflow {
            decay_length: Some(0.08),
            tail: None,
        },
        Effect::AirCoflowLine {
            onset: Some(0.3),
            ramp_width: Some(0.03),
        },
        Effect::AirTemperatureProfile {
            decay_length: Some(0.04),
        },
    ];
    let physics = effects
        .iter()
        .try_fold(Physics::paper(), |p, e| e.apply(p))
        .unwrap();
    let m = model_for(&experiment(3), physics);
    let mut p = m.parameters(1.0, &TRUTH).unwrap();
    for (name, v) in [
        ("air_coflow", 60.0),
        ("air_coflow_line", 3.0),
        ("air_temperature_profile", 120.0),
    ] {
        p[m.param_index(name).unwrap()] = v;
    }
    assert_eq!(p[m.param_index("air_coflow.decay_length").unwrap()], 0.08);
    // the exponential tail r = 0, where the decay is evaluated by its series
    assert_eq!(p[m.param_index("air_coflow.tail").unwrap()], 0.0);
    assert_eq!(p[m.param_index("air_coflow_line.onset").unwrap()], 0.3);
    (m, p)
}

#[test]
fn shape_parameter_derivatives_match_finite_differences() {
    let (m, p) = profiled_model();
    let s = simulate_params(&m, &p, None, &opts()).unwrap().solution;
    let sens = Sensitivities::compute(&m, &s).unwrap();
    let xs: Vec<f64> = (1..=10).map(|i| m.length() * i as f64 / 10.0).collect();
    // fixed mesh: the sensitivities are exact derivatives of the discrete system, only the FD
    // truncation error remains (same tolerance as the strengths in diagnose_candidates.rs)
    const TOL: f64 = 1e-7;
    for name in [
        "air_coflow.decay_length",
        "air_coflow.tail",
        "air_coflow_line.onset",
        "air_coflow_line.ramp_width",
        "air_temperature_profile.decay_length",
        "air_coflow",
        "air_coflow_line",
    ] {
        let j = m.param_index(name).unwrap();
        let h = 1e-4 * p[j].abs().max(0.1);
        let solve_at = |dv: f64| {
            let mut q = p.clone();
            q[j] += dv;
            let sol = Solver::new(&m, SolveOptions::fixed_mesh())
                .solve(&q, &Guess::from(&s))
                .unwrap();
            xs.iter().map(|&x| sol.eval(x)[0]).collect::<Vec<f64>>()
        };
        let (up, dn) = (solve_at(h), solve_at(-h));
        let scale = xs.iter().map(|&x| sens.at(x)[j].abs()).fold(0.0, f64::max);
        assert!(scale > 0.0, "{name}: zero sensitivity");
        let worst = xs
            .iter()
            .enumerate()
            .map(|(i, &x)| (sens.at(x)[j] - (up[i] - dn[i]) / (2.0 * h)).abs() / scale)
            .fold(0.0, f64::max);
        println!("{name}: max |dual - FD| / max |dual| = {worst:.2e}");
        assert!(worst <= TOL, "{name}: {worst:.2e}");
    }
}

#[test]
fn coflow_faster_than_the_fiber_pulls_it_forward() {
    let e = experiment(3);
    // ℓ = 0.03 m: at the nozzle the air is still slower than the fiber (300 m/s e^(-10))
    let effect = Effect::AirCoflow {
        decay_length: Some(0.05),
        tail: None,
    };
    let m = model_for(&e, effect.apply(Physics::paper()).unwrap());
    let mut p = m.parameters(1.0, &TRUTH).unwrap();
    let still = simulate_params(&m, &p, None, &opts()).unwrap().solution;
    p[m.param_index("air_coflow").unwrap()] = 300.0;
    let fast = simulate_params(&m, &p, None, &opts()).unwrap().solution;
    let l = m.length();
    let u_o = m.scaling.reference.velocity;
    let drag = |sol: &diffbvp::Solution, x: f64| {
        let y = sol.eval(x);
        let terms = m.terms_at(x, &y, &sol.params);
        let d = terms.iter().find(|t| t.0 == "air_drag").unwrap();
        assert_eq!(d.1, Balance::Momentum);
        let conv = terms.iter().find(|t| t.0 == "convection").unwrap().2;
        (d.2, conv, y)
    };
    // the air (300 m/s at the take-up) overtakes the fiber (a few m/s): the drag pulls forward
    let (d_fast, c_fast, y_end) = drag(&fast, l);
    let (d_still, _, _) = drag(&still, l);
    println!(
        "take-up: fiber {:.3} m/s, drag with co-flow {d_fast:.4e}, in still air {d_still:.4e}",
        y_end[0] * u_o
    );
    assert!(y_end[0] * u_o < 300.0);
    assert!(
        d_fast > 0.0,
        "drag {d_fast} with a 300 m/s co-flow at the take-up"
    );
    assert!(d_still < 0.0, "drag {d_still} in still air");
    // the fiber cools everywhere (the Nusselt law uses the magnitude of the relative speed)
    assert!(c_fast < 0.0);
    for i in 0..=50 {
        let x = l * i as f64 / 50.0;
        let (_, c, _) = drag(&fast, x);
        assert!(c < 0.0, "convection {c} at s = {x}");
    }
    // a forward force enters N' = Q ε̇ − Σ F with the opposite sign of the still-air drag:
    // N(L) − N(0) drops
    let rise = |sol: &diffbvp::Solution| sol.eval(l)[1] - sol.eval(0.0)[1];
    println!(
        "N(L) - N(0): still {:.4e}, co-flow {:.4e}",
        rise(&still),
        rise(&fast)
    );
    assert!(rise(&fast) < rise(&still));
    // and the relative speed changes sign along the line without breaking Newton
    let (d_start, _, _) = drag(&fast, 0.0);
    assert!(d_start < 0.0, "drag at the nozzle {d_start}");
}

#[test]
fn gauge_parameters_enter_the_residuals_exactly() {
    let e = experiment(3);
    let spec = ModelSpec::default().with_candidates(&[Effect::GaugeScale, Effect::GaugeOffset]);
    let m = model_for(&e, spec.physics().unwrap());
    let p = m.parameters(1.0, &TRUTH).unwrap();
    let sol = simulate_params(&m, &p, None, &opts()).unwrap().solution;
    let lo = m.scaling.reference.length;
    let dd = m.scaling.diameter();
    let xs: Vec<f64> = positions().iter().map(|s| s / lo).collect();
    let d_meas: Vec<f64> = xs
        .iter()
        .map(|&x| 1.01 * m.fiber_diameter(&sol.eval(x), &p))
        .collect();
    let (gi, oi) = (
        m.param_index("gauge_scale").unwrap(),
        m.param_index("gauge_offset").unwrap(),
    );
    let sigma = 0.015;
    let (g, o_um) = (0.03, 4.0);
    let mut pg = p.clone();
    pg[gi] = g;
    pg[oi] = o_um;
    // the gauge does not change the fiber: the same solution with the gauge parameters
    let mut sol_g = sol.clone();
    sol_g.params = pg.clone();
    let sens = Sensitivities::compute(&m, &sol_g).unwrap();
    let sigmas = vec![sigma; d_meas.len()];
    let res = RelativeResidual {
        model: &m,
        d_meas: &d_meas,
        sigma: &sigmas,
    };
    let (r, jac) = residual_jacobian(&m, &sol_g, &sens, &xs, &res).unwrap();
    let q = pg.len();
    for (i, &x) in xs.iter().enumerate() {
        let d = m.fiber_diameter(&sol.eval(x), &p);
        let reading = (1.0 + g) * d + o_um * 1e-6 / dd;
        let expect = (reading / d_meas[i] - 1.0) / sigma;
        assert!(
            (r[i] - expect).abs() <= 1e-12 * expect.abs().max(1.0),
            "{i}"
        );
        let col_g = jac[i * q + gi];
        let col_o = jac[i * q + oi];
        let (eg, eo) = (d / (sigma * d_meas[i]), 1e-6 / dd / (sigma * d_meas[i]));
        assert!(
            (col_g - eg).abs() <= 1e-12 * eg.abs(),
            "{i}: {col_g} vs {eg}"
        );
        assert!(
            (col_o - eo).abs() <= 1e-12 * eo.abs(),
            "{i}: {col_o} vs {eo}"
        );
    }
    // the rheometer's reported residuals use the same reading
    let set = ExperimentSet {
        material: Material::pmma7n(),
        air: Air::paper(),
        experiments: vec![e.clone()],
        measurements: vec![Some(Measurements {
            positions: positions(),
            diameters: d_meas.iter().map(|v| v * dd).collect(),
        })],
        relative_uncertainty: None,
    };
    let rh = Rheometer::with_spec(&set, spec).unwrap();
    let rel = rh.relative_residuals(0, &sol_g);
    for (i, v) in rel.iter().enumerate() {
        assert!(
            (v - r[i] * sigma).abs() <= 1e-12,
            "{i}: {v} vs {}",
            r[i] * sigma
        );
    }
}

#[test]
fn settings_round_trip_and_name_the_bad_token() {
    for name in ALL_NAMES {
        let s: EffectSetting = name.parse().unwrap();
        assert_eq!(s.effect.name(), name);
        assert!(s.value.is_none());
        let (lo, hi) = s.effect.bounds();
        let (plo, phi) = s.effect.physical_range();
        assert!(
            lo <= plo && phi <= hi,
            "{name}: search range inside the physical one"
        );
        assert!(s.effect.judge(s.effect.neutral()).is_none(), "{name}");
    }
    assert!(BUILTIN_NAMES.iter().all(|n| ALL_NAMES.contains(n)));
    assert!(!BUILTIN_NAMES.contains(&"inlet_velocity"));
    // strong co-flows are admissible now
    let s: EffectSetting = "air_coflow=40:decay_length=0.2".parse().unwrap();
    assert_eq!(s.value, Some(40.0));
    assert_eq!(s.effect.shape_settings()[0].1, Some(0.2));
    assert!(s.effect.free_shapes().is_empty());
    let s: EffectSetting = "air_coflow_line:onset=0.3:ramp_width=0.05".parse().unwrap();
    assert_eq!(s.value, None);
    let v: Vec<Option<f64>> = s.effect.shape_settings().iter().map(|x| x.1).collect();
    assert_eq!(v, [Some(0.3), Some(0.05)]);
    for (bad, token) in [
        ("air_coflow:decay=0.2", "decay"),
        ("air_coflow:decay_length=abc", "abc"),
        ("air_coflow:decay_length=9", "decay_length"),
        ("radiation:decay_length=0.1", "radiation has no shape"),
        ("air_coflow:0.2", "0.2"),
        ("gauge_scale=0.5", "gauge_scale"),
    ] {
        let e = bad.parse::<EffectSetting>().unwrap_err();
        assert!(e.contains(token), "{bad}: {e}");
    }
    // through ModelSpec and the fit layout: the fixed shape is a model parameter at its value,
    // not freed; a fitted one is freed with the strength, with length-limited bounds
    let spec = ModelSpec::default()
        .with("air_coflow:decay_length=0.2".parse().unwrap())
        .with("air_temperature_profile".parse().unwrap());
    let e = experiment(3);
    let m = model_for(&e, spec.physics().unwrap());
    let layout = Layout::new(&m, &spec, &FitStart::at(TRUTH), &IdentifyOptions::default()).unwrap();
    let li = m.param_index("air_coflow.decay_length").unwrap();
    assert_eq!(layout.template[li], 0.2);
    assert!(!layout.free.contains(&li));
    let wi = m
        .param_index("air_temperature_profile.decay_length")
        .unwrap();
    let col = layout.free.iter().position(|&i| i == wi).unwrap();
    assert_eq!(layout.names[col], "air_temperature_profile.decay_length");
    assert_eq!(layout.lower[col], 0.005);
    assert_eq!(layout.upper[col], e.spinline_length.min(1.0));
}

#[test]
fn judge_and_categories() {
    let msg = Effect::Radiation.judge(2.0).unwrap();
    assert!(msg.contains("radiation would need ε = 2 > 1"), "{msg}");
    assert!(msg.contains("not physical"), "{msg}");
    assert!(Effect::Radiation.judge(0.9).is_none());
    assert!(Effect::Radiation.judge(-0.1).unwrap().contains("< 0"));
    let coflow = Effect::AirCoflow {
        decay_length: None,
        tail: None,
    };
    assert!(coflow.judge(250.0).is_none());
    assert!(coflow.judge(500.0).unwrap().contains("m/s"));
    let die = Effect::DieTemperatureOffset.judge(-40.0).unwrap();
    assert!(die.contains("-40 K < -30 K"), "{die}");
    assert!(Effect::GaugeScale.judge(0.2).is_some());
    assert!(Effect::GaugeOffset.judge(f64::NAN).is_some());
    assert_eq!(Effect::GaugeOffset.category(), Category::Instrument);
    assert_eq!(Effect::MassFlowScale.category(), Category::Process);
    assert_eq!(Effect::InletVelocity.category(), Category::Process);
    assert_eq!(coflow.category(), Category::Physics);
    assert_eq!(
        serde_json::to_string(&Category::Instrument).unwrap(),
        "\"instrument\""
    );
    let shapes = Effect::AirCoflowLine {
        onset: None,
        ramp_width: None,
    }
    .shape_parameters();
    assert_eq!(shapes.len(), 2);
    // both fitted with the speed; the global search scans the onset only
    assert!(shapes[0].fitted_with_strength && shapes[1].fitted_with_strength);
    assert!(shapes[0].scanned && !shapes[1].scanned);
}

/// Noisy data of experiments `exps` from `simulate` (true diameters in metres of each
/// experiment), 1.5% white noise from `seed`.
fn data_set(
    exps: &[Experiment],
    seed: u64,
    noise: Option<SyntheticNoise>,
    simulate: impl Fn(&Experiment) -> Vec<f64>,
) -> ExperimentSet {
    let mut rng = SplitMix64::new(seed);
    let measurements = exps
        .iter()
        .map(|e| {
            let clean = simulate(e);
            let d = match noise {
                Some(n) => n.apply(&positions(), &clean, &mut rng).unwrap(),
                None => clean,
            };
            Some(Measurements {
                positions: positions(),
                diameters: d,
            })
        })
        .collect();
    ExperimentSet {
        material: Material::pmma7n(),
        air: Air::paper(),
        experiments: exps.to_vec(),
        measurements,
        relative_uncertainty: None,
    }
}

const WHITE: SyntheticNoise = SyntheticNoise {
    relative_sd: 0.015,
    disturbance_start: 10.0,
    disturbance_width: 1.0,
    disturbance_amplitude: 0.0,
};

fn fit_with(set: &ExperimentSet, setting: &str) -> FitSummary {
    let spec = ModelSpec::default().with(setting.parse().unwrap());
    let rh = Rheometer::with_spec(set, spec).unwrap();
    let id = rh.identify(TRUTH, &IdentifyOptions::default()).unwrap();
    let rep = id.summary.clone();
    println!("{}", rep.to_text());
    rep
}

fn exps() -> Vec<Experiment> {
    [3, 4, 7, 2].iter().map(|&i| experiment(i)).collect()
}

#[test]
fn fit_recovers_a_die_temperature_offset_made_through_the_inlet_temperature() {
    // the melt leaves the die 10 K hotter than the file says: data simulated with the
    // experiment's inlet temperature raised by 10 K (no candidate code path)
    let hot = |e: &Experiment| {
        let mut h = e.clone();
        h.inlet_temperature += 10.0;
        let m = model_for(&h, Physics::paper());
        diameters_m(&m, &m.parameters(1.0, &TRUTH).unwrap())
    };
    for (noise, seed) in [(None, 1), (Some(WHITE), 7)] {
        let set = data_set(&exps(), seed, noise, hot);
        let rep = fit_with(&set, "die_temperature_offset");
        let e = &rep.effects[0];
        println!(
            "die_temperature_offset = {:.4} +/- {:.4} K (truth +10 K)",
            e.strength.value, e.strength.stderr
        );
        match noise {
            // noise-free: the truth is the exact minimum
            None => assert!(
                (e.strength.value - 10.0).abs() < 0.05,
                "{}",
                e.strength.value
            ),
            Some(_) => {
                assert!(
                    (e.strength.value - 10.0).abs() < 3.0 * e.strength.stderr,
                    "{} +/- {}",
                    e.strength.value,
                    e.strength.stderr
                );
                assert!(rep.kappa.ci95[0] <= TRUTH[1] && TRUTH[1] <= rep.kappa.ci95[1]);
            }
        }
    }
}

#[test]
fn fit_recovers_a_gauge_scale_made_by_scaling_the_measurements() {
    // the gauge reads 3% high: the true diameters scaled by 1.03 before the noise
    let high = |e: &Experiment| {
        let m = model_for(e, Physics::paper());
        diameters_m(&m, &m.parameters(1.0, &TRUTH).unwrap())
            .into_iter()
            .map(|d| 1.03 * d)
            .collect()
    };
    for (noise, seed) in [(None, 1), (Some(WHITE), 11)] {
        let set = data_set(&exps(), seed, noise, high);
        let rep = fit_with(&set, "gauge_scale");
        let e = &rep.effects[0];
        println!(
            "gauge_scale = {:.5} +/- {:.5} (truth 0.03)",
            e.strength.value, e.strength.stderr
        );
        match noise {
            None => assert!(
                (e.strength.value - 0.03).abs() < 1e-4,
                "{}",
                e.strength.value
            ),
            Some(_) => {
                assert!(
                    (e.strength.value - 0.03).abs() < 3.0 * e.strength.stderr,
                    "{} +/- {}",
                    e.strength.value,
                    e.strength.stderr
                );
                assert!(rep.kappa.ci95[0] <= TRUTH[1] && TRUTH[1] <= rep.kappa.ci95[1]);
            }
        }
    }
}

#[test]
fn vft_offsets_are_the_model_of_changed_material_data() {
    let nominal = Material::pmma7n();
    let e = experiment(3);
    let t_o = model_for(&e, Physics::paper())
        .scaling
        .reference
        .temperature;
    let nominal_model = model_for(&e, Physics::paper());
    let base = diameters_m(
        &nominal_model,
        &nominal_model.parameters(1.0, &TRUTH).unwrap(),
    );
    // far from neutral: B + 250 K, T_VF − 12 K; μ_c rescaled so that μ_s0(T_o) stays
    for (effect, strength) in [(Effect::VftBOffset, 250.0), (Effect::VftTvfOffset, -12.0)] {
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

        let m = model_for(&e, effect.apply(Physics::paper()).unwrap());
        let neutral = diameters_m(&m, &m.parameters(1.0, &TRUTH).unwrap());
        let mut p = m.parameters(1.0, &TRUTH).unwrap();
        p[m.param_index(effect.model_param()).unwrap()] = strength;
        let with_param = diameters_m(&m, &p);
        let direct_model = model_with(&changed, &e, Physics::paper());
        let direct = diameters_m(
            &direct_model,
            &direct_model.parameters(1.0, &TRUTH).unwrap(),
        );
        let diff = max_rel_diff(&with_param, &direct);
        let change = max_rel_diff(&direct, &base);
        println!(
            "{}: parameter vs changed material data {diff:.2e}, change {change:.2e}, neutral vs \
             nominal {:.2e}",
            effect.name(),
            max_rel_diff(&neutral, &base)
        );
        // the same function by two code paths, both solved to tol 1e-8
        assert!(diff < 1e-8, "{}: {diff:e}", effect.name());
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
    let m = model_for(&experiment(3), physics);
    let mut p = m.parameters(1.0, &TRUTH).unwrap();
    p[m.param_index("vft_b_offset").unwrap()] = 120.0;
    p[m.param_index("vft_t_vf_offset").unwrap()] = -7.0;
    let s = simulate_params(&m, &p, None, &opts()).unwrap().solution;
    let sens = Sensitivities::compute(&m, &s).unwrap();
    let q = sens.num_params();
    let xs: Vec<f64> = (1..=10).map(|i| m.length() * i as f64 / 10.0).collect();
    // fixed mesh: only the FD truncation error remains (as for the shape parameters above)
    const TOL: f64 = 1e-7;
    for (name, h) in [("vft_b_offset", 0.05), ("vft_t_vf_offset", 0.005)] {
        let j = m.param_index(name).unwrap();
        let solve_at = |dv: f64| {
            let mut pp = p.clone();
            pp[j] += dv;
            let sol = Solver::new(&m, SolveOptions::fixed_mesh())
                .solve(&pp, &Guess::from(&s))
                .unwrap();
            xs.iter().map(|&x| sol.eval(x)).collect::<Vec<Vec<f64>>>()
        };
        let (up, dn) = (solve_at(h), solve_at(-h));
        // velocity (state 0) and temperature (state 2)
        for state in [0usize, 2] {
            let col = |x: f64| sens.at(x)[state * q + j];
            let scale = xs.iter().map(|&x| col(x).abs()).fold(0.0, f64::max);
            assert!(scale > 0.0, "{name}: zero sensitivity of state {state}");
            let worst = xs
                .iter()
                .enumerate()
                .map(|(i, &x)| (col(x) - (up[i][state] - dn[i][state]) / (2.0 * h)).abs() / scale)
                .fold(0.0, f64::max);
            println!("{name}, state {state}: max |dual - FD| / max |dual| = {worst:.2e}");
            assert!(worst <= TOL, "{name}, state {state}: {worst:.2e}");
        }
    }
}

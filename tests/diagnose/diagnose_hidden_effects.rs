//! Missing-physics diagnosis on synthetic data with a hidden effect, made in memory with the
//! project's simulator: multiplicative noise (1.5%) plus a larger disturbance near the take-up,
//! from a small deterministic PRNG. The model is fitted *without* the effect; the diagnosis must
//! flag the residuals as systematic, rank the hidden effect first, and after adding it bring the
//! RMS relative residual to within 20% of the noise level and cover the true (n, κ) by the
//! reported 95% CIs. On data without a hidden effect no candidate may earn its place.

use diffbvp::DualNum;
use rheometer::data::synthetic::{SplitMix64, SyntheticNoise};
use rheometer::diagnostics::{diagnose, DiagnoseOptions, DiagnosisRun};
use rheometer::model::simulate_params;
use rheometer::model::{Air, Experiment, ExperimentSet, Material, Measurements};
use rheometer::model::{Effect, LawChoice, ModelSpec};
use rheometer::{
    model::Balance, model::CarreauLike, model::FiberModel, model::FiberTerm, model::SiState,
    model::SimulateOptions,
};

/// 1.5% white noise plus up to 3% extra near the take-up (aspirator disturbance): 3% at
/// s = 0.50 m.
const NOISE: SyntheticNoise = SyntheticNoise {
    relative_sd: 0.015,
    disturbance_start: 0.35,
    disturbance_width: 0.15,
    disturbance_amplitude: 0.03,
};

fn positions() -> Vec<f64> {
    (0..26).map(|i| 0.02 * i as f64).collect()
}

/// RMS of the noise model over the measurement positions (the level the data were made with).
fn noise_level() -> f64 {
    NOISE.rms_level(&positions())
}

fn experiment(i: usize) -> Experiment {
    Experiment::pmma7n_synthetic_truth().swap_remove(i)
}

/// A user-written effect: natural convection near the nozzle,
/// `−h π d (T − T_air) exp(−s/0.05 m)` with `h` = 10 W/(m² K) per unit strength.
#[derive(Clone)]
struct NozzleConvection;
impl FiberTerm for NozzleConvection {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, st: &SiState<D>) -> D {
        -(st.temperature - st.air_temperature)
            * st.diameter
            * (10.0 * std::f64::consts::PI * (-st.s / 0.05).exp())
    }
}

fn nozzle_convection() -> Effect {
    Effect::custom("nozzle_convection", Balance::Energy, NozzleConvection)
}

/// Data made by the simulator with `hidden` at `strength` (or none), law `(n, κ)`.
fn make_data(
    exps: &[usize],
    law: [f64; 2],
    hidden: Option<(Effect, f64)>,
    seed: u64,
) -> ExperimentSet {
    let mut rng = SplitMix64::new(seed);
    let mut spec = ModelSpec::default();
    if let Some((e, _)) = &hidden {
        if !matches!(e, Effect::StrainThinning) {
            spec = spec.with_candidates(std::slice::from_ref(e));
        }
    }
    let mut experiments = Vec::new();
    let mut measurements = Vec::new();
    for &i in exps {
        let e = experiment(i);
        let m = FiberModel::new(
            &Material::pmma7n(),
            &Air::paper(),
            &e,
            CarreauLike::new(),
            spec.physics().unwrap(),
        )
        .unwrap();
        let mut p = m.parameters(1.0, &law).unwrap();
        if let Some((eff, s)) = &hidden {
            if !matches!(eff, Effect::StrainThinning) {
                p[m.param_index(eff.model_param()).unwrap()] = eff.param_value(*s);
            }
        }
        let sol = simulate_params(&m, &p, None, &SimulateOptions::with_tol(1e-8))
            .unwrap()
            .solution;
        let pos = positions();
        let lo = m.scaling.reference.length;
        let clean: Vec<f64> = pos
            .iter()
            .map(|&s| {
                let y = sol.eval(s / lo);
                m.diameter(y[0], m.density(y[2])) * m.scaling.diameter()
            })
            .collect();
        let d = NOISE.apply(&pos, &clean, &mut rng).unwrap();
        experiments.push(e);
        measurements.push(Some(Measurements {
            positions: pos,
            diameters: d,
        }));
    }
    ExperimentSet {
        material: Material::pmma7n(),
        air: Air::paper(),
        experiments,
        measurements,
        relative_uncertainty: None,
    }
}

fn run(set: &ExperimentSet, law: LawChoice, extra: Option<Effect>) -> DiagnosisRun {
    let mut opts = DiagnoseOptions::default();
    if let Some(e) = extra {
        opts.candidates.push(e);
    }
    let r = diagnose(set, &ModelSpec::new(law), &opts).unwrap();
    println!("{}", r.diagnosis.to_text());
    r
}

fn assert_found(r: &DiagnosisRun, hidden: &str, truth: Option<[f64; 2]>) {
    let d = &r.diagnosis;
    assert!(d.systematic, "residuals not flagged as systematic");
    assert_eq!(
        d.candidates[0].effect, hidden,
        "ranking: {:?}",
        d.candidates
    );
    assert_eq!(d.most_likely_missing.as_deref(), Some(hidden));
    let c = &d.candidates[0];
    let ratio = c.rms_relative_residual_after() / noise_level();
    println!(
        "{hidden}: RMS after {:.4} % vs noise {:.4} % (ratio {ratio:.3}); strength {:.4} +/- {:.4}",
        100.0 * c.rms_relative_residual_after(),
        100.0 * noise_level(),
        c.strength(),
        c.stderr_strength()
    );
    assert!((ratio - 1.0).abs() <= 0.2, "RMS/noise after = {ratio}");
    if let Some([n, k]) = truth {
        assert!(
            c.ci95_n()[0] <= n && n <= c.ci95_n()[1],
            "n = {n} outside {:?}",
            c.ci95_n()
        );
        assert!(
            c.ci95_kappa()[0] <= k && k <= c.ci95_kappa()[1],
            "κ = {k} outside {:?}",
            c.ci95_kappa()
        );
    }
}

#[test]
fn hidden_radiation_is_found() {
    let truth = [0.8, 11.71];
    let set = make_data(&[3, 4, 7, 2], truth, Some((Effect::Radiation, 0.9)), 11);
    let r = run(&set, LawChoice::Carreau, None);
    assert_found(&r, "radiation", Some(truth));
    let c = &r.diagnosis.candidates[0];
    assert!((c.strength() - 0.9).abs() <= 3.0 * c.stderr_strength());
}

#[test]
fn hidden_air_coflow_is_found() {
    let truth = [0.75, 12.0];
    let e: Effect = "air_coflow".parse().unwrap();
    let set = make_data(&[0, 5, 6, 3], truth, Some((e, 8.0)), 22);
    let r = run(&set, LawChoice::Carreau, None);
    assert_found(&r, "air_coflow", Some(truth));
}

#[test]
fn hidden_warm_air_is_found() {
    let truth = [0.85, 11.5];
    let e: Effect = "air_temperature_profile".parse().unwrap();
    let set = make_data(&[1, 4, 8, 6, 0], truth, Some((e, 80.0)), 33);
    let r = run(&set, LawChoice::Carreau, None);
    assert_found(&r, "air_temperature_profile", Some(truth));
}

#[test]
fn carreau_truth_under_a_newtonian_model_needs_strain_thinning() {
    let truth = [0.7, 11.2];
    let set = make_data(
        &[3, 4, 5, 8],
        truth,
        Some((Effect::StrainThinning, 0.3)),
        44,
    );
    let r = run(&set, LawChoice::Newtonian, None);
    assert_found(&r, "strain_thinning", Some(truth));
}

#[test]
fn hidden_user_written_effect_is_found() {
    let truth = [0.8, 11.71];
    let set = make_data(&[0, 4, 7], truth, Some((nozzle_convection(), 2.0)), 55);
    let r = run(&set, LawChoice::Carreau, Some(nozzle_convection()));
    assert_found(&r, "nozzle_convection", Some(truth));
}

#[test]
fn without_a_hidden_effect_no_candidate_earns_its_place() {
    let set = make_data(&[2, 3, 7, 8], [0.8, 11.71], None, 66);
    let r = run(&set, LawChoice::Carreau, None);
    let d = &r.diagnosis;
    assert!(
        d.most_likely_missing.is_none(),
        "{:?}",
        d.most_likely_missing
    );
    assert!(
        d.candidates.iter().all(|c| c.delta_bic > -10.0),
        "{:?}",
        d.candidates
    );
    assert!(
        !d.systematic,
        "RMS/noise {} ρ1 {}",
        d.rms_over_noise(),
        d.lag1_autocorrelation()
    );
}

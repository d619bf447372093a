//! The global search of `diagnose` on data made independently of the candidate code paths: a
//! test-only grey-body heat loss written directly as a user term with an emissivity of 1.7
//! (beyond any physical grey body). The radiation candidate can only explain it with ε > 1: it
//! must be reported as not physical and never named as the missing effect; its profile of `J`
//! must be in the diagnosis.

use diffbvp::DualNum;
use rheometer::data::synthetic::{SplitMix64, SyntheticNoise};
use rheometer::diagnostics::{diagnose, DiagnoseOptions, StrengthStatus};
use rheometer::model::simulate_params;
use rheometer::model::SimulateOptions;
use rheometer::model::{Air, Experiment, ExperimentSet, Material, Measurements};
use rheometer::model::{LawChoice, ModelSpec};
use rheometer::{
    model::Balance, model::CarreauLike, model::FiberModel, model::FiberTerm, model::Physics,
    model::SiState,
};

/// Grey-body radiation `−π d ε σ (T⁴ − T_air⁴)` \[W/m\] with ε = 1.7, written here, not taken
/// from the radiation candidate.
#[derive(Clone)]
struct StrongRadiation;
impl FiberTerm for StrongRadiation {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, st: &SiState<D>) -> D {
        let t4 = st.temperature.powi(4) - st.air_temperature.powi(4);
        -(st.diameter * t4) * (std::f64::consts::PI * 1.7 * 5.670_374e-8)
    }
}

#[test]
fn radiation_needing_emissivity_above_one_is_reported_and_not_named() {
    let noise = SyntheticNoise {
        relative_sd: 0.01,
        disturbance_start: 0.35,
        disturbance_width: 0.15,
        disturbance_amplitude: 0.0,
    };
    let mut rng = SplitMix64::new(77);
    let law = [0.8, 11.71];
    let pos: Vec<f64> = (0..26).map(|i| 0.02 * i as f64).collect();
    let mut experiments = Vec::new();
    let mut measurements = Vec::new();
    for i in [3usize, 4, 7, 2] {
        let e = Experiment::pmma7n_synthetic_truth().swap_remove(i);
        let physics =
            Physics::paper().with_custom("strong_radiation", Balance::Energy, StrongRadiation);
        let m = FiberModel::new(
            &Material::pmma7n(),
            &Air::paper(),
            &e,
            CarreauLike::new(),
            physics,
        )
        .unwrap();
        let p = m.parameters(1.0, &law).unwrap();
        let sol = simulate_params(&m, &p, None, &SimulateOptions::with_tol(1e-8))
            .unwrap()
            .solution;
        let lo = m.scaling.reference.length;
        let clean: Vec<f64> = pos
            .iter()
            .map(|&s| {
                let y = sol.eval(s / lo);
                m.diameter(y[0], m.density(y[2])) * m.scaling.diameter()
            })
            .collect();
        experiments.push(e);
        measurements.push(Some(Measurements {
            positions: pos.clone(),
            diameters: noise.apply(&pos, &clean, &mut rng).unwrap(),
        }));
    }
    let set = ExperimentSet {
        material: Material::pmma7n(),
        air: Air::paper(),
        experiments,
        measurements,
        relative_uncertainty: None,
    };
    let r = diagnose(
        &set,
        &ModelSpec::new(LawChoice::Carreau),
        &DiagnoseOptions::default(),
    )
    .unwrap();
    let d = &r.diagnosis;
    println!("{}", d.to_text());
    let rad = d
        .candidates
        .iter()
        .find(|c| c.effect == "radiation")
        .unwrap();
    assert!(rad.refitted());
    // the data need a strong radiation: the refit strength lies beyond ε = 1 (or at the
    // search bound), which is reported
    assert!(
        rad.strength() > 1.0,
        "radiation strength {}",
        rad.strength()
    );
    assert_ne!(rad.status, StrengthStatus::Physical);
    let note = rad.status_note.as_deref().unwrap();
    assert!(note.contains("radiation"), "{note}");
    assert!(d.to_text().contains("NOT NAMED: radiation"));
    // never named, whatever else is
    assert_ne!(d.most_likely_missing.as_deref(), Some("radiation"));
    if let Some(name) = &d.most_likely_missing {
        let c = d.candidates.iter().find(|c| &c.effect == name).unwrap();
        assert_eq!(c.status, StrengthStatus::Physical);
    }
    // the profile of J against ε covers the physical range and is lowest at its edge ε = 1;
    // the refinement (bounded by the wider search range) goes beyond it
    let prof = &rad.profiles[0];
    assert!(prof.points.len() >= 5);
    let best = prof.minimum().unwrap();
    assert!(
        best.strength >= 1.0 - 1e-12,
        "profile minimum at {}",
        best.strength
    );
    assert!(best.cost < prof.cost_base);
    assert!(rad.strength() > 1.0, "refined ε = {}", rad.strength());
    // JSON carries the status and the profile
    let js = serde_json::to_string(d).unwrap();
    assert!(js.contains("\"status\":\"unphysical\"") || js.contains("\"status\":\"at_bound\""));
    assert!(js.contains("\"profiles\""));
}

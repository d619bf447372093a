//! Book, "When the model fails": writing your own physical effect.
//!
//! A grey-body radiation loss −π d ε σ (T⁴ − T_air⁴) [W/m] written by the user as a
//! [`FiberTerm`] in SI units, added to the paper's model with `Physics::with_custom`, and
//! checked against the built-in radiation term. The term is generic over dual numbers, so the
//! solver's Jacobians, sensitivities and fits include it exactly.
//!
//! Run with `cargo run --release --example tutorial_custom_term`.

// `tests/book_examples.rs` includes this file as a module and checks `run()`'s numbers.
#![allow(dead_code)]

use diffbvp::DualNum;
use rheometer::model::STEFAN_BOLTZMANN;
use rheometer::model::{Air, Experiment, Inlet, Material, TakeUp};
use rheometer::{
    model::simulate, model::Balance, model::CarreauLike, model::FiberModel, model::FiberTerm,
    model::Physics, model::Profiles, model::SiState, model::SimulateOptions, FiberError,
};
use std::f64::consts::PI;

// ANCHOR: term
/// Grey-body radiation, a heat gain per length [W/m] (negative: the fiber loses heat).
struct MyRadiation {
    /// Emissivity ε [-].
    emissivity: f64,
}

impl FiberTerm for MyRadiation {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, st: &SiState<D>) -> D {
        let t4 = st.temperature.powi(4) - st.air_temperature.powi(4);
        -(st.diameter * t4) * (PI * self.emissivity * STEFAN_BOLTZMANN)
    }
}
// ANCHOR_END: term

/// The numbers the tutorial prints (checked by `tests/book_examples.rs`).
pub struct CustomTermSummary {
    /// Diameters [m] at the report positions: paper model, with the user term, with the
    /// built-in radiation term.
    pub diameters: [Vec<f64>; 3],
    /// Temperatures [K] at the report positions, same order.
    pub temperatures: [Vec<f64>; 3],
    /// The user term's value [W/m] at the report positions.
    pub user_term: Vec<f64>,
    /// The built-in convection term [W/m] at the report positions (with the user term on).
    pub convection: Vec<f64>,
}

/// Report positions [m].
pub const POSITIONS: [f64; 5] = [0.0, 0.02, 0.05, 0.1, 0.51];

fn term<'a>(p: &'a Profiles, name: &str) -> Option<&'a Vec<f64>> {
    p.terms.iter().find(|t| t.0 == name).map(|t| &t.2)
}

/// Runs the tutorial.
pub fn run() -> Result<CustomTermSummary, FiberError> {
    // ANCHOR: setup
    let experiment = Experiment {
        name: "v0p53_p2".into(),
        mass_flow: 3.08e-5,                    // kg/s
        inlet: Inlet::Diameter(1.134e-3),      // m
        inlet_temperature: 513.15,             // K
        air_temperature: 293.15,               // K
        spinline_length: 0.51,                 // m
        take_up: Some(TakeUp::Diameter(9e-5)), // m
    };
    let model = |physics: Physics| {
        FiberModel::new(
            &Material::pmma7n(),
            &Air::paper(),
            &experiment,
            CarreauLike::new(),
            physics,
        )
    };
    let paper = model(Physics::paper())?;
    let mine = model(Physics::paper().with_custom(
        "my_radiation",
        Balance::Energy,
        MyRadiation { emissivity: 0.9 },
    ))?;
    let builtin = model(Physics::paper().with_radiation(0.9))?;
    // ANCHOR_END: setup

    // ANCHOR: simulate
    let law = [0.8, 11.71]; // (n, κ)
    let options = SimulateOptions::default();
    let a = simulate(&paper, &law, &options)?.profiles(&paper, &POSITIONS);
    let b = simulate(&mine, &law, &options)?.profiles(&mine, &POSITIONS);
    let c = simulate(&builtin, &law, &options)?.profiles(&builtin, &POSITIONS);
    // ANCHOR_END: simulate

    let missing = |n: &str| FiberError::InvalidInput(format!("no term named {n} in the report"));
    let user_term = term(&b, "my_radiation").ok_or_else(|| missing("my_radiation"))?;
    let convection = term(&b, "convection").ok_or_else(|| missing("convection"))?;
    println!(
        "{:>6} | {:>9} {:>9} {:>9} | {:>8} {:>8} {:>8} | {:>9} {:>9}",
        "s [m]",
        "d paper",
        "d +mine",
        "d +built",
        "T paper",
        "T +mine",
        "T +built",
        "my_rad",
        "convect."
    );
    println!(
        "{:>6} | {:>29} | {:>26} | {:>19}",
        "", "diameter [µm]", "temperature [K]", "heat gain [W/m]"
    );
    for i in 0..POSITIONS.len() {
        println!(
            "{:>6.2} | {:>9.2} {:>9.2} {:>9.2} | {:>8.2} {:>8.2} {:>8.2} | {:>9.4} {:>9.4}",
            POSITIONS[i],
            1e6 * a.diameter[i],
            1e6 * b.diameter[i],
            1e6 * c.diameter[i],
            a.temperature[i],
            b.temperature[i],
            c.temperature[i],
            user_term[i],
            convection[i]
        );
    }
    Ok(CustomTermSummary {
        diameters: [a.diameter.clone(), b.diameter.clone(), c.diameter.clone()],
        temperatures: [
            a.temperature.clone(),
            b.temperature.clone(),
            c.temperature.clone(),
        ],
        user_term: user_term.clone(),
        convection: convection.clone(),
    })
}

fn main() -> Result<(), FiberError> {
    run().map(|_| ())
}

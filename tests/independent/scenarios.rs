//! The scenarios of issue 11's acceptance tests. All but [`other_material`] use the shipped
//! set's nine experiments and 26 positions (0, 0.02, …, 0.50 m), PMMA7N, truth
//! (n, κ) = (0.8, 11.71) unless stated, and 1.5 % relative Gaussian noise. Strengths and shapes
//! are deliberately far from the project's candidate defaults (co-flow `V e^{−(L−s)/0.1 m}`,
//! warm air `ΔT e^{−s/0.05 m}`).

use super::dataset::{Expected, ExperimentSpec, Faults, Scenario};
use super::model::{AirFlow, AirHeat, Law, Material};

/// Relative noise σ of every scenario [-].
pub const NOISE_SD: f64 = 0.015;

/// The shipped set's experiments: (name, stencil mm/s, bar, d_out m).
const SHIPPED: [(&str, f64, f64, f64); 9] = [
    ("v0p27_p1", 0.27, 1.0, 110e-6),
    ("v0p27_p2", 0.27, 2.0, 70e-6),
    ("v0p27_p3", 0.27, 3.0, 55e-6),
    ("v0p53_p1", 0.53, 1.0, 140e-6),
    ("v0p53_p2", 0.53, 2.0, 90e-6),
    ("v0p53_p3", 0.53, 3.0, 70e-6),
    ("v1p06_p1", 1.06, 1.0, 180e-6),
    ("v1p06_p2", 1.06, 2.0, 120e-6),
    ("v1p06_p3", 1.06, 3.0, 95e-6),
];

fn shipped_experiments() -> Vec<ExperimentSpec> {
    SHIPPED
        .iter()
        .map(|&(name, v, p, d_out)| ExperimentSpec {
            name: name.into(),
            stencil_velocity_mm_s: v,
            take_up_pressure_bar: p,
            mass_flow: 3.08e-5 * v / 0.53,
            take_up_diameter: d_out,
            positions: (0..26).map(|i| 0.02 * i as f64).collect(),
        })
        .collect()
}

/// The shipped set's conditions, no hidden effect.
fn base(name: &'static str, seed: u64) -> Scenario {
    Scenario {
        name,
        material: Material::pmma7n(),
        law: Law {
            n: 0.8,
            kappa: 11.71,
        },
        experiments: shipped_experiments(),
        inlet_temperature: 513.15,
        inlet_diameter: 1.134e-3,
        length: 0.51,
        air_temperature: 293.15,
        air_flow: AirFlow::Still,
        air_heat: AirHeat::Uniform,
        emissivity: 0.0,
        line_force: None,
        faults: Faults::none(),
        noise_sd: NOISE_SD,
        take_up_noise: 1.0,
        noise_lag1: 0.0,
        hardening: 0.0,
        seed,
        acceptable: vec![],
        expected: None,
    }
}

/// No effect at all: nothing may be named.
pub fn control() -> Scenario {
    base("control", 101)
}

/// Strong aspirator jet: 150 m/s at the take-up, Lorentzian decay length 0.08 m.
pub fn aspirator_strong() -> Scenario {
    Scenario {
        air_flow: AirFlow::Aspirator {
            speed: 150.0,
            length: 0.08,
        },
        acceptable: vec!["air_coflow"],
        ..base("aspirator_strong", 102)
    }
}

/// Short aspirator jet: 40 m/s at the take-up, decay length 0.03 m.
pub fn aspirator_short() -> Scenario {
    Scenario {
        air_flow: AirFlow::Aspirator {
            speed: 40.0,
            length: 0.03,
        },
        acceptable: vec!["air_coflow"],
        ..base("aspirator_short", 103)
    }
}

/// Co-flow along the line: 12 m/s, tanh ramp centred at s = 0.25 m, width 0.06 m.
pub fn coflow_line() -> Scenario {
    Scenario {
        air_flow: AirFlow::Ramp {
            speed: 12.0,
            onset: 0.25,
            width: 0.06,
        },
        acceptable: vec!["air_coflow_line", "air_coflow"],
        ..base("coflow_line", 104)
    }
}

/// Warm air near the nozzle: +120 K/(1 + s/0.03 m)².
pub fn warm_air_inverse_square() -> Scenario {
    Scenario {
        air_heat: AirHeat::InverseSquare {
            excess: 120.0,
            length: 0.03,
        },
        acceptable: vec!["air_temperature_profile"],
        ..base("warm_air_inverse_square", 105)
    }
}

/// Warm air decaying linearly: +80 K at the nozzle, zero from s = 0.15 m.
pub fn warm_air_linear() -> Scenario {
    Scenario {
        air_heat: AirHeat::Linear {
            excess: 80.0,
            end: 0.15,
        },
        acceptable: vec!["air_temperature_profile"],
        ..base("warm_air_linear", 106)
    }
}

/// Grey-body radiation, ε = 0.6.
pub fn radiation() -> Scenario {
    Scenario {
        emissivity: 0.6,
        acceptable: vec!["radiation"],
        expected: Some(("radiation", Expected::Emissivity(0.6))),
        ..base("radiation", 107)
    }
}

/// The melt leaves the die 10 K colder than the nominal 513.15 K.
pub fn die_colder() -> Scenario {
    Scenario {
        faults: Faults {
            die_offset_k: -10.0,
            ..Faults::none()
        },
        acceptable: vec!["die_temperature_offset"],
        expected: Some(("die_temperature_offset", Expected::DieOffsetK(-10.0))),
        ..base("die_colder", 108)
    }
}

/// The true mass flow is 4 % below the nominal one.
pub fn mass_flow_low() -> Scenario {
    Scenario {
        faults: Faults {
            mass_flow_factor: 0.96,
            ..Faults::none()
        },
        acceptable: vec!["mass_flow_scale", "inlet_velocity", "inlet_diameter"],
        expected: Some(("mass_flow_scale", Expected::MassFlowFactor(0.96))),
        ..base("mass_flow_low", 109)
    }
}

/// The gauge reads 3 % high.
pub fn gauge_scale() -> Scenario {
    Scenario {
        faults: Faults {
            gauge_factor: 1.03,
            ..Faults::none()
        },
        acceptable: vec!["gauge_scale"],
        expected: Some(("gauge_scale", Expected::GaugeFactor(1.03))),
        ..base("gauge_scale", 110)
    }
}

/// The gauge reads 3 µm high.
pub fn gauge_offset() -> Scenario {
    Scenario {
        faults: Faults {
            gauge_offset_m: 3e-6,
            ..Faults::none()
        },
        acceptable: vec!["gauge_offset"],
        expected: Some(("gauge_offset", Expected::GaugeOffsetM(3e-6))),
        ..base("gauge_offset", 111)
    }
}

/// Seven gross outliers (+15…+35 %), no effect: nothing physical may be named.
pub fn outliers() -> Scenario {
    Scenario {
        faults: Faults {
            outliers: 7,
            ..Faults::none()
        },
        ..base("outliers", 112)
    }
}

/// Two at once: radiation ε = 0.85 and the gauge reading 2.5 % high.
pub fn radiation_and_gauge() -> Scenario {
    Scenario {
        emissivity: 0.85,
        faults: Faults {
            gauge_factor: 1.025,
            ..Faults::none()
        },
        acceptable: vec!["radiation", "gauge_scale"],
        ..base("radiation_and_gauge", 113)
    }
}

/// Another material (n, κ) = (0.65, 12.3), other VFT data, inlet 520 K, other mass flows,
/// non-uniform positions (denser near the nozzle), six experiments, with radiation ε = 0.45.
pub fn other_material() -> Scenario {
    let material = Material {
        mu_c: 2.0e-4,
        vft_b: 3800.0,
        vft_t_vf: 270.0,
        rho_slope: -0.9,
        rho_intercept: 1550.0,
        ..Material::pmma7n()
    };
    let positions: Vec<f64> = (0..22)
        .map(|i| 0.48 * (i as f64 / 21.0).powf(1.6))
        .map(|s| (s * 1e4).round() / 1e4)
        .collect();
    let runs = [
        (2.2e-5, 100e-6),
        (2.2e-5, 65e-6),
        (4.0e-5, 130e-6),
        (4.0e-5, 85e-6),
        (5.0e-5, 150e-6),
        (5.0e-5, 100e-6),
    ];
    let experiments = runs
        .iter()
        .enumerate()
        .map(|(i, &(q, d_out))| ExperimentSpec {
            name: format!("run{}", i + 1),
            stencil_velocity_mm_s: q / 3.08e-5 * 0.53,
            take_up_pressure_bar: 1.0 + (i % 2) as f64,
            mass_flow: q,
            take_up_diameter: d_out,
            positions: positions.clone(),
        })
        .collect();
    Scenario {
        material,
        law: Law {
            n: 0.65,
            kappa: 12.3,
        },
        experiments,
        inlet_temperature: 520.0,
        air_temperature: 298.15,
        emissivity: 0.45,
        acceptable: vec!["radiation"],
        expected: Some(("radiation", Expected::Emissivity(0.45))),
        ..base("other_material", 114)
    }
}

/// An aspirator jet of `speed` m/s at the take-up and Lorentzian decay length `length` m
/// (issue 11's range: 30–300 m/s, 0.03–0.3 m).
pub fn aspirator(speed: f64, length: f64, seed: u64) -> Scenario {
    Scenario {
        air_flow: AirFlow::Aspirator { speed, length },
        acceptable: vec!["air_coflow"],
        ..base("aspirator_range", seed)
    }
}

/// Warm air near the nozzle with the profile `heat`.
pub fn warm_air(heat: AirHeat, seed: u64) -> Scenario {
    Scenario {
        air_heat: heat,
        acceptable: vec!["air_temperature_profile"],
        ..base("warm_air_range", seed)
    }
}

/// Warm air near the die (+150 K, inverse-square decay over 0.08 m) and an aspirator jet at
/// the take-up (60 m/s, Lorentzian of 0.10 m) together: two effects at once (issue 26; the
/// book's `data/two_effects`).
pub fn warm_air_and_coflow() -> Scenario {
    Scenario {
        name: "warm_air_and_coflow",
        air_heat: AirHeat::InverseSquare {
            excess: 150.0,
            length: 0.08,
        },
        air_flow: AirFlow::Aspirator {
            speed: 60.0,
            length: 0.10,
        },
        ..aspirator(60.0, 0.10, 2604)
    }
}

/// Grey-body radiation with emissivity `emissivity`.
pub fn radiating(emissivity: f64, seed: u64) -> Scenario {
    Scenario {
        emissivity,
        acceptable: vec!["radiation"],
        expected: Some(("radiation", Expected::Emissivity(emissivity))),
        ..base("radiation_range", seed)
    }
}

/// One process or instrument fault (the first that is set of: die offset, mass flow, gauge
/// scale, gauge offset), or outliers alone (nothing to name).
pub fn with_faults(faults: Faults, seed: u64) -> Scenario {
    let expected = if faults.die_offset_k != 0.0 {
        Some((
            "die_temperature_offset",
            Expected::DieOffsetK(faults.die_offset_k),
        ))
    } else if faults.mass_flow_factor != 1.0 {
        Some((
            "mass_flow_scale",
            Expected::MassFlowFactor(faults.mass_flow_factor),
        ))
    } else if faults.gauge_factor != 1.0 {
        Some(("gauge_scale", Expected::GaugeFactor(faults.gauge_factor)))
    } else if faults.gauge_offset_m != 0.0 {
        Some((
            "gauge_offset",
            Expected::GaugeOffsetM(faults.gauge_offset_m),
        ))
    } else {
        None
    };
    Scenario {
        faults,
        acceptable: expected.iter().map(|e| e.0).collect(),
        expected,
        ..base("fault_range", seed)
    }
}

/// A melt without strain thinning (issue 31): the Newtonian law, `n = 1` (`κ` then does not
/// enter; 11.71 kept for the record), the shipped set's conditions, no hidden effect.
pub fn newtonian() -> Scenario {
    Scenario {
        law: Law {
            n: 1.0,
            kappa: 11.71,
        },
        ..base("newtonian", 115)
    }
}

/// A melt with barely any strain thinning (issue 31): `n = 0.99`, `κ = 11.71`, the shipped
/// set's conditions, no hidden effect (`n = 0.95` is detected on these conditions: LR 340).
pub fn slightly_thinning() -> Scenario {
    Scenario {
        law: Law {
            n: 0.99,
            kappa: 11.71,
        },
        ..base("slightly_thinning", 116)
    }
}

/// Three of the shipped set's experiments (the slowest at 1 bar, the middle one, the fastest
/// at 3 bar) with an aspirator jet of `speed` m/s at the take-up and Lorentzian decay length
/// `length` m (issue 65: few runs, where a strength scan's valley is narrow).
pub fn three_runs_aspirator(speed: f64, length: f64, seed: u64) -> Scenario {
    let experiments = shipped_experiments().into_iter().step_by(4).collect();
    Scenario {
        name: "three_runs_aspirator",
        experiments,
        ..aspirator(speed, length, seed)
    }
}

/// A die `die_offset_k` K off its declared temperature (negative: colder) together with an
/// aspirator jet of `speed` m/s at the take-up and Lorentzian decay length `length` m (issue
/// 65: a process fault with a near-twin, the Nusselt factor, inside a pair).
pub fn die_offset_and_coflow(die_offset_k: f64, speed: f64, length: f64, seed: u64) -> Scenario {
    Scenario {
        name: "die_offset_and_coflow",
        faults: Faults {
            die_offset_k,
            ..Faults::none()
        },
        air_flow: AirFlow::Aspirator { speed, length },
        acceptable: vec!["air_coflow", "die_temperature_offset"],
        ..base("die_offset_and_coflow", seed)
    }
}

/// A strongly thinning melt (`n` = 0.45, `κ` = 12.0) with one process or instrument fault
/// (`faults`), the shipped set's conditions otherwise (issue 65: strong thinning with a fault).
pub fn strongly_thinning_with(faults: Faults, seed: u64) -> Scenario {
    Scenario {
        name: "strongly_thinning_with_fault",
        law: Law {
            n: 0.45,
            kappa: 12.0,
        },
        ..with_faults(faults, seed)
    }
}

/// Grey-body radiation of emissivity `emissivity` and warm air near the die (`excess` K over
/// an inverse square of `length` m) together: two physics effects at once (issue 65).
pub fn radiation_with_warm_air(emissivity: f64, excess: f64, length: f64, seed: u64) -> Scenario {
    Scenario {
        name: "radiation_with_warm_air",
        emissivity,
        air_heat: AirHeat::InverseSquare { excess, length },
        acceptable: vec!["radiation", "air_temperature_profile"],
        expected: None,
        ..base("radiation_with_warm_air", seed)
    }
}

//! A scenario (the truth: law, true process conditions, hidden physics, instrument faults,
//! outliers) and its data set written in the project's input format (TOML + one CSV per
//! experiment) to a fresh directory under `target/independent-data/`.

use super::line_force::{forced_diameters, ForcedLine, LineForce};
use super::model::{AirFlow, AirHeat, Law, Line, Material};
use super::rng::Rng;
use super::solve::diameters;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

/// One experiment as the user records it (nominal values) plus its true take-up diameter.
#[derive(Debug, Clone, PartialEq)]
pub struct ExperimentSpec {
    /// Name.
    pub name: String,
    /// Stencil velocity [mm/s] (metadata).
    pub stencil_velocity_mm_s: f64,
    /// Take-up pressure [bar] (metadata).
    pub take_up_pressure_bar: f64,
    /// Nominal mass flow written to the TOML [kg/s].
    pub mass_flow: f64,
    /// True take-up diameter [m] (not written: the rheometer takes it from the data).
    pub take_up_diameter: f64,
    /// Measurement positions [m].
    pub positions: Vec<f64>,
}

/// Process and instrument faults (all neutral in [`Faults::none`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Faults {
    /// True inlet temperature minus the nominal one written to the TOML [K].
    pub die_offset_k: f64,
    /// True mass flow over the nominal one written to the TOML [-].
    pub mass_flow_factor: f64,
    /// Gauge reading over the true diameter [-] (1.03: 3 % high).
    pub gauge_factor: f64,
    /// Gauge offset added to every reading [m].
    pub gauge_offset_m: f64,
    /// Number of gross outliers (each reading multiplied by 1 + U(0.15, 0.35)).
    pub outliers: usize,
}

impl Faults {
    /// No faults.
    pub const fn none() -> Self {
        Faults {
            die_offset_k: 0.0,
            mass_flow_factor: 1.0,
            gauge_factor: 1.0,
            gauge_offset_m: 0.0,
            outliers: 0,
        }
    }
}

/// A strength the diagnosis should recover, in a stated convention; [`Expected::in_unit`]
/// converts it to a candidate's reported unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Expected {
    /// Emissivity [-].
    Emissivity(f64),
    /// True − nominal inlet temperature [K].
    DieOffsetK(f64),
    /// True / nominal mass flow [-].
    MassFlowFactor(f64),
    /// Reading / true diameter [-].
    GaugeFactor(f64),
    /// Reading − true diameter [m].
    GaugeOffsetM(f64),
}

impl Expected {
    /// The truth in the unit of a candidate's reported `strength` (`unit` its unit string), if
    /// the unit is understood. A dimensionless factor may be reported as the factor (neutral 1)
    /// or as the relative change (neutral 0): a strength within 0.5 of 1 is taken as the factor.
    pub fn in_unit(&self, unit: &str, strength: f64) -> Option<f64> {
        let u = unit.trim();
        let factor = |f: f64| match u {
            "-" | "" | "1" if (strength - 1.0).abs() < 0.5 => Some(f),
            "-" | "" | "1" => Some(f - 1.0),
            "%" => Some(100.0 * (f - 1.0)),
            _ => None,
        };
        match *self {
            Expected::Emissivity(e) => Some(e),
            Expected::DieOffsetK(k) => (u == "K").then_some(k),
            Expected::MassFlowFactor(f) | Expected::GaugeFactor(f) => factor(f),
            Expected::GaugeOffsetM(m) => match u {
                "m" => Some(m),
                "µm" | "um" | "μm" => Some(m * 1e6),
                _ => None,
            },
        }
    }
}

/// A scenario: everything needed to make its data, and the truth the tests check against.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// Short name (also the directory name prefix).
    pub name: &'static str,
    /// Material (written to the TOML).
    pub material: Material,
    /// True viscosity law (n, κ).
    pub law: Law,
    /// Experiments.
    pub experiments: Vec<ExperimentSpec>,
    /// Nominal inlet temperature written to the TOML [K].
    pub inlet_temperature: f64,
    /// Inlet diameter (after die swell) [m].
    pub inlet_diameter: f64,
    /// Spin-line length [m].
    pub length: f64,
    /// Ambient air temperature [K].
    pub air_temperature: f64,
    /// Hidden air flow.
    pub air_flow: AirFlow,
    /// Hidden warm air.
    pub air_heat: AirHeat,
    /// Hidden grey-body emissivity [-].
    pub emissivity: f64,
    /// Hidden concentrated line force (still air only).
    pub line_force: Option<LineForce>,
    /// Process and instrument faults.
    pub faults: Faults,
    /// Relative Gaussian noise σ [-].
    pub noise_sd: f64,
    /// Noise near the take-up: σ times this factor for `s > 0.8 L` (1: uniform noise).
    pub take_up_noise: f64,
    /// Lag-1 autocorrelation of the noise along each line, an AR(1) process in the points'
    /// order (0: white noise; 0.5: as from a vibrating fiber or a slow gauge) [-].
    pub noise_lag1: f64,
    /// Strain hardening β of the melt [-] (see [`Line::hardening`]; 0: none).
    pub hardening: f64,
    /// Seed of the noise.
    pub seed: u64,
    /// Candidate names accepted as the cause ranked first (empty: nothing may be named).
    pub acceptable: Vec<&'static str>,
    /// The candidate whose parametrisation equals the truth's, and the strength it must
    /// recover when it is named.
    pub expected: Option<(&'static str, Expected)>,
}

/// A generated data set.
#[derive(Debug, Clone)]
pub struct Generated {
    /// The TOML file.
    pub toml: PathBuf,
    /// (experiment index, measurement index) of the outliers.
    pub outliers: Vec<(usize, usize)>,
    /// Noise-free true diameters [m] per experiment (before instrument faults).
    pub clean: Vec<Vec<f64>>,
}

impl Scenario {
    /// The true line of experiment `k`.
    pub fn line(&self, k: usize) -> Line {
        let e = &self.experiments[k];
        Line {
            material: self.material.clone(),
            law: self.law,
            mass_flow: e.mass_flow * self.faults.mass_flow_factor,
            inlet_temperature: self.inlet_temperature + self.faults.die_offset_k,
            inlet_diameter: self.inlet_diameter,
            take_up_diameter: e.take_up_diameter,
            length: self.length,
            air_temperature: self.air_temperature,
            air_flow: self.air_flow,
            air_heat: self.air_heat,
            emissivity: self.emissivity,
            hardening: self.hardening,
        }
    }

    /// Noise-free true diameters [m] of experiment `k` at its positions.
    fn clean_diameters(&self, k: usize) -> Result<Vec<f64>, String> {
        let positions = &self.experiments[k].positions;
        match self.line_force {
            Some(force) => {
                if !matches!(self.air_flow, AirFlow::Still) {
                    return Err("a line force is modelled in still air only".into());
                }
                let forced = ForcedLine {
                    line: self.line(k),
                    force,
                };
                forced_diameters(&forced, positions)
            }
            None => diameters(&self.line(k), positions),
        }
    }

    /// Simulates every experiment, applies the faults, noise and outliers, and writes the data
    /// set to a fresh directory.
    pub fn generate(&self) -> Result<Generated, String> {
        let clean: Vec<Vec<f64>> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..self.experiments.len())
                .map(|k| scope.spawn(move || self.clean_diameters(k)))
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or_else(|_| Err("panic".into())))
                .collect::<Result<_, String>>()
        })?;
        let mut rng = Rng::new(self.seed);
        let f = &self.faults;
        let mut measured: Vec<Vec<f64>> = clean
            .iter()
            .enumerate()
            .map(|(k, d)| {
                // AR(1) along the line, unit variance: e_i = ρ e_(i-1) + √(1 - ρ²) z_i,
                // started from its stationary distribution (white noise at ρ = 0, the same
                // draws as without correlation)
                let rho = self.noise_lag1;
                let mut e: Option<f64> = None;
                d.iter()
                    .zip(&self.experiments[k].positions)
                    .map(|(&di, &s)| {
                        let sd = if s > 0.8 * self.length {
                            self.noise_sd * self.take_up_noise
                        } else {
                            self.noise_sd
                        };
                        let z = rng.normal();
                        let now = match e {
                            Some(prev) => rho * prev + (1.0 - rho * rho).sqrt() * z,
                            None => z,
                        };
                        e = Some(now);
                        (di * f.gauge_factor + f.gauge_offset_m) * (1.0 + sd * now)
                    })
                    .collect()
            })
            .collect();
        let total: usize = measured.iter().map(Vec::len).sum();
        let mut outliers = Vec::new();
        while outliers.len() < f.outliers.min(total) {
            let mut idx = (rng.uniform() * total as f64) as usize;
            let mut k = 0;
            while idx >= measured[k].len() {
                idx -= measured[k].len();
                k += 1;
            }
            if outliers.contains(&(k, idx)) {
                continue;
            }
            measured[k][idx] *= 1.0 + 0.15 + 0.20 * rng.uniform();
            outliers.push((k, idx));
        }
        let toml = self.write(&measured)?;
        Ok(Generated {
            toml,
            outliers,
            clean,
        })
    }

    fn write(&self, measured: &[Vec<f64>]) -> Result<PathBuf, String> {
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        // one directory per test binary, scenario and data set made in this process: a later
        // run of the same test overwrites its own data instead of adding to them
        let binary = std::env::current_exe()
            .ok()
            .and_then(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
            .map(|s| s.split('-').next().unwrap_or("tests").to_string())
            .unwrap_or_else(|| "tests".to_string());
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("target")
            .join("independent-data")
            .join(binary)
            .join(format!(
                "{}-{}",
                self.name,
                COUNTER.fetch_add(1, Ordering::Relaxed)
            ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let m = &self.material;
        let mut t = String::new();
        let _ = writeln!(
            t,
            "# Generated by tests/independent (scenario {}); the truth is in the test code.\n",
            self.name
        );
        let _ = writeln!(t, "[material]");
        for (k, v) in [
            ("density_slope_kg_m3_K", m.rho_slope),
            ("density_intercept_kg_m3", m.rho_intercept),
            ("heat_capacity_slope_J_kg_K2", m.cp_slope),
            ("heat_capacity_intercept_J_kg_K", m.cp_intercept),
            ("vft_mu_c_Pa_s", m.mu_c),
            ("vft_B_K", m.vft_b),
            ("vft_T_VF_K", m.vft_t_vf),
            ("air_density_kg_m3", m.air_rho),
            ("air_heat_capacity_J_kg_K", m.air_cp),
            ("air_kinematic_viscosity_m2_s", m.air_nu),
            ("air_heat_conductivity_W_m_K", m.air_lambda),
        ] {
            let _ = writeln!(t, "{k} = {v:?}");
        }
        let _ = writeln!(
            t,
            "\n[defaults]\nspinline_length_m = {:?}\ninlet_temperature_K = {:?}\nair_temperature_K = {:?}\ninlet_diameter_m = {:?}",
            self.length, self.inlet_temperature, self.air_temperature, self.inlet_diameter
        );
        for (e, d) in self.experiments.iter().zip(measured) {
            let file = format!("{}.csv", e.name);
            let _ = writeln!(
                t,
                "\n[[experiment]]\nname = \"{}\"\nstencil_velocity_mm_s = {:?}\ntake_up_pressure_bar = {:?}\nmass_flow_kg_s = {:?}\ndata = \"{file}\"",
                e.name, e.stencil_velocity_mm_s, e.take_up_pressure_bar, e.mass_flow
            );
            let mut csv = String::from("position_m,diameter_m\n");
            for (s, di) in e.positions.iter().zip(d) {
                let _ = writeln!(csv, "{s:.6},{di:.7e}");
            }
            let path = dir.join(&file);
            std::fs::write(&path, csv).map_err(|e| format!("{}: {e}", path.display()))?;
        }
        let path = dir.join("experiments.toml");
        std::fs::write(&path, t).map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(path)
    }
}

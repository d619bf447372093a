//! Inputs of a spinning experiment in SI units, as a user fills them in or as they are loaded
//! from the project's TOML + CSV format.

/// Polymer material data (paper Table 1).
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Slope `a_ρ` of the density line `ρ(T) = a_ρ T + b_ρ` [kg/(m³ K)].
    pub density_slope: f64,
    /// Intercept `b_ρ` of the density line \[kg/m³\].
    pub density_intercept: f64,
    /// Slope `a_cp` of the heat-capacity line `c_p(T) = a_cp T + b_cp` [J/(kg K²)].
    pub heat_capacity_slope: f64,
    /// Intercept `b_cp` of the heat-capacity line [J/(kg K)].
    pub heat_capacity_intercept: f64,
    /// VFT prefactor `μ_c` of the zero-shear viscosity `μ_s0(T) = μ_c exp(B/(T - T_VF))` \[Pa s\].
    pub vft_mu_c: f64,
    /// VFT activation temperature `B` (K).
    pub vft_b: f64,
    /// Vogel temperature `T_VF` (K).
    pub vft_t_vf: f64,
    /// Trouton ratio `μ_e0/μ_s0` \[-\] (3 for generalized Newtonian fluids).
    pub trouton: f64,
}

impl Material {
    /// PMMA7N of the paper (Table 1).
    pub fn pmma7n() -> Self {
        Material {
            density_slope: -0.964,
            density_intercept: 1572.33,
            heat_capacity_slope: 3.2,
            heat_capacity_intercept: 648.22,
            vft_mu_c: 3.7074e-4,
            vft_b: 3649.0,
            vft_t_vf: 273.15,
            trouton: 3.0,
        }
    }

    /// Density `ρ(T)` \[kg/m³\] at temperature `t` \[K\].
    pub fn density(&self, t: f64) -> f64 {
        self.density_slope * t + self.density_intercept
    }

    /// Specific heat capacity `c_p(T)` [J/(kg K)] at temperature `t` \[K\].
    pub fn heat_capacity(&self, t: f64) -> f64 {
        self.heat_capacity_slope * t + self.heat_capacity_intercept
    }

    /// Zero-shear viscosity `μ_s0(T)` \[Pa s\] at temperature `t` \[K\].
    pub fn zero_shear_viscosity(&self, t: f64) -> f64 {
        self.vft_mu_c * (self.vft_b / (t - self.vft_t_vf)).exp()
    }
}

/// Ambient air properties (constant along the spin line; paper Table 1).
#[derive(Debug, Clone, PartialEq)]
pub struct Air {
    /// Density `ρ_*` \[kg/m³\].
    pub density: f64,
    /// Specific heat capacity `c_p,*` [J/(kg K)].
    pub heat_capacity: f64,
    /// Kinematic viscosity `ν_*` \[m²/s\].
    pub kinematic_viscosity: f64,
    /// Heat conductivity `λ_*` [W/(m K)].
    pub heat_conductivity: f64,
}

impl Air {
    /// The paper's air (Table 1).
    pub fn paper() -> Self {
        Air {
            density: 1.0,
            heat_capacity: 1000.0,
            kinematic_viscosity: 2e-5,
            heat_conductivity: 0.031,
        }
    }
}

/// How the fiber enters the spin line (after die swell).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Inlet {
    /// Inlet diameter `d_in` \[m\]; the inlet speed follows as `u_in = 4 Q/(π ρ(T_in) d_in²)`.
    Diameter(f64),
    /// Inlet speed `u_in` \[m/s\].
    Velocity(f64),
}

/// The take-up boundary condition at `s = L`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TakeUp {
    /// Take-up diameter `d_out` \[m\]: `d(L) = d_out`.
    Diameter(f64),
    /// Take-up speed `u_out` [m/s]: `u(L) = u_out`.
    Velocity(f64),
}

/// One spinning experiment (process conditions), SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct Experiment {
    /// Name used in reports and output file names.
    pub name: String,
    /// Mass flow `Q` \[kg/s\].
    pub mass_flow: f64,
    /// Inlet condition.
    pub inlet: Inlet,
    /// Fiber temperature at the inlet `T_in` (K).
    pub inlet_temperature: f64,
    /// Ambient air temperature `T_air` (K).
    pub air_temperature: f64,
    /// Spin-line length `L` \[m\].
    pub spinline_length: f64,
    /// Take-up condition, if known (the shipped measurement set has none: the rheometer takes
    /// it from the data).
    pub take_up: Option<TakeUp>,
}

/// Names, stencil velocities (mm/s) and true take-up diameters (m) of the nine experiments of
/// the shipped data set `data/pmma7n_synthetic` (its TRUTH.md).
const PMMA7N_SYNTHETIC: [(&str, f64, f64); 9] = [
    ("v0p27_p1", 0.27, 110e-6),
    ("v0p27_p2", 0.27, 70e-6),
    ("v0p27_p3", 0.27, 55e-6),
    ("v0p53_p1", 0.53, 140e-6),
    ("v0p53_p2", 0.53, 90e-6),
    ("v0p53_p3", 0.53, 70e-6),
    ("v1p06_p1", 1.06, 180e-6),
    ("v1p06_p2", 1.06, 120e-6),
    ("v1p06_p3", 1.06, 95e-6),
];

impl Experiment {
    /// The nine experiments of the shipped PMMA7N-like data set (`data/pmma7n_synthetic`) with
    /// the true take-up diameters of its TRUTH.md (the TOML has none): mass flow
    /// 3.08e-5 kg/s × v/(0.53 mm/s) for stencil velocity v = 0.27, 0.53, 1.06 mm/s, inlet
    /// diameter 1.134 mm at 513.15 K, air at 293.15 K, spin line 0.51 m. Reference cases for
    /// examples, tests, benchmarks and synthetic data.
    pub fn pmma7n_synthetic_truth() -> Vec<Experiment> {
        PMMA7N_SYNTHETIC
            .iter()
            .map(|&(name, v, d_out)| Experiment {
                name: name.into(),
                mass_flow: 3.08e-5 * v / 0.53,
                inlet: Inlet::Diameter(1.134e-3),
                inlet_temperature: 513.15,
                air_temperature: 293.15,
                spinline_length: 0.51,
                take_up: Some(TakeUp::Diameter(d_out)),
            })
            .collect()
    }

    /// Experiment `v0p53_p2` of [`pmma7n_synthetic_truth`](Self::pmma7n_synthetic_truth)
    /// (mass flow 3.08e-5 kg/s, take-up diameter 90 µm): a single reference case.
    pub fn pmma7n_v0p53_p2() -> Self {
        Self::pmma7n_synthetic_truth().swap_remove(4)
    }
}

/// Measured diameters of one experiment.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurements {
    /// Positions `s` along the spin line \[m\], strictly increasing.
    pub positions: Vec<f64>,
    /// Measured fiber diameters \[m\].
    pub diameters: Vec<f64>,
}

/// A set of experiments on one material, with their measurements.
#[derive(Debug, Clone, PartialEq)]
pub struct ExperimentSet {
    /// The polymer.
    pub material: Material,
    /// The ambient air.
    pub air: Air,
    /// The experiments.
    pub experiments: Vec<Experiment>,
    /// Measurements per experiment (same order; `None` where an experiment has no data file).
    pub measurements: Vec<Option<Measurements>>,
    /// Relative measurement uncertainty of the diameters \[-\], if given.
    pub relative_uncertainty: Option<f64>,
}

impl ExperimentSet {
    /// The experiments' names, in order.
    pub fn names(&self) -> Vec<String> {
        self.experiments.iter().map(|e| e.name.clone()).collect()
    }
}

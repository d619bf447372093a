//! Loading a set of spinning experiments from the project's TOML + CSV input format.
//!
//! # Format
//!
//! A data set is one TOML file describing the material and the experiments, plus one CSV file
//! of measured diameters per experiment. All quantities are SI; **the unit is part of every key
//! name** (`_m`, `_kg_s`, `_K`, …). Unknown keys are an error (naming file, line, table and key,
//! with a suggestion for likely typos), so a misspelt key is never silently ignored.
//!
//! ```toml
//! relative_uncertainty = 0.015   # optional, top level (before the first [table]):
//!                                # relative measurement uncertainty of the diameters [-]
//! [material]
//! density_slope_kg_m3_K = -0.964           # rho(T) = slope * T + intercept, T in K
//! density_intercept_kg_m3 = 1572.33
//! heat_capacity_slope_J_kg_K2 = 3.2        # c_p(T) = slope * T + intercept
//! heat_capacity_intercept_J_kg_K = 648.22
//! vft_mu_c_Pa_s = 0.00037074               # mu_s0(T) = mu_c exp(B / (T - T_VF))
//! vft_B_K = 3649.0
//! vft_T_VF_K = 273.15
//! trouton_ratio = 3.0                      # optional, default 3: mu_e0 = trouton_ratio * mu_s0
//! air_density_kg_m3 = 1.0
//! air_heat_capacity_J_kg_K = 1000.0
//! air_kinematic_viscosity_m2_s = 2e-05
//! air_heat_conductivity_W_m_K = 0.031
//!
//! [defaults]                               # optional; any per-experiment key except name/data
//! spinline_length_m = 0.51
//! inlet_temperature_K = 513.15
//! air_temperature_K = 293.15
//!
//! [[experiment]]                           # one table per experiment, at least one
//! name = "v0p27_p1"                        # unique; used in reports and output file names
//! mass_flow_kg_s = 1.569e-05
//! inlet_diameter_m = 0.001134              # or inlet_velocity_m_s (exactly one of the two)
//! # take_up_diameter_m = 1.1e-4            # optional, or take_up_velocity_m_s (at most one)
//! data = "v0p27_p1.csv"                    # optional; relative to the TOML file's directory
//! stencil_velocity_mm_s = 0.27             # optional, descriptive only (kept as metadata)
//! take_up_pressure_bar = 1.0               # optional, descriptive only (kept as metadata)
//! spinline_length_m = 0.51                 # any [defaults] key may be overridden here
//! ```
//!
//! Optional standard uncertainties of what the data cannot identify (process conditions,
//! instrument, material data), for the error budget of a fit; each experiment may override them
//! in its own table (see [`fiber::uncertainty`](crate::fiber::uncertainty) for the keys,
//! defaults and scopes):
//!
//! ```toml
//! [uncertainty]                            # optional, top level
//! inlet_temperature_K = 3.0                # melt temperature at the die, ± K
//! mass_flow_rel = 0.02                     # relative: 0.02 = 2 %
//! inlet_diameter_rel = 0.03
//! gauge_scale_rel = 0.01
//! gauge_offset_um = 2.0                    # µm
//!
//! [[experiment]]
//! name = "a"
//! # ...
//! [experiment.uncertainty]                 # optional, this experiment only
//! mass_flow_rel = 0.05
//! ```
//!
//! Required per experiment (in its table or in `[defaults]`): `mass_flow_kg_s`,
//! `spinline_length_m`, `inlet_temperature_K`, `air_temperature_K` and one inlet key. The inlet
//! keys (`inlet_diameter_m`/`inlet_velocity_m_s`) and the take-up keys
//! (`take_up_diameter_m`/`take_up_velocity_m_s`) are resolved as pairs: if an experiment gives
//! either key of a pair, `[defaults]` is not consulted for that pair. Integers are accepted
//! where numbers are expected; `nan` and `inf` are rejected.
//!
//! Checks: mass flow, diameters, velocities, lengths and temperatures must be positive and
//! within plausible ranges for melt spinning ([`PLAUSIBLE_RANGES`]; diameters between
//! [`MIN_PLAUSIBLE_DIAMETER_M`] = 1 µm and [`MAX_PLAUSIBLE_DIAMETER_M`] = 2 cm, larger ones
//! being probably millimetres); the inlet and air temperatures must exceed `vft_T_VF_K` (the VFT
//! viscosity is undefined at and below it) and the zero-shear viscosity at the inlet must be
//! finite and at most [`MAX_INLET_VISCOSITY_PA_S`] (a glass is not a melt); density and heat
//! capacity must be positive at the inlet and air temperatures; the derived inlet velocity
//! `4 Q/(π ρ(T_in) d_in²)` (or inlet diameter, when the velocity is given) must be finite and
//! plausible; a take-up diameter must be smaller than the inlet diameter (a take-up velocity
//! larger than the inlet velocity), with a draw ratio of at most [`MAX_DRAW_RATIO`]; experiment
//! names must be unique. Errors about values that come from `[defaults]` name the experiment too.
//!
//! The CSV file has the header `position_m,diameter_m` and one row per measurement: the
//! position `s` along the spin line \[m\] (strictly increasing, within `[0, spinline_length_m]`)
//! and the measured fiber diameter \[m\] (between 1 µm and 0.02 m). Blank lines and lines
//! starting with `#` are ignored; surrounding spaces are trimmed. At least
//! [`DEFAULT_MIN_POINTS`] rows are required by [`load_experiments`]; the minimum is a parameter
//! of [`load_measurements`] and [`load_experiments_with`].
//!
//! Loading only reads files; it never modifies or writes them.
//!
//! # Layout
//!
//! * `error`: [`Location`] and [`InputError`], the messages of every failure;
//! * `schema`: the keys of each table, the rules their values obey, plausible ranges, and
//!   hints for misspelt or misplaced keys;
//! * `spanned`: reading the TOML document with spans, so that every error names a line;
//! * `experiments`: building the [`ExperimentSet`](super::setup::ExperimentSet) from the
//!   tables, with the plausibility checks of each experiment;
//! * `measurements`: reading the measurement CSV files;
//! * `uncertainty`: reading the `[uncertainty]` tables (declared standard uncertainties of
//!   process conditions, instrument and material data, see
//!   [`fiber::uncertainty`](crate::fiber::uncertainty)).

mod error;
mod experiments;
mod measurements;
mod schema;
mod spanned;
mod uncertainty;

use std::path::Path;

pub use error::{InputError, Location};
pub use experiments::{
    load_experiments, load_experiments_with, parse_experiments, ExperimentDetails,
    LoadedExperiments, MAX_DRAW_RATIO, MAX_INLET_VISCOSITY_PA_S,
};
pub use measurements::{load_measurements, parse_measurements, CSV_HEADER, DEFAULT_MIN_POINTS};
pub use schema::{MAX_PLAUSIBLE_DIAMETER_M, MIN_PLAUSIBLE_DIAMETER_M, PLAUSIBLE_RANGES};

/// Reads a whole input file as text.
fn read_text(path: &Path) -> Result<String, InputError> {
    std::fs::read_to_string(path).map_err(|source| InputError::Io {
        path: path.to_path_buf(),
        source,
    })
}

//! Loading a set of spinning experiments from the project's TOML + CSV input format.
//!
//! # Format
//!
//! A data set is one TOML file describing the material and the experiments, plus one CSV file
//! of measured diameters per experiment. **The unit is part of every key name** (`_m`, `_kg_s`,
//! `_K`, …) and of every CSV column name. The process conditions may be given in the units of a
//! lab sheet, converted once at load to SI (the
//! [`ExperimentSet`](crate::model::ExperimentSet) is SI whatever the file used); a quantity
//! given twice in different units is an error naming both keys:
//!
//! | quantity | units (key suffix) |
//! |---|---|
//! | `mass_flow` | `kg_s`, `g_s`, `g_min`, `g_h`, `kg_h` |
//! | `inlet_diameter`, `take_up_diameter` | `m`, `mm`, `um` |
//! | `spinline_length` | `m`, `cm`, `mm` |
//! | `inlet_velocity`, `take_up_velocity` | `m_s`, `mm_s`, `m_min` |
//! | `inlet_temperature`, `air_temperature`, `vft_T_VF` | `K`, `C` (°C) |
//! | CSV `position`, `diameter` columns | `m`, `cm`, `mm`; `m`, `mm`, `um` |
//!
//! Unknown keys are an error (naming file, line, table and key, with a suggestion for likely
//! typos), so a misspelt key is never silently ignored.
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
//! in its own table (see [`fiber::uncertainty`](crate::data::uncertainty) for the keys,
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
//! Checks (on the SI values, so that a value in the wrong unit is still caught, with a hint at
//! the key that would make it plausible): mass flow, diameters, velocities, lengths and
//! temperatures must be positive and within plausible ranges for melt spinning
//! (a refusal names the range; diameters between 1 µm and 2 cm, larger ones being probably
//! millimetres); the inlet and
//! air temperatures must exceed `vft_T_VF_K` (the VFT viscosity is undefined at and below it;
//! a kelvin value that reads as °C gets a hint) and the zero-shear viscosity at the inlet must
//! be finite and at most 10¹² Pa s (a glass is not a melt); density and heat capacity must be
//! plausible for a polymer at the inlet and air temperatures (300–3500 kg/m³,
//! 300–10 000 J/(kg K)); the inlet velocity
//! `4 Q/(π ρ(T_in) d_in²)` must be at most 5 m/s (a faster one
//! is blamed on the mass flow's unit) and the derived inlet diameter plausible; a take-up
//! diameter must be smaller than the inlet diameter (a take-up velocity larger than the inlet
//! velocity), with a draw ratio of at most 10⁶; experiment names must be unique
//! (also ignoring case), without leading or trailing spaces, and at most 236 bytes long (they
//! name output files: 255 bytes less the longest suffix, `_fitted_profile.csv`). Errors about
//! values that come from `[defaults]` name the experiment too. With the measurements,
//! [`load_experiments_with`] also checks the inlet diameter against the first measured diameter
//! and, for an experiment whose take-up diameter will be `d_fit(L)` of its data, the spin-line
//! length against the measured range
//! (a warning a little beyond, an error far beyond: [`LoadOptions::take_up_warn_beyond`]).
//!
//! Inputs are read only from regular files (a FIFO, device or directory is refused before it is
//! opened), under the caps of [`LoadOptions`] checked while reading: the size of each file, the
//! length of a CSV line, the rows per file, the number of experiments and the estimated memory
//! of a fit ([`estimated_fit_memory_bytes`]). A file that is not UTF-8 is refused with the byte
//! offset, line and what it looks like (UTF-16, Latin-1, binary, a spreadsheet).
//!
//! The CSV file has the header `position_m,diameter_m` (or other units, as above) and one row
//! per measurement: the position `s` along the spin line (strictly increasing, within `[0,
//! spinline_length_m]`) and the measured fiber diameter (between 1 µm and 0.02 m). Blank lines
//! and lines starting with `#` are ignored; surrounding spaces and quotes are trimmed; the
//! dialects of other tools (semicolons, tabs, decimal commas, trailing commas, Fortran `D`
//! exponents) are refused with what to change. At least
//! `DEFAULT_MIN_POINTS` rows are required by [`load_experiments`]; the minimum is a parameter
//! of [`load_measurements_with`] and [`load_experiments_with`].
//!
//! Loading only reads files; it never modifies or writes them.
//!
//! # Layout
//!
//! Bottom to top (each file imports only from the files listed before it; the files of the
//! experiments file are in `toml_file`, those of the measurement files in `csv_file`):
//!
//! * `options`: [`LoadOptions`] (the caps) and the fit-memory estimate;
//! * `error`: [`Location`], [`InputError`] and `InputWarning`, the messages of every failure;
//! * `source`: opening regular files only, bounded reading, encoding checks;
//! * `json`: reading a JSON report back (`fit --from`, `compare --fit`), bounded and strict
//!   (`read_json`: the file checks of `source`, `-` for standard input, duplicate keys,
//!   `NaN`, numbers out of range and truncation named with the field's path);
//! * `toml_file::syntax`: messages for duplicate keys and for files that are not experiments files;
//! * `toml_file::schema`: the keys of each table, the rules their values obey, plausible
//!   ranges, and hints for misspelt or misplaced keys;
//! * `toml_file::spanned`: reading the TOML document with spans, so that every error names a
//!   line;
//! * `toml_file::uncertainty`: reading the `[uncertainty]` tables (declared standard
//!   uncertainties of process conditions, instrument and material data, see
//!   [`fiber::uncertainty`](crate::data::uncertainty));
//! * `loaded`: what loading yields, as values ([`LoadedExperiments`], `ExperimentDetails`);
//! * `csv_file::row_budget`: the rows the measurement files may still hold (the per-file cap
//!   and the fit's memory), counted while they are read;
//! * `toml_file::experiment`: one `[[experiment]]` table, its units and plausibility checks;
//! * `csv_file::measurements`: reading the measurement CSV files;
//! * `cross_checks`: the checks that need the TOML and the data together;
//! * `experiments`: building the [`ExperimentSet`](crate::model::ExperimentSet) from the
//!   tables, and loading a whole data set (the last step: it calls the others).

mod cross_checks;
mod csv_file;
mod error;
mod experiments;
mod json;
mod loaded;
mod options;
mod source;
mod toml_file;

pub(crate) use csv_file::measurements::DEFAULT_MIN_POINTS;
pub use csv_file::measurements::{load_measurements_with, parse_measurements};
pub use error::{InputError, Location};
pub use experiments::{
    load_experiments, load_experiments_with, parse_experiments, parse_experiments_with,
};
pub(crate) use json::parse_json;
pub(crate) use json::read_json;
pub(crate) use json::show_json_path;
pub(crate) use json::JsonSource;
pub use json::DEFAULT_MAX_JSON_BYTES;
pub use loaded::LoadedExperiments;
pub(crate) use options::max_fit_rows;
pub(crate) use options::show_count;
pub use options::{estimated_fit_memory_bytes, Limit, LoadOptions, DEFAULT_MAX_ROWS_PER_FILE};
pub(crate) use toml_file::schema::MAX_PLAUSIBLE_DIAMETER_M;
pub(crate) use toml_file::schema::PLAUSIBLE_RANGES;

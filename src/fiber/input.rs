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

use super::error::Readable;
use std::f64::consts::PI;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

use toml::de::{DeTable, DeValue};
use toml::Spanned;

use super::setup::{Air, Experiment, ExperimentSet, Inlet, Material, Measurements, TakeUp};

/// Minimum number of measurement rows per CSV file used by [`load_experiments`].
pub const DEFAULT_MIN_POINTS: usize = 4;

/// Largest plausible fiber diameter \[m\]; larger values suggest the file is in millimetres.
pub const MAX_PLAUSIBLE_DIAMETER_M: f64 = 0.02;

/// Smallest plausible fiber diameter \[m\] (1 µm); smaller values are probably a unit error.
pub const MIN_PLAUSIBLE_DIAMETER_M: f64 = 1e-6;

/// Plausible ranges `(key, min, max)` of the per-experiment quantities of melt spinning (SI, the
/// unit is in the key); a value outside is rejected as a probable unit or typing error. The
/// diameters have their own bounds ([`MIN_PLAUSIBLE_DIAMETER_M`], [`MAX_PLAUSIBLE_DIAMETER_M`]).
pub const PLAUSIBLE_RANGES: &[(&str, f64, f64)] = &[
    ("mass_flow_kg_s", 1e-10, 1.0),
    ("inlet_velocity_m_s", 1e-6, 1e3),
    ("take_up_velocity_m_s", 1e-6, 1e3),
    ("spinline_length_m", 1e-3, 100.0),
    ("inlet_temperature_K", 100.0, 1500.0),
    ("air_temperature_K", 100.0, 1500.0),
];

/// Largest plausible zero-shear viscosity of the melt at the inlet \[Pa s\]: 1e12 Pa s is the
/// conventional viscosity of a glass at its glass transition; above it the polymer is not a melt.
pub const MAX_INLET_VISCOSITY_PA_S: f64 = 1e12;

/// Largest plausible draw ratio `u_out/u_in = (d_in/d_out)²` \[-\].
pub const MAX_DRAW_RATIO: f64 = 1e6;

/// The required CSV header (column names carry the unit: metres).
pub const CSV_HEADER: [&str; 2] = ["position_m", "diameter_m"];

/// A place in an input file: the path and, where known, the 1-based line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The input file.
    pub path: PathBuf,
    /// 1-based line number, if known.
    pub line: Option<usize>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        match self.line {
            Some(line) => write!(f, ":{line}"),
            None => Ok(()),
        }
    }
}

/// Why an input file could not be loaded. Every message starts with `file[:line]` and names
/// the TOML table (`[material]`, `[defaults]`, `[[experiment]] #2 "name"`) and key, or the CSV
/// line, involved.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// The file could not be read (missing, unreadable, not UTF-8).
    #[error("{}: cannot read file: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not valid TOML.
    #[error("{at}{}: malformed TOML: {message}", column.map(|c| format!(":{c}")).unwrap_or_default())]
    Toml {
        /// File and line of the syntax error.
        at: Location,
        /// 1-based column (characters) of the syntax error, if known.
        column: Option<usize>,
        /// The parser's message.
        message: String,
    },
    /// A key that the format does not know (probably a typo).
    #[error("{at}: unknown key `{key}` in {table}{hint}")]
    UnknownKey {
        /// Where the key is.
        at: Location,
        /// The table holding it.
        table: String,
        /// The key.
        key: String,
        /// A suggestion (starts with `"; "`) or empty.
        hint: String,
    },
    /// A required key (or table) is missing.
    #[error("{at}: {table}: missing required key `{key}`{hint}")]
    MissingKey {
        /// The table that should hold the key.
        at: Location,
        /// The table.
        table: String,
        /// The key.
        key: String,
        /// Where else the key may be given (starts with `" "`) or empty.
        hint: String,
    },
    /// A value has the wrong TOML type.
    #[error("{at}: {table}: `{key}` must be {expected}, found {found}")]
    WrongType {
        /// Where the value is.
        at: Location,
        /// The table.
        table: String,
        /// The key.
        key: String,
        /// The expected type.
        expected: &'static str,
        /// The type found.
        found: &'static str,
    },
    /// A numeric value is NaN or infinite.
    #[error("{at}: {table}: `{key}` = {value} is not a finite number")]
    NotFinite {
        /// Where the value is.
        at: Location,
        /// The table.
        table: String,
        /// The key.
        key: String,
        /// The value as written.
        value: String,
    },
    /// A value is out of its admissible range.
    #[error("{at}: {table}: `{key}` = {}: {reason}", Readable(*.value))]
    InvalidValue {
        /// Where the value is.
        at: Location,
        /// The table.
        table: String,
        /// The key.
        key: String,
        /// The value.
        value: f64,
        /// What is wrong with it.
        reason: String,
    },
    /// Keys that are individually valid but inconsistent together (both inlet keys, take-up
    /// diameter not below the inlet diameter, duplicate names, …).
    #[error("{at}: {table}: {message}")]
    Inconsistent {
        /// Where the problem shows.
        at: Location,
        /// The table.
        table: String,
        /// What is wrong.
        message: String,
    },
    /// A problem in a measurement CSV file (`at.line` is the CSV line, if applicable).
    #[error("{at}: {message}")]
    Csv {
        /// File and line.
        at: Location,
        /// What is wrong.
        message: String,
    },
    /// The data file of an experiment could not be loaded; `cause` names the CSV file.
    #[error("{at}: experiment \"{experiment}\": {cause}")]
    Data {
        /// The `data` key in the TOML file.
        at: Location,
        /// The experiment's name.
        experiment: String,
        /// The error in the data file.
        cause: Box<InputError>,
    },
}

/// Descriptive information on an experiment that is not part of the model input.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ExperimentDetails {
    /// Stencil velocity of the extruder \[mm/s\] (`stencil_velocity_mm_s`), if given.
    pub stencil_velocity_mm_s: Option<f64>,
    /// Take-up (aspirator) pressure \[bar\] (`take_up_pressure_bar`), if given.
    pub take_up_pressure_bar: Option<f64>,
    /// The measurement CSV file (resolved against the TOML file's directory), if given.
    pub data: Option<PathBuf>,
    /// 1-based line of the experiment's `name` key in the TOML file, if known (for messages
    /// that name the experiment).
    pub line: Option<usize>,
}

/// An experiment set together with per-experiment details (same order as the experiments).
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedExperiments {
    /// The model input (measurements are `None` when parsed without reading CSV files).
    pub set: ExperimentSet,
    /// Descriptive metadata and data-file paths.
    pub details: Vec<ExperimentDetails>,
}

/// Loads a TOML experiment file and the CSV files it refers to, requiring at least
/// [`DEFAULT_MIN_POINTS`] measurements per file.
pub fn load_experiments(path: &Path) -> Result<ExperimentSet, InputError> {
    load_experiments_with(path, DEFAULT_MIN_POINTS).map(|loaded| loaded.set)
}

/// Loads a TOML experiment file and its CSV files, requiring at least `min_points` rows per
/// CSV file, and returns the set with the experiments' metadata.
pub fn load_experiments_with(
    path: &Path,
    min_points: usize,
) -> Result<LoadedExperiments, InputError> {
    let text = read_text(path)?;
    let mut loaded = parse_experiments(&text, path)?;
    let doc = Doc::new(path, &text);
    for (i, details) in loaded.details.iter().enumerate() {
        let Some(data) = &details.data else { continue };
        let experiment = &loaded.set.experiments[i];
        let measured =
            load_measurements(data, experiment.spinline_length, min_points).map_err(|cause| {
                InputError::Data {
                    at: doc.data_key_location(i),
                    experiment: experiment.name.clone(),
                    cause: Box::new(cause),
                }
            })?;
        loaded.set.measurements[i] = Some(measured);
    }
    Ok(loaded)
}

/// Parses the TOML text of an experiment file without reading any CSV file (all measurements
/// are `None`). `path` is used in error messages and to resolve the `data` paths.
pub fn parse_experiments(text: &str, path: &Path) -> Result<LoadedExperiments, InputError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let root = DeTable::parse(text).map_err(|e| toml_error(path, text, &e))?;
    let doc = Doc::new(path, text);
    let top = Tab {
        doc: &doc,
        name: "the top level".into(),
        table: root.get_ref(),
        line: None,
    };
    top.check_keys(TOP_KEYS)?;
    let relative_uncertainty = match top.get("relative_uncertainty") {
        Some(field) => Some(relative_uncertainty(&field)?),
        None => None,
    };
    let material_tab = top
        .sub_table("material", "[material]")?
        .ok_or_else(|| top.missing("material", " (the [material] table)"))?;
    let (material, air) = material(&material_tab)?;
    let defaults = top.sub_table("defaults", "[defaults]")?;
    if let Some(defaults) = &defaults {
        defaults.check_keys(&names(EXPERIMENT_NUMBERS))?;
        for (key, rule) in EXPERIMENT_NUMBERS {
            if let Some(field) = defaults.get(key) {
                field.number(*rule)?;
            }
        }
    }
    let tables = top.experiment_tables()?;
    let mut experiments = Vec::with_capacity(tables.len());
    let mut details = Vec::with_capacity(tables.len());
    let mut seen: Vec<(String, Option<usize>)> = Vec::new();
    for tab in tables {
        let label = tab.name.clone();
        let (experiment, mut detail, name_at) = experiment(tab, defaults.as_ref(), &material)?;
        detail.line = name_at.line;
        if let Some((_, first)) = seen.iter().find(|(n, _)| *n == experiment.name) {
            let first = first
                .map(|l| format!(" (first defined at line {l})"))
                .unwrap_or_default();
            return Err(InputError::Inconsistent {
                at: name_at,
                table: format!("{label} \"{}\"", experiment.name),
                message: format!("duplicate experiment name \"{}\"{first}", experiment.name),
            });
        }
        seen.push((experiment.name.clone(), name_at.line));
        experiments.push(experiment);
        details.push(detail);
    }
    let measurements = vec![None; experiments.len()];
    Ok(LoadedExperiments {
        set: ExperimentSet {
            material,
            air,
            experiments,
            measurements,
            relative_uncertainty,
        },
        details,
    })
}

/// Loads one measurement CSV file (`position_m,diameter_m`), requiring positions within
/// `[0, spinline_length]` \[m\] (pass `f64::INFINITY` to skip that check) and at least
/// `min_points` rows.
pub fn load_measurements(
    path: &Path,
    spinline_length: f64,
    min_points: usize,
) -> Result<Measurements, InputError> {
    let text = read_text(path)?;
    parse_measurements(&text, path, spinline_length, min_points)
}

/// Parses the text of a measurement CSV file; `path` is used in error messages only. See
/// [`load_measurements`].
pub fn parse_measurements(
    text: &str,
    path: &Path,
    spinline_length: f64,
    min_points: usize,
) -> Result<Measurements, InputError> {
    let csv_error = |line: Option<u64>, message: String| InputError::Csv {
        at: Location {
            path: path.to_path_buf(),
            line: line.map(|l| l as usize),
        },
        message,
    };
    if spinline_length.is_nan() || spinline_length <= 0.0 {
        return Err(csv_error(
            None,
            format!(
                "cannot check the positions against a spin-line length of {spinline_length} m \
                 (it must be positive, or infinite to skip the check)"
            ),
        ));
    }
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let mut records = reader.records();
    let header = match records.next() {
        None => {
            return Err(csv_error(
                None,
                format!("empty file; expected the header `{}`", CSV_HEADER.join(",")),
            ))
        }
        Some(record) => record.map_err(|e| csv_read_error(path, &e))?,
    };
    let header_line = header.position().map(|p| p.line());
    if header.iter().ne(CSV_HEADER) {
        let found = header.iter().collect::<Vec<_>>().join(",");
        let note = if header.iter().all(|c| c.parse::<f64>().is_ok()) {
            " (the header line is missing)"
        } else {
            " (values must be in metres)"
        };
        return Err(csv_error(
            header_line,
            format!(
                "wrong header `{found}`; expected `{}`{note}",
                CSV_HEADER.join(",")
            ),
        ));
    }
    let mut positions: Vec<f64> = Vec::new();
    let mut diameters: Vec<f64> = Vec::new();
    let mut previous_line = 0;
    for record in records {
        let record = record.map_err(|e| csv_read_error(path, &e))?;
        let line = record.position().map_or(0, |p| p.line());
        let err = |message: String| csv_error(Some(line), message);
        if record.len() != 2 {
            return Err(err(format!(
                "expected 2 columns ({}), found {}",
                CSV_HEADER.join(","),
                record.len()
            )));
        }
        let mut cells = [0.0; 2];
        for (k, cell) in record.iter().enumerate() {
            let value: f64 = cell.parse().map_err(|_| {
                err(format!(
                    "non-numeric cell `{cell}` in column `{}`",
                    CSV_HEADER[k]
                ))
            })?;
            if !value.is_finite() {
                return Err(err(format!(
                    "`{cell}` in column `{}` is not finite",
                    CSV_HEADER[k]
                )));
            }
            cells[k] = value;
        }
        let [s, d] = cells;
        if s < 0.0 {
            return Err(err(format!("position {s} m is negative")));
        }
        if s > spinline_length {
            return Err(err(format!(
                "position {s} m lies beyond the spin-line length {spinline_length} m"
            )));
        }
        if let Some(&last) = positions.last() {
            if s == last {
                return Err(err(format!(
                    "position {s} m repeats the one on line {previous_line}; positions must be strictly increasing"
                )));
            }
            if s < last {
                return Err(err(format!(
                    "position {s} m is smaller than {last} m on line {previous_line}; positions must be strictly increasing"
                )));
            }
        }
        if d <= 0.0 {
            return Err(err(format!("diameter {d} m is not positive")));
        }
        if d < MIN_PLAUSIBLE_DIAMETER_M {
            return Err(err(format!(
                "diameter {} m is implausibly small for a fiber (< {MIN_PLAUSIBLE_DIAMETER_M:e} m \
                 = 1 µm); the values must be in metres",
                Readable(d)
            )));
        }
        if d > MAX_PLAUSIBLE_DIAMETER_M {
            return Err(err(format!(
                "diameter {} is implausibly large for metres (> {MAX_PLAUSIBLE_DIAMETER_M} m); \
                 the file looks like millimetres or micrometres: convert to metres",
                Readable(d)
            )));
        }
        positions.push(s);
        diameters.push(d);
        previous_line = line;
    }
    if positions.len() < min_points {
        return Err(csv_error(
            None,
            format!(
                "only {} measurement point(s); at least {min_points} are required",
                positions.len()
            ),
        ));
    }
    Ok(Measurements {
        positions,
        diameters,
    })
}

impl ExperimentSet {
    /// Loads an experiment set from a TOML file and its CSV files (see [`load_experiments`]).
    pub fn load(path: &Path) -> Result<Self, InputError> {
        load_experiments(path)
    }
}

fn read_text(path: &Path) -> Result<String, InputError> {
    std::fs::read_to_string(path).map_err(|source| InputError::Io {
        path: path.to_path_buf(),
        source,
    })
}

fn csv_read_error(path: &Path, e: &csv::Error) -> InputError {
    InputError::Csv {
        at: Location {
            path: path.to_path_buf(),
            line: e.position().map(|p| p.line() as usize),
        },
        message: format!("unreadable CSV: {e}"),
    }
}

fn toml_error(path: &Path, text: &str, e: &toml::de::Error) -> InputError {
    let (line, column) = match e.span() {
        Some(span) => {
            let (l, c) = line_col(text, span.start);
            (Some(l), Some(c))
        }
        None => (None, None),
    };
    InputError::Toml {
        at: Location {
            path: path.to_path_buf(),
            line,
        },
        column,
        message: e.message().trim().to_string(),
    }
}

/// 1-based line and column (in characters) of byte `offset` in `text`.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text.as_bytes()[..offset];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1);
    let column = text
        .get(line_start..offset)
        .map_or(offset - line_start, |s| s.chars().count())
        + 1;
    (line, column)
}

// ---------------------------------------------------------------------------------------------
// Keys and their rules

/// What a numeric key must satisfy.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Rule {
    Finite,
    Positive,
    NonNegative,
    /// Positive and at most [`MAX_PLAUSIBLE_DIAMETER_M`].
    Diameter,
    /// In (0, 1): a relative uncertainty.
    Fraction,
}

const TOP_KEYS: &[&str] = &["relative_uncertainty", "material", "defaults", "experiment"];

const MATERIAL_NUMBERS: &[(&str, Rule)] = &[
    ("density_slope_kg_m3_K", Rule::Finite),
    ("density_intercept_kg_m3", Rule::Positive),
    ("heat_capacity_slope_J_kg_K2", Rule::Finite),
    ("heat_capacity_intercept_J_kg_K", Rule::Finite),
    ("vft_mu_c_Pa_s", Rule::Positive),
    ("vft_B_K", Rule::Positive),
    ("vft_T_VF_K", Rule::NonNegative),
    ("trouton_ratio", Rule::Positive),
    ("air_density_kg_m3", Rule::Positive),
    ("air_heat_capacity_J_kg_K", Rule::Positive),
    ("air_kinematic_viscosity_m2_s", Rule::Positive),
    ("air_heat_conductivity_W_m_K", Rule::Positive),
];

const EXPERIMENT_NUMBERS: &[(&str, Rule)] = &[
    ("mass_flow_kg_s", Rule::Positive),
    ("inlet_diameter_m", Rule::Diameter),
    ("inlet_velocity_m_s", Rule::Positive),
    ("take_up_diameter_m", Rule::Diameter),
    ("take_up_velocity_m_s", Rule::Positive),
    ("spinline_length_m", Rule::Positive),
    ("inlet_temperature_K", Rule::Positive),
    ("air_temperature_K", Rule::Positive),
    ("stencil_velocity_mm_s", Rule::Positive),
    ("take_up_pressure_bar", Rule::Finite),
];

/// String-valued keys of an `[[experiment]]` table (not allowed in `[defaults]`).
const STRING_KEYS: &[&str] = &["name", "data"];

fn names(rules: &[(&'static str, Rule)]) -> Vec<&'static str> {
    rules.iter().map(|(k, _)| *k).collect()
}

fn rule_of(rules: &[(&str, Rule)], key: &str) -> Option<Rule> {
    rules.iter().find(|(k, _)| *k == key).map(|(_, r)| *r)
}

/// Where a key belongs, for hints on keys given in the wrong table.
fn home_of(key: &str) -> Option<&'static str> {
    if key == "relative_uncertainty" {
        Some("the top level (before the first [table] header)")
    } else if rule_of(MATERIAL_NUMBERS, key).is_some() {
        Some("[material]")
    } else if STRING_KEYS.contains(&key) {
        Some("[[experiment]] (it cannot be a default)")
    } else if rule_of(EXPERIMENT_NUMBERS, key).is_some() {
        Some("[defaults] or [[experiment]]")
    } else {
        None
    }
}

fn key_hint(key: &str, allowed: &[&str]) -> String {
    if let Some(home) = home_of(key) {
        return format!("; this key belongs in {home}");
    }
    let lower = key.to_lowercase();
    let best = allowed
        .iter()
        .map(|a| (levenshtein(&lower, &a.to_lowercase()), *a))
        .min();
    match best {
        Some((d, candidate)) if d <= (key.len() / 3).max(2) => {
            format!("; did you mean `{candidate}`?")
        }
        _ => format!("; expected one of: {}", allowed.join(", ")),
    }
}

fn levenshtein(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let substitution = diagonal + usize::from(ca != cb);
            diagonal = row[j + 1];
            row[j + 1] = substitution.min(row[j] + 1).min(row[j + 1] + 1);
        }
    }
    row[b.len()]
}

// ---------------------------------------------------------------------------------------------
// Spanned TOML access

/// The TOML text being parsed, for locations.
struct Doc<'a> {
    path: &'a Path,
    text: &'a str,
}

impl<'a> Doc<'a> {
    fn new(path: &'a Path, text: &'a str) -> Self {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        Doc { path, text }
    }

    fn at(&self, span: &Range<usize>) -> Location {
        self.at_line(Some(line_col(self.text, span.start).0))
    }

    fn at_line(&self, line: Option<usize>) -> Location {
        Location {
            path: self.path.to_path_buf(),
            line,
        }
    }

    /// Location of the `data` key of experiment `index` (for errors in its CSV file).
    fn data_key_location(&self, index: usize) -> Location {
        let span = DeTable::parse(self.text).ok().and_then(|root| {
            let experiment = root.get_ref().get("experiment")?;
            let DeValue::Array(array) = experiment.get_ref() else {
                return None;
            };
            let table = array.get(index)?;
            let DeValue::Table(table) = table.get_ref() else {
                return None;
            };
            table.get("data").map(|v| v.span())
        });
        match span {
            Some(span) => self.at(&span),
            None => self.at_line(None),
        }
    }
}

/// A TOML table with the name used in messages.
struct Tab<'a> {
    doc: &'a Doc<'a>,
    name: String,
    table: &'a DeTable<'a>,
    line: Option<usize>,
}

/// One key's value in a table.
struct Field<'a> {
    doc: &'a Doc<'a>,
    table: String,
    key: &'a str,
    value: &'a Spanned<DeValue<'a>>,
}

impl<'a> Tab<'a> {
    fn get(&self, key: &'a str) -> Option<Field<'a>> {
        self.table.get(key).map(|value| Field {
            doc: self.doc,
            table: self.name.clone(),
            key,
            value,
        })
    }

    fn missing(&self, key: &str, hint: &str) -> InputError {
        InputError::MissingKey {
            at: self.doc.at_line(self.line),
            table: self.name.clone(),
            key: key.to_string(),
            hint: hint.to_string(),
        }
    }

    /// Errors on the first (in file order) key not in `allowed`.
    fn check_keys(&self, allowed: &[&str]) -> Result<(), InputError> {
        let unknown = self
            .table
            .iter()
            .filter(|(k, _)| !allowed.contains(&&**k.get_ref()))
            .min_by_key(|(k, _)| k.span().start);
        match unknown {
            None => Ok(()),
            Some((key, _)) => Err(InputError::UnknownKey {
                at: self.doc.at(&key.span()),
                table: self.name.clone(),
                key: key.get_ref().to_string(),
                hint: key_hint(key.get_ref(), allowed),
            }),
        }
    }

    /// The sub-table `key`, if present; an error if `key` is not a table.
    fn sub_table(&self, key: &'a str, name: &str) -> Result<Option<Tab<'a>>, InputError> {
        let Some(field) = self.get(key) else {
            return Ok(None);
        };
        match field.value.get_ref() {
            DeValue::Table(table) => Ok(Some(Tab {
                doc: self.doc,
                name: name.to_string(),
                table,
                line: field.at().line,
            })),
            other => Err(field.wrong_type("a table", other)),
        }
    }

    /// The `[[experiment]]` tables (at least one).
    fn experiment_tables(&self) -> Result<Vec<Tab<'a>>, InputError> {
        let field = self
            .get("experiment")
            .ok_or_else(|| self.missing("experiment", " (at least one [[experiment]] table)"))?;
        let DeValue::Array(array) = field.value.get_ref() else {
            return Err(
                field.wrong_type("an array of tables `[[experiment]]`", field.value.get_ref())
            );
        };
        if array.is_empty() {
            return Err(InputError::Inconsistent {
                at: field.at(),
                table: "the top level".into(),
                message: "`experiment` is empty; give at least one [[experiment]] table".into(),
            });
        }
        array
            .iter()
            .enumerate()
            .map(|(i, item)| match item.get_ref() {
                DeValue::Table(table) => Ok(Tab {
                    doc: self.doc,
                    name: format!("[[experiment]] #{}", i + 1),
                    table,
                    line: Some(line_col(self.doc.text, item.span().start).0),
                }),
                other => Err(InputError::WrongType {
                    at: self.doc.at(&item.span()),
                    table: "the top level".into(),
                    key: format!("experiment[{i}]"),
                    expected: "a table",
                    found: type_name(other),
                }),
            })
            .collect()
    }
}

impl Field<'_> {
    fn at(&self) -> Location {
        self.doc.at(&self.value.span())
    }

    fn wrong_type(&self, expected: &'static str, found: &DeValue<'_>) -> InputError {
        InputError::WrongType {
            at: self.at(),
            table: self.table.clone(),
            key: self.key.to_string(),
            expected,
            found: type_name(found),
        }
    }

    fn invalid(&self, value: f64, reason: impl Into<String>) -> InputError {
        InputError::InvalidValue {
            at: self.at(),
            table: self.table.clone(),
            key: self.key.to_string(),
            value,
            reason: reason.into(),
        }
    }

    /// The table name for an error about experiment `experiment_table`: the experiment, and
    /// where the value came from if it is another table (`[defaults]`).
    fn table_in(&self, experiment_table: &str) -> String {
        if self.table == experiment_table {
            self.table.clone()
        } else {
            format!("{experiment_table} (value from {})", self.table)
        }
    }

    /// Like [`invalid`](Self::invalid), for a check of experiment `experiment_table`.
    fn invalid_in(&self, experiment_table: &str, value: f64, reason: String) -> InputError {
        InputError::InvalidValue {
            at: self.at(),
            table: self.table_in(experiment_table),
            key: self.key.to_string(),
            value,
            reason,
        }
    }

    /// Like [`inconsistent`](Self::inconsistent), for a check of experiment `experiment_table`.
    fn inconsistent_in(&self, experiment_table: &str, message: String) -> InputError {
        InputError::Inconsistent {
            at: self.at(),
            table: self.table_in(experiment_table),
            message,
        }
    }

    fn inconsistent(&self, message: String) -> InputError {
        InputError::Inconsistent {
            at: self.at(),
            table: self.table.clone(),
            message,
        }
    }

    fn string(&self) -> Result<&str, InputError> {
        match self.value.get_ref() {
            DeValue::String(s) => Ok(s.as_ref()),
            other => Err(self.wrong_type("a string", other)),
        }
    }

    /// The value as a number satisfying `rule`.
    fn number(&self, rule: Rule) -> Result<f64, InputError> {
        // TOML allows `_` between digits (`1_000`); Rust's parsers do not
        let (value, raw) = match self.value.get_ref() {
            DeValue::Float(f) => (f.as_str().replace('_', "").parse::<f64>().ok(), f.as_str()),
            DeValue::Integer(i) => (
                i64::from_str_radix(&i.as_str().replace('_', ""), i.radix())
                    .ok()
                    .map(|v| v as f64),
                i.as_str(),
            ),
            other => return Err(self.wrong_type("a number", other)),
        };
        let Some(value) = value.filter(|v| v.is_finite()) else {
            return Err(InputError::NotFinite {
                at: self.at(),
                table: self.table.clone(),
                key: self.key.to_string(),
                value: raw.to_string(),
            });
        };
        match rule {
            Rule::Finite => Ok(value),
            Rule::Positive | Rule::Diameter if value <= 0.0 => {
                Err(self.invalid(value, "must be positive"))
            }
            Rule::NonNegative if value < 0.0 => Err(self.invalid(value, "must not be negative")),
            Rule::Diameter if value > MAX_PLAUSIBLE_DIAMETER_M => Err(self.invalid(
                value,
                format!(
                    "implausibly large for a diameter in metres (> {MAX_PLAUSIBLE_DIAMETER_M} m); \
                     was it given in millimetres?"
                ),
            )),
            Rule::Diameter if value < MIN_PLAUSIBLE_DIAMETER_M => Err(self.invalid(
                value,
                format!(
                    "implausibly small for a fiber diameter in metres (< {MIN_PLAUSIBLE_DIAMETER_M:e} m \
                     = 1 µm)"
                ),
            )),
            Rule::Fraction if value <= 0.0 || value >= 1.0 => Err(self.invalid(
                value,
                "must lie in (0, 1) (a relative uncertainty: 0.015 means 1.5 %)",
            )),
            _ => self.plausible(value),
        }
    }

    /// `value` if it lies in the key's plausible range ([`PLAUSIBLE_RANGES`]), if it has one.
    fn plausible(&self, value: f64) -> Result<f64, InputError> {
        match PLAUSIBLE_RANGES.iter().find(|(k, _, _)| *k == self.key) {
            Some(&(_, min, max)) if value < min || value > max => {
                let unit = unit_of(self.key);
                let side = if value < min { "small" } else { "large" };
                Err(self.invalid(
                    value,
                    format!(
                        "implausibly {side} for melt spinning (expected {min:e} to {max:e} {unit}); \
                         check the unit"
                    ),
                ))
            }
            _ => Ok(value),
        }
    }
}

/// The unit of a key, from its suffix (`mass_flow_kg_s` → `kg/s`).
fn unit_of(key: &str) -> &'static str {
    [("_kg_s", "kg/s"), ("_m_s", "m/s"), ("_m", "m"), ("_K", "K")]
        .iter()
        .find(|(suffix, _)| key.ends_with(suffix))
        .map_or("", |(_, unit)| *unit)
}

fn type_name(value: &DeValue<'_>) -> &'static str {
    match value {
        DeValue::String(_) => "a string",
        DeValue::Integer(_) => "an integer",
        DeValue::Float(_) => "a float",
        DeValue::Boolean(_) => "a boolean",
        DeValue::Datetime(_) => "a datetime",
        DeValue::Array(_) => "an array",
        DeValue::Table(_) => "a table",
    }
}

// ---------------------------------------------------------------------------------------------
// Tables

fn relative_uncertainty(field: &Field<'_>) -> Result<f64, InputError> {
    field.number(Rule::Fraction)
}

fn material(tab: &Tab<'_>) -> Result<(Material, Air), InputError> {
    tab.check_keys(&names(MATERIAL_NUMBERS))?;
    let get = |key: &'static str| -> Result<f64, InputError> {
        let rule = rule_of(MATERIAL_NUMBERS, key).unwrap_or(Rule::Finite);
        match tab.get(key) {
            Some(field) => field.number(rule),
            None if key == "trouton_ratio" => Ok(3.0),
            None => Err(tab.missing(key, "")),
        }
    };
    let material = Material {
        density_slope: get("density_slope_kg_m3_K")?,
        density_intercept: get("density_intercept_kg_m3")?,
        heat_capacity_slope: get("heat_capacity_slope_J_kg_K2")?,
        heat_capacity_intercept: get("heat_capacity_intercept_J_kg_K")?,
        vft_mu_c: get("vft_mu_c_Pa_s")?,
        vft_b: get("vft_B_K")?,
        vft_t_vf: get("vft_T_VF_K")?,
        trouton: get("trouton_ratio")?,
    };
    let air = Air {
        density: get("air_density_kg_m3")?,
        heat_capacity: get("air_heat_capacity_J_kg_K")?,
        kinematic_viscosity: get("air_kinematic_viscosity_m2_s")?,
        heat_conductivity: get("air_heat_conductivity_W_m_K")?,
    };
    Ok((material, air))
}

/// An experiment table backed by `[defaults]`.
struct Scope<'s, 'a> {
    table: &'s Tab<'a>,
    defaults: Option<&'s Tab<'a>>,
}

impl<'a> Scope<'_, 'a> {
    fn get(&self, key: &'a str) -> Option<Field<'a>> {
        self.table
            .get(key)
            .or_else(|| self.defaults.and_then(|d| d.get(key)))
    }

    fn rule(key: &str) -> Rule {
        rule_of(EXPERIMENT_NUMBERS, key).unwrap_or(Rule::Finite)
    }

    fn optional(&self, key: &'a str) -> Result<Option<(f64, Field<'a>)>, InputError> {
        match self.get(key) {
            Some(field) => Ok(Some((field.number(Self::rule(key))?, field))),
            None => Ok(None),
        }
    }

    fn required(&self, key: &'a str) -> Result<(f64, Field<'a>), InputError> {
        let hint = " (give it here or in [defaults])";
        self.optional(key)?
            .ok_or_else(|| self.table.missing(key, hint))
    }

    /// One of two mutually exclusive keys, resolved as a pair: the experiment table first,
    /// then `[defaults]`. Returns `(first_key_given, value, field)`.
    fn either(&self, a: &'a str, b: &'a str) -> Result<Option<(bool, f64, Field<'a>)>, InputError> {
        for tab in std::iter::once(self.table).chain(self.defaults) {
            match (tab.get(a), tab.get(b)) {
                (Some(_), Some(fb)) => {
                    return Err(fb.inconsistent(format!("give either `{a}` or `{b}`, not both")))
                }
                (Some(fa), None) => return Ok(Some((true, fa.number(Self::rule(a))?, fa))),
                (None, Some(fb)) => return Ok(Some((false, fb.number(Self::rule(b))?, fb))),
                (None, None) => {}
            }
        }
        Ok(None)
    }
}

/// Parses one `[[experiment]]` table; also returns the location of its name.
fn experiment(
    mut tab: Tab<'_>,
    defaults: Option<&Tab<'_>>,
    material: &Material,
) -> Result<(Experiment, ExperimentDetails, Location), InputError> {
    // name the table by the experiment's name (if readable) before reporting unknown keys
    if let Some(name) = tab
        .get("name")
        .and_then(|f| f.string().ok().map(str::to_string))
    {
        tab.name = format!("{} \"{name}\"", tab.name);
    }
    tab.check_keys(&[STRING_KEYS, &names(EXPERIMENT_NUMBERS)].concat())?;
    let name_field = tab.get("name").ok_or_else(|| tab.missing("name", ""))?;
    let name = name_field.string()?.to_string();
    if name.trim().is_empty() || name.contains(['/', '\\']) || name.chars().any(char::is_control) {
        return Err(name_field.inconsistent(format!(
            "`name` = {name:?} must be non-empty, without path separators or control characters"
        )));
    }
    let name_at = name_field.at();
    let scope = Scope {
        table: &tab,
        defaults,
    };
    let (mass_flow, q_field) = scope.required("mass_flow_kg_s")?;
    let (spinline_length, _) = scope.required("spinline_length_m")?;
    let (inlet_temperature, t_in_field) = scope.required("inlet_temperature_K")?;
    let (air_temperature, t_air_field) = scope.required("air_temperature_K")?;
    let table = tab.name.as_str();

    let t_vf = material.vft_t_vf;
    if inlet_temperature <= t_vf {
        return Err(t_in_field.invalid_in(
            table,
            inlet_temperature,
            format!(
                "must exceed the Vogel temperature vft_T_VF_K = {t_vf} K of [material]: the VFT \
                 viscosity is undefined at and below it"
            ),
        ));
    }
    if air_temperature <= t_vf {
        return Err(t_air_field.invalid_in(
            table,
            air_temperature,
            format!(
                "must exceed the Vogel temperature vft_T_VF_K = {t_vf} K of [material]: the fiber \
                 cools towards the air temperature, and the VFT viscosity is undefined at and \
                 below T_VF"
            ),
        ));
    }
    for (t, field) in [
        (inlet_temperature, &t_in_field),
        (air_temperature, &t_air_field),
    ] {
        let (rho, cp) = (material.density(t), material.heat_capacity(t));
        if !(rho > 0.0 && cp > 0.0) {
            return Err(field.invalid_in(
                table,
                t,
                format!(
                    "[material] gives a non-positive density ({rho} kg/m³) or heat capacity \
                     ({cp} J/(kg K)) at this temperature"
                ),
            ));
        }
    }
    let mu_in = material.zero_shear_viscosity(inlet_temperature);
    if !(mu_in.is_finite() && mu_in <= MAX_INLET_VISCOSITY_PA_S) {
        let what = if mu_in.is_finite() {
            format!(
                "a zero-shear viscosity of {mu_in:.3e} Pa s at the inlet, above \
                 {MAX_INLET_VISCOSITY_PA_S:e} Pa s (a glass, not a melt)"
            )
        } else {
            "an infinite zero-shear viscosity at the inlet (beyond the floating-point range)"
                .to_string()
        };
        return Err(t_in_field.invalid_in(
            table,
            inlet_temperature,
            format!(
                "the inlet temperature is only {:.4} K above the Vogel temperature \
                 vft_T_VF_K = {t_vf} K: the VFT law mu_c exp(B/(T - T_VF)) gives {what}",
                inlet_temperature - t_vf
            ),
        ));
    }

    let (inlet_is_diameter, inlet_value, inlet_field) = scope
        .either("inlet_diameter_m", "inlet_velocity_m_s")?
        .ok_or_else(|| InputError::Inconsistent {
            at: tab.doc.at_line(tab.line),
            table: tab.name.clone(),
            message: "missing inlet condition: give `inlet_diameter_m` or `inlet_velocity_m_s` \
                      (here or in [defaults])"
                .into(),
        })?;
    let inlet = if inlet_is_diameter {
        Inlet::Diameter(inlet_value)
    } else {
        Inlet::Velocity(inlet_value)
    };
    // the other inlet quantity, from the mass balance Q = ρ(T_in) u_in π d_in²/4
    let rho_in = material.density(inlet_temperature);
    let (d_in, u_in) = match inlet {
        Inlet::Diameter(d) => (d, 4.0 * mass_flow / (PI * rho_in * d * d)),
        Inlet::Velocity(u) => (2.0 * (mass_flow / (PI * rho_in * u)).sqrt(), u),
    };
    let (derived, value, unit, min, max) = if inlet_is_diameter {
        ("inlet velocity 4 Q/(π ρ d_in²)", u_in, "m/s", 1e-6, 1e3)
    } else {
        (
            "inlet diameter 2 √(Q/(π ρ u_in))",
            d_in,
            "m",
            MIN_PLAUSIBLE_DIAMETER_M,
            MAX_PLAUSIBLE_DIAMETER_M,
        )
    };
    if !(value.is_finite() && value >= min && value <= max) {
        return Err(inlet_field.inconsistent_in(
            table,
            format!(
                "`mass_flow_kg_s` = {mass_flow} (line {}) and `{}` = {inlet_value} give an {derived} \
                 = {value:.3e} {unit} (with ρ(T_in) = {rho_in:.1} kg/m³), outside the plausible range \
                 {min:e} to {max:e} {unit}",
                q_field.at().line.unwrap_or(0),
                inlet_field.key
            ),
        ));
    }
    let given = |derived_from: &str| {
        if derived_from.is_empty() {
            String::new()
        } else {
            format!(" (derived from `mass_flow_kg_s` and `{derived_from}`)")
        }
    };
    let take_up = match scope.either("take_up_diameter_m", "take_up_velocity_m_s")? {
        None => None,
        Some((true, d_out, field)) => {
            let from = given(if inlet_is_diameter {
                ""
            } else {
                "inlet_velocity_m_s"
            });
            if d_out >= d_in {
                return Err(field.inconsistent_in(
                    table,
                    format!(
                        "take-up diameter {d_out} m must be smaller than the inlet diameter {d_in} m{from}"
                    ),
                ));
            }
            let ratio = (d_in / d_out).powi(2);
            if ratio > MAX_DRAW_RATIO {
                return Err(field.inconsistent_in(
                    table,
                    format!(
                        "take-up diameter {d_out} m and inlet diameter {d_in} m{from} give a draw \
                         ratio (d_in/d_out)² = {ratio:.3e}, above the plausible {MAX_DRAW_RATIO:e}"
                    ),
                ));
            }
            Some(TakeUp::Diameter(d_out))
        }
        Some((false, u_out, field)) => {
            let from = given(if inlet_is_diameter {
                "inlet_diameter_m"
            } else {
                ""
            });
            if u_out <= u_in {
                return Err(field.inconsistent_in(
                    table,
                    format!(
                        "take-up velocity {u_out} m/s must be larger than the inlet velocity {u_in} m/s{from}"
                    ),
                ));
            }
            let ratio = u_out / u_in;
            if ratio > MAX_DRAW_RATIO {
                return Err(field.inconsistent_in(
                    table,
                    format!(
                        "take-up velocity {u_out} m/s and inlet velocity {u_in} m/s{from} give a \
                         draw ratio u_out/u_in = {ratio:.3e}, above the plausible {MAX_DRAW_RATIO:e}"
                    ),
                ));
            }
            Some(TakeUp::Velocity(u_out))
        }
    };

    let metadata = |key| scope.optional(key).map(|v| v.map(|(x, _)| x));
    let data = match tab.get("data") {
        None => None,
        Some(field) => {
            let file = field.string()?;
            if file.trim().is_empty() {
                return Err(field.inconsistent("`data` must name a CSV file".into()));
            }
            let dir = tab.doc.path.parent().unwrap_or(Path::new(""));
            Some(dir.join(file))
        }
    };
    let details = ExperimentDetails {
        stencil_velocity_mm_s: metadata("stencil_velocity_mm_s")?,
        take_up_pressure_bar: metadata("take_up_pressure_bar")?,
        data,
        line: None,
    };
    let experiment = Experiment {
        name,
        mass_flow,
        inlet,
        inlet_temperature,
        air_temperature,
        spinline_length,
        take_up,
    };
    Ok((experiment, details, name_at))
}

#[cfg(test)]
mod tests {
    use super::*;

    const MATERIAL: &str = r#"
[material]
density_slope_kg_m3_K = -0.964
density_intercept_kg_m3 = 1572.33
heat_capacity_slope_J_kg_K2 = 3.2
heat_capacity_intercept_J_kg_K = 648.22
vft_mu_c_Pa_s = 0.00037074
vft_B_K = 3649.0
vft_T_VF_K = 273.15
air_density_kg_m3 = 1.0
air_heat_capacity_J_kg_K = 1000.0
air_kinematic_viscosity_m2_s = 2e-05
air_heat_conductivity_W_m_K = 0.031

[defaults]
spinline_length_m = 0.51
inlet_temperature_K = 513.15
air_temperature_K = 293
"#;

    fn parse(experiments: &str) -> Result<LoadedExperiments, InputError> {
        let text = format!("{MATERIAL}\n{experiments}");
        parse_experiments(&text, Path::new("dir/exp.toml"))
    }

    fn parse_err(experiments: &str) -> String {
        parse(experiments).unwrap_err().to_string()
    }

    const ONE: &str =
        "[[experiment]]\nname = \"a\"\nmass_flow_kg_s = 3e-5\ninlet_diameter_m = 1e-3\n";

    #[test]
    fn minimal_experiment_parses_with_defaults() {
        let loaded = parse(&format!(
            "{ONE}data = \"a.csv\"\ntake_up_pressure_bar = 2\n"
        ))
        .unwrap();
        let set = &loaded.set;
        assert_eq!(set.material, Material::pmma7n());
        assert_eq!(set.air, Air::paper());
        let e = &set.experiments[0];
        assert_eq!(e.name, "a");
        assert_eq!(e.inlet, Inlet::Diameter(1e-3));
        assert_eq!(e.air_temperature, 293.0);
        assert_eq!(e.take_up, None);
        assert_eq!(set.measurements, vec![None]);
        assert_eq!(set.relative_uncertainty, None);
        assert_eq!(loaded.details[0].data, Some(PathBuf::from("dir/a.csv")));
        assert_eq!(loaded.details[0].take_up_pressure_bar, Some(2.0));
        assert_eq!(loaded.details[0].stencil_velocity_mm_s, None);
    }

    #[test]
    fn relative_uncertainty_at_top_level() {
        let text = format!("relative_uncertainty = 0.015\n{MATERIAL}\n{ONE}");
        let loaded = parse_experiments(&text, Path::new("x.toml")).unwrap();
        assert_eq!(loaded.set.relative_uncertainty, Some(0.015));
        let text = format!("relative_uncertainty = 1.5\n{MATERIAL}\n{ONE}");
        let msg = parse_experiments(&text, Path::new("x.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("x.toml:1") && msg.contains("relative_uncertainty"),
            "{msg}"
        );
    }

    #[test]
    fn relative_uncertainty_in_defaults_is_pointed_to_top_level() {
        let text = MATERIAL.replace("[defaults]\n", "[defaults]\nrelative_uncertainty = 0.01\n");
        let msg = parse_experiments(&format!("{text}\n{ONE}"), Path::new("x.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("unknown key `relative_uncertainty` in [defaults]"),
            "{msg}"
        );
        assert!(msg.contains("top level"), "{msg}");
    }

    #[test]
    fn typo_gets_suggestion_with_line() {
        let msg = parse_err(&ONE.replace("mass_flow_kg_s", "mass_flow_kgs"));
        assert!(msg.starts_with("dir/exp.toml:"), "{msg}");
        assert!(
            msg.contains("unknown key `mass_flow_kgs` in [[experiment]] #1"),
            "{msg}"
        );
        assert!(msg.contains("did you mean `mass_flow_kg_s`?"), "{msg}");
    }

    #[test]
    fn integers_are_numbers_and_strings_are_not() {
        let loaded = parse(&format!("{ONE}spinline_length_m = 1\n")).unwrap();
        assert_eq!(loaded.set.experiments[0].spinline_length, 1.0);
        // TOML's digit separators, in integers and floats
        let loaded = parse(&format!(
            "{ONE}air_temperature_K = 2_93\nspinline_length_m = 0.5_1\n"
        ))
        .unwrap();
        assert_eq!(loaded.set.experiments[0].air_temperature, 293.0);
        assert_eq!(loaded.set.experiments[0].spinline_length, 0.51);
        let msg = parse_err(&ONE.replace("3e-5", "\"3e-5\""));
        assert!(
            msg.contains("`mass_flow_kg_s` must be a number, found a string"),
            "{msg}"
        );
    }

    #[test]
    fn nan_and_inf_are_rejected() {
        for v in ["nan", "inf", "-inf"] {
            let msg = parse_err(&ONE.replace("3e-5", v));
            assert!(msg.contains("is not a finite number"), "{msg}");
        }
    }

    #[test]
    fn take_up_velocity_must_exceed_inlet_velocity() {
        let exp = ONE.replace("inlet_diameter_m = 1e-3", "inlet_velocity_m_s = 0.02");
        let ok = parse(&format!("{exp}take_up_velocity_m_s = 0.5\n")).unwrap();
        assert_eq!(ok.set.experiments[0].take_up, Some(TakeUp::Velocity(0.5)));
        let msg = parse_err(&format!("{exp}take_up_velocity_m_s = 0.01\n"));
        assert!(
            msg.contains("must be larger than the inlet velocity"),
            "{msg}"
        );
    }

    #[test]
    fn inlet_temperature_below_vogel_temperature() {
        let msg = parse_err(&format!("{ONE}inlet_temperature_K = 260\n"));
        assert!(msg.contains("Vogel temperature"), "{msg}");
    }

    #[test]
    fn bad_names() {
        let msg = parse_err(&ONE.replace("\"a\"", "\"a/b\""));
        assert!(msg.contains("`name`"), "{msg}");
        let msg = parse_err(&ONE.replace("name = \"a\"\n", ""));
        assert!(msg.contains("missing required key `name`"), "{msg}");
    }

    #[test]
    fn experiment_must_be_array_of_tables() {
        let msg = parse_err(&ONE.replace("[[experiment]]", "[experiment]"));
        assert!(msg.contains("array of tables"), "{msg}");
        let msg = parse_err("");
        assert!(msg.contains("missing required key `experiment`"), "{msg}");
    }

    #[test]
    fn line_col_counts_characters() {
        assert_eq!(line_col("ab\ncµd", 6), (2, 3));
        assert_eq!(line_col("", 5), (1, 1));
    }

    #[test]
    fn levenshtein_distances() {
        assert_eq!(levenshtein("kitten", "sitting"), 3);
        assert_eq!(levenshtein("", "abc"), 3);
        assert_eq!(levenshtein("vft_b_k", "vft_b_k"), 0);
    }

    fn csv(text: &str) -> Result<Measurements, InputError> {
        parse_measurements(text, Path::new("m.csv"), 0.51, 2)
    }

    #[test]
    fn csv_accepts_comments_blank_lines_and_spaces() {
        let m = csv("# comment\nposition_m, diameter_m\n\n0.0, 1e-3\n0.1 ,5e-4\n").unwrap();
        assert_eq!(m.positions, vec![0.0, 0.1]);
        assert_eq!(m.diameters, vec![1e-3, 5e-4]);
    }

    #[test]
    fn csv_errors_name_line() {
        let msg = csv("position_m,diameter_m\n0.0,1e-3\n0.1\n")
            .unwrap_err()
            .to_string();
        assert_eq!(
            msg,
            "m.csv:3: expected 2 columns (position_m,diameter_m), found 1"
        );
        let msg = csv("0.0,1e-3\n0.1,1e-3\n").unwrap_err().to_string();
        assert!(
            msg.starts_with("m.csv:1: wrong header") && msg.contains("missing"),
            "{msg}"
        );
        let msg = csv("").unwrap_err().to_string();
        assert!(msg.contains("empty file"), "{msg}");
        let msg = csv("position_m,diameter_m\n0.0,nan\n0.1,1e-3\n")
            .unwrap_err()
            .to_string();
        assert!(
            msg.starts_with("m.csv:2:") && msg.contains("not finite"),
            "{msg}"
        );
    }
}

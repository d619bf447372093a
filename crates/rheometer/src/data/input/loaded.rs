//! What loading a data set yields, as values: the experiment set with each experiment's
//! descriptive details ([`ExperimentDetails`]), the declared uncertainties and the warnings
//! ([`LoadedExperiments`]). Built by `experiments` (one table at a time by `experiment`), read
//! by the cross-checks and the callers.

use std::path::PathBuf;

use super::error::{short, InputError, InputWarning, Location};
use crate::data::uncertainty::Uncertainties;
use crate::model::setup::ExperimentSet;

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
    /// The model input, in SI units whatever units the file used (measurements are `None`
    /// when parsed without reading CSV files).
    pub set: ExperimentSet,
    /// Descriptive metadata and data-file paths.
    pub details: Vec<ExperimentDetails>,
    /// Declared standard uncertainties (`[uncertainty]` and the experiments' own tables; empty
    /// when nothing is declared).
    pub uncertainty: Uncertainties,
    /// Warnings about inputs that are accepted but doubtful (a take-up diameter extrapolated
    /// beyond the measured positions, a °C value that looks like kelvin), each naming file and
    /// line; callers should show them.
    pub warnings: Vec<InputWarning>,
    /// The experiments file (for messages).
    pub path: PathBuf,
}

impl LoadedExperiments {
    /// An error naming the first experiment without a data file (file, line of its
    /// `[[experiment]]` table, and the key to add), for callers that need measurements (a
    /// fit); `Ok` if every experiment has one.
    pub fn require_data(&self) -> Result<(), InputError> {
        let Some(k) = self.details.iter().position(|d| d.data.is_none()) else {
            return Ok(());
        };
        let name = &self.set.experiments[k].name;
        Err(InputError::MissingKey {
            at: Location {
                path: self.path.clone(),
                line: self.details[k].line,
            },
            table: format!("[[experiment]] #{} \"{}\"", k + 1, short(name, 40)),
            key: "data".into(),
            hint: format!(
                ": the experiment has no measurements; add `data = \"{}.csv\"` (the CSV file \
                 of its measured diameters, relative to the experiments file) to its table",
                short(name, 40)
            ),
        })
    }
}

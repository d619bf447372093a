//! Errors of the input readers: where ([`Location`]: file and line) and what ([`InputError`]).

use std::fmt;
use std::path::PathBuf;

use crate::fiber::error::Readable;

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

//! Errors of the input readers: where ([`Location`]: file and line) and what ([`InputError`]).

use std::fmt;
use std::path::{Path, PathBuf};

use super::options::Limit;
use crate::error::Readable;

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
        write!(f, "{}", ShowPath(&self.path))?;
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
#[non_exhaustive]
pub enum InputError {
    /// The file could not be read (missing, unreadable).
    #[error("{}: cannot read file: {source}{hint}", ShowPath(path))]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
        /// A suggestion (starts with `"; "`) or empty.
        hint: String,
    },
    /// The path is not a regular file (a FIFO, device, socket or directory): refused before it
    /// is opened, so that nothing blocks or reads without end.
    #[error("{}: {kind}, not a regular file; {hint}", ShowPath(path))]
    NotRegular {
        /// The path.
        path: PathBuf,
        /// What it is (`"a FIFO (named pipe)"`, `"a character device"`, …).
        kind: &'static str,
        /// What to do.
        hint: String,
    },
    /// A file, line, row count or the data set exceeds a cap of
    /// [`LoadOptions`](super::LoadOptions).
    #[error("{at}: {message}")]
    Limit {
        /// File and line (if the cap was reached at a line).
        at: Location,
        /// The cap.
        limit: Limit,
        /// What exceeded it and how to raise it.
        message: String,
    },
    /// The file is not UTF-8 text (another encoding, binary data, a spreadsheet).
    #[error("{at}{}: {message}", column.map(|c| format!(":{c}")).unwrap_or_default())]
    Encoding {
        /// File and line of the first offending byte.
        at: Location,
        /// 1-based column (characters) of the offending byte, if known.
        column: Option<usize>,
        /// 0-based byte offset of the offending byte in the file.
        offset: u64,
        /// What the bytes look like and how to re-save the file.
        message: String,
    },
    /// The file given as the experiments file is something else (a CSV table, a JSON report).
    #[error("{at}: this is not an experiments file: {message}")]
    NotExperiments {
        /// The file (and the line that shows it).
        at: Location,
        /// What it looks like and what to pass instead.
        message: String,
    },
    /// A JSON report read back is malformed: truncated, a duplicate key, `NaN`, a number out
    /// of range, a syntax error; the message names the field (`n.value`).
    #[error("{at}{}: {message}", column.map(|c| format!(":{c}")).unwrap_or_default())]
    Json {
        /// File and line.
        at: Location,
        /// 1-based column, if known.
        column: Option<usize>,
        /// What is wrong, at which field, and what to do.
        message: String,
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

/// An input that is accepted but doubtful (a take-up diameter extrapolated beyond the
/// measured positions, a °C value that looks like kelvin): where and what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputWarning {
    /// File and line of the key concerned.
    pub at: Location,
    /// What is doubtful and what to do.
    pub message: String,
}

impl InputError {
    /// The cap of [`LoadOptions`](super::LoadOptions) this error says was exceeded, also
    /// where it is the cause of an experiment's data file ([`InputError::Data`]); `None` for
    /// any other error.
    pub fn exceeded_limit(&self) -> Option<Limit> {
        match self {
            InputError::Limit { limit, .. } => Some(*limit),
            InputError::Data { cause, .. } => cause.exceeded_limit(),
            _ => None,
        }
    }
}

impl fmt::Display for InputWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.at, self.message)
    }
}

/// A path as shown in messages: as is, or quoted (`"v0p27_p1.csv "`) when leading or trailing
/// spaces or control characters would be invisible.
pub(super) struct ShowPath<'a>(pub &'a Path);

impl fmt::Display for ShowPath<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let text = self.0.to_string_lossy();
        let needs_quotes = text.starts_with(char::is_whitespace)
            || text.ends_with(char::is_whitespace)
            || text.chars().any(char::is_control);
        let text = short(&text, 300);
        if needs_quotes {
            write!(f, "{text:?}")
        } else {
            write!(f, "{text}")
        }
    }
}

/// `text` cut to at most `max` characters for a message, saying how long it was
/// (`"1111111111… (1000002 characters)"`).
pub(super) fn short(text: &str, max: usize) -> String {
    let n = text.chars().count();
    if n <= max {
        return text.to_string();
    }
    let head: String = text.chars().take(max.saturating_sub(1)).collect();
    format!("{head}… ({n} characters)")
}

/// `x` with 4 significant digits for a message (`14.43`, `1.569e-5`, `1e308`), for computed
/// values; values as the user typed them are shown as typed.
pub(super) fn sig(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || !a.is_finite() {
        return format!("{x}");
    }
    if (1e-3..1e5).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{x:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        let s = format!("{x:.3e}");
        match s.split_once('e') {
            Some((m, e)) if m.contains('.') => {
                format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
            }
            _ => s,
        }
    }
}

/// The `Readable` form of a value for messages.
pub(super) fn readable(x: f64) -> String {
    Readable(x).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_for_messages() {
        assert_eq!(sig(14.4321), "14.43");
        assert_eq!(sig(1.5690566037735852e-05), "1.569e-5");
        assert_eq!(sig(1e308), "1e308");
        assert_eq!(sig(0.51), "0.51");
        assert_eq!(sig(513.15), "513.1");
        assert_eq!(sig(-2.0), "-2");
        assert_eq!(sig(12345.6), "12346");
        assert_eq!(readable(1e308), "1e308");
    }

    #[test]
    fn long_text_is_cut() {
        assert_eq!(short("abc", 80), "abc");
        let long = "1".repeat(1000);
        let s = short(&long, 80);
        assert!(s.len() < 110 && s.ends_with("(1000 characters)"), "{s}");
        assert_eq!(ShowPath(Path::new("a.csv ")).to_string(), "\"a.csv \"");
        assert_eq!(ShowPath(Path::new("dir/a.csv")).to_string(), "dir/a.csv");
    }
}

//! Span-tracking access to the parsed TOML document: tables and fields that know their line,
//! so that every error names file, line, table and key.

use std::ops::Range;
use std::path::Path;

use toml::de::{DeTable, DeValue};
use toml::Spanned;

use super::error::{InputError, Location};
use super::schema::{
    key_hint, unit_of, Rule, MAX_PLAUSIBLE_DIAMETER_M, MIN_PLAUSIBLE_DIAMETER_M, PLAUSIBLE_RANGES,
};

/// The [`InputError::Toml`] of a TOML syntax error, located by line and column.
pub(super) fn toml_error(path: &Path, text: &str, e: &toml::de::Error) -> InputError {
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
pub(super) fn line_col(text: &str, offset: usize) -> (usize, usize) {
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

/// The TOML text being parsed, for locations.
pub(super) struct Doc<'a> {
    pub(super) path: &'a Path,
    pub(super) text: &'a str,
}

impl<'a> Doc<'a> {
    pub(super) fn new(path: &'a Path, text: &'a str) -> Self {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        Doc { path, text }
    }

    pub(super) fn at(&self, span: &Range<usize>) -> Location {
        self.at_line(Some(line_col(self.text, span.start).0))
    }

    pub(super) fn at_line(&self, line: Option<usize>) -> Location {
        Location {
            path: self.path.to_path_buf(),
            line,
        }
    }

    /// Location of the `data` key of experiment `index` (for errors in its CSV file).
    pub(super) fn data_key_location(&self, index: usize) -> Location {
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
pub(super) struct Tab<'a> {
    pub(super) doc: &'a Doc<'a>,
    pub(super) name: String,
    pub(super) table: &'a DeTable<'a>,
    pub(super) line: Option<usize>,
}

/// One key's value in a table.
pub(super) struct Field<'a> {
    pub(super) doc: &'a Doc<'a>,
    pub(super) table: String,
    pub(super) key: &'a str,
    pub(super) value: &'a Spanned<DeValue<'a>>,
}

impl<'a> Tab<'a> {
    pub(super) fn get(&self, key: &'a str) -> Option<Field<'a>> {
        self.table.get(key).map(|value| Field {
            doc: self.doc,
            table: self.name.clone(),
            key,
            value,
        })
    }

    pub(super) fn missing(&self, key: &str, hint: &str) -> InputError {
        InputError::MissingKey {
            at: self.doc.at_line(self.line),
            table: self.name.clone(),
            key: key.to_string(),
            hint: hint.to_string(),
        }
    }

    /// Errors on the first (in file order) key not in `allowed`.
    pub(super) fn check_keys(&self, allowed: &[&str]) -> Result<(), InputError> {
        self.check_keys_hinted(allowed, |key| key_hint(key, allowed))
    }

    /// As [`check_keys`](Self::check_keys), with the hint for an unknown key from `hint`.
    pub(super) fn check_keys_hinted(
        &self,
        allowed: &[&str],
        hint: impl Fn(&str) -> String,
    ) -> Result<(), InputError> {
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
                hint: hint(key.get_ref()),
            }),
        }
    }

    /// The sub-table `key`, if present; an error if `key` is not a table.
    pub(super) fn sub_table(
        &self,
        key: &'a str,
        name: &str,
    ) -> Result<Option<Tab<'a>>, InputError> {
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
    pub(super) fn experiment_tables(&self) -> Result<Vec<Tab<'a>>, InputError> {
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
    pub(super) fn at(&self) -> Location {
        self.doc.at(&self.value.span())
    }

    pub(super) fn wrong_type(&self, expected: &'static str, found: &DeValue<'_>) -> InputError {
        InputError::WrongType {
            at: self.at(),
            table: self.table.clone(),
            key: self.key.to_string(),
            expected,
            found: type_name(found),
        }
    }

    pub(super) fn invalid(&self, value: f64, reason: impl Into<String>) -> InputError {
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
    pub(super) fn table_in(&self, experiment_table: &str) -> String {
        if self.table == experiment_table {
            self.table.clone()
        } else {
            format!("{experiment_table} (value from {})", self.table)
        }
    }

    /// Like [`invalid`](Self::invalid), for a check of experiment `experiment_table`.
    pub(super) fn invalid_in(
        &self,
        experiment_table: &str,
        value: f64,
        reason: String,
    ) -> InputError {
        InputError::InvalidValue {
            at: self.at(),
            table: self.table_in(experiment_table),
            key: self.key.to_string(),
            value,
            reason,
        }
    }

    /// Like [`inconsistent`](Self::inconsistent), for a check of experiment `experiment_table`.
    pub(super) fn inconsistent_in(&self, experiment_table: &str, message: String) -> InputError {
        InputError::Inconsistent {
            at: self.at(),
            table: self.table_in(experiment_table),
            message,
        }
    }

    pub(super) fn inconsistent(&self, message: String) -> InputError {
        InputError::Inconsistent {
            at: self.at(),
            table: self.table.clone(),
            message,
        }
    }

    pub(super) fn string(&self) -> Result<&str, InputError> {
        match self.value.get_ref() {
            DeValue::String(s) => Ok(s.as_ref()),
            other => Err(self.wrong_type("a string", other)),
        }
    }

    /// The value as a number satisfying `rule`.
    pub(super) fn number(&self, rule: Rule) -> Result<f64, InputError> {
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
    pub(super) fn plausible(&self, value: f64) -> Result<f64, InputError> {
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

pub(super) fn type_name(value: &DeValue<'_>) -> &'static str {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_col_counts_characters() {
        assert_eq!(line_col("ab\ncµd", 6), (2, 3));
        assert_eq!(line_col("", 5), (1, 1));
    }
}

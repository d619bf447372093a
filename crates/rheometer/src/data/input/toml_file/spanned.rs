//! Span-tracking access to the parsed TOML document: tables and fields that know their line,
//! so that every error names file, line, table and key.

use std::ops::Range;
use std::path::Path;

use toml::de::{DeTable, DeValue};
use toml::Spanned;

use super::schema::{
    key_hint, plausible_range, Quantity, Rule, Unit, MAX_PLAUSIBLE_DIAMETER_M,
    MIN_PLAUSIBLE_DIAMETER_M,
};
use crate::data::input::error::{readable, short, InputError, Location};

/// The error of a TOML syntax error, located by line and column: a file that is not TOML at
/// all (JSON, CSV) is said to be so, and a duplicate key or table is named.
pub(in crate::data::input) fn toml_error(
    path: &Path,
    text: &str,
    e: &toml::de::Error,
) -> InputError {
    if let Some(other) = super::syntax::not_experiments(path, text) {
        return other;
    }
    let (line, column) = match e.span() {
        Some(span) => {
            let (l, c) = line_col(text, span.start);
            (Some(l), Some(c))
        }
        None => (None, None),
    };
    let message = e.message().trim();
    let message = match e.span() {
        Some(span) if message.starts_with("duplicate key") => {
            super::syntax::duplicate_message(text, span).unwrap_or_else(|| message.to_string())
        }
        _ => short(message, 300),
    };
    InputError::Toml {
        at: Location {
            path: path.to_path_buf(),
            line,
        },
        column,
        message,
    }
}

/// 1-based line and column (in characters) of byte `offset` in `text`.
pub(in crate::data::input) fn line_col(text: &str, offset: usize) -> (usize, usize) {
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
pub(in crate::data::input) struct Doc<'a> {
    pub(in crate::data::input) path: &'a Path,
    pub(in crate::data::input) text: &'a str,
    /// Byte offsets of the starts of lines 2, 3, … (a line number is a binary search).
    line_starts: Vec<usize>,
}

impl<'a> Doc<'a> {
    pub(in crate::data::input) fn new(path: &'a Path, text: &'a str) -> Self {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let line_starts = text
            .bytes()
            .enumerate()
            .filter(|&(_, b)| b == b'\n')
            .map(|(i, _)| i + 1)
            .collect();
        Doc {
            path,
            text,
            line_starts,
        }
    }

    /// 1-based line of byte `offset`.
    pub(in crate::data::input) fn line_of(&self, offset: usize) -> usize {
        self.line_starts.partition_point(|&start| start <= offset) + 1
    }

    pub(in crate::data::input) fn at(&self, span: &Range<usize>) -> Location {
        self.at_line(Some(self.line_of(span.start)))
    }

    pub(in crate::data::input) fn at_line(&self, line: Option<usize>) -> Location {
        Location {
            path: self.path.to_path_buf(),
            line,
        }
    }
}

/// A TOML table with the name used in messages.
pub(in crate::data::input) struct Tab<'a> {
    pub(in crate::data::input) doc: &'a Doc<'a>,
    pub(in crate::data::input) name: String,
    pub(in crate::data::input) table: &'a DeTable<'a>,
    pub(in crate::data::input) line: Option<usize>,
}

/// One key's value in a table.
pub(in crate::data::input) struct Field<'a> {
    pub(in crate::data::input) doc: &'a Doc<'a>,
    pub(in crate::data::input) table: String,
    pub(in crate::data::input) key: &'a str,
    pub(in crate::data::input) value: &'a Spanned<DeValue<'a>>,
}

impl<'a> Tab<'a> {
    pub(in crate::data::input) fn get(&self, key: &str) -> Option<Field<'a>> {
        self.table.get_key_value(key).map(|(k, value)| Field {
            doc: self.doc,
            table: self.name.clone(),
            key: k.get_ref().as_ref(),
            value,
        })
    }

    /// The key of quantity `q` in this table, in whichever unit it is given; an error naming
    /// both keys if it is given in two units.
    pub(in crate::data::input) fn quantity(
        &self,
        q: &Quantity,
    ) -> Result<Option<(Field<'a>, Unit)>, InputError> {
        let mut found: Option<(Field<'a>, Unit)> = None;
        for unit in q.units {
            let Some(field) = self.get(&q.key(unit)) else {
                continue;
            };
            if let Some((first, _)) = &found {
                let (a, b) = if first.value.span().start <= field.value.span().start {
                    (first, &field)
                } else {
                    (&field, first)
                };
                return Err(b.inconsistent(format!(
                    "`{}` (line {}) and `{}` (line {}) give the same quantity twice, in \
                     different units; keep one",
                    a.key,
                    a.line(),
                    b.key,
                    b.line()
                )));
            }
            found = Some((field, *unit));
        }
        Ok(found)
    }

    pub(in crate::data::input) fn missing(&self, key: &str, hint: &str) -> InputError {
        InputError::MissingKey {
            at: self.doc.at_line(self.line),
            table: self.name.clone(),
            key: key.to_string(),
            hint: hint.to_string(),
        }
    }

    /// Errors on the first (in file order) key not in `allowed`.
    pub(in crate::data::input) fn check_keys<S: AsRef<str>>(
        &self,
        allowed: &[S],
    ) -> Result<(), InputError> {
        let allowed: Vec<&str> = allowed.iter().map(AsRef::as_ref).collect();
        let allowed = &allowed[..];
        self.check_keys_hinted(allowed, |key| key_hint(key, allowed))
    }

    /// As [`check_keys`](Self::check_keys), with the hint for an unknown key from `hint`.
    pub(in crate::data::input) fn check_keys_hinted(
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
    pub(in crate::data::input) fn sub_table(
        &self,
        key: &str,
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
    pub(in crate::data::input) fn experiment_tables(&self) -> Result<Vec<Tab<'a>>, InputError> {
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
                    line: Some(self.doc.line_of(item.span().start)),
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
    pub(in crate::data::input) fn at(&self) -> Location {
        self.doc.at(&self.value.span())
    }

    /// 1-based line of the value.
    pub(in crate::data::input) fn line(&self) -> usize {
        self.doc.line_of(self.value.span().start)
    }

    /// The value as written in the file (cut for messages).
    pub(in crate::data::input) fn raw(&self) -> String {
        let span = self.value.span();
        short(self.doc.text.get(span).unwrap_or("?").trim(), 40)
    }

    /// `` `key` = value (line N)`` for messages.
    pub(in crate::data::input) fn shown(&self) -> String {
        format!("`{}` = {} (line {})", self.key, self.raw(), self.line())
    }

    pub(in crate::data::input) fn wrong_type(
        &self,
        expected: &'static str,
        found: &DeValue<'_>,
    ) -> InputError {
        InputError::WrongType {
            at: self.at(),
            table: self.table.clone(),
            key: self.key.to_string(),
            expected,
            found: type_name(found),
        }
    }

    pub(in crate::data::input) fn invalid(
        &self,
        value: f64,
        reason: impl Into<String>,
    ) -> InputError {
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
    pub(in crate::data::input) fn table_in(&self, experiment_table: &str) -> String {
        if self.table == experiment_table {
            self.table.clone()
        } else {
            format!("{experiment_table} (value from {})", self.table)
        }
    }

    /// Like [`invalid`](Self::invalid), for a check of experiment `experiment_table`.
    pub(in crate::data::input) fn invalid_in(
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
    pub(in crate::data::input) fn inconsistent_in(
        &self,
        experiment_table: &str,
        message: String,
    ) -> InputError {
        InputError::Inconsistent {
            at: self.at(),
            table: self.table_in(experiment_table),
            message,
        }
    }

    pub(in crate::data::input) fn inconsistent(&self, message: String) -> InputError {
        InputError::Inconsistent {
            at: self.at(),
            table: self.table.clone(),
            message,
        }
    }

    pub(in crate::data::input) fn string(&self) -> Result<&str, InputError> {
        match self.value.get_ref() {
            DeValue::String(s) => Ok(s.as_ref()),
            other => Err(self.wrong_type("a string", other)),
        }
    }

    /// The value as a finite number (integers accepted; `nan` and `inf` refused).
    pub(in crate::data::input) fn finite(&self) -> Result<f64, InputError> {
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
        match value.filter(|v| v.is_finite()) {
            Some(value) => Ok(value),
            None => Err(InputError::NotFinite {
                at: self.at(),
                table: self.table.clone(),
                key: self.key.to_string(),
                value: short(raw, 40),
            }),
        }
    }

    /// The value as a number satisfying `rule` (no unit conversion, no plausible range).
    pub(in crate::data::input) fn number(&self, rule: Rule) -> Result<f64, InputError> {
        let value = self.finite()?;
        match rule {
            Rule::Positive | Rule::Diameter if value <= 0.0 => {
                Err(self.invalid(value, "must be positive"))
            }
            Rule::NonNegative if value < 0.0 => Err(self.invalid(value, "must not be negative")),
            Rule::Fraction if value <= 0.0 || value >= 1.0 => Err(self.invalid(
                value,
                "must lie in (0, 1) (a relative uncertainty: 0.015 means 1.5 %)",
            )),
            _ => Ok(value),
        }
    }

    /// The value of quantity `q` given in `unit`, converted to SI, checked against the rule
    /// and the plausible range of `q` (after conversion), with a hint at the unit that would
    /// make it plausible.
    pub(in crate::data::input) fn quantity(
        &self,
        q: &Quantity,
        unit: &Unit,
    ) -> Result<f64, InputError> {
        let value = self.finite()?;
        let si = unit.to_si(value);
        let below = if unit.offset == 0.0 {
            "must be positive".to_string()
        } else {
            format!("is at or below absolute zero ({} K)", readable(si))
        };
        match q.rule {
            Rule::Positive | Rule::Diameter if si <= 0.0 => return Err(self.invalid(value, below)),
            Rule::NonNegative if si < 0.0 => {
                return Err(self.invalid(
                    value,
                    if unit.offset == 0.0 {
                        "must not be negative".to_string()
                    } else {
                        below
                    },
                ))
            }
            _ => {}
        }
        let range = match q.rule {
            Rule::Diameter => Some(
                plausible_range(q).unwrap_or((MIN_PLAUSIBLE_DIAMETER_M, MAX_PLAUSIBLE_DIAMETER_M)),
            ),
            _ => plausible_range(q),
        };
        let Some((min, max)) = range else {
            return Ok(si);
        };
        if (min..=max).contains(&si) {
            return Ok(si);
        }
        let si_unit = q.units[0].symbol;
        let side = if si < min { "small" } else { "large" };
        let what = if q.rule == Rule::Diameter {
            format!("a diameter in {}", unit.name)
        } else {
            format!("melt spinning in {}", unit.name)
        };
        let converted = if unit.suffix == q.units[0].suffix {
            String::new()
        } else {
            format!(" = {} {si_unit}", readable(si))
        };
        let mut reason = format!(
            "implausibly {side} for {what}{converted} (expected {} to {} {si_unit}); check the unit",
            readable(min),
            readable(max)
        );
        let fits: Vec<String> = q
            .units
            .iter()
            .filter(|u| u.suffix != unit.suffix && (min..=max).contains(&u.to_si(value)))
            .map(|u| format!("`{} = {}` if it is in {}", q.key(u), self.raw(), u.name))
            .collect();
        if !fits.is_empty() {
            reason.push_str(&format!(": write {}", fits.join(", or ")));
        }
        Err(self.invalid(value, reason))
    }
}

pub(in crate::data::input) fn type_name(value: &DeValue<'_>) -> &'static str {
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
        let doc = Doc::new(Path::new("x"), "ab\ncd\n\ne");
        let lines: Vec<usize> = (0..9).map(|i| doc.line_of(i)).collect();
        assert_eq!(lines, vec![1, 1, 1, 2, 2, 2, 3, 4, 4]);
    }
}

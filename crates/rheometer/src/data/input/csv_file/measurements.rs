//! Reading the measurement CSV files (`position_m,diameter_m`, or the same quantities in other
//! units: `position_mm,diameter_um`), streamed line by line under the caps of
//! [`LoadOptions`], with the checks of each row and hints for the CSV dialects of other tools
//! (semicolons, tabs, decimal commas, trailing commas, Fortran `D` exponents, millimetres).

use std::path::Path;

use super::row_budget::FitBudget;
use crate::data::input::error::{readable, short, InputError, Location};
use crate::data::input::options::{Limit, LoadOptions};
use crate::data::input::source::{text_lines, Lines};
use crate::data::input::toml_file::schema::{
    Unit, DIAMETER, LENGTH, MAX_PLAUSIBLE_DIAMETER_M, MIN_PLAUSIBLE_DIAMETER_M,
};
use crate::model::setup::Measurements;

/// Minimum number of measurement rows per CSV file used by
/// [`load_experiments`](crate::data::input::load_experiments).
pub const DEFAULT_MIN_POINTS: usize = 4;

/// The CSV header in SI units. The columns may also be given in other units, named in the
/// header: positions in `position_m`, `position_cm`, `position_mm`; diameters in
/// `diameter_m`, `diameter_mm`, `diameter_um` (or `diameter_µm`); in either order.
pub const CSV_HEADER: [&str; 2] = ["position_m", "diameter_m"];

/// Loads one measurement CSV file, requiring positions within `[0, spinline_length]` \[m\]
/// (pass `f64::INFINITY` to skip that check) and at least `options.min_points` rows, under the
/// byte, line and row caps of `options`.
pub fn load_measurements_with(
    path: &Path,
    spinline_length: f64,
    options: &LoadOptions,
) -> Result<Measurements, InputError> {
    let mut budget = FitBudget::unlimited(options.max_rows_per_file);
    read_measurements(path, spinline_length, options, &mut budget)
}

/// Streams one CSV file within `budget`.
pub(in crate::data::input) fn read_measurements(
    path: &Path,
    spinline_length: f64,
    options: &LoadOptions,
    budget: &mut FitBudget,
) -> Result<Measurements, InputError> {
    let mut parser = Parser::new(path, spinline_length, budget)?;
    let mut lines = Lines::open(path, options.max_csv_bytes, options.max_line_bytes)?;
    while let Some((n, line)) = lines.next_line()? {
        parser.line(n, line, budget)?;
    }
    let m = parser.finish(options.min_points)?;
    budget.add(m.positions.len());
    Ok(m)
}

/// Parses the text of a measurement CSV file; `path` is used in error messages only. See
/// `load_measurements`.
pub fn parse_measurements(
    text: &str,
    path: &Path,
    spinline_length: f64,
    min_points: usize,
) -> Result<Measurements, InputError> {
    let budget = FitBudget::unlimited(usize::MAX);
    let mut parser = Parser::new(path, spinline_length, &budget)?;
    for (n, line) in text_lines(text) {
        parser.line(n, line, &budget)?;
    }
    parser.finish(min_points)
}

/// Which cell holds what, in which unit.
struct Columns {
    position: (usize, Unit),
    diameter: (usize, Unit),
}

struct Parser<'p> {
    path: &'p Path,
    spinline_length: f64,
    /// Most rows, and the cap that sets it.
    cap: (usize, Limit),
    columns: Option<Columns>,
    positions: Vec<f64>,
    diameters: Vec<f64>,
    previous_line: usize,
}

/// Up to 4 cells of a line split at commas outside double quotes, trimmed and unquoted, and
/// the number of cells.
fn split(line: &str) -> (usize, [&str; 4]) {
    let mut cells = [""; 4];
    let mut count = 0;
    let mut start = 0;
    let mut quoted = false;
    let bytes = line.as_bytes();
    for i in 0..=bytes.len() {
        let end = i == bytes.len();
        if !end && bytes[i] == b'"' {
            quoted = !quoted;
        }
        if end || (bytes[i] == b',' && !quoted) {
            if count < 4 {
                let cell = line[start..i].trim();
                let cell = cell
                    .strip_prefix('"')
                    .and_then(|c| c.strip_suffix('"'))
                    .map_or(cell, str::trim);
                cells[count] = cell;
            }
            count += 1;
            start = i + 1;
        }
    }
    (count, cells)
}

/// The unit of a header cell `prefix_unit` among `units` (case-insensitive; `µm` and `μm`
/// read as `um`).
fn header_unit(cell: &str, prefix: &str, units: &[Unit]) -> Option<Unit> {
    let lower = cell.to_lowercase().replace(['µ', 'μ'], "u");
    let suffix = lower.strip_prefix(prefix)?.strip_prefix('_')?;
    units.iter().find(|u| u.suffix == suffix).copied()
}

/// The hint for a line that is not two comma-separated cells, if a known dialect explains it.
fn dialect_hint(line: &str, count: usize, cells: &[&str; 4]) -> Option<String> {
    let resave = "save the file as comma-separated values with a point as decimal separator \
                  (in Excel: File \u{203a} Save As \u{203a} \"CSV UTF-8\" with the system's \
                  decimal separator set to a point)";
    let number = |s: &str| s.parse::<f64>().is_ok();
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    if line.contains(';') {
        let comma = if line.contains(',') {
            " and has decimal commas"
        } else {
            " (as spreadsheets save CSV where the decimal separator is a comma)"
        };
        return Some(format!(
            "the line is separated by semicolons `;`{comma}, but this reader expects commas \
             between the columns and points in the numbers: {resave}"
        ));
    }
    if line.contains('\t') {
        return Some(format!(
            "the line is separated by tabs, but this reader expects commas: {resave}"
        ));
    }
    if count == 1 && line.split_whitespace().count() == 2 {
        return Some(format!(
            "the line is separated by spaces, but this reader expects commas: {resave}"
        ));
    }
    if count == 3 && cells[2].is_empty() {
        return Some(
            "the line ends with a comma (an empty third column): remove the trailing commas, \
             or delete the empty column in the spreadsheet before saving"
                .into(),
        );
    }
    let decimal = |a: &str, b: &str| {
        digits(b.split(['e', 'E']).next().unwrap_or(b)) && number(&format!("{a}.{b}"))
    };
    let decimal_commas = match count {
        4 => decimal(cells[0], cells[1]) && decimal(cells[2], cells[3]),
        3 => {
            (decimal(cells[0], cells[1]) && number(cells[2]))
                || (number(cells[0]) && decimal(cells[1], cells[2]))
        }
        _ => false,
    };
    if decimal_commas {
        return Some(format!(
            "the numbers seem to have decimal commas (`{},{}`), which cannot be told apart from \
             the column separator: {resave}",
            cells[0], cells[1]
        ));
    }
    None
}

/// The hint for a cell that is not a number.
fn cell_hint(cell: &str) -> String {
    let fortran = cell.contains(['d', 'D'])
        && cell.replacen(['d', 'D'], "e", 1).parse::<f64>().is_ok()
        && cell.parse::<f64>().is_err();
    if fortran {
        return format!(
            ": `D` exponents (Fortran) are not read; write `E`: `{}`",
            short(&cell.replacen(['d', 'D'], "E", 1), 40)
        );
    }
    if cell.contains(',') && cell.replace(',', ".").parse::<f64>().is_ok() {
        return ": decimal commas are not read; write a point (`0.02`, not `0,02`)".into();
    }
    String::new()
}

impl<'p> Parser<'p> {
    fn new(path: &'p Path, spinline_length: f64, budget: &FitBudget) -> Result<Self, InputError> {
        let parser = Parser {
            path,
            spinline_length,
            cap: budget.file_cap(),
            columns: None,
            positions: Vec::new(),
            diameters: Vec::new(),
            previous_line: 0,
        };
        if spinline_length.is_nan() || spinline_length <= 0.0 {
            return Err(parser.error(
                None,
                format!(
                    "cannot check the positions against a spin-line length of {} m (it must be \
                     positive, or infinite to skip the check)",
                    readable(spinline_length)
                ),
            ));
        }
        Ok(parser)
    }

    fn error(&self, line: Option<usize>, message: String) -> InputError {
        InputError::Csv {
            at: Location {
                path: self.path.to_path_buf(),
                line,
            },
            message,
        }
    }

    /// Reads line `n`: the header, a data row, or nothing (blank or comment).
    fn line(&mut self, n: usize, line: &str, budget: &FitBudget) -> Result<(), InputError> {
        let trimmed = line.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            return Ok(());
        }
        let (count, cells) = split(trimmed);
        if self.columns.is_none() {
            self.columns = Some(self.header(n, trimmed, count, &cells)?);
            return Ok(());
        }
        if self.positions.len() >= self.cap.0 {
            return Err(budget.exceeded(self.path, n, self.cap.1));
        }
        if count != 2 {
            let hint = dialect_hint(trimmed, count, &cells)
                .map(|h| format!("; {h}"))
                .unwrap_or_default();
            return Err(self.error(
                Some(n),
                format!("expected 2 columns ({}), found {count}{hint}", self.names()),
            ));
        }
        self.row(n, trimmed, &cells)
    }

    /// The header's column names (for messages).
    fn names(&self) -> String {
        match &self.columns {
            Some(c) => {
                let mut names = [
                    (c.position.0, format!("position_{}", c.position.1.suffix)),
                    (c.diameter.0, format!("diameter_{}", c.diameter.1.suffix)),
                ];
                names.sort();
                format!("{},{}", names[0].1, names[1].1)
            }
            None => CSV_HEADER.join(","),
        }
    }

    fn header(
        &self,
        n: usize,
        line: &str,
        count: usize,
        cells: &[&str; 4],
    ) -> Result<Columns, InputError> {
        let expected = format!(
            "expected `{}` (or other units named in the header: position_m, position_cm, \
             position_mm; diameter_m, diameter_mm, diameter_um)",
            CSV_HEADER.join(",")
        );
        let found = short(line, 80);
        if count == 2 {
            let find = |prefix: &str, units: &[Unit]| {
                let hits: Vec<(usize, Unit)> = (0..2)
                    .filter_map(|k| header_unit(cells[k], prefix, units).map(|u| (k, u)))
                    .collect();
                hits
            };
            let positions = find("position", LENGTH);
            let diameters = find("diameter", DIAMETER);
            if let ([p], [d]) = (&positions[..], &diameters[..]) {
                return Ok(Columns {
                    position: *p,
                    diameter: *d,
                });
            }
            if positions.len() == 2 || diameters.len() == 2 {
                return Err(self.error(
                    Some(n),
                    format!(
                        "the header `{found}` names the same quantity twice, in different units; \
                         {expected}"
                    ),
                ));
            }
        }
        let note = if cells[..count.min(4)]
            .iter()
            .all(|c| c.parse::<f64>().is_ok())
        {
            " (the header line is missing)".to_string()
        } else if let Some(h) = dialect_hint(line, count, cells) {
            format!("; {h}")
        } else {
            " (the column names carry the unit: values in metres are `position_m,diameter_m`)"
                .to_string()
        };
        Err(self.error(Some(n), format!("wrong header `{found}`; {expected}{note}")))
    }

    /// A data row: two numbers, checked in SI.
    fn row(&mut self, n: usize, line: &str, cells: &[&str; 4]) -> Result<(), InputError> {
        let Some(columns) = &self.columns else {
            return Ok(());
        };
        let (pk, pu) = columns.position;
        let (dk, du) = columns.diameter;
        let value = |k: usize, unit: &Unit, what: &str| -> Result<f64, InputError> {
            let cell = cells[k];
            let column = format!("{what}_{}", unit.suffix);
            let v: f64 = cell.parse().map_err(|_| {
                self.error(
                    Some(n),
                    format!(
                        "non-numeric cell `{}` in column `{column}`{}",
                        short(cell, 80),
                        dialect_hint(line, 2, cells)
                            .map(|h| format!("; {h}"))
                            .unwrap_or_else(|| cell_hint(cell))
                    ),
                )
            })?;
            if !v.is_finite() {
                return Err(self.error(
                    Some(n),
                    format!("`{}` in column `{column}` is not finite", short(cell, 80)),
                ));
            }
            Ok(unit.to_si(v))
        };
        let s = value(pk, &pu, "position")?;
        let d = value(dk, &du, "diameter")?;
        let (s_cell, d_cell) = (short(cells[pk], 40), short(cells[dk], 40));
        let err = |message: String| {
            Err(InputError::Csv {
                at: Location {
                    path: self.path.to_path_buf(),
                    line: Some(n),
                },
                message,
            })
        };
        if s < 0.0 {
            return err(format!("position {s_cell} {} is negative", pu.symbol));
        }
        let l = self.spinline_length;
        if s > l {
            let fits: Vec<&Unit> = LENGTH
                .iter()
                .filter(|u| {
                    s > 5.0 * l && u.divisor > pu.divisor && s * pu.divisor / u.divisor <= l
                })
                .collect();
            let hint = if fits.is_empty() {
                String::new()
            } else {
                format!(
                    "; the positions look like {}: name the column {} (or convert them to {})",
                    fits.iter().map(|u| u.name).collect::<Vec<_>>().join(" or "),
                    fits.iter()
                        .map(|u| format!("`position_{}`", u.suffix))
                        .collect::<Vec<_>>()
                        .join(" or "),
                    pu.name
                )
            };
            return err(format!(
                "position {s_cell} {} lies beyond the spin-line length {} m{hint}",
                pu.symbol,
                readable(l)
            ));
        }
        if let Some(&last) = self.positions.last() {
            let prev = self.previous_line;
            if s == last {
                return err(format!(
                    "position {s_cell} {} repeats the one on line {prev}; positions must be \
                     strictly increasing",
                    pu.symbol
                ));
            }
            if s < last {
                return err(format!(
                    "position {s_cell} {} is smaller than {} {} on line {prev}; positions must \
                     be strictly increasing",
                    pu.symbol,
                    readable(pu.of_si(last)),
                    pu.symbol
                ));
            }
        }
        self.diameter(n, d, &d_cell, &du)?;
        self.positions.push(s);
        self.diameters.push(d);
        self.previous_line = n;
        Ok(())
    }

    /// Checks diameter `d` \[m\] (typed `cell` in `unit`).
    fn diameter(&self, n: usize, d: f64, cell: &str, unit: &Unit) -> Result<(), InputError> {
        let symbol = unit.symbol;
        let (min, max) = (MIN_PLAUSIBLE_DIAMETER_M, MAX_PLAUSIBLE_DIAMETER_M);
        let other = |v: f64| {
            DIAMETER
                .iter()
                .filter(|u| u.suffix != unit.suffix)
                .filter(|u| (min..=max).contains(&u.to_si(v)))
                .map(|u| format!("`diameter_{}` ({})", u.suffix, u.name))
                .collect::<Vec<_>>()
        };
        let v = unit.of_si(d);
        let message = if d <= 0.0 {
            format!("diameter {cell} {symbol} is not positive")
        } else if d < min {
            let alt = other(v);
            let hint = if alt.is_empty() {
                String::new()
            } else {
                format!(
                    "; if the column is in another unit, name it {}",
                    alt.join(" or ")
                )
            };
            format!(
                "diameter {cell} {symbol} is implausibly small for a fiber (< 1 µm); the values \
                 must be in {}{hint}",
                unit.name
            )
        } else if d > max {
            let alt = other(v);
            let looks = if unit.suffix == "m" {
                "the file looks like millimetres or micrometres: ".to_string()
            } else {
                String::new()
            };
            format!(
                "diameter {cell} is implausibly large for {} (> 0.02 m); {looks}name the column \
                 {} or convert the values",
                unit.name,
                if alt.is_empty() {
                    "by its unit".to_string()
                } else {
                    alt.join(" or ")
                }
            )
        } else {
            return Ok(());
        };
        Err(self.error(Some(n), message))
    }

    fn finish(self, min_points: usize) -> Result<Measurements, InputError> {
        if self.columns.is_none() {
            return Err(self.error(
                None,
                format!("empty file; expected the header `{}`", CSV_HEADER.join(",")),
            ));
        }
        if self.positions.len() < min_points {
            return Err(self.error(
                None,
                format!(
                    "only {} measurement point(s); at least {min_points} are required",
                    self.positions.len()
                ),
            ));
        }
        Ok(Measurements {
            positions: self.positions,
            diameters: self.diameters,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn csv(text: &str) -> Result<Measurements, InputError> {
        parse_measurements(text, Path::new("m.csv"), 0.51, 2)
    }

    fn err(text: &str) -> String {
        csv(text).unwrap_err().to_string()
    }

    #[test]
    fn csv_accepts_comments_blank_lines_and_spaces() {
        let m = csv("# comment\nposition_m, diameter_m\n\n0.0, 1e-3\n0.1 ,5e-4\n").unwrap();
        assert_eq!(m.positions, vec![0.0, 0.1]);
        assert_eq!(m.diameters, vec![1e-3, 5e-4]);
        let m = csv("position_m,diameter_m\r\n\"0.0\",\"1e-3\"\r\n0.1,5e-4\r\n").unwrap();
        assert_eq!(m.positions, vec![0.0, 0.1]);
    }

    #[test]
    fn csv_errors_name_line() {
        assert_eq!(
            err("position_m,diameter_m\n0.0,1e-3\n0.1\n"),
            "m.csv:3: expected 2 columns (position_m,diameter_m), found 1"
        );
        let msg = err("0.0,1e-3\n0.1,1e-3\n");
        assert!(
            msg.starts_with("m.csv:1: wrong header") && msg.contains("missing"),
            "{msg}"
        );
        assert!(err("").contains("empty file"));
        let msg = err("position_m,diameter_m\n0.0,nan\n0.1,1e-3\n");
        assert!(
            msg.starts_with("m.csv:2:") && msg.contains("not finite"),
            "{msg}"
        );
    }

    #[test]
    fn units_in_the_header() {
        let m = csv("diameter_um,position_mm\n1100,0\n500,100\n").unwrap();
        assert_eq!(m.positions, vec![0.0, 0.1]);
        assert_eq!(m.diameters, vec![1.1e-3, 5e-4]);
        let m = csv("Position_cm,Diameter_µm\n0,1100\n10,500\n").unwrap();
        assert_eq!(m.positions, vec![0.0, 0.1]);
        let msg = err("position_m,position_mm\n0,1\n");
        assert!(msg.contains("same quantity twice"), "{msg}");
    }

    #[test]
    fn dialects_are_named() {
        let msg = err("position_m;diameter_m\n0;1e-3\n");
        assert!(msg.contains("semicolons"), "{msg}");
        let msg = err("position_m,diameter_m\n0;1,1e-3\n");
        assert!(
            msg.contains("semicolons") && msg.contains("has decimal commas"),
            "{msg}"
        );
        let msg = err("position_m\tdiameter_m\n");
        assert!(msg.contains("tabs"), "{msg}");
        let msg = err("position_m,diameter_m,\n");
        assert!(msg.contains("ends with a comma"), "{msg}");
        let msg = err("position_m,diameter_m\n0,00,1,1e-03\n");
        assert!(msg.contains("decimal commas"), "{msg}");
        let msg = err("position_m,diameter_m\n0.0,1.1D-03\n");
        assert!(msg.contains("`1.1E-03`"), "{msg}");
        let msg = err("position_m,diameter_m\n0,1e-3\n20,1e-4\n");
        assert!(msg.contains("`position_mm`"), "{msg}");
        let msg = err(&format!(
            "position_m,diameter_m\n0,{}\n",
            "1".repeat(100_000)
        ));
        assert!(
            msg.len() < 300 && msg.contains("100000 characters"),
            "{msg}"
        );
        let msg = err("position_m,diameter_m\n0,1e-3\n1e308,9e-5\n");
        assert!(msg.contains("1e308") && msg.len() < 200, "{msg}");
    }
}

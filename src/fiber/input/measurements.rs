//! Reading the measurement CSV files (`position_m,diameter_m`), with the checks of each row.

use std::path::Path;

use super::error::{InputError, Location};
use super::read_text;
use super::schema::{MAX_PLAUSIBLE_DIAMETER_M, MIN_PLAUSIBLE_DIAMETER_M};
use crate::fiber::error::Readable;
use crate::fiber::setup::Measurements;

/// Minimum number of measurement rows per CSV file used by
/// [`load_experiments`](super::load_experiments).
pub const DEFAULT_MIN_POINTS: usize = 4;

/// The required CSV header (column names carry the unit: metres).
pub const CSV_HEADER: [&str; 2] = ["position_m", "diameter_m"];

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

fn csv_read_error(path: &Path, e: &csv::Error) -> InputError {
    InputError::Csv {
        at: Location {
            path: path.to_path_buf(),
            line: e.position().map(|p| p.line() as usize),
        },
        message: format!("unreadable CSV: {e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

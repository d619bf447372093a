//! The limits and switches of the loader ([`LoadOptions`]), which limit an input exceeded
//! ([`Limit`]), and the estimate of a fit's memory that one of them bounds.

/// Default [`LoadOptions::max_toml_bytes`]: 16 MiB (a data set of a thousand experiments is
/// about 200 kB).
pub const DEFAULT_MAX_TOML_BYTES: u64 = 16 << 20;

/// Default [`LoadOptions::max_csv_bytes`]: 128 MiB per measurement file (a million rows of two
/// numbers are about 30 MB).
pub const DEFAULT_MAX_CSV_BYTES: u64 = 128 << 20;

/// Default [`LoadOptions::max_line_bytes`]: 64 KiB per CSV line (a row of two numbers is
/// under 60 bytes).
pub const DEFAULT_MAX_LINE_BYTES: usize = 64 << 10;

/// Default [`LoadOptions::max_rows_per_file`]: one million measurement rows per CSV file.
pub const DEFAULT_MAX_ROWS_PER_FILE: usize = 1_000_000;

/// Default [`LoadOptions::max_experiments`]: 1000 experiments per data set.
pub const DEFAULT_MAX_EXPERIMENTS: usize = 1000;

/// Default [`LoadOptions::max_fit_memory_bytes`]: 4 GiB of estimated fit memory
/// ([`estimated_fit_memory_bytes`]).
pub const DEFAULT_MAX_FIT_MEMORY_BYTES: u64 = 4 << 30;

/// Bytes of fit memory per Jacobian entry (one measurement row times one fitted parameter),
/// measured on the release build with `/usr/bin/time` (9 experiments of 100 000 and 300 000
/// rows): the Jacobian and its copies in the trust-region solver.
pub const FIT_BYTES_PER_ENTRY: u64 = 56;

/// Bytes of fit memory per experiment (its solver, mesh and sensitivities), measured as
/// [`FIT_BYTES_PER_ENTRY`] (100 and 200 experiments of 27 rows: 140 and 290 MB).
pub const FIT_BYTES_PER_EXPERIMENT: u64 = 1_100_000;

/// Resident memory of the program before any fit \[bytes\] (20 MB measured).
pub const FIT_BASE_BYTES: u64 = 20_000_000;

/// Estimated peak memory \[bytes\] of a fit of `rows` measurement rows in `experiments`
/// experiments with the default (principled) estimator, which fits `experiments + 2`
/// parameters (n, κ and one scale per experiment): a dense Jacobian of `rows × (experiments +
/// 2)` entries (`FIT_BYTES_PER_ENTRY` each) and `FIT_BYTES_PER_EXPERIMENT` per experiment,
/// above `FIT_BASE_BYTES`. The constants were measured; the estimate is meant to be within
/// a factor of two.
pub fn estimated_fit_memory_bytes(rows: u64, experiments: u64) -> u64 {
    let params = experiments.saturating_add(2);
    FIT_BASE_BYTES
        .saturating_add(
            rows.saturating_mul(params)
                .saturating_mul(FIT_BYTES_PER_ENTRY),
        )
        .saturating_add(experiments.saturating_mul(FIT_BYTES_PER_EXPERIMENT))
}

/// The most rows in all of `experiments` experiments whose estimated fit memory
/// ([`estimated_fit_memory_bytes`]) stays within `max_bytes` (0 if the experiments alone
/// exceed it).
pub fn max_fit_rows(experiments: u64, max_bytes: u64) -> u64 {
    let fixed = estimated_fit_memory_bytes(0, experiments);
    let per_row = experiments
        .saturating_add(2)
        .saturating_mul(FIT_BYTES_PER_ENTRY);
    max_bytes.saturating_sub(fixed) / per_row.max(1)
}

/// How the experiment loader reads its inputs: the minimum number of measurements per file,
/// caps that bound the time and memory of loading (and of the fit that follows), and the
/// checks that depend on how the data will be used. [`Default`] gives generous caps; every cap
/// may be raised.
///
/// Every cap is checked while reading: a file is refused as soon as it exceeds its cap, never
/// after it was read whole. Inputs must be regular files (a FIFO, device, socket or directory
/// is refused before it is opened); the experiments file alone may also be standard input
/// (`/dev/stdin`, `/dev/fd/N`), read up to [`max_toml_bytes`](Self::max_toml_bytes).
#[derive(Debug, Clone, PartialEq)]
pub struct LoadOptions {
    /// Minimum number of measurement rows per CSV file (default
    /// `DEFAULT_MIN_POINTS` = 4).
    pub min_points: usize,
    /// Largest experiments (TOML) file \[bytes\] (default `DEFAULT_MAX_TOML_BYTES`).
    pub max_toml_bytes: u64,
    /// Largest measurement (CSV) file \[bytes\] (default `DEFAULT_MAX_CSV_BYTES`).
    pub max_csv_bytes: u64,
    /// Longest line of a CSV file \[bytes\] (default `DEFAULT_MAX_LINE_BYTES`).
    pub max_line_bytes: usize,
    /// Most measurement rows per CSV file (default [`DEFAULT_MAX_ROWS_PER_FILE`]).
    pub max_rows_per_file: usize,
    /// Most experiments per data set (default 1000).
    pub max_experiments: usize,
    /// Largest estimated memory of a fit of the whole data set \[bytes\]
    /// ([`estimated_fit_memory_bytes`] of all rows and experiments; default
    /// `DEFAULT_MAX_FIT_MEMORY_BYTES`). Checked as the rows are read.
    pub max_fit_memory_bytes: u64,
    /// Whether an experiment without a take-up condition in the TOML will take `d_fit(L)` of its
    /// smoothed data (the rheometer's convention, default `true`): then a spin line much longer
    /// than the measured range is refused or warned about (see
    /// [`take_up_warn_beyond`](Self::take_up_warn_beyond)). Set `false` when the caller gives
    /// the take-up diameter itself.
    pub take_up_from_data: bool,
    /// Warn when `d_fit(L)` is extrapolated beyond the last measured position by more than this
    /// fraction of the measured span (default 0.1).
    pub take_up_warn_beyond: f64,
    /// Refuse when `d_fit(L)` is extrapolated beyond the last measured position by more than
    /// this fraction of the measured span (default 1: farther than the data reach).
    pub take_up_error_beyond: f64,
    /// Whether every experiment must name a data file (default `false`: simulations need none;
    /// a fit does, see [`LoadedExperiments::require_data`](super::LoadedExperiments::require_data)).
    pub require_data: bool,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            min_points: super::DEFAULT_MIN_POINTS,
            max_toml_bytes: DEFAULT_MAX_TOML_BYTES,
            max_csv_bytes: DEFAULT_MAX_CSV_BYTES,
            max_line_bytes: DEFAULT_MAX_LINE_BYTES,
            max_rows_per_file: DEFAULT_MAX_ROWS_PER_FILE,
            max_experiments: DEFAULT_MAX_EXPERIMENTS,
            max_fit_memory_bytes: DEFAULT_MAX_FIT_MEMORY_BYTES,
            take_up_from_data: true,
            take_up_warn_beyond: 0.1,
            take_up_error_beyond: 1.0,
            require_data: false,
        }
    }
}

impl LoadOptions {
    /// The default options with at least `min_points` rows per CSV file.
    pub fn with_min_points(min_points: usize) -> Self {
        LoadOptions {
            min_points,
            ..Self::default()
        }
    }
}

/// A cap of [`LoadOptions`] that an input exceeded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Limit {
    /// [`LoadOptions::max_toml_bytes`].
    TomlBytes,
    /// [`LoadOptions::max_csv_bytes`].
    CsvBytes,
    /// [`LoadOptions::max_line_bytes`].
    LineBytes,
    /// [`LoadOptions::max_rows_per_file`].
    RowsPerFile,
    /// [`LoadOptions::max_experiments`].
    Experiments,
    /// [`LoadOptions::max_fit_memory_bytes`].
    FitMemory,
    /// `JsonSource::max_bytes`: a JSON report read back.
    JsonBytes,
}

impl Limit {
    /// The name of the [`LoadOptions`] field that sets this cap.
    pub fn option(self) -> &'static str {
        match self {
            Limit::TomlBytes => "max_toml_bytes",
            Limit::CsvBytes => "max_csv_bytes",
            Limit::LineBytes => "max_line_bytes",
            Limit::RowsPerFile => "max_rows_per_file",
            Limit::Experiments => "max_experiments",
            Limit::FitMemory => "max_fit_memory_bytes",
            Limit::JsonBytes => "max_json_bytes",
        }
    }
}

/// `bytes` for a reader: `16 MiB`, `3.2 GB`.
pub(super) fn show_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    if bytes >= 1 << 30 {
        format!("{:.1} GB", b / 1e9)
    } else if bytes >= 1 << 20 {
        format!("{:.0} MB", b / 1e6)
    } else if bytes >= 1 << 10 {
        format!("{:.0} kB", b / 1e3)
    } else {
        format!("{bytes} bytes")
    }
}

/// `n` with thousands separators: `1,000,000`.
pub(crate) fn show_count(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_and_bytes_read_well() {
        assert_eq!(show_count(0), "0");
        assert_eq!(show_count(999), "999");
        assert_eq!(show_count(1000), "1,000");
        assert_eq!(show_count(9_000_000), "9,000,000");
        assert_eq!(show_bytes(16 << 20), "17 MB");
        assert_eq!(show_bytes(5_300_000_000), "5.3 GB");
    }

    #[test]
    fn memory_estimate_grows_with_rows_and_experiments() {
        let small = estimated_fit_memory_bytes(243, 9);
        assert!(small < 100 << 20, "{small}");
        let rows = estimated_fit_memory_bytes(9_000_000, 9);
        assert!(rows > DEFAULT_MAX_FIT_MEMORY_BYTES, "{rows}");
        let r = max_fit_rows(9, DEFAULT_MAX_FIT_MEMORY_BYTES);
        assert!(estimated_fit_memory_bytes(r, 9) <= DEFAULT_MAX_FIT_MEMORY_BYTES);
        assert!(estimated_fit_memory_bytes(r + 1, 9) > DEFAULT_MAX_FIT_MEMORY_BYTES);
        assert_eq!(max_fit_rows(1_000_000, DEFAULT_MAX_FIT_MEMORY_BYTES), 0);
        assert_eq!(estimated_fit_memory_bytes(u64::MAX, u64::MAX), u64::MAX);
    }
}

//! The rows the measurement files of a data set may still hold ([`FitBudget`]): the per-file
//! cap of [`LoadOptions`] and what the estimated memory of a fit of all experiments leaves,
//! counted while the files are read, with the error of a file that exceeds it.

use std::path::Path;

use crate::data::input::error::{InputError, Location};
use crate::data::input::options::{
    max_fit_rows, show_bytes, show_count, Limit, LoadOptions, FIT_BYTES_PER_ENTRY,
    FIT_BYTES_PER_EXPERIMENT,
};

/// Rows the measurement files may still hold: the per-file cap and what the estimated memory
/// of a fit of all experiments leaves.
pub(in crate::data::input) struct FitBudget {
    experiments: u64,
    /// Rows read so far (all files).
    rows: u64,
    /// Most rows in all files within [`LoadOptions::max_fit_memory_bytes`].
    max_rows: u64,
    max_bytes: u64,
    per_file: usize,
}

impl FitBudget {
    pub(in crate::data::input) fn new(experiments: usize, options: &LoadOptions) -> Self {
        let experiments = experiments as u64;
        FitBudget {
            experiments,
            rows: 0,
            max_rows: max_fit_rows(experiments, options.max_fit_memory_bytes),
            max_bytes: options.max_fit_memory_bytes,
            per_file: options.max_rows_per_file,
        }
    }

    /// The unbounded budget of a file parsed alone.
    pub(in crate::data::input) fn unlimited(per_file: usize) -> Self {
        FitBudget {
            experiments: 0,
            rows: 0,
            max_rows: u64::MAX,
            max_bytes: u64::MAX,
            per_file,
        }
    }

    /// The most rows the next file may have, and the cap that sets it.
    pub(in crate::data::input) fn file_cap(&self) -> (usize, Limit) {
        let left = self.max_rows.saturating_sub(self.rows);
        if left < self.per_file as u64 {
            (left as usize, Limit::FitMemory)
        } else {
            (self.per_file, Limit::RowsPerFile)
        }
    }

    /// Counts `rows` more rows.
    pub(in crate::data::input) fn add(&mut self, rows: usize) {
        self.rows = self.rows.saturating_add(rows as u64);
    }

    /// The error of a file that has more rows than [`file_cap`](Self::file_cap) allowed, at
    /// `line` of `path`.
    pub(in crate::data::input) fn exceeded(
        &self,
        path: &Path,
        line: usize,
        limit: Limit,
    ) -> InputError {
        let thin = "thin the data (every 10th row carries the same information for the \
                    smoothing and the fit, at a tenth of the cost)";
        let message = match limit {
            Limit::FitMemory => format!(
                "the measurement files reach {} rows here, the most that a fit of {} \
                 experiments can hold within the limit of {} (estimated: a dense Jacobian of \
                 rows x (experiments + 2) entries of {FIT_BYTES_PER_ENTRY} bytes, and {} per \
                 experiment); {thin}, or raise the limit `{}`",
                show_count(self.max_rows.saturating_add(1)),
                self.experiments,
                show_bytes(self.max_bytes),
                show_bytes(FIT_BYTES_PER_EXPERIMENT),
                limit.option()
            ),
            _ => format!(
                "more than {} measurement rows in this file; {thin}, or raise the limit `{}`",
                show_count(self.per_file as u64),
                limit.option()
            ),
        };
        InputError::Limit {
            at: Location {
                path: path.to_path_buf(),
                line: Some(line),
            },
            limit,
            message,
        }
    }
}

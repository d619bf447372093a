//! The checks that need the experiments file and the measurements together: the rows the fit
//! can afford (its estimated memory), the inlet diameter against the first measured diameter,
//! and the spin-line length against the measured range when the take-up diameter is to be
//! extrapolated from the data.

use std::path::Path;

use super::error::{readable, short, sig, InputError, InputWarning, Location};
use super::experiment::Located;
use super::experiments::LoadedExperiments;
use super::options::{
    estimated_fit_memory_bytes, max_fit_rows, show_bytes, show_count, Limit, LoadOptions,
    FIT_BYTES_PER_ENTRY, FIT_BYTES_PER_EXPERIMENT,
};
use super::schema::LENGTH;
use crate::fiber::setup::Inlet;

/// Rows the measurement files may still hold: the per-file cap and what the estimated memory
/// of a fit of all experiments leaves.
pub(super) struct FitBudget {
    experiments: u64,
    /// Rows read so far (all files).
    rows: u64,
    /// Most rows in all files within [`LoadOptions::max_fit_memory_bytes`].
    max_rows: u64,
    max_bytes: u64,
    per_file: usize,
}

impl FitBudget {
    pub(super) fn new(experiments: usize, options: &LoadOptions) -> Self {
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
    pub(super) fn unlimited(per_file: usize) -> Self {
        FitBudget {
            experiments: 0,
            rows: 0,
            max_rows: u64::MAX,
            max_bytes: u64::MAX,
            per_file,
        }
    }

    /// The most rows the next file may have, and the cap that sets it.
    pub(super) fn file_cap(&self) -> (usize, Limit) {
        let left = self.max_rows.saturating_sub(self.rows);
        if left < self.per_file as u64 {
            (left as usize, Limit::FitMemory)
        } else {
            (self.per_file, Limit::RowsPerFile)
        }
    }

    /// Counts `rows` more rows.
    pub(super) fn add(&mut self, rows: usize) {
        self.rows = self.rows.saturating_add(rows as u64);
    }

    /// The error of a file that has more rows than [`file_cap`](Self::file_cap) allowed, at
    /// `line` of `path`.
    pub(super) fn exceeded(&self, path: &Path, line: usize, limit: Limit) -> InputError {
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

/// The error of an experiment's data file, at its `data` key.
pub(super) fn data_error(at: &Located, experiment: &str, cause: InputError) -> InputError {
    InputError::Data {
        at: at.data.clone().unwrap_or_else(|| at.name.clone()),
        experiment: short(experiment, 60),
        cause: Box::new(cause),
    }
}

/// Refuses a data set whose experiments alone exceed the fit's memory cap (before any CSV is
/// read), if any of them has data to fit.
pub(super) fn check_experiment_memory(
    loaded: &LoadedExperiments,
    options: &LoadOptions,
) -> Result<(), InputError> {
    let n = loaded.set.experiments.len() as u64;
    let need = estimated_fit_memory_bytes(0, n);
    if need <= options.max_fit_memory_bytes || loaded.details.iter().all(|d| d.data.is_none()) {
        return Ok(());
    }
    Err(InputError::Limit {
        at: Location {
            path: loaded.path.clone(),
            line: None,
        },
        limit: Limit::FitMemory,
        message: format!(
            "a fit of {} experiments would need an estimated {} of memory before any \
             measurement, above the limit of {}; split the data set, or raise the limit `{}`",
            show_count(n),
            show_bytes(need),
            show_bytes(options.max_fit_memory_bytes),
            Limit::FitMemory.option()
        ),
    })
}

/// The checks of experiment `i` with its measurements: the inlet diameter against the first
/// measured diameter, and the extrapolation of `d_fit(L)` (a warning or an error).
pub(super) fn cross_check(
    loaded: &LoadedExperiments,
    i: usize,
    at: &Located,
    options: &LoadOptions,
) -> Result<Option<InputWarning>, InputError> {
    let e = &loaded.set.experiments[i];
    let Some(m) = &loaded.set.measurements[i] else {
        return Ok(None);
    };
    let (Some(&s0), Some(&d0), Some(&s_last)) =
        (m.positions.first(), m.diameters.first(), m.positions.last())
    else {
        return Ok(None);
    };
    let data = loaded.details[i]
        .data
        .as_deref()
        .map(super::source::show)
        .unwrap_or_default();
    let d_in = match e.inlet {
        Inlet::Diameter(d) => d,
        Inlet::Velocity(u) => {
            let rho = loaded.set.material.density(e.inlet_temperature);
            2.0 * (e.mass_flow / (std::f64::consts::PI * rho * u)).sqrt()
        }
    };
    let near_die = s0 <= 0.005 * e.spinline_length;
    let ratio = d_in / d0;
    if (near_die && ratio > 2.0) || ratio < 0.5 {
        let derived = match e.inlet {
            Inlet::Diameter(_) => String::new(),
            Inlet::Velocity(_) => " (derived from the mass flow and the inlet velocity)".into(),
        };
        let times = if ratio > 1.0 {
            format!("{} times", sig(ratio))
        } else {
            format!("1/{} of", sig(1.0 / ratio))
        };
        return Err(InputError::Inconsistent {
            at: at.inlet.0.clone(),
            table: at.table.clone(),
            message: format!(
                "{}: the inlet diameter {} mm{derived} is {times} the first measured diameter \
                 {} mm (at s = {} m in {data}); the inlet diameter (after die swell) should \
                 match the diameter measured near the die within a factor of 2, and no \
                 downstream diameter exceeds it: check the units of the inlet key and of the \
                 CSV's diameter column",
                at.inlet.1,
                sig(d_in * 1e3),
                sig(d0 * 1e3),
                readable(s0)
            ),
        });
    }
    if !options.take_up_from_data || e.take_up.is_some() {
        return Ok(None);
    }
    let span = s_last - s0;
    let beyond = e.spinline_length - s_last;
    if span <= 0.0 || beyond <= options.take_up_warn_beyond * span {
        return Ok(None);
    }
    let fraction = beyond / span;
    let l = e.spinline_length;
    let unit_hint = LENGTH
        .iter()
        .skip(1)
        .filter(|u| {
            let l_alt = u.to_si(l);
            l_alt >= s_last && l_alt - s_last <= options.take_up_warn_beyond * span
        })
        .map(|u| {
            format!(
                " (is {} in {}? then write `spinline_length_{}`)",
                readable(l),
                u.name,
                u.suffix
            )
        })
        .next()
        .unwrap_or_default();
    let text = format!(
        "{}: the measurements of experiment \"{}\" cover s = {} to {} m ({data}), and without a \
         take-up condition the take-up diameter is d_fit(L), the smoothed data extrapolated \
         {} m beyond the last measurement to L = {} m ({} times the measured span)",
        at.spinline.1,
        short(&e.name, 60),
        readable(s0),
        readable(s_last),
        sig(beyond),
        readable(l),
        sig(fraction)
    );
    if fraction > options.take_up_error_beyond {
        return Err(InputError::Inconsistent {
            at: at.spinline.0.clone(),
            table: at.table.clone(),
            message: format!(
                "{text}: too far to trust{unit_hint}; check `spinline_length_m`, give the \
                 take-up diameter (`take_up_diameter_m`) or velocity, or measure closer to the \
                 take-up"
            ),
        });
    }
    Ok(Some(InputWarning {
        at: at.spinline.0.clone(),
        message: format!(
            "{}: {text}; the take-up diameter is an extrapolation (give `take_up_diameter_m` if \
             it was measured){unit_hint}",
            at.table
        ),
    }))
}

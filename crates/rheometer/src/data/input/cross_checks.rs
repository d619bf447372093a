//! The checks that need the experiments file and the measurements together: the memory a fit
//! of the experiments needs before any row (the rows themselves are counted while the files are
//! read, see `row_budget`), the inlet diameter against the first measured diameter, and the
//! spin-line length against the measured range when the take-up diameter is to be extrapolated
//! from the data.

use std::path::Path;

use super::error::{readable, short, sig, InputError, InputWarning, Location};
use super::loaded::LoadedExperiments;
use super::options::{estimated_fit_memory_bytes, show_bytes, show_count, Limit, LoadOptions};
use super::toml_file::experiment::Located;
use super::toml_file::schema::LENGTH;
use crate::model::setup::{Experiment, Inlet};

/// The error of an experiment's data file, at its `data` key.
pub(super) fn data_error(at: &Located, experiment: &str, cause: InputError) -> InputError {
    InputError::Data {
        at: at.data.clone().unwrap_or_else(|| at.name.clone()),
        experiment: short(experiment, 60),
        cause: Box::new(cause),
    }
}

/// A missing data file of an experiments file reached through a symbolic link (the file itself
/// or a folder on its path) gets a hint: relative `data` paths are resolved from the folder the
/// experiments file was given in, not from the link's target, and whether the file exists
/// beside the target.
pub(super) fn with_link_hint(experiments: &Path, data: &Path, cause: InputError) -> InputError {
    let InputError::Io { path, source, hint } = cause else {
        return cause;
    };
    if source.kind() != std::io::ErrorKind::NotFound || !hint.is_empty() {
        return InputError::Io { path, source, hint };
    }
    let given = experiments.parent().unwrap_or(Path::new(""));
    let given = if given.as_os_str().is_empty() {
        Path::new(".")
    } else {
        given
    };
    let (Ok(target), Ok(given_real)) = (
        std::fs::canonicalize(experiments),
        std::fs::canonicalize(given),
    ) else {
        return InputError::Io { path, source, hint };
    };
    let Some(target_dir) = target.parent() else {
        return InputError::Io { path, source, hint };
    };
    if target_dir == given_real {
        return InputError::Io { path, source, hint };
    }
    let beside_target = data
        .strip_prefix(experiments.parent().unwrap_or(Path::new("")))
        .ok()
        .filter(|rel| rel.is_relative())
        .map(|rel| target_dir.join(rel))
        .filter(|p| p.is_file());
    let hint = format!(
        "; the experiments file {} is a symbolic link (or lies in a linked folder) to {}, and \
         relative `data` paths are resolved from the folder it was given in ({}), not from the \
         link's target{}",
        experiments.display(),
        target.display(),
        given.display(),
        match beside_target {
            Some(found) => format!(
                "; {} exists: give the experiments file by its own path, or `data` as an \
                 absolute path",
                found.display()
            ),
            None => String::new(),
        }
    );
    InputError::Io { path, source, hint }
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
    check_inlet_diameter(loaded, e, at, (s0, d0), &data)?;
    check_take_up_extrapolation(e, at, options, (s0, s_last), &data)
}

/// The inlet diameter of `e` against the first measured diameter `d0` (at `s0`, in the data
/// file `data`): an error where the inlet is below half of it, or above twice it with the
/// measurement taken near the die.
fn check_inlet_diameter(
    loaded: &LoadedExperiments,
    e: &Experiment,
    at: &Located,
    (s0, d0): (f64, f64),
    data: &str,
) -> Result<(), InputError> {
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
    Ok(())
}

/// Without a take-up condition (and with `take_up_from_data`), the extrapolation of the
/// smoothed data of `e` (measured from `s0` to `s_last`, in `data`) to the spin-line length: a
/// warning beyond `take_up_warn_beyond` of the measured span, an error beyond
/// `take_up_error_beyond`.
fn check_take_up_extrapolation(
    e: &Experiment,
    at: &Located,
    options: &LoadOptions,
    (s0, s_last): (f64, f64),
    data: &str,
) -> Result<Option<InputWarning>, InputError> {
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

/// One warning per data file that several experiments read (the same file after resolving
/// links and `.`/`..`), at the `data` key of the second of them, naming the first two and how
/// many more: two experiments with one set of measurements is most likely a copied table whose
/// `data` was not changed.
pub(super) fn shared_data_files(
    loaded: &LoadedExperiments,
    located: &[Located],
) -> Vec<InputWarning> {
    let files: Vec<Option<std::path::PathBuf>> = loaded
        .details
        .iter()
        .map(|d| {
            d.data
                .as_ref()
                .map(|p| std::fs::canonicalize(p).unwrap_or_else(|_| p.clone()))
        })
        .collect();
    // the experiments of each file, in the order of the experiments file
    let mut readers: Vec<(&std::path::PathBuf, Vec<usize>)> = Vec::new();
    for (i, file) in files.iter().enumerate() {
        let Some(file) = file else { continue };
        match readers.iter_mut().find(|(f, _)| *f == file) {
            Some((_, r)) => r.push(i),
            None => readers.push((file, vec![i])),
        }
    }
    let name = |i: usize| short(&loaded.set.experiments[i].name, 60);
    readers
        .into_iter()
        .filter(|(_, r)| r.len() > 1)
        .map(|(file, r)| InputWarning {
            at: located[r[1]]
                .data
                .clone()
                .unwrap_or_else(|| located[r[1]].name.clone()),
            message: format!(
                "experiments {} and {}{} read the same data file {}: each experiment needs its \
                 own measurements (a copied table whose `data` was not changed?)",
                name(r[0]),
                name(r[1]),
                match r.len() - 2 {
                    0 => String::new(),
                    more => format!(" (and {more} more)"),
                },
                file.display()
            ),
        })
        .collect()
}

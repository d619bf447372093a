//! The take-up condition a model uses for an experiment: the data set's own (diameter or
//! speed), else the caller's rule for a missing one — a given diameter, `d_fit(L)` of the
//! smoothed measurements (the rheometer's convention), or an error. One place for the rule
//! that the rheometer, the comparison and the `rheometer simulate` program follow.

use crate::data::smoothing::{smooth, SmoothFit, SmoothingError};
use crate::model::setup::{Experiment, Measurements, TakeUp};
use std::fmt;

/// What to do for an experiment whose data set gives no take-up condition.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MissingTakeUp {
    /// An error naming the experiment.
    Error,
    /// `d_fit(L)` of the smoothed measurements (the rheometer's convention).
    FromData,
    /// This take-up diameter (m).
    Diameter(f64),
}

/// Why no take-up condition could be found (callers say it in their own words: a TOML key, a
/// command-line flag).
#[derive(Debug, Clone)]
pub(crate) enum TakeUpError {
    /// The experiment has none and the rule is [`MissingTakeUp::Error`].
    Missing,
    /// [`MissingTakeUp::FromData`] for an experiment without measurements.
    NoMeasurements,
    /// [`MissingTakeUp::FromData`]: smoothing the measurements failed.
    Smoothing(SmoothingError),
}

impl fmt::Display for TakeUpError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TakeUpError::Missing => write!(f, "no take-up condition"),
            TakeUpError::NoMeasurements => write!(f, "no measurements to take the take-up from"),
            TakeUpError::Smoothing(e) => write!(f, "smoothing the measurements failed: {e}"),
        }
    }
}

impl std::error::Error for TakeUpError {}

/// The resolved take-up condition of one experiment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ResolvedTakeUp {
    /// The condition the model uses.
    pub take_up: TakeUp,
    /// `d_fit(L)` \[m\] if it was taken from the smoothed measurements.
    pub from_data: Option<f64>,
}

/// The take-up condition for `experiment`: its own if the data set gives one, else per
/// `missing`. For [`MissingTakeUp::FromData`] the measurements are smoothed, unless `fit`
/// (their smoothing, already computed) is given. `d_fit(L)` is not checked for sign: callers
/// that need a positive diameter check [`ResolvedTakeUp::from_data`].
pub(crate) fn resolve_take_up(
    experiment: &Experiment,
    measurements: Option<&Measurements>,
    missing: MissingTakeUp,
    fit: Option<&SmoothFit>,
) -> Result<ResolvedTakeUp, TakeUpError> {
    if let Some(t) = experiment.take_up {
        return Ok(ResolvedTakeUp {
            take_up: t,
            from_data: None,
        });
    }
    match missing {
        MissingTakeUp::Error => Err(TakeUpError::Missing),
        MissingTakeUp::Diameter(d) => Ok(ResolvedTakeUp {
            take_up: TakeUp::Diameter(d),
            from_data: None,
        }),
        MissingTakeUp::FromData => {
            let d = match fit {
                Some(f) => f.diameter(experiment.spinline_length),
                None => {
                    let m = measurements.ok_or(TakeUpError::NoMeasurements)?;
                    smooth(&m.positions, &m.diameters)
                        .map_err(TakeUpError::Smoothing)?
                        .diameter(experiment.spinline_length)
                }
            };
            Ok(ResolvedTakeUp {
                take_up: TakeUp::Diameter(d),
                from_data: Some(d),
            })
        }
    }
}

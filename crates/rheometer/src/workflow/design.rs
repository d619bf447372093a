//! The `design` workflow: fit the model to the data (no error budget, no profile intervals:
//! the design needs the estimate, its solutions and its noise level), then predict, for every
//! candidate experiment, the uncertainty after adding it ([`design_for_estimation`](crate::design::design_for_estimation)).

use super::fit::{fit, FitRequest, FitRun};
use crate::data::input::LoadedExperiments;
use crate::design::discrimination::design_for_discrimination_with;
use crate::design::estimation::design_for_estimation_with;
use crate::design::{
    Design, DesignEstimate, DesignRequest, Discrimination, DiscriminationRequest, Rival,
};
use crate::fit::uncertainty::profile::{newtonian_test_of, ProfileMode};
use crate::fit::RheometerError;
use crate::model::effects::{Effect, EffectSetting};

/// The outcome of the `design` workflow.
#[derive(Debug)]
pub struct DesignRun {
    /// The fit the design starts from.
    pub fit: FitRun,
    /// The ranked candidates.
    pub design: Design,
}

/// Fits `fit_request`'s model to `data` (error budget and profile intervals off) and designs
/// the next experiment by `request`.
pub fn design(
    data: &LoadedExperiments,
    fit_request: &FitRequest,
    request: &DesignRequest,
) -> Result<DesignRun, RheometerError> {
    design_with_estimate(data, fit_request, request, &|_| {})
}

/// [`design`], telling `estimate` how long the candidates will take once their first rows
/// are done (a grid of more than two rows per thread; see [`DesignEstimate`]).
pub fn design_with_estimate(
    data: &LoadedExperiments,
    fit_request: &FitRequest,
    request: &DesignRequest,
    estimate: &(dyn Fn(&DesignEstimate) + Sync),
) -> Result<DesignRun, RheometerError> {
    request.grid.validate().map_err(RheometerError::Data)?;
    let mut fr = fit_request.clone();
    fr.error_budget = false;
    fr.profile = ProfileMode::Never;
    fr.baseline = false;
    fr.newtonian_reference = false;
    let run = fit(data, &fr)?;
    let mut design =
        design_for_estimation_with(&run.rheometer, &run.identification, request, estimate)?;
    if newtonian_on_data(&run, &fr) {
        design.notes.insert(
            0,
            "the data show no strain thinning (the Newtonian law fits as well: likelihood-ratio \
             test as in `fit`): n and kappa below are the fit's point in the Newtonian corner, \
             not estimates, and the predicted uncertainties are linearised there; read the \
             ranking as the direction that stretches the melt faster (where thinning would \
             show), not as a predicted precision"
                .into(),
        );
    }
    Ok(DesignRun { fit: run, design })
}

/// Whether the fit's law is Newtonian within the data's strain rates (the fit's
/// likelihood-ratio test, which the design's fit skips with the profile intervals).
fn newtonian_on_data(run: &FitRun, request: &FitRequest) -> bool {
    matches!(
        newtonian_test_of(&run.rheometer, &run.identification, &request.identify),
        Ok(Some(t)) if t.law_not_estimated.is_some()
    )
}

/// The outcome of the discrimination workflow.
#[derive(Debug)]
pub struct DiscriminationRun {
    /// The rivals' fits: the request's model plus each effect, in the order given.
    pub fits: Vec<FitRun>,
    /// The candidates ranked by how well they tell the rivals apart.
    pub design: Discrimination,
}

/// Fits the rivals — `fit_request`'s model plus each of `effects` (strength fitted) — to
/// `data` (error budget and profile intervals off) and ranks the candidates of `request` by
/// how well they tell them apart ([`design_for_discrimination`](crate::design::design_for_discrimination)).
///
/// Errors: fewer than two effects, an effect given twice or already in the model, a fit that
/// fails, and the design's errors.
pub fn discriminate(
    data: &LoadedExperiments,
    fit_request: &FitRequest,
    effects: &[Effect],
    request: &DiscriminationRequest,
) -> Result<DiscriminationRun, RheometerError> {
    discriminate_with_estimate(data, fit_request, effects, request, &|_| {})
}

/// [`discriminate`], telling `estimate` how long the candidates will take once their first
/// rows are done (see [`DesignEstimate`]).
pub fn discriminate_with_estimate(
    data: &LoadedExperiments,
    fit_request: &FitRequest,
    effects: &[Effect],
    request: &DiscriminationRequest,
    estimate: &(dyn Fn(&DesignEstimate) + Sync),
) -> Result<DiscriminationRun, RheometerError> {
    request.grid.validate().map_err(RheometerError::Data)?;
    if effects.len() < 2 {
        return Err(RheometerError::Data(
            "give at least two rival effects to tell apart".into(),
        ));
    }
    // every rival is checked before the first fit
    let mut requests = Vec::with_capacity(effects.len());
    for e in effects {
        if fit_request.model.contains(e.id()) {
            return Err(RheometerError::Data(format!(
                "{} is already in the model: a rival adds an effect the model lacks",
                e.name()
            )));
        }
        let mut fr = fit_request.clone();
        fr.error_budget = false;
        fr.profile = ProfileMode::Never;
        fr.baseline = false;
        fr.newtonian_reference = false;
        fr.model = fr.model.with(EffectSetting::fitted(e.clone()));
        fr.model.validate().map_err(RheometerError::Data)?;
        requests.push(fr);
    }
    let fits = requests
        .iter()
        .map(|fr| fit(data, fr))
        .collect::<Result<Vec<_>, _>>()?;
    let rivals: Vec<Rival> = effects
        .iter()
        .zip(&fits)
        .map(|(e, f)| Rival {
            name: e.name(),
            rheometer: &f.rheometer,
            fit: &f.identification,
        })
        .collect();
    let design = design_for_discrimination_with(&rivals, request, estimate)?;
    Ok(DiscriminationRun { fits, design })
}

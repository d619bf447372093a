//! The `fit` workflow: start point, identification, error budget, profile-likelihood
//! intervals and the likelihood-ratio test against the Newtonian law, the flow curve, and what
//! the figures need (the Newtonian reference and, for a model with added effects, the same fit
//! without them).

use crate::data::input::LoadedExperiments;
use crate::diagnostics::refits::consistency;
use crate::fit::uncertainty::profile::{intervals, ProfileMode};
use crate::fit::{
    error_budget, FitSummary, FlowCurve, FlowCurveOptions, Identification, IdentifyOptions,
    Rheometer, RheometerError, StartPoint,
};
use crate::model::catalog::STRAIN_THINNING;
use crate::model::effects::{LawChoice, ModelSpec, STRAIN_THINNING_REFERENCE_KAPPA};
use crate::report::figures::ResidualView;
use crate::report::fit_html::{fit_report_page, FitReportInput, ReportExperiment};
use crate::report::html_page::HtmlPage;
use diffbvp::solution::Solution;

/// What to fit.
#[derive(Debug, Clone)]
pub struct FitRequest {
    /// The model: law and effects (fitted or fixed); no candidates.
    pub model: ModelSpec,
    /// Estimator, loss, bounds, BVP settings.
    pub identify: IdentifyOptions,
    /// Start `(n, κ)`; `None`: the paper's start heuristic for a fitted law, `(1, 13.5)` for a
    /// Newtonian one.
    pub start: Option<[f64; 2]>,
    /// Start values of the effects' fitted strengths (by effect name) and shapes (by
    /// model-parameter name), e.g. a previous fit's ([`FitSummary::continued_effects`]; `fit
    /// --from`). The fit from them (at `start`) is kept where it ends lower than the nested
    /// fit, which starts the effects at neutral strength.
    pub start_strengths: Vec<(String, f64)>,
    /// Also fit the model without its added effects (the before/after residuals of a model
    /// with effects; nothing for the paper's model).
    pub baseline: bool,
    /// Also solve the Newtonian model at the fitted `κ` (paper Fig. 3's reference curves).
    pub newtonian_reference: bool,
    /// Compute the error budget (default `true`; a bootstrap replicate or a screening that
    /// needs only the estimates saves about half the fit's time without it).
    pub error_budget: bool,
    /// Profile-likelihood intervals and the likelihood-ratio test against the Newtonian law
    /// (default `ProfileMode::Auto`).
    pub profile: ProfileMode,
    /// The flow curve's temperature, resolution and isotherms.
    pub flow_curve: FlowCurveOptions,
}

impl FitRequest {
    /// The paper's model (Carreau-type law, no effects) with `identify`'s settings.
    pub fn new(identify: IdentifyOptions) -> Self {
        FitRequest {
            model: ModelSpec::default(),
            identify,
            start: None,
            start_strengths: Vec::new(),
            baseline: false,
            newtonian_reference: false,
            error_budget: true,
            profile: ProfileMode::Auto,
            flow_curve: FlowCurveOptions::default(),
        }
    }

    /// Whether `n` (or strain thinning) is fitted: the start heuristic applies.
    pub fn law_fitted(&self) -> bool {
        self.model.law == LawChoice::Carreau
            || self
                .model
                .effects
                .iter()
                .any(|w| w.effect.id() == STRAIN_THINNING.id() && w.value.is_none())
    }
}

/// The outcome of the `fit` workflow.
#[derive(Debug)]
pub struct FitRun {
    /// The prepared data and models.
    pub rheometer: Rheometer,
    /// The identification; its summary carries the error budget when it could be computed.
    pub identification: Identification,
    /// The start heuristic's trace, when it chose the start.
    pub start_heuristic: Option<StartPoint>,
    /// Why the error budget is missing, if it is.
    pub budget_error: Option<String>,
    /// Why the profile intervals or the likelihood-ratio test are missing, if they are.
    pub profile_error: Option<String>,
    /// Why the flow curve is missing, if it is.
    pub flow_curve_error: Option<String>,
    /// The same fit without the model's added effects ([`FitRequest::baseline`]).
    pub baseline: Option<Identification>,
    /// The Newtonian model at the fitted `κ` ([`FitRequest::newtonian_reference`]).
    pub newtonian: Option<Vec<Solution>>,
}

impl FitRun {
    /// The outcome as reported.
    pub fn summary(&self) -> &FitSummary {
        &self.identification.summary
    }

    /// The HTML report of this fit ([`fit_report_page`]): its summary and flow curve, the
    /// experiments of `data` (the data set fitted) with the file `data.path`, and the relative
    /// residuals of the fitted solutions (evaluated, not refitted).
    pub fn html_report(&self, data: &LoadedExperiments) -> HtmlPage {
        let rh = &self.rheometer;
        let residuals: Vec<Vec<f64>> = (self.identification.solutions.iter().enumerate())
            .map(|(k, sol)| rh.relative_residuals(k, sol))
            .collect();
        let views: Vec<ResidualView<'_>> = (rh.experiments.iter().zip(&rh.measurements))
            .zip(&residuals)
            .map(|((e, m), r)| ResidualView {
                name: &e.name,
                positions: &m.positions,
                residuals: r,
            })
            .collect();
        let experiments = ReportExperiment::of(data);
        fit_report_page(&FitReportInput {
            summary: self.summary(),
            experiments_file: &data.path,
            experiments: &experiments,
            residuals: &views,
        })
    }
}

/// Fits `request`'s model to `data`: the start (given, heuristic or Newtonian), the
/// identification, its error budget (declared or default uncertainties of what the data cannot
/// identify; none unless [`FitRequest::error_budget`]), the profile-likelihood intervals and
/// the likelihood-ratio test against the Newtonian law, the flow curve (none of these three
/// fails the fit: what could not be computed is named in the run) and the optional reference
/// computations.
pub fn fit(data: &LoadedExperiments, request: &FitRequest) -> Result<FitRun, RheometerError> {
    request.model.validate().map_err(RheometerError::Data)?;
    let opts = &request.identify;
    let rh = Rheometer::with_spec(&data.set, request.model.clone())?;
    let (start, start_heuristic) = match request.start {
        Some(s) => (s, None),
        None if !request.law_fitted() => ([1.0, STRAIN_THINNING_REFERENCE_KAPPA], None),
        None => {
            let sp = rh.start_heuristic(opts)?;
            (sp.start, Some(sp))
        }
    };
    // a model with fitted effects never ends worse than the model without them
    // (and from the effects' given strengths, where that ends lower)
    let nested = rh.identify_nested_from(start, &request.start_strengths, opts)?;
    let mut id = nested.fit;
    // an effect whose strength must differ between the experiments is a stand-in
    let fitted: Vec<String> = id
        .summary
        .effects
        .iter()
        .filter(|e| e.strength.fitted)
        .map(|e| e.effect.clone())
        .collect();
    for c in consistency::check(&id, &fitted, &data.set) {
        if !c.consistent() {
            id.summary.warnings.push(consistency::warning(&c));
        }
    }
    let budget = request
        .error_budget
        .then(|| error_budget(&rh, &id, &data.uncertainty, opts));
    let budget_error = match budget {
        Some(Ok(budget)) => {
            id.summary = id.summary.clone().with_error_budget(budget);
            None
        }
        Some(Err(e)) => Some(e.to_string()),
        None => None,
    };
    let profile_error = match intervals(&rh, &id, opts, request.profile) {
        Ok((found, test)) => {
            id.summary.intervals = found;
            id.summary.newtonian_test = test;
            id.summary.drop_law_estimate_warnings();
            None
        }
        Err(e) => Some(e.to_string()),
    };
    let curve = rh
        .models
        .first()
        .ok_or_else(|| "no experiment".to_string())
        .and_then(|m| FlowCurve::of(m, &id.local_params, &id.summary, &request.flow_curve));
    let flow_curve_error = match curve {
        Ok(c) => {
            id.summary.flow_curve = Some(c);
            None
        }
        Err(e) => Some(e),
    };
    // the model without its effects: the nested fit's plain model where every effect is
    // fitted (held at neutral strength it is that model), else fitted here
    let all_fitted = request.model.effects.iter().all(|e| e.value.is_none());
    let baseline = if !request.baseline || request.model.effects.is_empty() {
        None
    } else if let (true, Some(plain)) = (all_fitted, nested.plain) {
        Some(plain)
    } else {
        let rh0 = Rheometer::with_spec(&data.set, ModelSpec::new(request.model.law))?;
        let s0 = match request.model.law {
            LawChoice::Carreau => id.law(),
            LawChoice::Newtonian => [1.0, STRAIN_THINNING_REFERENCE_KAPPA],
        };
        Some(rh0.identify(s0, opts)?)
    };
    let newtonian = if request.newtonian_reference {
        Some(rh.newtonian_solutions(id.law()[1], opts)?)
    } else {
        None
    };
    Ok(FitRun {
        rheometer: rh,
        identification: id,
        start_heuristic,
        budget_error,
        profile_error,
        flow_curve_error,
        baseline,
        newtonian,
    })
}

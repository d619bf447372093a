//! Stage 1: the setting of a diagnosis and the user's fit.

use super::DiagnoseOptions;
use crate::fiber::effects::{Effect, LawChoice, ModelSpec, STRAIN_THINNING_REFERENCE_KAPPA};
use crate::fiber::rheometer::{
    Estimator, FitStart, Identification, IdentifyOptions, Layout, Rheometer, RheometerError,
};
use crate::fiber::setup::ExperimentSet;

/// What every stage reads: the user's model with the candidates at neutral strength, the fit
/// settings, the start law and the candidates.
pub(crate) struct Context<'a> {
    /// The diagnosis' options.
    pub options: &'a DiagnoseOptions,
    /// Fit settings (principled estimator, factorisation kept at the solution).
    pub opts: IdentifyOptions,
    /// The user's model with the candidates carried at neutral strength.
    pub spec: ModelSpec,
    /// The data and models.
    pub rh: Rheometer,
    /// Relative uncertainty the residuals are divided by (declared, else 1) \[-\].
    pub sigma: f64,
    /// Start `(n, κ)` of the user's fit.
    pub law0: [f64; 2],
    /// The candidates.
    pub cands: Vec<Effect>,
    /// The layout of the user's fit (names, bounds of the shared parameters).
    pub layout: Layout,
    /// Spin-line length \[m\] that bounds the shapes (the shortest line).
    pub length: f64,
}

impl<'a> Context<'a> {
    /// The setting of a diagnosis of `base_spec` on `set`.
    pub fn new(
        set: &ExperimentSet,
        base_spec: &ModelSpec,
        options: &'a DiagnoseOptions,
    ) -> Result<Self, RheometerError> {
        let mut opts = options.identify.clone();
        opts.estimator = Estimator::Principled;
        opts.simulate.factor_at_solution = true;
        let spec = base_spec.clone().with_candidates(&options.candidates);
        let rh = Rheometer::with_spec(set, spec.clone())?;
        let sigma = opts
            .relative_uncertainty
            .or(rh.relative_uncertainty)
            .unwrap_or(1.0);
        let law0 = match spec.law {
            LawChoice::Carreau => match options.start {
                Some(s) => s,
                None => rh.start_heuristic(&opts)?.start,
            },
            LawChoice::Newtonian => [1.0, STRAIN_THINNING_REFERENCE_KAPPA],
        };
        let layout = Layout::new(&rh.models[0], &rh.spec, &FitStart::at(law0), &opts)?;
        let length = rh
            .experiments
            .iter()
            .map(|e| e.spinline_length)
            .fold(f64::INFINITY, f64::min);
        Ok(Context {
            options,
            opts,
            cands: spec.candidates.clone(),
            spec,
            rh,
            sigma,
            law0,
            layout,
            length,
        })
    }

    /// Stage 1: the user's model fitted with the principled estimator (the candidates at
    /// neutral strength reproduce it exactly).
    pub fn fit_base(&self) -> Result<Identification, RheometerError> {
        self.rh.identify(self.law0, &self.opts)
    }

    /// The column of the shared parameter `name` in the user's fit.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.layout.names.iter().position(|s| s == name)
    }
}

//! Stage 1: the setting of a diagnosis and the user's fit.

use super::DiagnoseOptions;
use crate::fiber::effects::{Effect, LawChoice, ModelSpec, STRAIN_THINNING_REFERENCE_KAPPA};
use crate::fiber::rheometer::identification::WarmFit;
use crate::fiber::rheometer::summary_checks::check_misfit;
use crate::fiber::rheometer::WarningCode;
use crate::fiber::rheometer::{
    Estimator, FitStart, Identification, IdentifyOptions, Layout, Rheometer, RheometerError,
};
use crate::fiber::setup::ExperimentSet;
use std::sync::Arc;

/// Weight factor of a gross outlier in the diagnosis' fits (its residual counts 1/1000).
pub const OUTLIER_FACTOR: f64 = 1000.0;

/// What every stage reads: the user's model with the candidates at neutral strength, the fit
/// settings, the start law and the candidates.
pub(crate) struct Context<'a> {
    /// The diagnosis' options.
    pub options: &'a DiagnoseOptions,
    /// Fit settings (principled estimator, factorisation kept at the solution, no
    /// discretisation check).
    pub opts: IdentifyOptions,
    /// The discretisation check of the user's fit ([`IdentifyOptions::max_discretisation_shift`]).
    pub check: Option<f64>,
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
        // the diagnosis' many fits run at the matched tolerance without each checking it; the
        // user's fit is checked (fit_base)
        let check = opts.max_discretisation_shift.take();
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
            check,
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
    /// neutral strength reproduce it exactly), started from `warm` (a previous step's refit
    /// with the effects of this model) where given.
    pub fn fit_base(
        &self,
        warm: Option<&Identification>,
    ) -> Result<Identification, RheometerError> {
        let checked = IdentifyOptions {
            max_discretisation_shift: self.check,
            ..self.opts.clone()
        };
        let Some(w) = warm else {
            // the user's effects never leave the fit worse than the model without them
            return Ok(self.rh.identify_nested(self.law0, &checked)?.fit);
        };
        let start = FitStart {
            strengths: w.fitted_strengths(),
            warm: Some(w.solutions.clone()),
            ..FitStart::at(w.law())
        };
        let fit = WarmFit {
            take_up: w.take_up_factors().to_vec(),
            stop_tolerance: None,
        };
        self.rh.identify_warm(&start, &checked, &fit)
    }

    /// Stage 1 (cont.): the user's fit again with each point weighted by its local noise level
    /// where the noise varies along the line (the take-up region noisier), and with the gross
    /// outliers of its noise model left out (weighted by [`OUTLIER_FACTOR`]); every later fit
    /// of the diagnosis uses the same weights, so that neither the noisier points nor the
    /// outliers dominate the cost and a flexible candidate cannot earn its place by fitting
    /// them. Unchanged when the noise is declared, or even and without outliers.
    pub fn weighted_base(
        &mut self,
        base: Identification,
    ) -> Result<Identification, RheometerError> {
        let noise = &base.summary.noise;
        let Some(m) = noise.model.as_ref() else {
            return Ok(base);
        };
        let varies = m.varies_along_line && !noise.declared() && noise.level > 0.0;
        if !varies && m.outliers.is_empty() {
            return Ok(base);
        }
        let factors: Vec<Vec<f64>> = self
            .rh
            .measurements
            .iter()
            .enumerate()
            .map(|(k, meas)| {
                meas.positions
                    .iter()
                    .enumerate()
                    .map(|(i, &s)| {
                        let f = if varies {
                            m.local_sigma_at(k, s) / noise.level
                        } else {
                            1.0
                        };
                        if m.is_outlier(k, i) {
                            f * OUTLIER_FACTOR
                        } else {
                            f
                        }
                    })
                    .collect()
            })
            .collect();
        self.opts.noise_factors = Some(Arc::new(factors));
        let start = FitStart {
            warm: Some(base.solutions.clone()),
            strengths: base.fitted_strengths(),
            ..FitStart::at(base.law())
        };
        let warm = WarmFit {
            take_up: base.take_up_factors().to_vec(),
            stop_tolerance: None,
        };
        let mut weighted = self.rh.identify_warm(&start, &self.opts, &warm)?;
        // the one noise level of these data and this model is the plain fit's, and the misfit
        // warning reads it (not the weighted fit's own estimate)
        weighted.summary.noise = base.summary.noise.clone();
        let mut misfit = Vec::new();
        check_misfit(&weighted.summary, &mut misfit);
        let warnings = &mut weighted.summary.warnings;
        let at = warnings.iter().position(|w| w.code == WarningCode::Misfit);
        warnings.retain(|w| w.code != WarningCode::Misfit);
        for (k, w) in misfit.into_iter().enumerate() {
            warnings.insert(at.unwrap_or(warnings.len()).min(warnings.len()) + k, w);
        }
        Ok(weighted)
    }

    /// The column of the shared parameter `name` in the user's fit.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.layout.names.iter().position(|s| s == name)
    }
}

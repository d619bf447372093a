//! Stage 1: the setting of a diagnosis and the user's fit.

use super::DiagnoseOptions;
use crate::data::noise_summary::NoiseSummary;
use crate::diagnostics::diagnosis::RobustWeights;
use crate::fit::identify::identification::WarmFit;
use crate::fit::summary::checks::check_misfit;
use crate::fit::WarningCode;
use crate::fit::{
    Estimator, FitStart, Identification, IdentifyOptions, Layout, Rheometer, RheometerError,
};
use crate::model::effects::{Effect, LawChoice, ModelSpec, STRAIN_THINNING_REFERENCE_KAPPA};
use crate::model::setup::ExperimentSet;
use diffbvp::least_squares::Loss;
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
    /// The user's robust loss (`None`: least squares): it weights the points
    /// ([`weighted_base`](Self::weighted_base)), and the fits after the user's are least
    /// squares with its weights.
    pub robust: Option<Loss>,
    /// How the robust loss weighted the points at this step's fit.
    pub weights: Option<RobustWeights>,
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
        let robust = (!opts.loss.is_linear()).then_some(opts.loss);
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
            robust,
            weights: None,
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
            // the user's effects never leave the fit worse than the model without them (and
            // start from their given values too, where that ends lower)
            let strengths = &self.options.start_strengths;
            return Ok(self
                .rh
                .identify_nested_from(self.law0, strengths, &checked)?
                .fit);
        };
        // a further step: `w` was fitted with the previous step's weights, which carry a robust
        // loss's down-weighting, so this fit is least squares with them (the loss again would
        // down-weight the same points twice)
        let checked = IdentifyOptions {
            loss: Loss::Linear,
            ..checked
        };
        let start = FitStart {
            strengths: w.fitted_strengths(),
            warm: Some(w.solutions.clone()),
            ..FitStart::at(w.law())
        };
        let fit = WarmFit {
            take_up: w.take_up_factors().to_vec(),
            stop_tolerance: None,
            solve_at_take_up: true,
        };
        self.rh.identify_warm(&start, &checked, &fit)
    }

    /// Stage 1 (cont.): the user's fit again with each point weighted by its local noise level
    /// where the noise varies along the line (the take-up region noisier), and with the gross
    /// outliers of its noise model left out (weighted by [`OUTLIER_FACTOR`]) — or, with a
    /// robust loss, each point down-weighted as the loss weights it at this fit
    /// ([`RobustWeights`]; least squares from here on); every later fit
    /// of the diagnosis uses the same weights, so that neither the noisier points nor the
    /// outliers dominate the cost and a flexible candidate cannot earn its place by fitting
    /// them. Unchanged when the noise is declared, or even and without outliers (a further
    /// step's fit, which starts with the previous step's weights, is then refitted without
    /// them).
    pub fn weighted_base(
        &mut self,
        base: Identification,
    ) -> Result<Identification, RheometerError> {
        let noise = &base.summary.noise;
        let robust = self
            .robust
            .map(|loss| {
                let o = IdentifyOptions {
                    loss,
                    ..self.opts.clone()
                };
                self.rh.robust_margin(&o).map(|m| (loss, m))
            })
            .transpose()?;
        let model = noise.model.as_ref();
        let varies =
            model.is_some_and(|m| m.varies_along_line) && !noise.declared() && noise.level > 0.0;
        let outliers = model.is_some_and(|m| !m.outliers.is_empty());
        if !varies && !outliers && robust.is_none() {
            // a further step's fit carries the previous step's weights: this step's noise
            // model has no use for them
            if self.opts.noise_factors.take().is_none() {
                return Ok(base);
            }
            return self.refit_weighted(base);
        }
        // each point's noise factor: its local noise level over the one level, times the
        // robust loss's down-weighting (1/√ρ' of its residual against the local soft margin)
        // or, without a loss, OUTLIER_FACTOR for a gross outlier
        let mut beyond = 0;
        let mut smallest = 1.0_f64;
        let mut factors = Vec::with_capacity(self.rh.measurements.len());
        for (k, meas) in self.rh.measurements.iter().enumerate() {
            let r = base.residual_profiles.get(k).map(|p| p.1.as_slice());
            let mut fk = Vec::with_capacity(meas.positions.len());
            for (i, &s) in meas.positions.iter().enumerate() {
                let f = match model {
                    Some(m) if varies => m.local_sigma_at(k, s) / noise.level,
                    _ => 1.0,
                };
                fk.push(match robust {
                    Some((loss, (c, _))) => {
                        let ri = r.and_then(|r| r.get(i)).copied().unwrap_or(0.0);
                        let z = (ri / (c * f)).powi(2);
                        let w = loss.rho(z).1.clamp(f64::EPSILON, 1.0);
                        beyond += usize::from(z > 1.0);
                        smallest = smallest.min(w);
                        f / w.sqrt()
                    }
                    None if model.is_some_and(|m| m.is_outlier(k, i)) => f * OUTLIER_FACTOR,
                    None => f,
                });
            }
            factors.push(fk);
        }
        if let Some((loss, (c, source))) = robust {
            self.weights = Some(RobustWeights {
                loss,
                f_scale: c,
                f_scale_source: source,
                down_weighted: beyond,
                points: factors.iter().map(Vec::len).sum(),
                smallest_weight: smallest,
            });
        }
        self.opts.loss = Loss::Linear;
        self.opts.noise_factors = Some(Arc::new(factors));
        self.refit_weighted(base)
    }

    /// `base` refitted with the weights of [`IdentifyOptions::noise_factors`] as they now
    /// stand, keeping `base`'s noise level (the residual statistics are the refit's own).
    fn refit_weighted(&self, base: Identification) -> Result<Identification, RheometerError> {
        let start = FitStart {
            warm: Some(base.solutions.clone()),
            strengths: base.fitted_strengths(),
            ..FitStart::at(base.law())
        };
        let warm = WarmFit {
            take_up: base.take_up_factors().to_vec(),
            stop_tolerance: None,
            solve_at_take_up: true,
        };
        let mut weighted = self.rh.identify_warm(&start, &self.opts, &warm)?;
        // the one noise level of these data and this model is the plain fit's, and the misfit
        // warning reads it (not the weighted fit's own estimate); the residual statistics
        // (RMS, lag-1 autocorrelation, outliers) are the weighted fit's own, the fit every
        // later stage judges (the plain fit's are bent by the outliers it fits)
        let plain = &base.summary.noise;
        let own = weighted.summary.noise.model.take();
        weighted.summary.noise = NoiseSummary {
            rms_over_noise: own
                .as_ref()
                .map_or(plain.rms_over_noise, |m| m.rms / plain.level),
            model: own.or_else(|| plain.model.clone()),
            ..plain.clone()
        };
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

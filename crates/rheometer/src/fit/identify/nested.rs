//! Fits of a model with fitted effects that never end worse than the same model without them.
//!
//! A model with fitted effects contains the plain model: every fitted effect at its neutral
//! strength reproduces it exactly. Its optimum can therefore be no worse than the plain
//! model's. A fit started at the heuristic law with the effects at neutral strength takes a
//! different path through the larger parameter space and can end in a local minimum above the
//! plain optimum: nothing in the trust-region method forbids it.
//! [`Rheometer::identify_nested`] therefore also fits the plain model (the fitted effects held
//! at neutral strength) and starts the full model from its optimum (its law, take-up factors
//! and solutions, the effects at neutral strength), which can only lower `J`, and keeps the
//! better of the two fits.

use super::identification::{Identification, WarmFit};
use crate::fit::data::Rheometer;
use crate::fit::layout::FitStart;
use crate::fit::options::{IdentifyOptions, RheometerError};
use crate::model::effects::EffectSetting;

/// Where the kept fit of [`Rheometer::identify_nested`] started.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NestedStart {
    /// The model has no fitted effect: one fit from the given start.
    Plain,
    /// The given start law with the effects at neutral strength ended lowest.
    Given,
    /// The plain model's optimum (effects at neutral strength) ended lower than the given
    /// start.
    PlainOptimum,
    /// The given start law with the effects at given strengths (a previous fit's) ended
    /// lowest ([`Rheometer::identify_nested_from`]).
    GivenStrengths,
}

/// The outcome of [`Rheometer::identify_nested`].
#[derive(Debug)]
pub struct NestedFit {
    /// The kept fit (the lower cost of the two starts).
    pub fit: Identification,
    /// Where it started.
    pub start: NestedStart,
    /// The plain model's fit (the fitted effects held at neutral strength, the fixed ones as
    /// given); `None` without fitted effects or when it failed.
    pub plain: Option<Identification>,
    /// Cost `J` \[-\] the fit from the given start reached (`None` when it failed).
    pub given_cost: Option<f64>,
}

impl NestedFit {
    /// Cost `J` \[-\] of the plain model's optimum (the fitted effects at neutral strength);
    /// `None` without fitted effects.
    pub fn plain_cost(&self) -> Option<f64> {
        self.plain.as_ref().map(|p| p.summary.cost)
    }
}

impl Rheometer {
    /// Identification of this model from `start = (n, κ)` that never ends worse than the plain
    /// model (see the module). Without fitted effects it is
    /// [`identify`](Self::identify). Costs two more fits with them. An error of the fit from
    /// the given start is kept only when the fit from the plain optimum fails too.
    pub fn identify_nested(
        &self,
        start: [f64; 2],
        options: &IdentifyOptions,
    ) -> Result<NestedFit, RheometerError> {
        let fitted = self.spec.effects.iter().any(|s| s.value.is_none());
        if !fitted {
            return Ok(NestedFit {
                fit: self.identify(start, options)?,
                start: NestedStart::Plain,
                plain: None,
                given_cost: None,
            });
        }
        let given = self.identify(start, options);
        let mut plain_spec = self.spec.clone();
        for s in &mut plain_spec.effects {
            if s.value.is_none() {
                let neutral = s.effect.neutral();
                *s = EffectSetting::fixed(s.effect.clone(), neutral);
            }
        }
        let from_plain = self
            .respecified(plain_spec)
            .and_then(|plain_rh| plain_rh.identify(start, options))
            .and_then(|plain| {
                let warm_start = FitStart {
                    warm: Some(plain.solutions.clone()),
                    ..FitStart::at(plain.law())
                };
                let warm = WarmFit {
                    take_up: plain.take_up_factors().to_vec(),
                    stop_tolerance: None,
                    solve_at_take_up: true,
                };
                self.identify_warm(&warm_start, options, &warm)
                    .map(|fit| (plain, fit))
            });
        match (given, from_plain) {
            (Ok(g), Ok((plain, p))) => {
                let given_cost = Some(g.summary.cost);
                // ties keep the fit from the given start: the plain optimum replaces it only
                // where it is strictly better
                let (fit, start) = if p.summary.cost < g.summary.cost {
                    (p, NestedStart::PlainOptimum)
                } else {
                    (g, NestedStart::Given)
                };
                Ok(NestedFit {
                    fit,
                    start,
                    plain: Some(plain),
                    given_cost,
                })
            }
            (Ok(g), Err(_)) => Ok(NestedFit {
                given_cost: Some(g.summary.cost),
                fit: g,
                start: NestedStart::Given,
                plain: None,
            }),
            (Err(_), Ok((plain, p))) => Ok(NestedFit {
                fit: p,
                start: NestedStart::PlainOptimum,
                plain: Some(plain),
                given_cost: None,
            }),
            (Err(e), Err(_)) => Err(e),
        }
    }

    /// [`identify_nested`](Self::identify_nested) and, with `strengths` (start values of the
    /// fitted effects' strengths by effect name and shapes by model-parameter name, e.g. a
    /// previous fit's), also the fit from them at `start`; the lowest cost is kept. A fit from
    /// them that fails leaves the nested fit, which never ends worse than the plain model.
    pub fn identify_nested_from(
        &self,
        start: [f64; 2],
        strengths: &[(String, f64)],
        options: &IdentifyOptions,
    ) -> Result<NestedFit, RheometerError> {
        let mut nested = self.identify_nested(start, options)?;
        if strengths.is_empty() {
            return Ok(nested);
        }
        let from = FitStart {
            strengths: strengths.to_vec(),
            ..FitStart::at(start)
        };
        if let Ok(f) = self.identify_from(&from, options) {
            if f.summary.cost < nested.fit.summary.cost {
                nested.fit = f;
                nested.start = NestedStart::GivenStrengths;
            }
        }
        Ok(nested)
    }
}

//! Intervals that hold: profile-likelihood intervals of the fitted shared parameters (`n`, `κ`,
//! effect strengths), one-sided bounds at a bound of the search range, and the
//! likelihood-ratio test of the fit against the nested Newtonian law (`n = 1`).
//!
//! **Profile.** For a parameter `θ` held at a value, every other parameter (the rest of the law,
//! the strengths, the take-up factors) is refitted, warm-started from the neighbouring refit
//! (its solutions, take-up factors and strengths). The deviance
//! `D(θ) = (J(θ) − J_min)/σ̂²`, with the residual variance `σ̂² = J_min/(N − p)` of the fit
//! (the same `σ̂²` as the linearised covariance; times the long-run factor
//! [`variance_inflation`](crate::data::noise_model::NoiseModel::variance_inflation) where the
//! noise is correlated along the line), is compared with `χ²₁(0.95) = 3.84`: the
//! 95 % interval is `{θ : D(θ) ≤ 3.84}`. Each side starts at the linearised end
//! `θ̂ ± 1.96 se` (where `D = 3.84` if the likelihood is quadratic) and is refined by secant
//! steps on the signed root `√D`, which is linear in `θ` for a quadratic profile. A profile
//! that reaches the end of the search range below 3.84 leaves that end open (`NaN`).
//!
//! **When the linearised interval is not trusted** ([`ProfileInterval::reasons`]): the
//! estimate at a bound of its search range, a correlation above [`RIDGE_CORRELATION`] with
//! another fitted parameter (a ridge), or a profile whose deviance at a linearised end departs
//! from 3.84 by more than [`QUADRATIC_DEPARTURE`] (relative). The report then gives the profile
//! interval, and the flow curve's band follows the profile.
//!
//! **One-sided bound.** At a bound the one-sided 95 % bound is where `D = χ²₁(0.90) = 2.71`:
//! the likelihood-ratio statistic of a parameter on the boundary of its range is a 50:50
//! mixture of `χ²₀` and `χ²₁` (Self & Liang 1987), whose 95 % point is 2.71.
//!
//! **Nested Newtonian law.** The Newtonian law is the Carreau-type law at `n = 1` (where `κ`
//! no longer enters). The statistic `LR = (J_N − J)/σ̂²` of the Newtonian refit against the
//! fit is compared with the boundary mixture, `p = ½ P(χ²₁ > LR)`. `κ` is not identified
//! under the null, so this `p` is too small (Davies 1987): where it is below the level but not
//! far below it (`CALIBRATION_FLOOR`) it is calibrated by a simulated reference distribution
//! ([`lr_calibration`](super::lr_calibration)); the test prefers the Newtonian law when
//! `p ≥ 0.05`. It runs before the profiles: where it prefers the Newtonian law, `n` and `κ` are
//! not estimates (the law is Newtonian over the data at `n = 1` and at `n → 0` with `K` beyond
//! the data's stresses alike) and are not profiled; the [`ThinningBound`] says how much
//! thinning the data still allow instead.

use crate::data::statistics::chi2_1_survival;
use crate::fit::data::Rheometer;
use crate::fit::identify::identification::{Identification, WarmFit};
use crate::fit::layout::FitStart;
use crate::fit::lr_calibration::{calibrated_p, REPLICATES};
use crate::fit::options::{IdentifyOptions, RheometerError};
use crate::fit::summary::{BoundSide, FitSummary, Z95};
use crate::fit::values::likelihood::trace_of;
pub use crate::fit::values::likelihood::{
    NewtonianTest, OneSidedBound, ProfileInterval, ProfilePoint, ThinningBound,
};
use crate::fit::values::thresholds::PLAUSIBLE_N;
use crate::model::effects::{LawChoice, STRAIN_THINNING_REFERENCE_KAPPA};
use diffbvp::solution::Solution;

/// `χ²₁(0.95)`: the two-sided 95 % deviance.
pub const CHI2_95: f64 = Z95 * Z95;
/// `χ²₁(0.90)`: the one-sided 95 % deviance at a boundary (50:50 mixture of `χ²₀` and `χ²₁`).
pub const CHI2_90: f64 = 2.705_543_454_095_404;
/// A linearised interval is not trusted when the deviance at one of its ends departs from
/// [`CHI2_95`] by more than this fraction.
pub const QUADRATIC_DEPARTURE: f64 = 0.2;
/// A linearised interval is not trusted when the parameter's correlation with another fitted
/// parameter exceeds this in magnitude.
pub const RIDGE_CORRELATION: f64 = 0.99;
/// Refits per side of a profile at most.
const MAX_REFITS_PER_SIDE: usize = 8;
/// A side's end is accepted when its deviance is within this fraction of the target.
const ROOT_TOLERANCE: f64 = 0.1;
/// Significance level of the likelihood-ratio test.
pub const LR_LEVEL: f64 = 0.05;
/// Below this boundary-mixture p-value the test is not calibrated: the calibrated p of a
/// statistic that large stays far below [`LR_LEVEL`] (Davies' bound `½P(χ²₁ > LR) +
/// V e^{−LR/2}/(2π)` would need a total variation `V` of the thinning direction over `κ` of
/// about 37 radians to reach the level from 1e-3, where a few radians are what the law has).
const CALIBRATION_FLOOR: f64 = 1e-3;
/// How far beyond `ln(η_E0 ε̇_max)` \[-\] the calibration's grid of `κ` and the onset's walk
/// start: at `K` e³ = 20 times the data's largest stress the law changes the viscosity there by
/// at most 0.12 % (`n = 0`), and its shape no longer changes with `κ`.
const CALIBRATION_BEYOND: f64 = 3.0;

/// Whether to compute profile intervals.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ProfileMode {
    /// For `n`, `κ` and the fitted strengths, refined only as far as needed (about two refits
    /// per parameter where the likelihood is quadratic).
    #[default]
    Auto,
    /// None.
    Never,
}

/// A refit of a profile: held value (model units), deviance, law `(n, κ)`.
type Sample = (f64, f64, Vec<f64>);

/// One side of a profile: from `theta` (deviance `z0²`) in direction `dir`.
struct Walk<'a> {
    theta: f64,
    z0: f64,
    dir: f64,
    /// Where the held parameter may go (model units).
    range: [f64; 2],
    /// The first step (model units).
    step: f64,
    hold: &'a dyn Fn(f64) -> Vec<(String, f64)>,
    options: &'a IdentifyOptions,
    warm: Warm,
}

/// A refit at a held value.
struct Refit {
    deviance: f64,
    law: Vec<f64>,
    warm: Warm,
}

/// What the next refit starts from.
#[derive(Clone)]
struct Warm {
    law: [f64; 2],
    strengths: Vec<(String, f64)>,
    take_up: Vec<f64>,
    solutions: Vec<Solution>,
}

impl Warm {
    fn of(id: &Identification) -> Self {
        let mut strengths = Vec::new();
        for slot in &id.effects {
            strengths.push((
                slot.effect.name().to_string(),
                slot.effect.strength_of(id.local_params[slot.local]),
            ));
            for sh in &slot.shapes {
                strengths.push((
                    sh.parameter.model_param.to_string(),
                    id.local_params[sh.local],
                ));
            }
        }
        Warm {
            law: id.law(),
            strengths,
            take_up: id.take_up_factors().to_vec(),
            solutions: id.solutions.clone(),
        }
    }
}

/// A fitted shared parameter to profile.
struct Target {
    name: String,
    unit: String,
    /// Column in the fit's parameter vector.
    column: usize,
    /// Model units → reported units.
    to_reported: Box<dyn Fn(f64) -> f64>,
}

/// The profiling of one fit.
struct Profiler<'a> {
    rh: &'a Rheometer,
    id: &'a Identification,
    options: &'a IdentifyOptions,
    /// `J_min` and `σ̂²`.
    cost: f64,
    s2: f64,
}

impl Profiler<'_> {
    /// The profiler of `id`'s fit, where its cost is a likelihood: not for the paper's
    /// estimator (a weighted distance to smoothed data) nor for a model that misses the data
    /// by several times the noise ([`FitSummary::likelihood_skipped`](crate::fit::FitSummary::likelihood_skipped)).
    fn of<'a>(
        rh: &'a Rheometer,
        id: &'a Identification,
        options: &'a IdentifyOptions,
    ) -> Option<Profiler<'a>> {
        if options.estimator != crate::fit::estimator::Estimator::Principled
            || id.summary.likelihood_skipped().is_some()
        {
            return None;
        }
        Some(Profiler {
            rh,
            id,
            options,
            cost: 2.0 * id.fit.cost,
            // the long-run variance where the noise is correlated along the line
            s2: id.fit.residual_variance() * id.summary.noise.variance_inflation(),
        })
    }

    /// Refit with `hold` (model units) from `warm` under `options`' bounds.
    fn refit(
        &self,
        options: &IdentifyOptions,
        hold: Vec<(String, f64)>,
        warm: &Warm,
    ) -> Result<Refit, RheometerError> {
        let id = self.refit_id(options, hold, warm)?;
        Ok(Refit {
            deviance: (2.0 * id.fit.cost - self.cost) / self.s2,
            law: id.law().to_vec(),
            warm: Warm::of(&id),
        })
    }

    /// The refit itself, at the BVP tolerance the fit ended with.
    fn refit_id(
        &self,
        options: &IdentifyOptions,
        hold: Vec<(String, f64)>,
        warm: &Warm,
    ) -> Result<Identification, RheometerError> {
        let mut opts = IdentifyOptions {
            hold,
            ..options.clone()
        };
        let tol = self.id.summary.solver.bvp_tolerance;
        if tol.is_finite() && tol > 0.0 {
            opts.simulate.tol = tol;
        }
        let start = FitStart {
            law: warm.law,
            free_candidates: Vec::new(),
            strengths: warm.strengths.clone(),
            warm: Some(warm.solutions.clone()),
        };
        let wf = WarmFit {
            take_up: warm.take_up.clone(),
            stop_tolerance: None,
            solve_at_take_up: false,
        };
        self.rh.identify_unchecked(&start, &opts, &wf)
    }

    /// The likelihood-ratio test against the Newtonian law (`n = 1`, `κ` then irrelevant),
    /// its p-value calibrated ([`lr_calibration`](super::lr_calibration)) where the boundary
    /// mixture's is below [`LR_LEVEL`] but above [`CALIBRATION_FLOOR`].
    fn newtonian_test(&self) -> Result<NewtonianTest, RheometerError> {
        let hold: Vec<(String, f64)> = [("n", 1.0), ("kappa", STRAIN_THINNING_REFERENCE_KAPPA)]
            .into_iter()
            .filter(|(n, _)| self.id.names.iter().any(|m| m == n))
            .map(|(n, v)| (n.to_string(), v))
            .collect();
        let mut warm = Warm::of(self.id);
        warm.law = [1.0, STRAIN_THINNING_REFERENCE_KAPPA];
        let n_id = self.refit_id(self.options, hold, &warm)?;
        let lr = ((2.0 * n_id.fit.cost - self.cost) / self.s2).max(0.0);
        let mixture = 0.5 * chi2_1_survival(lr);
        let (mut p_value, mut p_mixture, mut replicates) = (mixture, None, 0);
        if (CALIBRATION_FLOOR..LR_LEVEL).contains(&mixture) {
            let top = self.kappa_on().map_or(self.options.upper[1], |k| {
                (k + CALIBRATION_BEYOND).min(self.options.upper[1])
            });
            let range = [self.options.lower[1], top];
            let strengths = Warm::of(&n_id).strengths;
            if let Some(p) = calibrated_p(self.rh, &n_id, &strengths, self.options, range, lr)? {
                (p_value, p_mixture, replicates) = (p.max(mixture), Some(mixture), REPLICATES);
            }
        }
        let preferred = if p_value >= LR_LEVEL {
            LawChoice::Newtonian
        } else {
            LawChoice::Carreau
        };
        let (thinning_bound, law_not_estimated) = if preferred == LawChoice::Newtonian {
            (
                self.thinning_bound(&n_id, lr)?,
                Some(
                    "no strain thinning detected: the law is Newtonian within the data's strain \
                     rates, at n = 1 and at n -> 0 with K beyond the data's stresses alike; the \
                     fit's (n, kappa) is one of many such laws"
                        .to_string(),
                ),
            )
        } else {
            (None, None)
        };
        Ok(NewtonianTest {
            statistic: lr,
            p_value,
            p_mixture,
            calibration_replicates: replicates,
            rms_newtonian: n_id.rms(),
            preferred,
            law_not_estimated,
            thinning_bound,
        })
    }

    /// `ln(η_E0(T_ref)·ε̇_max)`: the `κ` at which the law's thinning sets in at the largest
    /// reduced strain rate the data cover (`None` without a coverage).
    fn kappa_on(&self) -> Option<f64> {
        let (cov, model) = (
            self.id.summary.strain_rates.as_ref()?,
            self.rh.models.first()?,
        );
        let sc = &model.scaling;
        let eta0 = model.viscosity_at(
            cov.reference_temperature_k / sc.reference.temperature,
            0.0,
            &self.id.local_params,
        ) * sc.reference.viscosity;
        let k = (eta0 * cov.reduced_per_s[2]).ln();
        k.is_finite().then_some(k)
    }

    /// The [`ThinningBound`], from the Newtonian refit `newtonian` (deviance `lr`); `None`
    /// without a strain-rate coverage or where `κ`'s range leaves no onset within the data.
    fn thinning_bound(
        &self,
        newtonian: &Identification,
        lr: f64,
    ) -> Result<Option<ThinningBound>, RheometerError> {
        let Some(kappa_on) = self.kappa_on() else {
            return Ok(None);
        };
        if !self.id.names.iter().any(|n| n == "n") {
            return Ok(None);
        }
        let mut options = self.options.clone();
        if kappa_on <= options.lower[1] + 0.1 {
            return Ok(None);
        }
        options.upper[1] = options.upper[1].min(kappa_on);
        let mut warm = Warm::of(newtonian);
        warm.law = [1.0, options.upper[1] - 0.1];
        let mut points = vec![(1.0, lr, newtonian.law().to_vec())];
        let walk = Walk {
            theta: 1.0,
            z0: lr.sqrt(),
            dir: -1.0,
            range: [options.lower[0], 1.0],
            step: 0.05,
            hold: &|t| vec![("n".to_string(), t)],
            options: &options,
            warm: warm.clone(),
        };
        self.walk(walk, &mut points)?;
        let bound = crossing(&points, 1.0, -1.0, CHI2_90).unwrap_or(f64::NAN);
        let (onset, onset_points) = self.onset(newtonian, lr, kappa_on)?;
        let to_points = |v: Vec<Sample>| {
            v.into_iter()
                .map(|(value, deviance, law)| ProfilePoint {
                    value,
                    deviance,
                    law,
                })
                .collect()
        };
        Ok(Some(ThinningBound {
            n_lower95: bound,
            k_max_pa: options.upper[1].exp(),
            points: to_points(points),
            onset_lower95_per_s: onset,
            onset_points: to_points(onset_points),
        }))
    }

    /// The one-sided 95 % lower bound \[1/s\] on where the strongest thinning a melt shows
    /// (`n` at [`PLAUSIBLE_N`]'s lower end, 0.2) sets in, `K_min/η_E0(T_ref)`, and its
    /// refits: `κ` walked down in steps of 1 from [`CALIBRATION_BEYOND`] above `kappa_on`
    /// (where that law is Newtonian on the data; deviance taken as the Newtonian refit's
    /// `lr`), warm from the Newtonian refit `newtonian` and then from the last refit below
    /// 2.71, until the deviance passes 2.71 (or a refit does not solve), then refined where
    /// it crosses 2.71. Beyond the data's stresses the law's thinning there is
    /// `∝ (η_E0 ε̇/K)² = e^{−2κ}·…`, so `√D` is about linear in `u = e^{−2κ}`: the secant
    /// steps and the crossing are taken in `u`.
    fn onset(
        &self,
        newtonian: &Identification,
        lr: f64,
        kappa_on: f64,
    ) -> Result<(Option<f64>, Vec<Sample>), RheometerError> {
        // n = 0 bounds the stress by K: no fiber solves where the draw needs more
        let n_lo = PLAUSIBLE_N[0].max(self.options.lower[0]);
        let (bottom, top) = (
            self.options.lower[1],
            (kappa_on + CALIBRATION_BEYOND).min(self.options.upper[1]),
        );
        let mut points = vec![(top, lr, vec![n_lo, top])];
        let mut warm = Warm::of(newtonian);
        warm.law = [n_lo, top];
        let u = |k: f64| (-2.0 * (k - top)).exp();
        // the crossing of D = 2.71 between an inside and an outside refit, linear in (u, √D)
        let cross = |(ki, di): (f64, f64), (ko, dout): (f64, f64)| {
            let (zi, zo, zc) = (di.max(0.0).sqrt(), dout.sqrt(), CHI2_90.sqrt());
            let f = ((zc - zi) / (zo - zi)).clamp(0.0, 1.0);
            -0.5 * (u(ki) + f * (u(ko) - u(ki))).ln() + top
        };
        let mut inside = (top, lr);
        let mut outside: Option<(f64, f64)> = None;
        let mut kappa = top - 1.0;
        for _ in 0..2 * MAX_REFITS_PER_SIDE {
            let hold = vec![("n".to_string(), n_lo), ("kappa".to_string(), kappa)];
            match self.refit(self.options, hold, &warm) {
                Ok(r) => {
                    points.push((kappa, r.deviance, r.law.clone()));
                    if (r.deviance / CHI2_90 - 1.0).abs() <= ROOT_TOLERANCE {
                        return Ok((Some(self.onset_rate(kappa, kappa_on)), points));
                    }
                    if r.deviance < CHI2_90 {
                        (inside, warm) = ((kappa, r.deviance), r.warm);
                    } else {
                        outside = Some((kappa, r.deviance));
                    }
                }
                // no fiber solves with that law: beyond the data's reach
                Err(_) => outside = Some((kappa, f64::INFINITY)),
            }
            kappa = match outside {
                None if inside.0 <= bottom => return Ok((None, points)),
                None => (inside.0 - 1.0).max(bottom),
                Some(o) if o.1.is_finite() => cross(inside, o),
                Some(o) => 0.5 * (inside.0 + o.0),
            };
        }
        let k_min = outside
            .filter(|o| o.1.is_finite())
            .map(|o| cross(inside, o));
        Ok((k_min.map(|k| self.onset_rate(k, kappa_on)), points))
    }

    /// The onset rate \[1/s\] `K/η_E0(T_ref)` of `K = e^kappa`, with `kappa_on` that of the
    /// largest reduced rate.
    fn onset_rate(&self, kappa: f64, kappa_on: f64) -> f64 {
        (kappa - kappa_on).exp() * self.max_rate()
    }

    /// The largest reduced strain rate the data cover \[1/s\] (`NaN` without a coverage).
    fn max_rate(&self) -> f64 {
        (self.id.summary.strain_rates.as_ref()).map_or(f64::NAN, |c| c.reduced_per_s[2])
    }

    /// Walks from `w.theta` in direction `w.dir` until the deviance reaches [`CHI2_95`]
    /// (within [`ROOT_TOLERANCE`]) or the end of the range, each refit warm-started from the
    /// last one inside; the refits go to `points`. Returns the deviance of the first refit.
    fn walk(&self, w: Walk<'_>, points: &mut Vec<Sample>) -> Result<f64, RheometerError> {
        let [lo, hi] = w.range;
        let edge = if w.dir < 0.0 { lo } else { hi };
        let zc = CHI2_95.sqrt();
        let mut t = (w.theta + w.dir * w.step).clamp(lo, hi);
        // the last refit inside the 95 % deviance (warm start of the next) and the first
        // beyond it
        let (mut t_in, mut z_in, mut warm) = (w.theta, w.z0, w.warm);
        let mut outside: Option<(f64, f64)> = None;
        let mut first = f64::NAN;
        for _ in 0..MAX_REFITS_PER_SIDE {
            let r = match self.refit(w.options, (w.hold)(t), &warm) {
                Ok(r) => r,
                // the model does not solve there (a law far from the data's): halfway back to
                // the last refit inside, which did solve
                Err(e) => {
                    if (t - t_in).abs() <= 1e-6 * (hi - lo).abs().max(1e-300) {
                        return Err(e);
                    }
                    t = t_in + 0.5 * (t - t_in);
                    continue;
                }
            };
            points.push((t, r.deviance, r.law.clone()));
            if first.is_nan() {
                first = r.deviance;
            }
            if (r.deviance / CHI2_95 - 1.0).abs() <= ROOT_TOLERANCE {
                break;
            }
            let z = r.deviance.max(0.0).sqrt();
            if r.deviance > CHI2_95 {
                outside = Some((t, z));
            } else {
                (t_in, z_in, warm) = (t, z, r.warm);
                if (t - edge).abs() <= 1e-12 * (hi - lo).abs().max(1.0) {
                    break; // open at the end of the range
                }
            }
            t = match outside {
                // secant on √D between the last inside and the first outside refit
                Some((t_out, z_out)) => t_in + (zc - z_in) / (z_out - z_in) * (t_out - t_in),
                // inside: extrapolate √D linearly from the start, 20 % beyond
                None => {
                    let slope = (z - w.z0).max(1e-3) / (t - w.theta).abs().max(1e-300);
                    let reach = ((zc - w.z0) / slope).min(4.0 * (t - w.theta).abs()) * 1.2;
                    (w.theta + w.dir * reach).clamp(lo, hi)
                }
            };
        }
        Ok(first)
    }

    /// Hold `target` at `value` (model units); `n` at 1 holds `κ` too (it no longer enters).
    fn hold(&self, target: &Target, value: f64) -> Vec<(String, f64)> {
        let mut h = vec![(target.name.clone(), value)];
        if target.name == "n" && value >= 1.0 - 1e-9 && self.id.names.iter().any(|n| n == "kappa") {
            h.push(("kappa".into(), STRAIN_THINNING_REFERENCE_KAPPA));
        }
        h
    }

    /// Why the linearised interval of column `c` is not to be trusted: at a bound (`side_at`),
    /// a strong correlation with another parameter, or a curved profile (its `departure` from
    /// the quadratic, or no finite standard error `se`).
    fn reasons(
        &self,
        c: usize,
        side_at: Option<BoundSide>,
        departure: f64,
        se: f64,
    ) -> Vec<String> {
        let fit = &self.id.fit;
        let corr = fit.correlation().map_or(0.0, |m| {
            let np = fit.p.len();
            (0..np)
                .filter(|&j| j != c)
                .map(|j| m[c * np + j].abs())
                .fold(0.0, f64::max)
        });
        let mut reasons = Vec::new();
        if side_at.is_some() {
            reasons.push("at_bound".to_string());
        }
        if corr > RIDGE_CORRELATION {
            reasons.push("correlation".to_string());
        }
        if departure > QUADRATIC_DEPARTURE || (side_at.is_none() && !se.is_finite()) {
            reasons.push("curved_profile".to_string());
        }
        reasons
    }

    /// The profile of `target`, both sides.
    fn profile(&self, target: &Target) -> Result<ProfileInterval, RheometerError> {
        let fit = &self.id.fit;
        let c = target.column;
        let theta = fit.p[c];
        let (lo, hi) = (self.id.lower[c], self.id.upper[c]);
        let se = fit.standard_errors().map_or(f64::NAN, |s| s[c]).abs();
        let side_at = crate::fit::summary::checks::bound_side(theta, lo, hi);
        let base = Warm::of(self.id);
        let mut points = vec![(theta, 0.0, self.id.law().to_vec())];
        let mut ends = [f64::NAN; 2];
        let mut departure = f64::NAN;
        for (k, dir) in [-1.0f64, 1.0].into_iter().enumerate() {
            let edge = if dir < 0.0 { lo } else { hi };
            if (theta - edge).abs() <= 1e-12 * (hi - lo).abs().max(1.0)
                || side_at
                    == Some(if dir < 0.0 {
                        BoundSide::Lower
                    } else {
                        BoundSide::Upper
                    })
            {
                ends[k] = edge;
                continue;
            }
            let linear = se.is_finite() && se > 0.0 && side_at.is_none();
            let walk = Walk {
                theta,
                z0: 0.0,
                dir,
                range: [lo, hi],
                step: if linear { Z95 * se } else { 0.1 * (hi - lo) },
                hold: &|t| self.hold(target, t),
                options: self.options,
                warm: base.clone(),
            };
            let first = self.walk(walk, &mut points)?;
            if linear {
                let d = (first / CHI2_95 - 1.0).abs();
                departure = if departure.is_nan() {
                    d
                } else {
                    departure.max(d)
                };
            }
            ends[k] = crossing(&points, theta, dir, CHI2_95).unwrap_or(f64::NAN);
        }
        let to = &target.to_reported;
        let mut ci = [to(ends[0]), to(ends[1])];
        if ci[0] > ci[1] {
            ci.swap(0, 1);
        }
        let one_sided = one_sided_bound(&points, theta, ends, [lo, hi], side_at, &**to);
        let reasons = self.reasons(c, side_at, departure, se);
        let mut range = [to(lo), to(hi)];
        if range[0] > range[1] {
            range.swap(0, 1);
        }
        Ok(ProfileInterval {
            parameter: target.name.clone(),
            unit: target.unit.clone(),
            reasons,
            ci95: ci,
            one_sided95: one_sided,
            search_range: range,
            quadratic_departure: departure,
            points: points
                .into_iter()
                .map(|(v, d, law)| ProfilePoint {
                    value: to(v),
                    deviance: d,
                    law,
                })
                .collect(),
        })
    }
}

/// The one-sided 90 % bound of a profile through `points` about `theta` where its interval
/// stays open towards one side (the crossings `ends` missing or beyond the search range
/// `[lo, hi]`) or the estimate is at a bound (`side_at`), on the reported scale `to`.
fn one_sided_bound(
    points: &[Sample],
    theta: f64,
    ends: [f64; 2],
    [lo, hi]: [f64; 2],
    side_at: Option<BoundSide>,
    to: &dyn Fn(f64) -> f64,
) -> Option<OneSidedBound> {
    // one-sided bounds: at a bound of the search range, or where the two-sided interval
    // stays open towards one end (the data are compatible with that end)
    let open_side = match (
        ends[0].is_nan() || ends[0] <= lo,
        ends[1].is_nan() || ends[1] >= hi,
    ) {
        _ if side_at.is_some() => side_at,
        (false, true) => Some(BoundSide::Upper),
        (true, false) => Some(BoundSide::Lower),
        _ => None,
    };
    open_side.and_then(|s| {
        let dir = if s == BoundSide::Lower { 1.0 } else { -1.0 };
        let b = crossing(points, theta, dir, CHI2_90)?;
        // a bound on the model parameter becomes one on the reported value
        let rising = to(theta + 1.0) > to(theta);
        let side = match (s, rising) {
            (BoundSide::Upper, true) | (BoundSide::Lower, false) => BoundSide::Lower,
            _ => BoundSide::Upper,
        };
        Some(OneSidedBound { side, bound: to(b) })
    })
}

/// Where the deviance crosses `level` on the `dir` side of `theta` (linear interpolation of
/// `√D` between the sampled points, or extrapolation over the outermost segment when its end
/// is within the root tolerance below `level`; `None` if it does not reach it).
fn crossing(points: &[Sample], theta: f64, dir: f64, level: f64) -> Option<f64> {
    let mut side: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| (p.0 - theta) * dir >= 0.0)
        .map(|p| ((p.0 - theta).abs(), p.1.max(0.0).sqrt()))
        .collect();
    side.sort_by(|a, b| a.0.total_cmp(&b.0));
    let zc = level.sqrt();
    let at = |(x0, z0): (f64, f64), (x1, z1): (f64, f64)| {
        theta + dir * (x0 + (zc - z0) / (z1 - z0) * (x1 - x0))
    };
    if let Some(w) = side
        .windows(2)
        .find(|w| w[0].1 <= zc && w[1].1 >= zc && w[1].1 > w[0].1)
    {
        return Some(at(w[0], w[1]));
    }
    let n = side.len();
    if n >= 2 {
        let (a, b) = (side[n - 2], side[n - 1]);
        if b.1 > a.1 && b.1 * b.1 >= level * (1.0 - ROOT_TOLERANCE) {
            return Some(at(a, b));
        }
    }
    None
}

/// The likelihood-ratio test of `id` against the Newtonian law alone (no profile intervals),
/// under the same conditions as [`intervals`]: `None` where `n` is not fitted, for the paper's
/// estimator, or where the model misses the data.
pub(crate) fn newtonian_test_of(
    rh: &Rheometer,
    id: &Identification,
    options: &IdentifyOptions,
) -> Result<Option<NewtonianTest>, RheometerError> {
    if !id.names.iter().any(|n| n == "n") {
        return Ok(None);
    }
    match Profiler::of(rh, id, options) {
        Some(p) => p.newtonian_test().map(Some),
        None => Ok(None),
    }
}

/// The profile intervals of `id`'s fitted law parameters and strengths (not shapes) and the
/// likelihood-ratio test against the Newtonian law (where `n` is fitted); none for the paper's
/// estimator (its cost is not a likelihood). Under a robust loss the deviance is that of the
/// robust cost (an approximation).
pub fn intervals(
    rh: &Rheometer,
    id: &Identification,
    options: &IdentifyOptions,
    mode: ProfileMode,
) -> Result<(Vec<ProfileInterval>, Option<NewtonianTest>), RheometerError> {
    let p = match Profiler::of(rh, id, options) {
        Some(p) if mode != ProfileMode::Never && !id.names.is_empty() => p,
        _ => return Ok((Vec::new(), None)),
    };
    let mut targets = Vec::new();
    for (c, name) in id.names.iter().enumerate() {
        if name == "n" || name == "kappa" {
            targets.push(Target {
                name: name.clone(),
                unit: "-".into(),
                column: c,
                to_reported: Box::new(|v| v),
            });
        } else if let Some(slot) = id.effects.iter().find(|s| s.column == Some(c)) {
            let e = slot.effect.clone();
            targets.push(Target {
                name: name.clone(),
                unit: e.unit().to_string(),
                column: c,
                to_reported: Box::new(move |v| e.strength_of(v)),
            });
        }
    }
    let test = if id.names.iter().any(|n| n == "n") {
        Some(p.newtonian_test()?)
    } else {
        None
    };
    // where the Newtonian law is preferred, n and κ are not estimates: no profiles of them
    // (in the corner n → 0, K beyond the data, each of their refits is slow, too)
    let newtonian = test.as_ref().is_some_and(|t| t.law_not_estimated.is_some());
    let mut out = Vec::new();
    for t in &targets {
        if !(newtonian && (t.name == "n" || t.name == "kappa")) {
            out.push(p.profile(t)?);
        }
    }
    Ok((out, test))
}

impl FitSummary {
    /// Whether the flow curve's band follows the profile: a law parameter whose linearised
    /// interval is not trusted.
    pub fn profile_band_needed(&self) -> bool {
        self.newtonian_on_data()
            || self
                .intervals
                .iter()
                .any(|i| (i.parameter == "n" || i.parameter == "kappa") && !i.linearised_trusted())
    }

    /// The laws `(n, κ)` along the law parameters' profiles within deviance `level` (the
    /// optimum included); where the Newtonian law is preferred
    /// ([`newtonian_on_data`](Self::newtonian_on_data)), the Newtonian law and the thinning
    /// laws within `level` that the `ThinningBound` refitted (onset within the data, and
    /// the strongest thinning's onset beyond them).
    pub fn profile_trace(&self, level: f64) -> Vec<Vec<f64>> {
        if let Some(t) = self
            .newtonian_test
            .as_ref()
            .filter(|_| self.newtonian_on_data())
        {
            let mut out = vec![vec![1.0, self.kappa.value]];
            if let Some(b) = &t.thinning_bound {
                out.extend(trace_of(&b.points, level));
                out.extend(trace_of(&b.onset_points, level));
            }
            return out;
        }
        let mut out = vec![self.law_params().to_vec()];
        for i in &self.intervals {
            if i.parameter == "n" || i.parameter == "kappa" {
                out.extend(i.trace(level));
            }
        }
        out
    }

    /// The profile interval of `parameter`, if computed.
    pub fn interval(&self, parameter: &str) -> Option<&ProfileInterval> {
        self.intervals.iter().find(|i| i.parameter == parameter)
    }
}

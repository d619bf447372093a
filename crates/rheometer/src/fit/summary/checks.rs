//! The checks of a fit: a bad fit is never printed as a good one.
//!
//! * **Estimates at a bound.** An estimate within `AT_BOUND_TOLERANCE` of the width of its
//!   search range from a bound is listed in [`FitSummary::at_bound`] and marked `AT LOWER
//!   BOUND` / `AT UPPER BOUND` in the text. The optimum then lies at or beyond the search
//!   range, and the normal-approximation interval is not valid: its `ci95` is `NaN` (`null` in
//!   JSON) and the text prints no interval for it.
//! * **Misfit far above the noise.** The RMS relative residual is compared with the fit's one
//!   noise level (`NoiseSummary`: declared, else
//!   estimated by the noise model). Above `MISFIT_RATIO` times the noise the report warns and
//!   names the worst experiments.
//! * **Huge standard errors**: `SE(n) > 0.2` (`LARGE_STDERR_N`), `SE(κ) > 1`
//!   (`LARGE_STDERR_KAPPA`), a fitted strength with a standard error above `LARGE_STDERR_STRENGTH_FRACTION` of its
//!   search range, or a `K` interval reaching `0` or `∞`.
//! * **A singular or ill-conditioned covariance** (no standard errors, or a correlation matrix
//!   with reciprocal condition number below `ILL_CONDITIONED_RCOND`).
//! * **A fit short of its optimum**: it ended without a convergence test being met (iteration
//!   budget, stall, collapsed trust region) and the Gauss–Newton step from its end would still
//!   lower `χ²` by at least `NOT_CONVERGED_CHI2`.
//! * **Data the model cannot describe**: measured diameters that do not decrease along the spin
//!   line ([`Rheometer::data_warnings`](crate::fit::Rheometer::data_warnings)).
//!
//! Each finding is a [`FitWarning`] (a [`WarningCode`] and a message naming the parameter or
//! experiment) in [`FitSummary::warnings`].

use crate::fit::estimator::Estimator;
use crate::fit::layout::EffectSlot;
use crate::fit::options::{FitWarning, WarningCode};
use crate::fit::summary::{BoundSide, FitSummary};
pub(crate) use crate::fit::values::thresholds::AT_BOUND_TOLERANCE;
pub(crate) use crate::fit::values::thresholds::ILL_CONDITIONED_RCOND;
pub(crate) use crate::fit::values::thresholds::IMPLAUSIBLE_NOISE_RATIO;
pub(crate) use crate::fit::values::thresholds::JUMP_SE;
pub(crate) use crate::fit::values::thresholds::LARGE_STDERR_STRENGTH_FRACTION;
pub(crate) use crate::fit::values::thresholds::MISFIT_RATIO;
pub(crate) use crate::fit::values::thresholds::MISFIT_WITHOUT_NOISE;
use crate::fit::values::thresholds::NOISE_FREE_LEVEL;
pub(crate) use crate::fit::values::thresholds::NOT_CONVERGED_CHI2;
pub(crate) use crate::fit::values::thresholds::PLAUSIBLE_N;
pub(crate) use crate::fit::values::thresholds::{LARGE_STDERR_KAPPA, LARGE_STDERR_N};
use crate::report::format::fmt_g;
use diffbvp::least_squares::{FitResult, Termination};
use nalgebra::{DMatrix, SymmetricEigen};

/// Which bound `value` is at (within [`AT_BOUND_TOLERANCE`] of the range width), if any.
pub(crate) fn bound_side(value: f64, lower: f64, upper: f64) -> Option<BoundSide> {
    let width = upper - lower;
    let tol = if width.is_finite() && width > 0.0 {
        AT_BOUND_TOLERANCE * width
    } else {
        AT_BOUND_TOLERANCE * value.abs().max(1.0)
    };
    if lower.is_finite() && value - lower <= tol {
        Some(BoundSide::Lower)
    } else if upper.is_finite() && upper - value <= tol {
        Some(BoundSide::Upper)
    } else {
        None
    }
}

/// One warning per estimate at a bound, with what it means for `n`, `κ` and take-up factors.
pub(crate) fn check_bounds(s: &FitSummary, w: &mut Vec<FitWarning>) {
    for b in &s.at_bound {
        let mut m = format!(
            "{} = {} is AT ITS {} BOUND {}: the optimum lies at or beyond the search range, \
             so its standard error and 95% interval are not valid",
            b.parameter,
            fmt_g(b.value),
            b.side.name().to_uppercase(),
            fmt_g(b.bound)
        );
        if b.parameter == "n" && b.side == BoundSide::Upper && b.bound >= 1.0 && s.law_fitted() {
            m.push_str(
                "; n = 1 is the Newtonian limit of the Carreau-type law, where kappa (K) no \
                 longer enters: the data show no strain thinning, or the model misses \
                 something (is the air hotter than the melt, are the data right?)",
            );
        } else if b.parameter == "kappa" {
            m.push_str(&format!(
                "; K = e^kappa = {:.4e} Pa sits at its {} limit: the data ask for K outside \
                 the search range",
                b.value.exp(),
                b.side.name()
            ));
        } else if b.parameter.starts_with("take_up_factor[") {
            m.push_str(
                "; the fitted take-up diameter is that far from d_fit(L) (or from the TOML's \
                 take_up_* value): check this experiment's take-up condition and data",
            );
        }
        w.push(FitWarning::new(WarningCode::AtBound, m));
    }
}

/// Singular or ill-conditioned covariance, huge standard errors, unbounded `K` intervals,
/// undetermined strengths.
pub(crate) fn check_uncertainty(
    s: &FitSummary,
    slots: &[EffectSlot],
    have_se: bool,
    corr: Option<&[DMatrix<f64>]>,
    np: usize,
    w: &mut Vec<FitWarning>,
) {
    check_covariance(s, have_se, corr, np, w);
    let at = |name: &str| s.bound_of(name).is_some();
    if s.n.fitted && s.n.stderr > LARGE_STDERR_N {
        w.push(FitWarning::new(
            WarningCode::LargeUncertainty,
            format!(
                "the standard error of n is {} (> {LARGE_STDERR_N}): the data do not \
                 determine n",
                fmt_g(s.n.stderr)
            ),
        ));
    }
    if s.kappa.fitted {
        if s.kappa.stderr > LARGE_STDERR_KAPPA {
            w.push(FitWarning::new(
                WarningCode::LargeUncertainty,
                format!(
                    "the standard error of kappa is {} (> {LARGE_STDERR_KAPPA}, a factor \
                     {:.3} in K): the data do not determine kappa or K",
                    fmt_g(s.kappa.stderr),
                    LARGE_STDERR_KAPPA.exp()
                ),
            ));
        }
        let [a, b] = s.k_pa.ci95;
        if !at("kappa") && s.kappa.stderr.is_finite() && (a <= 0.0 || b.is_infinite()) {
            w.push(FitWarning::new(
                WarningCode::LargeUncertainty,
                format!(
                    "the 95% interval of K is [{a:.4e}, {b:.4e}] Pa: unbounded, K is not \
                     determined"
                ),
            ));
        }
    }
    for (slot, e) in slots.iter().zip(&s.effects) {
        let st = &e.strength;
        if !st.fitted || st.at_bound.is_some() {
            continue;
        }
        let (lo, hi) = slot.effect.bounds();
        let limit = LARGE_STDERR_STRENGTH_FRACTION * (hi - lo).abs();
        if st.stderr > limit && !(slot.column == Some(0) && at("n")) {
            w.push(FitWarning::new(
                WarningCode::LargeUncertainty,
                format!(
                    "the standard error of the {} strength is {} {} (more than {}% of its \
                     search range [{lo}, {hi}]): the data do not determine it",
                    e.effect,
                    fmt_g(st.stderr),
                    st.unit,
                    100.0 * LARGE_STDERR_STRENGTH_FRACTION
                ),
            ));
        }
    }
}

fn check_covariance(
    s: &FitSummary,
    have_se: bool,
    corr: Option<&[DMatrix<f64>]>,
    np: usize,
    w: &mut Vec<FitWarning>,
) {
    if !have_se && np > 0 {
        w.push(FitWarning::new(
            WarningCode::SingularCovariance,
            format!(
                "the covariance is singular (J^T J cannot be inverted): the data do not \
                 determine all of the fitted parameters ({}{}); no standard errors or \
                 confidence intervals",
                s.fitted.join(", "),
                if s.estimator == Estimator::Principled {
                    ", take-up factors"
                } else {
                    ""
                }
            ),
        ));
        return;
    }
    let Some(groups) = corr else { return };
    if groups.iter().all(|m| m.iter().all(|v| v.is_finite())) {
        // the worst reciprocal condition number over the checked correlation matrices
        let rcond = groups
            .iter()
            .map(|m| {
                let ev = SymmetricEigen::new(m.clone()).eigenvalues;
                let max = ev.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                let min = ev.iter().fold(f64::INFINITY, |a, v| a.min(v.abs()));
                if max > 0.0 {
                    min / max
                } else {
                    f64::INFINITY
                }
            })
            .fold(f64::INFINITY, f64::min);
        if rcond < ILL_CONDITIONED_RCOND {
            w.push(FitWarning::new(
                WarningCode::IllConditioned,
                format!(
                    "the covariance is ill-conditioned (reciprocal condition number {:.1e} of \
                     the correlation matrix): some combination of the fitted parameters is not \
                     determined by the data; standard errors are unreliable",
                    rcond
                ),
            ));
        }
    } else {
        w.push(FitWarning::new(
            WarningCode::IllConditioned,
            "the correlation matrix of the fitted parameters is not finite: standard errors \
             are unreliable"
                .to_string(),
        ));
    }
}

/// An effect fixed (`--with radiation=2`) at a strength outside its physical range (G02):
/// the fit then rests on a model no spinning line can have; an `unphysical` warning naming the
/// effect, its value and its range ([`Effect::judge`](crate::model::Effect::judge)).
pub(crate) fn check_fixed_effects(s: &FitSummary, w: &mut Vec<FitWarning>) {
    for e in &s.effects {
        if e.strength.fitted {
            continue;
        }
        let Ok(effect) = e.effect.parse::<crate::model::effects::Effect>() else {
            continue;
        };
        if let Some(words) = effect.judge(e.strength.value) {
            let (lo, hi) = effect.physical_range();
            w.push(FitWarning::new(
                WarningCode::Unphysical,
                format!(
                    "{} is fixed outside its physical range [{}, {}]: {words}; the fit rests on \
                     a model no spinning line has (give a value inside the range, or fit it: \
                     --with {})",
                    e.effect,
                    fmt_g(lo),
                    fmt_g(hi),
                    e.effect
                ),
            ));
        }
    }
}

/// Whether `w` is one of this module's warnings about `n` or `κ` as an estimate: at a bound of
/// its range, its standard error or interval too large, an implausible `n` (by the words the
/// checks above and below write). Where the Newtonian law is preferred they are not estimates
/// and these warnings do not apply ([`FitSummary::newtonian_on_data`]).
pub(crate) fn about_the_law_estimate(w: &FitWarning) -> bool {
    let m = w.message.as_str();
    match w.code {
        WarningCode::AtBound | WarningCode::Implausible => {
            m.starts_with("n = ") || m.starts_with("kappa = ")
        }
        WarningCode::LargeUncertainty => [
            "the standard error of n ",
            "the standard error of kappa ",
            "the 95% interval of K ",
            "the 95% interval of n,",
        ]
        .iter()
        .any(|p| m.starts_with(p)),
        _ => false,
    }
}

/// An implausible material law (`n` below [`PLAUSIBLE_N`], at a bound of its range or not:
/// not a result), or a 95 % interval of `n` reaching beyond `[0, 1]` (the law's own range: the
/// linearised interval is not reliable there; a large-uncertainty warning). An `n` at its
/// upper bound 1 is the Newtonian limit, a law a melt can have: the at-bound warning says it.
pub(crate) fn check_law(s: &FitSummary, w: &mut Vec<FitWarning>) {
    let n = &s.n;
    if !n.fitted {
        return;
    }
    let at_bound = s.bound_of("n").is_some();
    if n.value < PLAUSIBLE_N[0] {
        w.push(FitWarning::new(
            WarningCode::Implausible,
            format!(
                "n = {}{} is implausible for a polymer melt (expected {} to {}): the fit \
                 compensates a model error with the viscosity law; this is not a material \
                 result",
                fmt_g(n.value),
                if at_bound {
                    " (at the lower bound of its range)"
                } else {
                    ""
                },
                PLAUSIBLE_N[0],
                PLAUSIBLE_N[1]
            ),
        ));
    } else if !at_bound && n.has_interval() && (n.ci95[0] < 0.0 || n.ci95[1] > 1.0) {
        w.push(FitWarning::new(
            WarningCode::LargeUncertainty,
            format!(
                "the 95% interval of n, [{}, {}], reaches beyond the law's range [0, 1]: the \
                 data do not determine n well enough for a linearised interval",
                fmt_g(n.ci95[0]),
                fmt_g(n.ci95[1])
            ),
        ));
    }
}

/// A law that jumped from the plain fit `base` by more than [`JUMP_SE`] of its standard errors
/// while the fit improved by less than that jump is worth (`z²` in units of the noise
/// variance: moving a parameter `z` standard errors costs `z²`): worth a note (the added
/// effect may buy a different law rather than explain the data; a plain fit biased by a
/// missing effect moves by many of its standard errors too). Returns the jump in standard
/// errors. A plain fit whose own law is implausible (`n` below [`PLAUSIBLE_N`]) is no
/// reference: a refit that moves it clearly into the plausible range (the 95 % interval of
/// its `n` above the lower bound, or its value where it has no interval) is not checked
/// against it.
pub(crate) fn law_jump(base: &FitSummary, refit: &FitSummary) -> Option<(f64, FitWarning)> {
    let lowest = if refit.n.has_interval() {
        refit.n.ci95[0]
    } else {
        refit.n.value
    };
    if base.n.value < PLAUSIBLE_N[0] && lowest >= PLAUSIBLE_N[0] {
        return None;
    }
    let z = |a: &crate::fit::summary::Estimate, b: &crate::fit::summary::Estimate| {
        if a.fitted && b.fitted && a.stderr > 0.0 && a.stderr.is_finite() {
            ((b.value - a.value) / a.stderr).abs()
        } else {
            0.0
        }
    };
    let jump = z(&base.n, &refit.n).max(z(&base.kappa, &refit.kappa));
    let dof = refit
        .residuals
        .saturating_sub(refit.fitted_parameters())
        .max(1) as f64;
    let s2 = refit.cost / dof;
    let gain = (base.cost - refit.cost) / s2;
    if jump > JUMP_SE && gain < jump * jump {
        Some((
            jump,
            FitWarning::new(
                WarningCode::Implausible,
                format!(
                    "the law moved by {:.1} standard errors from the plain fit (n {} -> {}, \
                     kappa {} -> {}) while the fit improved by only {:.1} (in units of the \
                     noise variance; such a move is worth {:.1}): the added effect may buy a \
                     different law rather than explain the data",
                    jump,
                    fmt_g(base.n.value),
                    fmt_g(refit.n.value),
                    fmt_g(base.kappa.value),
                    fmt_g(refit.kappa.value),
                    gain,
                    jump * jump
                ),
            ),
        ))
    } else {
        None
    }
}

/// The fit `fit` ended without a convergence test being met and its linearisation places the
/// optimum at least [`NOT_CONVERGED_CHI2`] lower in `χ²` (not checked under a robust loss,
/// whose steps are taken on rescaled residuals).
pub(crate) fn check_convergence(fit: &FitResult, w: &mut Vec<FitWarning>) {
    let stopped_short = matches!(
        fit.termination,
        Termination::MaxIterations | Termination::Stalled | Termination::RadiusCollapsed
    );
    if !stopped_short {
        return;
    }
    let variance = fit.residual_variance();
    let Some(gain) = fit.gauss_newton_gain() else {
        return;
    };
    let chi2 = 2.0 * gain / variance;
    if chi2.is_nan() || chi2 < NOT_CONVERGED_CHI2 {
        return;
    }
    w.push(FitWarning::new(
        WarningCode::NotConverged,
        format!(
            "the fit ended without converging ({} after {} iterations): its linearisation still \
             places the optimum {chi2:.1} lower in chi^2 (about {:.1} standard errors away, \
             possibly beyond the bounds); the estimates and intervals may belong to a point \
             short of it",
            fit.termination,
            fit.iterations,
            chi2.sqrt()
        ),
    ));
}

/// The misfit against the fit's one noise level, naming the worst experiments.
pub(crate) fn check_misfit(s: &FitSummary, w: &mut Vec<FitWarning>) {
    let rms = s.rms_relative_residual;
    let noise = s.noise.level;
    let (bad, limit) = if noise.is_finite() && noise > 0.0 {
        (rms > MISFIT_RATIO * noise, MISFIT_RATIO * noise)
    } else {
        (rms > MISFIT_WITHOUT_NOISE, MISFIT_WITHOUT_NOISE)
    };
    if !(bad || rms.is_nan()) {
        return;
    }
    let mut worst: Vec<(usize, f64)> = s
        .rms_relative_residual_by_experiment
        .iter()
        .copied()
        .enumerate()
        .filter(|(_, r)| r.is_nan() || *r > limit)
        .collect();
    worst.sort_by(|a, b| b.1.total_cmp(&a.1));
    let names: Vec<String> = worst
        .iter()
        .take(5)
        .map(|(k, r)| {
            let name = s
                .experiments
                .get(*k)
                .cloned()
                .unwrap_or_else(|| format!("#{}", k + 1));
            format!("{name} ({:.3} %)", 100.0 * r)
        })
        .collect();
    let noise_text = if noise.is_finite() && noise > 0.0 {
        format!(
            "{:.1} times the noise level {}",
            rms / noise,
            s.noise.describe()
        )
    } else {
        format!(
            "above {:.0} % (no noise level: too few points to estimate it)",
            100.0 * MISFIT_WITHOUT_NOISE
        )
    };
    let mut m = format!(
        "misfit far above the noise: the RMS relative residual {:.3} % is {noise_text}; the \
         model does not describe these data",
        100.0 * rms
    );
    if !names.is_empty() {
        m.push_str(&format!(
            "; experiments with RMS above {:.3} %: {}{}",
            100.0 * limit,
            names.join(", "),
            if worst.len() > names.len() {
                format!(" and {} more", worst.len() - names.len())
            } else {
                String::new()
            }
        ));
    }
    if s.noise.declared() {
        m.push_str(" (or the declared relative_uncertainty is too small)");
    } else if noise.is_finite() && rms > IMPLAUSIBLE_NOISE_RATIO * noise {
        m.push_str(
            "; the estimated noise level itself is implausibly small: rows without noise \
             (interpolated, smoothed or synthetic) in some files dominate the estimate; thin \
             them or declare relative_uncertainty at the top of the TOML",
        );
    }
    m.push_str(": check their data, TOML entries (temperatures, take-up) and the model");
    w.push(FitWarning::new(WarningCode::Misfit, m));
}

/// A noise level estimated from the residuals below [`NOISE_FREE_LEVEL`]: the data look
/// noise-free, and the intervals, which scale with the noise, are not meaningful (a declared
/// level is the user's statement and is not second-guessed).
pub(crate) fn check_noise_free(s: &FitSummary, w: &mut Vec<FitWarning>) {
    let level = s.noise.level;
    if s.noise.declared() || !(0.0..NOISE_FREE_LEVEL).contains(&level) {
        return;
    }
    w.push(FitWarning::new(
        WarningCode::NoiseFree,
        format!(
            "the data look noise-free: the noise level estimated from the residuals, {} %, is \
             far below any diameter gauge's resolution (synthetic or smoothed data?); standard \
             errors and intervals scale with the noise and are not meaningful here: fit the \
             measured diameters, add realistic noise to synthetic data, or declare the gauge's \
             relative_uncertainty at the top of the TOML",
            fmt_g(100.0 * level)
        ),
    ));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::summary::tests::refit_summary;
    use crate::fit::summary::{AtBound, BoundSide};

    /// Finding D58: a noise level estimated far below a gauge's resolution is warned about
    /// (the level printed), a realistic one is not, and a declared one is the user's word.
    #[test]
    fn noise_free_data_are_said_to_be_noise_free() {
        let mut s = refit_summary("radiation", (0.5, 0.1), (0.8, 0.01), (11.7, 0.05));
        let warned = |s: &FitSummary| {
            let mut w = Vec::new();
            check_noise_free(s, &mut w);
            w
        };
        s.noise.source = crate::data::noise_summary::NoiseSource::Estimated;
        s.noise.level = 2.4e-8;
        let w = warned(&s);
        assert_eq!(w.len(), 1);
        assert_eq!(w[0].code, WarningCode::NoiseFree);
        assert!(w[0].message.contains("2.4000e-6 %"), "{}", w[0].message);
        s.noise.level = 0.0;
        assert_eq!(warned(&s).len(), 1, "an exact fit is noise-free too");
        s.noise.level = 1.2e-5;
        assert!(warned(&s).is_empty(), "1.2e-5 is above the line");
        s.noise.level = 0.015;
        assert!(warned(&s).is_empty());
        s.noise.level = f64::NAN;
        assert!(warned(&s).is_empty(), "no level, no claim");
        s.noise.source = crate::data::noise_summary::NoiseSource::Declared;
        s.noise.level = 1e-8;
        assert!(
            warned(&s).is_empty(),
            "a declared level is not second-guessed"
        );
    }

    /// A refit moved 30 standard errors of the plain fit's `n` with a gain of 100 in units
    /// of the noise variance (worth 900): a jump from a plausible law, none from an
    /// implausible one into the plausible range.
    #[test]
    fn a_law_jump_is_judged_from_a_plausible_plain_fit_only() {
        let mut refit = refit_summary("a", (0.5, 0.1), (0.8, 0.01), (11.7, 0.1));
        refit.residuals = 1001;
        refit.cost = 0.5; // 4 fitted parameters: σ̂² = 0.5 / 997
        let with_base = |n: f64, se: f64| {
            let mut base = refit_summary("a", (0.0, 0.0), (n, se), (11.7, 0.1));
            base.cost = refit.cost + 100.0 * refit.cost / 997.0;
            base
        };
        let (jump, w) = law_jump(&with_base(0.5, 0.01), &refit).expect("a jump from n = 0.5");
        assert!((jump - 30.0).abs() < 1e-9, "{jump}");
        assert_eq!(w.code, WarningCode::Implausible);
        // the plain fit's own n = 0.18 is implausible: no reference to jump from
        assert!(law_jump(&with_base(0.18, 0.01), &refit).is_none());
        // unless the refit's interval reaches below 0.2 (0.24 ± 0.03: [0.18, 0.30])
        let mut edge = refit_summary("a", (0.5, 0.1), (0.24, 0.03), (11.7, 0.1));
        edge.residuals = refit.residuals;
        edge.cost = refit.cost;
        let base = with_base(0.15, 0.003);
        assert!(base.n.value < PLAUSIBLE_N[0] && edge.n.ci95[0] < PLAUSIBLE_N[0]);
        assert!(law_jump(&base, &edge).is_some());
        // a refit that stays implausible is still judged against it (0.10 -> 0.16, 30 se)
        let mut low = refit_summary("a", (0.5, 0.1), (0.16, 0.01), (11.7, 0.1));
        low.residuals = refit.residuals;
        low.cost = refit.cost;
        let (jump, _) = law_jump(&with_base(0.10, 0.002), &low).expect("a jump below 0.2");
        assert!((jump - 30.0).abs() < 1e-6, "{jump}");
    }

    fn at_bound(n: f64, bound: f64, side: BoundSide) -> FitSummary {
        let mut s = refit_summary("a", (0.5, 0.1), (n, 0.0), (15.0, 0.3));
        s.at_bound.push(AtBound {
            parameter: "n".into(),
            side,
            bound,
            value: n,
        });
        s
    }

    /// An `n` that the fit drove to the lower bound of its range (1e-4 at the bound 0: a
    /// strongly hardening melt, a candidate's refit buying the misfit with the law) is as
    /// implausible as one inside the range; the Newtonian limit `n = 1` at the upper bound is
    /// not; a plausible `n` whose interval leaves `[0, 1]` is a large uncertainty.
    #[test]
    fn an_n_below_the_plausible_range_is_implausible_at_its_bound_too() {
        let warnings = |s: &FitSummary| {
            let mut w = Vec::new();
            check_law(s, &mut w);
            w
        };
        let codes = |s: &FitSummary| warnings(s).iter().map(|w| w.code).collect::<Vec<_>>();
        let low = warnings(&at_bound(1.2e-4, 0.0, BoundSide::Lower));
        assert_eq!(low.len(), 1, "{low:?}");
        assert_eq!(low[0].code, WarningCode::Implausible);
        assert!(
            low[0].message.contains("at the lower bound"),
            "{}",
            low[0].message
        );
        assert!(codes(&at_bound(1.0, 1.0, BoundSide::Upper)).is_empty());
        let inside = refit_summary("a", (0.5, 0.1), (0.1, 0.02), (15.0, 0.3));
        assert_eq!(codes(&inside), vec![WarningCode::Implausible]);
        let wide = refit_summary("a", (0.5, 0.1), (0.9, 0.1), (15.0, 0.3));
        assert_eq!(codes(&wide), vec![WarningCode::LargeUncertainty]);
        let fine = refit_summary("a", (0.5, 0.1), (0.6, 0.05), (15.0, 0.3));
        assert!(codes(&fine).is_empty());
    }
}

//! Detection limits: how strong each candidate would have to be for `diagnose` to detect it, and
//! how far an effect just below that limit would move the fitted `(n, κ)`. A clean bill of
//! health must be earned: where the data cannot identify a process condition or an instrument
//! error, the report says how much it could shift the result.
//!
//! **Linearised at strength 0.** A candidate present with strength `s` adds `s c` to the
//! residuals (`c = ∂r/∂s`, its exact sensitivity column, weighted as the residuals are). The
//! refit of the fitted parameters absorbs the part of `c` they can mimic; what is left is the
//! orthogonalised signature `c⊥` (`scores`). With white noise of standard
//! deviation `σ` (in the residuals' units), the cost the candidate removes is
//! `σ² χ²₁(λ)`, a non-central χ² with one degree of freedom and non-centrality
//!
//! ```text
//! λ(s) = s² ‖c⊥‖² / σ².
//! ```
//!
//! The candidate earns its place (is *detected*) when `ΔBIC = N ln(J_after/J_before) + Δk ln N`
//! falls below the earn threshold `t` (−10). The effect itself raises `J_before`: with
//! `J_before = J_rest + ΔJ` (`ΔJ` the cost along `c⊥`, which the candidate removes; `J_rest` the
//! rest, `J_before − score` on the data at hand) the condition is
//! `ΔJ > ΔJ* = J_rest (e^{(Δk ln N − t)/N} − 1)`, and in χ² units `λ* = ΔJ*/σ²`, which for
//! residuals that are noise (`J_rest ≈ N σ²`) and large `N` is `|t| + Δk ln N`. The candidate is
//! then detected
//!
//! * **on average** (probability ≈ 50 %) when `λ = λ*`: `s50 = √λ* σ/‖c⊥‖`;
//! * **with 95 % probability** when `√λ ≥ √λ* + 1.645`: `s95 = (√λ* + 1.645) σ/‖c⊥‖`. This is
//!   an approximation: `χ²₁(λ) = (√λ + Z)²` with `Z ~ N(0, 1)` exceeds `λ*` when
//!   `Z > √λ* − √λ` (probability 95 % at the limit) or `Z < −√λ* − √λ` (negligible here).
//!
//! Being *named* as the most likely missing effect also needs the candidate to beat its rivals:
//! one whose signature is nearly parallel to another's (listed as indistinguishable) may be
//! detected and still lose the ranking to it.
//!
//! Both signs of `s` are symmetric in the linearisation. The limits are a guide for the process
//! and instrument candidates (whose effect on the diameters is close to linear over their
//! realistic range); they are cruder for the co-flow and other effects whose finite-size
//! signature differs from the first-order one (the global search of `diagnose` can find those
//! above the limit, and sometimes below it). Where an undetected effect would move a fitted
//! parameter by many standard errors, the 95 % limit is optimistic (on the independent
//! simulator's data a gauge offset at its `s95`, which moves `n` by 8 standard errors, was
//! detected on 3 of 5 noise seeds; `tests/detection_limits.rs`).
//!
//! **What an undetected effect does to the result.** The fit that leaves out an effect present
//! with strength `s` is biased by `−s dθ/dq`, with `dθ/dq = −(JᵀJ)⁻¹ Jᵀ c` the error budget's
//! exact propagation (`ParameterShift`); the report
//! gives that bias of `n` and `κ` at `s = +s95` (a negative strength reverses the sign), in
//! absolute units and in units of the fit's statistical standard error.

use super::scores::LinearScore;
use crate::model::effects::Effect;
use serde::{Deserialize, Serialize};

/// The one-sided 95 % quantile of the standard normal distribution.
pub(crate) const Z95_ONE_SIDED: f64 = 1.644_853_626_951_472_2;

/// One candidate's detection limit (JSON: an entry of `detection.limits`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DetectionLimit {
    /// Canonical name of the candidate.
    pub effect: String,
    /// Unit of the strengths `s50`, `s95` (the candidate's unit; `"-"`: relative).
    pub unit: String,
    /// `"physics"`, `"process"`, `"instrument"` or `"material"`.
    pub category: String,
    /// Extra parameters `Δk` the candidate costs in `ΔBIC`.
    pub extra_parameters: usize,
    /// `λ*`: the non-centrality (χ² units) at which the candidate is detected on average.
    pub required_chi2: f64,
    /// `‖c⊥‖/σ`: the square root of `λ` per unit strength \[1/unit\].
    pub chi_per_unit: f64,
    /// Strength detected with probability ≈ 50 % (magnitude; either sign) \[unit\].
    pub s50: f64,
    /// Strength detected with probability ≈ 95 % (magnitude; either sign) \[unit\].
    pub s95: f64,
    /// Bias of the fitted `n` when the data carry strength `+1 unit` the model leaves out
    /// \[1/unit\] (`null` where `n` is not fitted).
    pub dn_per_unit: Option<f64>,
    /// Bias of the fitted `κ` per unit of undetected strength \[1/unit\] (also the relative
    /// bias of `K`).
    pub dkappa_per_unit: Option<f64>,
    /// Bias of `n` at an undetected strength `+s95` (a negative strength reverses the sign).
    pub shift_n_at_s95: Option<f64>,
    /// Bias of `κ` at an undetected strength `+s95`.
    pub shift_kappa_at_s95: Option<f64>,
    /// `|shift_n_at_s95|` in units of the statistical standard error of `n`.
    pub shift_n_se: Option<f64>,
    /// `|shift_kappa_at_s95|` in units of the statistical standard error of `κ`.
    pub shift_kappa_se: Option<f64>,
}

/// The detection limits of a diagnosis (JSON: `detection`).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct DetectionLimits {
    /// Noise level `σ` the limits use (relative, \[-\]).
    pub noise_level: f64,
    /// Number of measurements `N`.
    pub measurements: usize,
    /// The earn threshold of `ΔBIC` (−10 by default).
    pub earn_threshold: f64,
    /// Per candidate with a visible signature, in the order of the diagnosis' options
    /// (not ranked).
    pub limits: Vec<DetectionLimit>,
    /// Candidates whose signature vanishes once the fitted parameters adapt (no strength
    /// can be detected, e.g. `strain_thinning` in a Carreau-type fit).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub invisible: Vec<String>,
    /// Why the shifts of the law are not given (`null`: they are): the user's `n` or `κ` at a
    /// bound of its range, where the fit's linearisation does not hold and its standard errors
    /// are not valid.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shifts_withheld: Option<String>,
}

/// What the limits need beyond the candidates' signatures.
#[derive(Debug, Clone, Copy)]
pub struct DetectionContext {
    /// Noise standard deviation in the residuals' units (the relative noise level divided by
    /// the residuals' weight `σ_w`: 1 when the data set declares its uncertainty).
    pub sigma: f64,
    /// The relative noise level \[-\] (reported).
    pub noise_level: f64,
    /// How many times `sigma` the noise a smooth signature picks up is \[-\]: 1 for white
    /// noise, `√((1 + ρ)/(1 − ρ))` for noise correlated along the line
    /// ([`NoiseModel::variance_inflation`](crate::data::noise_model::NoiseModel::variance_inflation)).
    /// It widens the margin between `s50` and `s95`.
    pub long_run_factor: f64,
    /// `J` of the user's fit.
    pub cost_before: f64,
    /// Number of measurements `N`.
    pub measurements: usize,
    /// The earn threshold of `ΔBIC` (negative).
    pub threshold: f64,
    /// Statistical standard error of `n` (NaN if not fitted).
    pub stderr_n: f64,
    /// Statistical standard error of `κ`.
    pub stderr_kappa: f64,
    /// Why the shifts of the law are withheld (`None`: they are computed), see
    /// [`DetectionLimits::shifts_withheld`].
    pub shifts_withheld: Option<&'static str>,
}

/// `ΔJ*`: the cost a candidate must remove to bring `ΔBIC = N ln(J_after/J_before) + Δk ln N`
/// down to `threshold`, where `J_before = cost_rest + ΔJ` (`cost_rest`: the cost the candidate
/// does not carry).
pub(crate) fn required_reduction(cost_rest: f64, n: usize, threshold: f64, extra: usize) -> f64 {
    let nf = n.max(1) as f64;
    let penalty = extra as f64 * nf.ln();
    cost_rest * ((penalty - threshold) / nf).exp_m1()
}

/// `(s50, s95)` for a signature `‖c⊥‖ = norm` per unit strength, noise `sigma` (both in the
/// residuals' units) and the non-centrality `lambda_star` at which the candidate is detected on
/// average (infinite where the signature vanishes).
pub(crate) fn strength_limits(norm: f64, sigma: f64, lambda_star: f64) -> (f64, f64) {
    if !(norm > 0.0 && norm.is_finite()) {
        return (f64::INFINITY, f64::INFINITY);
    }
    let root = lambda_star.max(0.0).sqrt();
    (root * sigma / norm, (root + Z95_ONE_SIDED) * sigma / norm)
}

/// The detection limits of `effects` (with their `extra` parameters, linearised `scores` and
/// fitted-parameter derivatives `dtheta[i] = dθ/ds`, columns `n_col`, `kappa_col` of `θ`).
pub fn detection_limits(
    effects: &[Effect],
    extra: &[usize],
    scores: &[LinearScore],
    dtheta: &[Vec<f64>],
    cols: (Option<usize>, Option<usize>),
    ctx: &DetectionContext,
) -> DetectionLimits {
    let mut out = DetectionLimits {
        noise_level: ctx.noise_level,
        measurements: ctx.measurements,
        earn_threshold: ctx.threshold,
        limits: Vec::new(),
        invisible: Vec::new(),
        shifts_withheld: ctx.shifts_withheld.map(str::to_string),
    };
    for (i, e) in effects.iter().enumerate() {
        let (Some(l), Some(&k)) = (scores.get(i), extra.get(i)) else {
            continue;
        };
        let rest = (ctx.cost_before - l.score).max(0.0);
        let lambda_star =
            required_reduction(rest, ctx.measurements, ctx.threshold, k) / (ctx.sigma * ctx.sigma);
        let (s50, s95) = strength_limits(l.norm, ctx.sigma, lambda_star);
        let s95 = s50 + (s95 - s50) * ctx.long_run_factor;
        let sigma_known = ctx.sigma > 0.0 && ctx.sigma.is_finite();
        if !s95.is_finite() || !sigma_known {
            out.invisible.push(e.name().to_string());
            continue;
        }
        // the bias of leaving out strength +1 is −dθ/ds
        let per = |c: Option<usize>| {
            c.filter(|_| ctx.shifts_withheld.is_none())
                .and_then(|c| dtheta.get(i).and_then(|d| d.get(c)))
                .map(|v| -v)
        };
        let (dn, dk) = (per(cols.0), per(cols.1));
        let in_se = |v: Option<f64>, se: f64| {
            v.filter(|_| se > 0.0 && se.is_finite())
                .map(|v| (v * s95).abs() / se)
        };
        out.limits.push(DetectionLimit {
            effect: e.name().to_string(),
            unit: e.unit().to_string(),
            category: e.category().name().to_string(),
            extra_parameters: k,
            required_chi2: lambda_star,
            chi_per_unit: l.norm / ctx.sigma,
            s50,
            s95,
            dn_per_unit: dn,
            dkappa_per_unit: dk,
            shift_n_at_s95: dn.map(|v| v * s95),
            shift_kappa_at_s95: dk.map(|v| v * s95),
            shift_n_se: in_se(dn, ctx.stderr_n),
            shift_kappa_se: in_se(dk, ctx.stderr_kappa),
        });
    }
    out
}

impl DetectionLimit {
    /// A strength of this candidate in words: relative process and instrument strengths in %
    /// (`"4.1 %"`), others in their unit (`"3.2 K"`, `"0.21"`).
    pub fn strength_words(&self, s: f64) -> String {
        match (self.unit.as_str(), self.category.as_str()) {
            ("-", "process" | "instrument") => format!("{} %", sig3(100.0 * s)),
            ("-", _) => sig3(s),
            (u, _) => format!("{} {u}", sig3(s)),
        }
    }

    /// The larger of the two biases at `s95`, in standard errors (0 if neither is known).
    pub fn worst_shift_se(&self) -> f64 {
        self.shift_n_se
            .unwrap_or(0.0)
            .max(self.shift_kappa_se.unwrap_or(0.0))
    }
}

impl DetectionLimits {
    /// The limits as a compact table: `[[What these data could have missed ...]]`.
    pub fn to_text(&self) -> String {
        if self.limits.is_empty() && self.invisible.is_empty() {
            return String::new();
        }
        let mut s = format!(
            "[[What these data could have missed: detection limits (noise {:.3} %, N = {}, detected \
             when delta BIC < {}; linearised at strength 0, both signs alike; a guide for the \
             process and instrument candidates, cruder for co-flow)]]\n",
            100.0 * self.noise_level,
            self.measurements,
            self.earn_threshold
        );
        s.push_str(&format!(
            "    {:<22} {:<9} {:>13} {:>13}  {:<17} {}\n",
            "effect", "category", "detected 50 %", "detected 95 %", "shift n at s95", "shift kappa"
        ));
        let shift = |v: Option<f64>, se: Option<f64>| match (v, se) {
            (Some(v), Some(se)) => format!("{} ({se:.1} se)", signed(v)),
            (Some(v), None) => signed(v),
            _ => "-".into(),
        };
        for l in &self.limits {
            s.push_str(&format!(
                "    {:<22} {:<9} {:>13} {:>13}  {:<17} {}\n",
                l.effect,
                l.category,
                l.strength_words(l.s50),
                l.strength_words(l.s95),
                shift(l.shift_n_at_s95, l.shift_n_se),
                shift(l.shift_kappa_at_s95, l.shift_kappa_se)
            ));
        }
        if !self.invisible.is_empty() {
            s.push_str(&format!(
                "    not detectable at all (the fitted parameters absorb them): {}\n",
                self.invisible.join(", ")
            ));
        }
        if let Some(why) = &self.shifts_withheld {
            s.push_str(&format!("    no shifts of the law: {why}\n"));
        }
        s.push_str(
            "(detected 50 %/95 %: the strength at which the candidate's own refit earns its \
             place with that probability, sqrt(lambda) >= sqrt(lambda*) + 1.645 for 95 %; \
             being named first also needs it to beat the rivals the data cannot tell apart \
             from it; shifts: the bias of the fit that leaves out an effect of +s95, in units \
             of the statistical standard error; a negative strength reverses the sign.)\n",
        );
        s
    }

    /// In words, for a diagnosis that names nothing: "These data would reveal (95 %):
    /// die_temperature_offset >= 3.1 K, …; an undetected die_temperature_offset of 3.1 K would
    /// shift kappa by … (… se)". `None` without process or instrument limits.
    pub fn words(&self) -> Option<String> {
        let pi: Vec<&DetectionLimit> = self
            .limits
            .iter()
            .filter(|l| l.category != "physics")
            .collect();
        if pi.is_empty() {
            return None;
        }
        let reveal: Vec<String> = pi
            .iter()
            .map(|l| format!("{} >= {}", l.effect, l.strength_words(l.s95)))
            .collect();
        let mut s = format!("These data would reveal (95 %): {}.", reveal.join(", "));
        let mut risky: Vec<&&DetectionLimit> =
            pi.iter().filter(|l| l.worst_shift_se() > 0.0).collect();
        risky.sort_by(|a, b| b.worst_shift_se().total_cmp(&a.worst_shift_se()));
        let parts: Vec<String> = risky
            .iter()
            .take(2)
            .map(|l| {
                let mut what = Vec::new();
                if let (Some(v), Some(se)) = (l.shift_kappa_at_s95, l.shift_kappa_se) {
                    what.push(format!("kappa by {v:+.4} ({se:.1} se)"));
                }
                if let (Some(v), Some(se)) = (l.shift_n_at_s95, l.shift_n_se) {
                    what.push(format!("n by {v:+.4} ({se:.1} se)"));
                }
                format!(
                    "an undetected {} of {} would shift {}",
                    l.effect,
                    l.strength_words(l.s95),
                    what.join(" and ")
                )
            })
            .collect();
        if !parts.is_empty() {
            let joined = parts.join("; ");
            let mut chars = joined.chars();
            let capital: String = chars
                .next()
                .map(|c| c.to_uppercase().chain(chars).collect())
                .unwrap_or_default();
            s.push_str(&format!(" {capital}."));
        }
        Some(s)
    }
}

/// A shift with its sign: four decimals where that is readable (`+0.0123`), else three
/// significant digits in scientific notation (`+2.960e13`).
fn signed(v: f64) -> String {
    if v.abs() < 1e3 {
        format!("{v:+.4}")
    } else {
        format!("{v:+.3e}")
    }
}

/// `v` with three significant digits.
pub(crate) fn sig3(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i64).clamp(0, 10) as usize;
    if v.abs() >= 1e5 || v.abs() < 1e-4 {
        format!("{v:.2e}")
    } else {
        format!("{v:.digits$}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// P(χ²₁(λ) > λ*) by the normal representation, Φ from a Simpson integral of the density.
    fn detection_probability(lambda: f64, lambda_star: f64) -> f64 {
        let phi = |z: f64| {
            // Φ(z) = 1/2 + ∫₀^z φ
            let n = 2000;
            let h = z / n as f64;
            let f = |t: f64| (-0.5 * t * t).exp() / (2.0 * std::f64::consts::PI).sqrt();
            let mut s = f(0.0) + f(z);
            for i in 1..n {
                s += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
            }
            0.5 + s * h / 3.0
        };
        let (a, b) = (lambda.sqrt(), lambda_star.sqrt());
        phi(a - b) + phi(-a - b)
    }

    #[test]
    fn limits_scale_with_the_noise_and_inversely_with_the_signature() {
        let (s50, s95) = strength_limits(2.0, 0.5, 16.0);
        // hand numbers: √16 · 0.5 / 2 = 1, (4 + 1.645) · 0.5 / 2
        assert!((s50 - 1.0).abs() < 1e-15);
        assert!((s95 - (4.0 + Z95_ONE_SIDED) * 0.25).abs() < 1e-15);
        for f in [0.1, 3.0, 17.0] {
            let (a50, a95) = strength_limits(2.0, 0.5 * f, 16.0);
            assert!((a50 / s50 - f).abs() < 1e-12 && (a95 / s95 - f).abs() < 1e-12);
            let (b50, b95) = strength_limits(2.0 * f, 0.5, 16.0);
            assert!((b50 * f / s50 - 1.0).abs() < 1e-12 && (b95 * f / s95 - 1.0).abs() < 1e-12);
        }
        assert_eq!(strength_limits(0.0, 0.5, 16.0).1, f64::INFINITY);
    }

    #[test]
    fn required_reduction_inverts_delta_bic() {
        let (rest, n, t) = (250.0, 234usize, -10.0);
        for k in [1usize, 2, 3] {
            let dj = required_reduction(rest, n, t, k);
            let nf = n as f64;
            // J_before = rest + ΔJ*, J_after = rest
            let bic = nf * (rest / (rest + dj)).ln() + k as f64 * nf.ln();
            assert!((bic - t).abs() < 1e-9, "ΔBIC at the limit {bic}");
            // residuals that are noise (J = N σ², σ = 1) and large N: |t| + Δk ln N
            let big = 1_000_000usize;
            let lam = required_reduction(big as f64, big, t, k);
            let approx = 10.0 + k as f64 * (big as f64).ln();
            assert!((lam / approx - 1.0).abs() < 1e-3, "{lam} vs {approx}");
        }
    }

    #[test]
    fn s95_is_detected_with_probability_near_95_percent() {
        for lambda_star in [10.0, 15.45, 30.0] {
            let (s50, s95) = strength_limits(1.0, 1.0, lambda_star);
            let p95 = detection_probability(s95 * s95, lambda_star);
            assert!((0.95 - 1e-9..0.96).contains(&p95), "p(s95) = {p95}");
            let p50 = detection_probability(s50 * s50, lambda_star);
            assert!((0.5 - 1e-9..0.52).contains(&p50), "p(s50) = {p50}");
        }
    }

    #[test]
    fn limits_and_biases_from_hand_made_numbers() {
        let effects = [
            Effect::DieTemperatureOffset,
            Effect::MassFlowScale,
            Effect::StrainThinning,
        ];
        let score = |norm: f64, score: f64| LinearScore {
            score,
            strength: 0.0,
            norm,
            signature: Vec::new(),
        };
        let scores = [score(4.0, 40.0), score(100.0, 40.0), score(0.0, 0.0)];
        // θ = (n, κ, take-up): dθ/ds
        let dtheta = vec![
            vec![0.001, -0.05, 0.0],
            vec![0.2, 3.0, 0.0],
            vec![0.0, 0.0, 0.0],
        ];
        let ctx = DetectionContext {
            sigma: 2.0,
            long_run_factor: 1.0,
            noise_level: 0.02,
            cost_before: 400.0,
            measurements: 100,
            threshold: -10.0,
            stderr_n: 0.01,
            stderr_kappa: 0.1,
            shifts_withheld: None,
        };
        let d = detection_limits(
            &effects,
            &[1, 1, 2],
            &scores,
            &dtheta,
            (Some(0), Some(1)),
            &ctx,
        );
        assert_eq!(d.invisible, ["strain_thinning"]);
        assert_eq!(d.limits.len(), 2);
        let die = &d.limits[0];
        // J_rest = J_before − the candidate's score
        let lam = required_reduction(360.0, 100, -10.0, 1) / 4.0;
        assert!((die.required_chi2 - lam).abs() < 1e-12);
        assert!((die.s95 - (lam.sqrt() + Z95_ONE_SIDED) * 2.0 / 4.0).abs() < 1e-12);
        assert_eq!(die.dkappa_per_unit, Some(0.05));
        assert!((die.shift_kappa_at_s95.unwrap() - 0.05 * die.s95).abs() < 1e-15);
        assert!((die.shift_kappa_se.unwrap() - 0.5 * die.s95).abs() < 1e-12);
        assert!((die.shift_n_se.unwrap() - 0.1 * die.s95).abs() < 1e-12);
        let mf = &d.limits[1];
        assert_eq!(mf.category, "process");
        assert_eq!(mf.strength_words(0.0412), "4.12 %");
        assert_eq!(die.strength_words(3.216), "3.22 K");
        assert!((mf.s95 / die.s95 - 4.0 / 100.0).abs() < 1e-12);
        // a user's law at a bound: the limits stand, the shifts of the law are withheld
        let why = "n at a bound";
        let held = detection_limits(
            &effects,
            &[1, 1, 2],
            &scores,
            &dtheta,
            (Some(0), Some(1)),
            &DetectionContext {
                shifts_withheld: Some(why),
                ..ctx
            },
        );
        assert_eq!(held.limits[0].s95, die.s95);
        assert!(held.limits.iter().all(|l| l.shift_n_at_s95.is_none()
            && l.shift_kappa_se.is_none()
            && l.worst_shift_se() == 0.0));
        let text = held.to_text();
        assert!(
            text.contains("no shifts of the law: n at a bound"),
            "{text}"
        );
        assert!(!text.contains("se)"), "{text}");
        assert_eq!(signed(0.01234), "+0.0123");
        assert_eq!(signed(-2.96e13), "-2.960e13");
    }
}

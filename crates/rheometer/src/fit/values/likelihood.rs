//! What the likelihood says beyond the linearised standard errors, as values: the
//! profile-likelihood interval of a fitted parameter ([`ProfileInterval`], its refits
//! [`ProfilePoint`] and a one-sided bound [`OneSidedBound`]), and the likelihood-ratio test
//! against the nested Newtonian law ([`NewtonianTest`], with the strain thinning the data still
//! allow, [`ThinningBound`]). A fit's summary holds them;
//! [`profile`](crate::fit::uncertainty::profile) computes them.

use crate::fit::options::BoundSide;
use crate::model::effects::LawChoice;
use serde::{Deserialize, Serialize};

/// One refit of a profile (JSON: `{"value": 0.81, "deviance": 0.9, "law": [0.81, 11.70]}`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProfilePoint {
    /// The held value of the parameter (in its reported unit).
    pub value: f64,
    /// Deviance `D = (J − J_min)/σ̂²` \[-\].
    pub deviance: f64,
    /// The law's parameters `(n, κ)` of the refit.
    pub law: Vec<f64>,
}

/// A one-sided 95 % bound (JSON: `{"side": "lower", "bound": 0.96}`: `n > 0.96`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OneSidedBound {
    /// `lower`: the parameter is above `bound`; `upper`: below it.
    pub side: BoundSide,
    /// The bound (reported unit).
    pub bound: f64,
}

/// The profile-likelihood interval of one fitted parameter (JSON: an entry of `intervals`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProfileInterval {
    /// `"n"`, `"kappa"` or an effect's name.
    pub parameter: String,
    /// Unit of the values (`"-"`, the effect's strength unit).
    pub unit: String,
    /// Why the linearised interval is not trusted (`"at_bound"`, `"correlation"`,
    /// `"curved_profile"`); empty: it is, and agrees with this one.
    #[serde(default)]
    pub reasons: Vec<String>,
    /// The 95 % profile interval (`NaN` where the profile stays below 3.84 to the end of the
    /// search range; at a bound that end is the bound).
    #[serde(deserialize_with = "crate::report::serde_nan::pair")]
    pub ci95: [f64; 2],
    /// The one-sided 95 % bound (deviance 2.71) of an estimate at a bound of its search range,
    /// or of one whose interval stays open towards an end of the range (the data are
    /// compatible with that end, e.g. `n` up to the Newtonian 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub one_sided95: Option<OneSidedBound>,
    /// The search range (reported unit).
    pub search_range: [f64; 2],
    /// Largest relative departure of the deviance at the linearised ends from 3.84 (`NaN`
    /// without a linearised interval).
    #[serde(deserialize_with = "crate::report::serde_nan::f64")]
    pub quadratic_departure: f64,
    /// The refits, the optimum first.
    pub points: Vec<ProfilePoint>,
}

impl ProfileInterval {
    /// Whether the linearised interval is trusted (no reason against it).
    pub fn linearised_trusted(&self) -> bool {
        self.reasons.is_empty()
    }

    /// The points within the two-sided 95 % deviance plus the interpolated ends: the law along
    /// the profile that the data support.
    pub fn trace(&self, level: f64) -> Vec<Vec<f64>> {
        trace_of(&self.points, level)
    }
}

/// The laws of the refits `points` within deviance `level` plus the interpolated crossings of
/// it (ordered by the held value).
pub(crate) fn trace_of(points: &[ProfilePoint], level: f64) -> Vec<Vec<f64>> {
    let mut out: Vec<Vec<f64>> = Vec::new();
    let mut pts: Vec<&ProfilePoint> = points.iter().collect();
    pts.sort_by(|a, b| a.value.total_cmp(&b.value));
    for w in pts.windows(2) {
        let (a, b) = (w[0], w[1]);
        if a.deviance <= level {
            out.push(a.law.clone());
        }
        // the crossing of the level between a and b (linear in √D)
        let (za, zb) = (a.deviance.max(0.0).sqrt(), b.deviance.max(0.0).sqrt());
        let zc = level.sqrt();
        if (za - zc) * (zb - zc) < 0.0 && a.law.len() == b.law.len() {
            let f = (zc - za) / (zb - za);
            out.push(
                a.law
                    .iter()
                    .zip(&b.law)
                    .map(|(x, y)| x + f * (y - x))
                    .collect(),
            );
        }
    }
    if let Some(last) = pts.last() {
        if last.deviance <= level {
            out.push(last.law.clone());
        }
    }
    out
}

/// The likelihood-ratio test of the fit against the nested Newtonian law (JSON:
/// `newtonian_test`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NewtonianTest {
    /// `LR = (J_N − J)/σ̂²` \[-\].
    pub statistic: f64,
    /// The p-value the decision uses \[-\]: `½ P(χ²₁ > LR)` (boundary mixture), or where
    /// that is below the level but not far below it, the calibrated one (see
    /// `p_mixture`; `profile` explains both).
    pub p_value: f64,
    /// Where `p_value` is calibrated: the boundary mixture's `½ P(χ²₁ > LR)` \[-\], which
    /// `κ`, not identified under the Newtonian law, makes too small.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub p_mixture: Option<f64>,
    /// Where `p_value` is calibrated: the simulated replicates of its reference distribution
    /// (the largest one-sided score for strain thinning over a grid of `κ`, under the
    /// Newtonian fit) \[-\]; 0: not calibrated.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub calibration_replicates: usize,
    /// RMS relative residual of the Newtonian refit \[-\].
    pub rms_newtonian: f64,
    /// The law the test prefers: Newtonian when `p ≥ 0.05`.
    pub preferred: LawChoice,
    /// Where the Newtonian law is preferred: why `n` and `κ` are not estimates (the law is
    /// Newtonian within the data's strain rates, at `n = 1` and at `n → 0` with `K` beyond
    /// the data's stresses alike: the fit's point is one of many such laws). Absent: they
    /// are estimates.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub law_not_estimated: Option<String>,
    /// Where the Newtonian law is preferred: how much strain thinning the data still allow.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thinning_bound: Option<ThinningBound>,
}

fn is_zero(v: &usize) -> bool {
    *v == 0
}

/// The one-sided 95 % lower bound on `n` for strain thinning that sets in within the strain
/// rates the data cover: the profile of `n` from the Newtonian `n = 1` down, with `κ` refitted
/// below `ln(η_E0(T_ref)·ε̇_max)`, where `η_E0(T_ref)` is the Newtonian plateau at the coverage's
/// temperature and `ε̇_max` its largest reduced strain rate (the Carreau-type law thins from
/// `η_E0 ε̇ ≈ K` on). Without that restriction `n` is not bounded: a `K` beyond the data makes
/// any `n` Newtonian over them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ThinningBound {
    /// `n` is above this (one-sided 95 %: deviance 2.71); `NaN`: not bounded above 0.
    #[serde(deserialize_with = "crate::report::serde_nan::f64")]
    pub n_lower95: f64,
    /// The largest `K = η_E0(T_ref)·ε̇_max` \[Pa\] allowed in the refits.
    pub k_max_pa: f64,
    /// The refits, `n = 1` first.
    pub points: Vec<ProfilePoint>,
    /// The one-sided 95 % lower bound on where the strongest thinning a polymer melt shows
    /// (`n = 0.2`; at `n → 0` the law bounds the stress by `K` and the fiber does not solve)
    /// sets in: `K_min/η_E0(T_ref)` \[1/s\] at the coverage's temperature, `K_min` where the
    /// deviance of the refits with `n` held there, `κ` walked down from beyond the data's
    /// stresses, reaches 2.71 (`None`: not reached, or not computed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub onset_lower95_per_s: Option<f64>,
    /// The refits of the onset's walk (`n` held at 0.2; value: `κ`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub onset_points: Vec<ProfilePoint>,
}

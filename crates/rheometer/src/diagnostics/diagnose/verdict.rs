//! Stage 11: the verdict — what the diagnosis may say.
//!
//! * An effect is named as missing only when it earns its place (credible strength and law,
//!   `ΔBIC` below the threshold), is unlikely to be a false alarm of the search over all
//!   candidates (`calibrate`), and removes at least
//!   `MIN_SHARE_OF_EXCESS` of the excess misfit (the cost above what the noise alone
//!   leaves).
//! * It is *the* explanation only when, with the named effects, the residuals are at the noise:
//!   RMS within `EXPLAINED_RMS_OVER_NOISE` of the noise level and no structure along the line
//!   (lag-1 autocorrelation `ρ₁ √pairs` below 3). Otherwise the verdict is "none of the
//!   candidates": which ones help and how much, and where along the line (and in which
//!   experiments) the unexplained residual lies — a user-written effect is the next step.
//!   It is "none of the candidates" too where the named effects bring the residuals to the
//!   noise only with a strength that differs between the experiments (the stage
//!   `consistency`): they stand in for something else.
//! * Where a candidate within the tie margin of the result (credible, or refused only for a
//!   strength outside its physical range or at a search bound), or a pair of candidates fitted
//!   jointly within the look-elsewhere margin (see [`pair`](crate::diagnostics::refits::pair)),
//!   explains the data about as well with a law outside the result's intervals, the verdict
//!   is "ambiguous":
//!   the data cannot tell the explanations apart, and the law is not a result (the range all
//!   span is given; see the stage `ambiguity`).

use crate::data::noise_model::NoiseModel;
use crate::data::noise_summary::NoiseSummary;
use crate::diagnostics::compare::segments::{find_segments, Segment, SegmentOptions};
use crate::fit::FitSummary;
use serde::{Deserialize, Serialize};

/// Share of the excess misfit an effect must remove to be named \[-\].
pub(crate) const MIN_SHARE_OF_EXCESS: f64 = 0.5;

/// RMS over the noise level at or below which the residuals are at the noise \[-\].
pub(crate) const EXPLAINED_RMS_OVER_NOISE: f64 = 1.2;

/// The lag-1 structure ([`NoiseModel::lag1_z`](crate::data::noise_model::NoiseModel::lag1_z),
/// standard errors) at or above which the residuals keep a structure along the line.
pub(crate) const STRUCTURE_Z: f64 = 3.0;

/// A candidate that helps: how much of the excess misfit it removes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Help {
    /// The effect.
    pub effect: String,
    /// Share of the excess misfit it removes \[-\] (1: all of it).
    pub share_of_excess: f64,
    /// Its `ΔBIC`.
    pub delta_bic: f64,
}

/// A stretch of the spin line where the residual stays systematic after the best candidates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Unexplained {
    /// Start \[m\].
    pub start_m: f64,
    /// End \[m\].
    pub end_m: f64,
    /// Mean relative residual there \[-\] (positive: the model too thick).
    pub mean: f64,
    /// Its size in standard errors.
    pub z: f64,
    /// The experiments with a residual of that sign there.
    pub experiments: Vec<String>,
}

/// What the diagnosis concludes (JSON: `{"kind": "explained", ...}`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Verdict {
    /// The residuals are consistent with the noise and no candidate earns its place.
    Adequate,
    /// The named effects bring the residuals to the noise.
    Explained {
        /// The effects, in the order they were found.
        effects: Vec<String>,
        /// RMS (outliers excluded) over the noise level with them \[-\].
        rms_over_noise: f64,
        /// The noise level of the verdict (relative \[-\]): the data's, or re-estimated with
        /// the named effects where lower (see `noise_for`).
        #[serde(default)]
        noise_level: f64,
    },
    /// The named effects bring the residuals to the noise, but explanations the data cannot
    /// tell apart from them (a candidate tied with the named one, a pair fitted jointly within
    /// the look-elsewhere margin) disagree on the material law: the cause is not determined and
    /// the law is not a result (see `ambiguity`).
    Ambiguous {
        /// The forward search's effects, in the order they were found.
        effects: Vec<String>,
        /// The other explanations whose law disagrees, each as its effects (one tied
        /// candidate, or a pair fitted jointly).
        alternatives: Vec<Vec<String>>,
        /// RMS (outliers excluded) over the noise level with `effects` \[-\].
        rms_over_noise: f64,
        /// The noise level of the verdict (relative \[-\], see `noise_for`).
        noise_level: f64,
        /// Where `n` lies over all these explanations' 95 % intervals \[-\].
        n_range: [f64; 2],
        /// Where `κ = ln K` lies over all these explanations' 95 % intervals (`K` in Pa·s).
        kappa_range: [f64; 2],
    },
    /// Something is missing that none of the candidates describes (or describes only in part).
    NoneOfTheCandidates {
        /// The candidates that help, most first (named ones included).
        helps: Vec<Help>,
        /// Where the residual stays systematic with the best of them.
        unexplained: Vec<Unexplained>,
        /// RMS (outliers excluded) over the noise level with the best of them \[-\].
        rms_over_noise: f64,
        /// The noise level of the verdict (relative \[-\], see `noise_for`).
        #[serde(default)]
        noise_level: f64,
        /// Named effects that bring the residuals to the noise, but only with a strength that
        /// differs between the experiments (stage `consistency`): stand-ins for an effect none
        /// of the candidates describes (empty where the residuals are not at the noise).
        #[serde(default)]
        stand_ins: Vec<crate::diagnostics::refits::consistency::Consistency>,
    },
}

impl Verdict {
    /// The short name of the verdict's kind, as in JSON (`"adequate"`, `"explained"`,
    /// `"ambiguous"`, `"none_of_the_candidates"`).
    pub fn kind(&self) -> &'static str {
        match self {
            Verdict::Adequate => "adequate",
            Verdict::Explained { .. } => "explained",
            Verdict::Ambiguous { .. } => "ambiguous",
            Verdict::NoneOfTheCandidates { .. } => "none_of_the_candidates",
        }
    }

    /// Whether the verdict leaves the material law of the final fit a result: not under
    /// "none of the candidates" (the law is biased by what is missing) nor "ambiguous" (two
    /// explanations disagree on it).
    pub fn law_is_a_result(&self) -> bool {
        matches!(self, Verdict::Adequate | Verdict::Explained { .. })
    }
}

/// `J` the noise alone leaves after fitting `q` parameters to `n` residuals of noise level
/// `sd` each (the fit's residual units).
pub(crate) fn noise_cost(sd: &[f64], q: usize) -> f64 {
    let n = sd.len().max(1) as f64;
    let s2: f64 = sd.iter().map(|v| v * v).sum();
    s2 * (n - q as f64).max(1.0) / n
}

/// The share of the excess misfit `J_before − J_noise` a refit to `J_after` removes (0 when
/// there is no excess).
pub(crate) fn share_of_excess(before: f64, after: f64, j_noise: f64) -> f64 {
    let excess = before - j_noise;
    if excess > 0.0 {
        ((before - after) / excess).clamp(0.0, f64::INFINITY)
    } else {
        0.0
    }
}

/// The noise level the verdict on `fit` uses: a declared level as declared; an estimated one
/// re-estimated from `fit`'s own residuals where that is lower — the plain model's misfit
/// inflates a noise estimate (second differences of residuals with a strong systematic part),
/// and an inflated level would call a poor fit "at the noise".
///
/// The noise's along-line correlation is the data's, decided once on the user's fit (`base`):
/// a refit's residuals do not decide it again (a wrong explanation's leftover misfit could pass
/// for correlated noise). `fit`'s own level is compared, and used, as it would be with the
/// data's correlation.
pub(crate) fn noise_for(fit: &FitSummary, base: &NoiseSummary) -> NoiseSummary {
    let rho = base.correlation();
    let own = fit.noise.correlation();
    let level = fit.noise.level * NoiseModel::level_factor(rho) / NoiseModel::level_factor(own);
    if base.declared() || level.partial_cmp(&base.level) != Some(std::cmp::Ordering::Less) {
        base.clone()
    } else {
        let mut noise = fit.noise.clone();
        noise.level = level;
        if let Some(m) = noise.model.as_mut() {
            m.correlation_used = rho;
        }
        noise
    }
}

/// RMS (outliers excluded) of `fit`'s residuals over the data's noise level `noise` and the
/// lag-1 structure statistic of its residuals against the data's correlation.
pub(crate) fn at_noise(fit: &FitSummary, noise: &NoiseSummary) -> (f64, f64) {
    let m = fit.noise.model.as_ref();
    let rms = m.map_or(fit.rms_relative_residual, |m| m.rms);
    let lag1_z = m.map_or(0.0, |m| m.lag1_z_against(noise.correlation()));
    (rms / noise.level, lag1_z)
}

/// Whether `fit` leaves residuals at the noise (see the module documentation; the noise level
/// of `noise_for`).
pub(crate) fn explained(fit: &FitSummary, noise: &NoiseSummary) -> bool {
    explained_within(fit, noise, 1.0)
}

/// [`explained`] with both limits `slack` times as wide (a screening fit solved less
/// accurately: `slack` ≥ 1).
pub(crate) fn explained_within(fit: &FitSummary, noise: &NoiseSummary, slack: f64) -> bool {
    let noise = noise_for(fit, noise);
    let (ratio, z) = at_noise(fit, &noise);
    let limit = noise.model.as_ref().map_or(EXPLAINED_RMS_OVER_NOISE, |m| {
        m.misfit_ratio_limit(EXPLAINED_RMS_OVER_NOISE)
    });
    ratio <= slack * limit && z < slack * STRUCTURE_Z
}

/// Where the residuals of `profiles` (positions and relative residuals per experiment, named
/// `names`) stay systematic at the noise level `sigma`: the segments of the pooled residual
/// ([`find_segments`]). Where the pooled residual has none, because the experiments' residuals
/// differ in sign at one position (an effect whose strength changes with the runs), each
/// experiment is searched on its own, and its segments are listed with it alone, strongest
/// first, at most [`MAX_PER_EXPERIMENT_SEGMENTS`].
pub(crate) fn unexplained(
    profiles: &[(Vec<f64>, Vec<f64>)],
    names: &[String],
    sigma: f64,
) -> Vec<Unexplained> {
    let options = SegmentOptions::default();
    let pooled: Vec<Unexplained> = find_segments(profiles, sigma, &options)
        .into_iter()
        .map(|seg| {
            let experiments = seg
                .per_experiment
                .iter()
                .filter(|(_, v)| (*v > 0.0) == (seg.mean > 0.0))
                .map(|(k, _)| name_of(names, *k))
                .collect();
            located(&seg, experiments)
        })
        .collect();
    if !pooled.is_empty() {
        return pooled;
    }
    let mut own: Vec<Unexplained> = profiles
        .iter()
        .enumerate()
        .flat_map(|(k, profile)| {
            let name = name_of(names, k);
            find_segments(std::slice::from_ref(profile), sigma, &options)
                .into_iter()
                .map(move |seg| located(&seg, vec![name.clone()]))
        })
        .collect();
    own.sort_by(|a, b| b.z.abs().total_cmp(&a.z.abs()));
    own.truncate(MAX_PER_EXPERIMENT_SEGMENTS);
    own
}

/// Experiment `k`'s name in `names` (`#k` if there is none).
fn name_of(names: &[String], k: usize) -> String {
    names.get(k).cloned().unwrap_or_else(|| format!("#{k}"))
}

/// The segment `seg` as an unexplained stretch of `experiments`.
fn located(seg: &Segment, experiments: Vec<String>) -> Unexplained {
    Unexplained {
        start_m: seg.start_m,
        end_m: seg.end_m,
        mean: seg.mean,
        z: seg.z,
        experiments,
    }
}

/// The most segments [`unexplained`] lists from the experiments searched one by one.
pub(crate) const MAX_PER_EXPERIMENT_SEGMENTS: usize = 6;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn residuals_of_opposite_sign_in_two_runs_are_located_run_by_run() {
        // 0.00, 0.01, ..., 0.50 m; +3 % in run a and -3 % in run b over 0.10-0.20 m, zero
        // elsewhere: the pooled residual cancels, each run alone is 9.9 standard errors off
        let s: Vec<f64> = (0..=50).map(|i| 0.01 * i as f64).collect();
        let bump = |sign: f64| -> Vec<f64> {
            s.iter()
                .map(|&x| {
                    if (0.095..0.205).contains(&x) {
                        sign * 0.03
                    } else {
                        0.0
                    }
                })
                .collect()
        };
        let profiles = vec![(s.clone(), bump(1.0)), (s.clone(), bump(-1.0))];
        let names = vec!["a".to_string(), "b".to_string()];
        assert!(find_segments(&profiles, 0.01, &SegmentOptions::default()).is_empty());
        let u = unexplained(&profiles, &names, 0.01);
        assert_eq!(u.len(), 2, "{u:?}");
        for seg in &u {
            assert!((seg.start_m - 0.10).abs() < 0.006 && (seg.end_m - 0.20).abs() < 0.006);
            assert!((seg.mean.abs() - 0.03).abs() < 1e-12 && seg.z.abs() > 9.0);
            let run = if seg.mean > 0.0 { "a" } else { "b" };
            assert_eq!(seg.experiments, vec![run.to_string()]);
        }
        // where the runs agree, the pooled segment is reported with both
        let same = vec![(s.clone(), bump(1.0)), (s.clone(), bump(1.0))];
        let u = unexplained(&same, &names, 0.01);
        assert_eq!(u.len(), 1);
        assert_eq!(u[0].experiments, names);
        // white noise stays unlocated
        let flat = vec![(s.clone(), vec![0.0; s.len()]), (s, vec![0.0; 51])];
        assert!(unexplained(&flat, &names, 0.01).is_empty());
    }

    #[test]
    fn shares_of_the_excess() {
        // J 300 with noise cost 100: a refit to 150 removes 3/4 of the excess
        assert!((share_of_excess(300.0, 150.0, 100.0) - 0.75).abs() < 1e-15);
        assert_eq!(share_of_excess(90.0, 80.0, 100.0), 0.0);
        let sd = vec![0.5; 100];
        assert!((noise_cost(&sd, 10) - 0.25 * 90.0).abs() < 1e-12);
    }

    #[test]
    fn an_ambiguous_verdict_leaves_no_law_a_result_and_says_so_in_json() {
        let v = Verdict::Ambiguous {
            effects: vec!["air_coflow_line".into()],
            alternatives: vec![vec!["air_temperature_profile".into(), "radiation".into()]],
            rms_over_noise: 1.01,
            noise_level: 0.015,
            n_range: [0.744, 0.813],
            kappa_range: [11.47, 12.13],
        };
        assert!(!v.law_is_a_result());
        let json = serde_json::to_value(&v).unwrap();
        assert_eq!(json["kind"], v.kind());
        assert_eq!(json["kind"], "ambiguous");
        assert_eq!(json["n_range"][1], 0.813);
        assert_eq!(serde_json::from_value::<Verdict>(json).unwrap(), v);
        assert!(Verdict::Adequate.law_is_a_result());
        let explained = Verdict::Explained {
            effects: vec!["radiation".into()],
            rms_over_noise: 1.0,
            noise_level: 0.015,
        };
        assert!(explained.law_is_a_result());
        for v in [&Verdict::Adequate, &explained] {
            assert_eq!(serde_json::to_value(v).unwrap()["kind"], v.kind());
        }
        let none = Verdict::NoneOfTheCandidates {
            helps: vec![],
            unexplained: vec![],
            rms_over_noise: 2.0,
            noise_level: 0.015,
            stand_ins: vec![],
        };
        assert!(!none.law_is_a_result());
        assert_eq!(serde_json::to_value(&none).unwrap()["kind"], none.kind());
        // a file written before the consistency stage reads with no stand-ins
        let old = serde_json::json!({"kind": "none_of_the_candidates", "helps": [],
            "unexplained": [], "rms_over_noise": 2.0, "noise_level": 0.015});
        assert_eq!(serde_json::from_value::<Verdict>(old).unwrap(), none);
    }
}

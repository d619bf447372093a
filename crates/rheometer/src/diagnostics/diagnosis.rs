//! The result of a diagnosis: what is written as JSON ([`Diagnosis`]) and what figures and
//! the next step need besides ([`DiagnosisRun`]).

use super::calibration::Calibration;
use super::candidate::{Candidate, Indistinguishable};
use super::detection::DetectionLimits;
use super::diagnose::verdict::Verdict;
use super::ties::Alternative;
use crate::fit::{FitSummary, Identification, IdentifyOptions};
use crate::model::effects::LawChoice;
use diffbvp::least_squares::Loss;
use serde::{Deserialize, Serialize};

/// Relative residuals along the spin line, per experiment: `(name, [(s in m, residual)])`.
pub type ResidualProfiles = Vec<(String, Vec<(f64, f64)>)>;

/// How the robust loss of `diagnose --loss` weighted the points: the user's model fitted
/// with the loss, each point then given the weight the loss gives it at that fit (its
/// residual's `ρ'`, against the local noise where the noise varies along the line), and every
/// further fit of the diagnosis a least-squares fit with these weights (so that its evidence,
/// `ΔBIC`, stays a Gaussian likelihood ratio). Each further step weights the points again from
/// its own fit.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RobustWeights {
    /// The loss.
    pub loss: Loss,
    /// Its soft margin `C`, a relative residual \[-\].
    pub f_scale: f64,
    /// Where `f_scale` came from (given, or the robust noise scale of the data).
    pub f_scale_source: String,
    /// Points beyond the soft margin (`|r| > C`, against the local noise), which the loss
    /// down-weights.
    pub down_weighted: usize,
    /// All points.
    pub points: usize,
    /// The smallest weight of a point relative to an ordinary one (`ρ'`, 1 inside the margin)
    /// \[-\].
    pub smallest_weight: f64,
}

impl RobustWeights {
    /// The weights in words.
    pub fn words(&self) -> String {
        format!(
            "Loss {}: the points are weighted as the robust fit of your model weights them \
             (soft margin {:.3} % relative residual, {}); {} of {} points lie beyond it and are \
             down-weighted (the smallest weight {:.3}); every fit of the diagnosis uses these \
             weights.",
            self.loss,
            100.0 * self.f_scale,
            self.f_scale_source,
            self.down_weighted,
            self.points,
            self.smallest_weight
        )
    }
}

/// The diagnosis (what is written as JSON).
///
/// The noise level the judgement uses is the user's plain fit's,
/// [`base_fit`](Self::base_fit)`.noise.level`: the same number `rheometer fit` prints for the
/// same data and model. The residual statistics (RMS over the noise, lag-1 autocorrelation,
/// outliers) are those of the fit the diagnosis judges: the user's model with its points
/// weighted by the local noise and the gross outliers left out (or weighted by a robust loss),
/// which `fit` prints too where the noise is even and there are no outliers.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Diagnosis {
    /// The user's law.
    pub model: LawChoice,
    /// The user's fit (principled estimator), with its one noise level.
    pub base_fit: FitSummary,
    /// How a robust loss weighted the points (`None`: least squares, the gross outliers of
    /// the noise model left out).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robust: Option<RobustWeights>,
    /// Whether the residuals are systematic: `rms_over_noise > 1.2`, or `ρ₁ √N > 3` (both
    /// widened for noise correlated along the line), or a candidate's refit lowers BIC below
    /// the threshold with a false-alarm probability within the limit (named or not: a strength
    /// or shape at a bound is not credible, but the misfit it removes is real).
    pub systematic: bool,
    /// The candidates, best first.
    pub candidates: Vec<Candidate>,
    /// Pairs of candidates with nearly parallel signatures.
    pub indistinguishable: Vec<Indistinguishable>,
    /// The best single candidate that may be named (the first step's, best by `ΔBIC`), if one
    /// earns its place. A pair that explains the data better ([`pair`](Self::pair)) replaces
    /// it in [`found`](Self::found). Under an ambiguous verdict it is one of the explanations
    /// the data cannot tell apart, and under "none of the candidates" a stand-in or a partial
    /// explanation (the report says which), not the cause.
    pub most_likely_missing: Option<String>,
    /// Other candidates about as consistent with the data as the named one: they earn their
    /// place too, with a `ΔBIC` less than the tie margin above the named one's (best first;
    /// empty when nothing is named or nothing ties; see `ties`).
    #[serde(default)]
    pub alternatives: Vec<Alternative>,
    /// What these data could have missed: per candidate, the strength named with 50 % and
    /// 95 % probability (linearised at strength 0) and the shift of `(n, κ)` an undetected
    /// effect of the 95 % strength would cause (`detection`).
    #[serde(default)]
    pub detection: DetectionLimits,
    /// The look-elsewhere calibration of the first step: the null distribution of the best
    /// `ΔBIC` over all candidates and shapes on effect-free data like these.
    #[serde(default)]
    pub calibration: Calibration,
    /// The steps after the first: each with the effects found before in the model.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub further_steps: Vec<ForwardStep>,
    /// The effects found, in order (the first is `most_likely_missing`, unless a pair replaced
    /// the forward search's result).
    #[serde(default)]
    pub found: Vec<String>,
    /// The best pair of candidates fitted jointly (stage 9b), where one qualifies: it replaces
    /// the forward search's result when better by more than its
    /// [`replace_margin`](super::refits::pair::PairFound::replace_margin) in `ΔBIC` (`found` then
    /// lists it), else it is reported beside it (with its fit), and where the two laws disagree the
    /// law is no result.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pair: Option<super::refits::pair::PairFound>,
    /// The fit with all found effects (fitted jointly), if any was found.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub final_fit: Option<FitSummary>,
    /// For each found effect, whether its strength in the final fit is the same in every
    /// experiment (stage `consistency`; empty where the test cannot be done).
    #[serde(default)]
    pub consistency: Vec<super::refits::consistency::Consistency>,
    /// Why the forward search stopped before its last step, where a step failed (the effects
    /// found before it stand; `None` where every step ran).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
    /// What the diagnosis concludes.
    pub verdict: Verdict,
    /// Wall time \[s\].
    pub wall_time_s: f64,
    /// Where the wall time went, stage by stage (reports written before it was kept: zeros).
    #[serde(default)]
    pub stage_times: StageTimes,
}

/// Where a diagnosis spent its wall time \[s\], stage by stage, the steps of the forward search
/// summed: what to look at when a diagnosis is slow (the stages run their candidates, shapes
/// and starts in parallel, so these are wall times, not CPU times).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct StageTimes {
    /// The fits each step starts from (the user's model, then with the effects found), with
    /// the noise model's weights \[s\].
    pub fits_s: f64,
    /// The linearisation at those fits, the detection limits and the look-elsewhere
    /// calibration \[s\].
    pub linearised_s: f64,
    /// The profile scans of the candidates' strengths \[s\].
    pub scans_s: f64,
    /// The refits of the scans' best points, from several laws \[s\].
    pub refits_s: f64,
    /// The pairs of candidates fitted jointly \[s\].
    pub pairs_s: f64,
    /// Everything else: judging, ties, the final fit's checks, the report's parts \[s\].
    pub rest_s: f64,
}

impl StageTimes {
    /// The sum of the stages the steps timed (all but the pairs and the rest) \[s\].
    pub(crate) fn steps_s(&self) -> f64 {
        self.fits_s + self.linearised_s + self.scans_s + self.refits_s
    }

    /// Adds the stage times of a step.
    pub(crate) fn add(&mut self, o: &StageTimes) {
        self.fits_s += o.fits_s;
        self.linearised_s += o.linearised_s;
        self.scans_s += o.scans_s;
        self.refits_s += o.refits_s;
    }
}

/// A step of the forward search after the first: the model with the effects found so far,
/// its fit, the remaining candidates ranked, and the one named.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ForwardStep {
    /// The effects in the model at this step (found before, fitted).
    pub model_effects: Vec<String>,
    /// The step's fit.
    pub base_fit: FitSummary,
    /// Its candidates, best first.
    pub candidates: Vec<Candidate>,
    /// The candidate named at this step.
    pub named: Option<String>,
}

impl Diagnosis {
    /// The candidate named `effect`, if it was a candidate.
    pub fn candidate(&self, effect: &str) -> Option<&Candidate> {
        self.candidates.iter().find(|c| c.effect == effect)
    }

    /// The named cause's record, if one earns its place.
    pub fn named(&self) -> Option<&Candidate> {
        self.most_likely_missing
            .as_deref()
            .and_then(|n| self.candidate(n))
    }

    /// The fit whose law the diagnosis reports: the final fit (with the found effects) where
    /// there is one, else the user's.
    pub fn law_fit(&self) -> &FitSummary {
        self.final_fit.as_ref().unwrap_or(&self.base_fit)
    }

    /// The law parameter (`n` or `kappa`) of [`law_fit`](Self::law_fit) at a bound of its
    /// range, if any: such a law has no valid interval and is no material result, whatever
    /// the verdict (a 300 m/s aspirator's co-flow "explained" the data with `κ` at its lower
    /// bound 7, `K` a hundred times below the truth).
    pub fn law_at_bound(&self) -> Option<&crate::fit::AtBound> {
        self.law_fit().law_at_bound()
    }

    /// Whether the reported law `(n, κ)` may be used as a result: no reason in
    /// [`law_not_a_result`](Self::law_not_a_result). Python's `Diagnosis.law_is_a_result`
    /// reads that reason from the JSON.
    pub fn law_is_a_result(&self) -> bool {
        self.law_not_a_result().is_none()
    }

    /// Why the reported law (that of [`law_fit`](Self::law_fit)) is not a result, if it is
    /// not: the verdict leaves none (the misfit is not explained, or is explained only by an
    /// effect whose strength differs between the experiments, or another explanation as good
    /// disagrees on the law: [`Verdict::law_is_a_result`](super::diagnose::verdict::Verdict::law_is_a_result)),
    /// or the fit's own rule ([`FitSummary::law_not_a_result`]: `n` or `κ` at a bound of its
    /// range, e.g. a 300 m/s aspirator's co-flow "explaining" the data with `κ` at its lower
    /// bound 7, `K` a hundred times below the truth; an implausible law, e.g. an "adequate"
    /// plain fit with `n` near 0). The text report's "NOT A RESULT" words; the JSON
    /// ([`Diagnosis::json`]) writes them as `law_not_a_result`.
    pub fn law_not_a_result(&self) -> Option<String> {
        let why = match self.verdict {
            Verdict::NoneOfTheCandidates { ref stand_ins, .. } if !stand_ins.is_empty() => {
                "the effect's strength differs between the experiments: a stand-in, see the verdict"
            }
            Verdict::NoneOfTheCandidates { .. } => "the misfit is not explained, see the verdict",
            Verdict::Ambiguous { .. } => {
                "another explanation as good disagrees on the law, see the verdict"
            }
            // the fit's own rule (a bound, an implausible warning): the one the fit's report,
            // figures and page apply
            Verdict::Adequate | Verdict::Explained { .. } => {
                return self.law_fit().law_not_a_result();
            }
        };
        Some(why.to_string())
    }

    /// Why the law of the user's model ([`base_fit`](Self::base_fit)) is not a result, if it
    /// is not: where the diagnosis found effects, the model lacks them (the law with them is
    /// the final fit's, see [`law_not_a_result`](Self::law_not_a_result)); else the reported
    /// law's reason, the user's fit being the reported one. The JSON writes it as
    /// `base_law_not_a_result`.
    pub fn base_law_not_a_result(&self) -> Option<String> {
        if self.final_fit.is_none() {
            return self.law_not_a_result();
        }
        Some(format!(
            "your model lacks the effects the diagnosis found ({}); the law with them is the \
             final fit's",
            self.found.join(" + ")
        ))
    }

    /// The diagnosis as its JSON is written (`rheometer diagnose --json`, `diagnosis.json`,
    /// Python's `Diagnosis.diagnosis`): every field of [`Diagnosis`] and, derived at writing,
    /// `law_not_a_result` and `base_law_not_a_result` (the reasons above, `null` where the law
    /// is a result), so that a reader of the JSON applies the library's rule without
    /// repeating it. Reading the JSON back ignores the two.
    pub fn json(&self) -> DiagnosisJson<'_> {
        DiagnosisJson {
            diagnosis: self,
            law_not_a_result: self.law_not_a_result(),
            base_law_not_a_result: self.base_law_not_a_result(),
        }
    }

    /// The noise level the judgement used \[-\] (the base fit's).
    pub fn noise_level(&self) -> f64 {
        self.base_fit.noise.level
    }

    /// RMS relative residual of the user's fit (outliers excluded) over the noise level \[-\].
    pub fn rms_over_noise(&self) -> f64 {
        self.base_fit.noise.rms_over_noise
    }

    /// Pooled lag-1 autocorrelation of the noise-normalised residuals of the user's fit
    /// (about zero, outliers excluded; `NaN` without a noise model) \[-\].
    pub fn lag1_autocorrelation(&self) -> f64 {
        self.base_fit
            .noise
            .model
            .as_ref()
            .map_or(f64::NAN, |m| m.lag1)
    }

    /// Gross outliers by experiment and position, of the final fit (with the found effects)
    /// where there is one, else of the user's fit: a point that only looks wrong to a model
    /// missing an effect is no outlier.
    pub fn outliers(&self) -> &[crate::data::noise_model::Outlier] {
        self.law_fit()
            .noise
            .model
            .as_ref()
            .map_or(&[], |m| &m.outliers)
    }
}

/// What a diagnosis' JSON holds ([`Diagnosis::json`]): the diagnosis and the reasons derived
/// from it.
#[derive(Debug, Serialize)]
pub struct DiagnosisJson<'a> {
    #[serde(flatten)]
    diagnosis: &'a Diagnosis,
    law_not_a_result: Option<String>,
    base_law_not_a_result: Option<String>,
}

/// A diagnosis with the data for figures.
#[derive(Debug, Clone)]
pub struct DiagnosisRun {
    /// The numbers.
    pub diagnosis: Diagnosis,
    /// Residuals of the user's fit.
    pub residuals_before: ResidualProfiles,
    /// Residuals after adding the named candidate.
    pub residuals_after: Option<ResidualProfiles>,
    /// The user's fit.
    pub base: Identification,
    /// The fit with all found effects (fitted jointly; the final fit).
    pub best: Option<Identification>,
    /// The fit settings the diagnosis used (principled estimator, the noise weights of its
    /// last step): a fit that continues from the diagnosis uses them.
    pub fit_options: IdentifyOptions,
}

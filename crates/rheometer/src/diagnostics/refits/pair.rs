//! A pair of candidate effects fitted jointly ([`PairFound`]) and how it is judged against the
//! forward search's result (the search itself is `diagnose::pairs`).
//!
//! * **Replacement** needs `ΔBIC` lower than the forward search's result by more than
//!   `replace_margin`: the tie margin plus `2 ln M` for the `M` pairs tried. The best of `M`
//!   pairs is the winner of a search, and giving each pair a prior weight `1/M` against the
//!   forward search's one result is what makes a spurious pair rare: on a die-offset set of the
//!   power study the best of 36 pairs (Nusselt factor + radiation) beat the true single effect
//!   by 9.1 with `n` 5 standard errors off.
//! * **Within the margin** the pair is reported beside the result. Where the two laws disagree
//!   (either estimate of `n` or `κ` outside the other's 95 % interval), the data cannot tell
//!   which law is right, and neither is a result.

use crate::fit::FitSummary;
use serde::{Deserialize, Serialize};

/// The best pair of candidates fitted jointly, judged against the forward search's result.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PairFound {
    /// The two effects (the one that helps more alone first).
    pub effects: [String; 2],
    /// `ΔBIC` of the pair against the user's model.
    pub delta_bic: f64,
    /// `ΔBIC` of the pair against each member alone (same order as `effects`: against the
    /// first alone, against the second alone).
    pub delta_bic_against_single: [f64; 2],
    /// Starts of the pair's joint fit.
    pub starts: usize,
    /// Starts that reached the kept optimum (relative `J` within 1e-4).
    pub starts_at_optimum: usize,
    /// Pairs fitted in all.
    pub pairs_tried: usize,
    /// `ΔBIC` against the user's model of what the forward search found (0 if nothing).
    pub delta_bic_of_steps: f64,
    /// `ΔBIC` gap by which the pair must beat the forward search's result to replace it
    /// (`replace_margin`).
    #[serde(default)]
    pub replace_margin: f64,
    /// Whether the pair replaces the forward search's result; otherwise it is an explanation
    /// the data do not clearly separate from it, reported beside it.
    pub replaces: bool,
    /// `n` of the pair's fit and of the forward search's final fit, where the two
    /// explanations disagree on the law (`laws_disagree`): the law is then no result.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub laws_disagree: Option<[f64; 2]>,
    /// The pair's fit where it does not replace the forward search's result (where it does,
    /// it is the diagnosis' final fit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit: Option<FitSummary>,
}

/// `ΔBIC` against the user's model (cost `j0`, `n` residuals) of a fit with cost `j` and `k`
/// extra parameters.
pub fn delta_bic(n: f64, j0: f64, j: f64, k: usize) -> f64 {
    n * (j / j0).ln() + k as f64 * n.ln()
}

/// The `ΔBIC` gap a pair must beat the forward search's result by to replace it: the tie
/// margin plus `2 ln M` for `M` pairs tried (each pair's prior weight `1/M`).
pub(crate) fn replace_margin(tie_margin: f64, pairs_tried: usize) -> f64 {
    tie_margin + 2.0 * (pairs_tried.max(1) as f64).ln()
}

/// The pair against the forward search's result (`ΔBIC` `steps_dbic`, final fit `steps_fit`
/// if any effect was found): `None` when the pair is worse by more than the tie margin (or
/// nothing was found and the pair does not clear [`replace_margin`]), else the pair with
/// [`PairFound::replaces`] and [`PairFound::laws_disagree`] set.
pub(crate) fn against_steps(
    mut pair: PairFound,
    steps_dbic: f64,
    steps_fit: Option<&FitSummary>,
    tie_margin: f64,
    pair_fit: &FitSummary,
) -> Option<PairFound> {
    pair.delta_bic_of_steps = steps_dbic;
    pair.replace_margin = replace_margin(tie_margin, pair.pairs_tried);
    if pair.delta_bic >= steps_dbic + tie_margin {
        return None;
    }
    pair.replaces = pair.delta_bic < steps_dbic - pair.replace_margin;
    let steps_fit = match steps_fit {
        Some(f) => f,
        None if pair.replaces => return Some(pair),
        None => return None,
    };
    if !pair.replaces {
        pair.laws_disagree =
            laws_disagree(steps_fit, pair_fit).then_some([pair_fit.n.value, steps_fit.n.value]);
        pair.fit = Some(pair_fit.clone());
    }
    Some(pair)
}

/// Whether two fits' laws disagree: either's `n` or `κ` outside the other's 95 % interval.
pub(crate) fn laws_disagree(a: &FitSummary, b: &FitSummary) -> bool {
    let outside = |v: f64, ci: [f64; 2]| v < ci[0] || v > ci[1];
    outside(a.n.value, b.n.ci95)
        || outside(b.n.value, a.n.ci95)
        || outside(a.kappa.value, b.kappa.ci95)
        || outside(b.kappa.value, a.kappa.ci95)
}

/// The union of the 95 % intervals of `n` and of `κ` over `fits`: where the law lies when the
/// data cannot choose between them.
pub(crate) fn law_envelope_of<'a>(fits: impl IntoIterator<Item = &'a FitSummary>) -> [[f64; 2]; 2] {
    let mut n = [f64::INFINITY, f64::NEG_INFINITY];
    let mut k = n;
    for f in fits {
        n = [n[0].min(f.n.ci95[0]), n[1].max(f.n.ci95[1])];
        k = [k[0].min(f.kappa.ci95[0]), k[1].max(f.kappa.ci95[1])];
    }
    [n, k]
}

/// The sentence on explanations that disagree on the law: the result's `n` (`result`, the
/// named effects), each rival's (`rivals`: its label, e.g. its effects, and its fit), the range
/// all span, and that none of the laws is a result.
pub(crate) fn disagreement(result: &FitSummary, rivals: &[(String, &FitSummary)]) -> String {
    let [n, k] = law_envelope_of(rivals.iter().map(|(_, f)| *f).chain([result]));
    let laws: Vec<String> = rivals
        .iter()
        .map(|(label, f)| format!("{:.3} with {label}", f.n.value))
        .collect();
    format!(
        "explanations of the data that the diagnosis cannot tell apart disagree on the material \
         law (n = {:.3} with the named effects, {}): {} law is a result; over all, n lies in \
         [{:.3}, {:.3}] and kappa in [{:.2}, {:.2}] (95 % intervals)",
        result.n.value,
        laws.join(", "),
        if rivals.len() == 1 { "neither" } else { "no" },
        n[0],
        n[1],
        k[0],
        k[1]
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::summary::tests::example;

    fn pair(dbic: f64) -> PairFound {
        PairFound {
            effects: ["a".into(), "b".into()],
            delta_bic: dbic,
            delta_bic_against_single: [-20.0, -20.0],
            starts: 3,
            starts_at_optimum: 3,
            pairs_tried: 36,
            delta_bic_of_steps: 0.0,
            replace_margin: 0.0,
            replaces: false,
            laws_disagree: None,
            fit: None,
        }
    }

    fn with_n(n: f64, half_width: f64) -> FitSummary {
        let mut s = example();
        s.n.value = n;
        s.n.ci95 = [n - half_width, n + half_width];
        s
    }

    #[test]
    fn a_pair_replaces_only_beyond_the_look_elsewhere_margin_and_flags_disagreeing_laws() {
        // 36 pairs tried: margin 6 + 2 ln 36 = 13.17
        assert!((replace_margin(6.0, 36) - 13.167).abs() < 1e-3);
        let steps = with_n(0.758, 0.014);
        let (near, far) = (with_n(0.765, 0.02), with_n(0.789, 0.024));
        // nothing found by the steps: a pair beyond the margin replaces, one within is dropped
        let p = against_steps(pair(-30.0), 0.0, None, 6.0, &far).unwrap();
        assert!(p.replaces && p.fit.is_none() && p.laws_disagree.is_none());
        assert!(against_steps(pair(-10.0), 0.0, None, 6.0, &far).is_none());
        // better by more than the margin: replaces, the law is the pair's
        let p = against_steps(pair(-46.0), -31.4, Some(&steps), 6.0, &far).unwrap();
        assert!(p.replaces && p.laws_disagree.is_none());
        assert_eq!(p.delta_bic_of_steps, -31.4);
        // better by 10.1, within the margin: beside it, and the laws disagree (0.789 is outside
        // [0.744, 0.772]) although the intervals overlap
        let p = against_steps(pair(-41.5), -31.4, Some(&steps), 6.0, &far).unwrap();
        assert!(!p.replaces && p.fit.is_some());
        assert_eq!(p.laws_disagree, Some([0.789, 0.758]));
        // worse by more than the tie margin: not reported
        assert!(against_steps(pair(-20.0), -31.4, Some(&steps), 6.0, &far).is_none());
        // as good, each law inside the other's interval: beside it, no warning
        let p = against_steps(pair(-33.0), -31.4, Some(&steps), 6.0, &near).unwrap();
        assert!(!p.replaces && p.laws_disagree.is_none());
    }

    #[test]
    fn delta_bic_counts_cost_and_parameters() {
        let n: f64 = 234.0;
        // the radiation + warm air pair against the user's fit (3 extra parameters)
        let d = delta_bic(n, 5.3045e-2, 4.1428e-2, 3);
        assert!((d - (n * (4.1428f64 / 5.3045).ln() + 3.0 * n.ln())).abs() < 1e-12);
        assert!(d < -41.0 && d > -42.0, "{d}");
        assert_eq!(delta_bic(n, 1.0, 1.0, 0), 0.0);
    }
}

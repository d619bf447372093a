//! A pair of candidate effects fitted jointly ([`PairFound`]) and how it is judged against the
//! forward search's result: `ΔBIC` against the user's model, replacement beyond the tie
//! margin, and disagreeing laws within it (the search itself is
//! `diagnose::pairs`).

use crate::fiber::rheometer::FitSummary;
use serde::{Deserialize, Serialize};

/// The pair named by the joint search.
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
    /// Whether the pair replaces the forward search's result (lower `ΔBIC` by more than the
    /// tie margin); otherwise it is an equally good explanation beside it.
    pub replaces: bool,
    /// `n` of the pair's fit and of the forward search's final fit, where the two
    /// explanations disagree on it (95 % intervals apart): the law is then no result.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub laws_disagree: Option<[f64; 2]>,
    /// The pair's fit where it does not replace the forward search's result (where it does,
    /// it is the diagnosis' final fit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit: Option<FitSummary>,
}

/// `ΔBIC` against the user's model (cost `j0`, `n` residuals) of a fit with cost `j` and `k`
/// extra parameters.
pub(crate) fn delta_bic(n: f64, j0: f64, j: f64, k: usize) -> f64 {
    n * (j / j0).ln() + k as f64 * n.ln()
}

/// The pair against the forward search's result (`ΔBIC` `steps_dbic`, final fit `steps_fit`
/// if any effect was found): `None` when the pair is worse by more than the tie margin, else
/// the pair with [`PairFound::replaces`] and [`PairFound::laws_disagree`] set.
pub(crate) fn against_steps(
    mut pair: PairFound,
    steps_dbic: f64,
    steps_fit: Option<&FitSummary>,
    tie_margin: f64,
    pair_fit: &FitSummary,
) -> Option<PairFound> {
    pair.delta_bic_of_steps = steps_dbic;
    if pair.delta_bic >= steps_dbic + tie_margin {
        return None;
    }
    pair.replaces = steps_fit.is_none() || pair.delta_bic < steps_dbic - tie_margin;
    if !pair.replaces {
        pair.laws_disagree = steps_fit
            .filter(|f| laws_disagree(f, pair_fit))
            .map(|f| [pair_fit.n.value, f.n.value]);
        pair.fit = Some(pair_fit.clone());
    }
    Some(pair)
}

/// Whether two fits' `n` disagree: their 95 % intervals do not overlap.
pub(crate) fn laws_disagree(a: &FitSummary, b: &FitSummary) -> bool {
    a.n.ci95[1] < b.n.ci95[0] || b.n.ci95[1] < a.n.ci95[0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fiber::rheometer::summary::tests::example;

    fn pair(dbic: f64) -> PairFound {
        PairFound {
            effects: ["a".into(), "b".into()],
            delta_bic: dbic,
            delta_bic_against_single: [-20.0, -20.0],
            starts: 3,
            starts_at_optimum: 3,
            pairs_tried: 45,
            delta_bic_of_steps: 0.0,
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
    fn a_pair_replaces_only_when_clearly_better_and_flags_disagreeing_laws() {
        let steps = with_n(0.758, 0.014);
        let (near, far) = (with_n(0.770, 0.02), with_n(0.789, 0.012));
        // nothing found by the steps: any qualifying pair replaces
        let p = against_steps(pair(-30.0), 0.0, None, 6.0, &far).unwrap();
        assert!(p.replaces && p.fit.is_none() && p.laws_disagree.is_none());
        // clearly better (by more than the tie margin): replaces, the law is the pair's
        let p = against_steps(pair(-41.5), -31.4, Some(&steps), 6.0, &far).unwrap();
        assert!(p.replaces && p.laws_disagree.is_none());
        assert_eq!(p.delta_bic_of_steps, -31.4);
        // worse by more than the margin: not reported
        assert!(against_steps(pair(-20.0), -31.4, Some(&steps), 6.0, &far).is_none());
        // as good, same law: beside it, no warning
        let p = against_steps(pair(-33.0), -31.4, Some(&steps), 6.0, &near).unwrap();
        assert!(!p.replaces && p.laws_disagree.is_none() && p.fit.is_some());
        // as good, intervals apart: the law is no result
        let p = against_steps(pair(-28.0), -31.4, Some(&steps), 6.0, &far).unwrap();
        assert_eq!(p.laws_disagree, Some([0.789, 0.758]));
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

//! Stage 5: per candidate, the refit to report — the best with the discrete shapes (scanned,
//! not fitted: the co-flow's tail) at their defaults, unless the best with other values is
//! better by more than the tie margin — and the other one where the data cannot choose.

use super::base::Context;
use super::linear::linearise::Linearisation;
use super::search::{discrete_shapes_at_defaults, Refined, Scans};
use crate::diagnostics::refits::scan::Refit;
use crate::model::effects::Effect;

/// A candidate's chosen refit with the variant it belongs to.
pub(crate) type Choice = (Effect, Refit);

/// Per candidate: the refit to report and the other shape's best refit within the tie margin.
pub(crate) fn choose_shapes(
    ctx: &Context<'_>,
    lin: &Linearisation,
    scans: &Scans,
    refined: Vec<Refined>,
    extra: &[usize],
) -> Vec<(Option<Choice>, Option<Choice>)> {
    let margin = ctx.options.tie_margin;
    let mut best_by_kind: Vec<[Option<Choice>; 2]> = vec![[None, None]; ctx.cands.len()];
    for Refined {
        candidate: i,
        scan: j,
        refit,
    } in refined
    {
        let variant = &scans.ok[j].1.effect;
        let kind = usize::from(!discrete_shapes_at_defaults(variant));
        if best_by_kind[i][kind]
            .as_ref()
            .is_none_or(|(_, b)| refit.cost < b.cost)
        {
            best_by_kind[i][kind] = Some((variant.clone(), refit));
        }
    }
    best_by_kind
        .into_iter()
        .enumerate()
        .map(|(i, [dflt, alt])| {
            let bic = |r: &Refit| lin.ic(r.cost, extra[i]).0;
            let (chosen, other) = match (dflt, alt) {
                (Some(d), Some(a)) if bic(&a.1) - bic(&d.1) < -margin => (Some(a), Some(d)),
                (Some(d), Some(a)) => (Some(d), Some(a)),
                (d, a) => (d.or(a), None),
            };
            let other = other.filter(|o| {
                chosen
                    .as_ref()
                    .is_some_and(|c| (bic(&o.1) - bic(&c.1)).abs() < margin)
            });
            (chosen, other)
        })
        .collect()
}

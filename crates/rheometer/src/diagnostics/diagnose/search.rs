//! Stage 4: the global search of every candidate — its strength scanned over the search range
//! for each shape variant ([`scan_profile`]), then the best grid points refined with the
//! strength (and fitted shapes) freed ([`refine`]) — all jobs in parallel.

use super::base::Context;
use super::linear::linearise::Linearisation;
use crate::diagnostics::candidate::Candidate;
use crate::diagnostics::refits::scan::{
    refine, scan_profile, shape_variants, GridStart, ProfileScan, Refit, ShapeParameter,
};
use crate::fit::{Identification, RheometerError};
use crate::model::effects::{Effect, LawChoice};
use rayon::prelude::*;

/// The scans that started, each with its candidate's index.
pub(crate) struct Scans {
    /// `(candidate, scan)`.
    pub ok: Vec<(usize, ProfileScan)>,
}

/// A refit of a candidate: its index, the scan it started from, and the fit.
pub(crate) struct Refined {
    /// The candidate.
    pub candidate: usize,
    /// Index into [`Scans::ok`].
    pub scan: usize,
    /// The fit.
    pub refit: Refit,
}

/// Whether every discrete shape of `variant` (scanned, not fitted: the co-flow's tail) is at
/// its default.
pub(crate) fn discrete_shapes_at_defaults(variant: &Effect) -> bool {
    variant
        .shape_values()
        .iter()
        .filter(|(sp, _)| sp.scanned && !sp.fitted_with_strength)
        .all(|(sp, v)| *v == sp.default)
}

/// The candidates to search: best linearised first, at most `refit_top`.
pub(crate) fn searched(ctx: &Context<'_>, lin: &Linearisation) -> Vec<usize> {
    let mut order: Vec<usize> = (0..ctx.cands.len()).collect();
    order.sort_by(|&a, &b| lin.scores[b].score.total_cmp(&lin.scores[a].score));
    order.truncate(ctx.options.refit_top);
    order
}

/// Scans every shape variant of the `searched` candidates in parallel; their profiles and
/// scan errors go into the candidates' records.
pub(crate) fn scan_all(
    ctx: &Context<'_>,
    base: &Identification,
    lin: &Linearisation,
    searched: &[usize],
    records: &mut [Candidate],
) -> Scans {
    let jobs: Vec<(usize, Effect, Vec<ShapeParameter>)> = searched
        .iter()
        .flat_map(|&i| {
            shape_variants(&ctx.cands[i], ctx.options.scan.scan_shapes, ctx.length)
                .into_iter()
                .map(move |(v, s)| (i, v, s))
        })
        .collect();
    // where the user's law is implausible, the sides are walked inwards again from the
    // diagnosis' start law (unless the options name another)
    let mut scan_options = ctx.options.scan.clone();
    if ctx.spec.law == LawChoice::Carreau {
        scan_options.restart_law = scan_options.restart_law.or(Some(ctx.law0));
    }
    let scan_options = &scan_options;
    let scans: Vec<(usize, Result<ProfileScan, RheometerError>)> = jobs
        .into_par_iter()
        .map(|(i, v, s)| {
            let sc = scan_profile(
                &ctx.rh,
                &ctx.cands[i],
                &v,
                s,
                base,
                lin.cost_before,
                &ctx.opts,
                scan_options,
            );
            (i, sc)
        })
        .collect();
    let mut ok = Vec::new();
    for (i, sc) in scans {
        match sc {
            Ok(sc) => {
                records[i].profiles.push(sc.profile.clone());
                ok.push((i, sc));
            }
            Err(e) => records[i].scan_errors.push(e.to_string()),
        }
    }
    Scans { ok }
}

/// The grid points to refine for candidate `i`, per kind of discrete shape (at defaults or
/// not: the choice between them needs the best refit of each): the lowest start, the next ones
/// close to it, and the lowest ones on the other side of the neutral value where they already
/// earn their place (the two signs are different regimes: a co-flow faster than the fiber
/// reverses the relative speed; warmer or colder air; a grid point's `J`, with the strength
/// and shape fixed, bounds its refit's from above).
fn refine_starts(
    ctx: &Context<'_>,
    lin: &Linearisation,
    scans: &Scans,
    i: usize,
    other_kind: bool,
    extra: usize,
) -> Vec<(usize, usize)> {
    let scan = &ctx.options.scan;
    let mut starts: Vec<(usize, usize, f64)> = scans
        .ok
        .iter()
        .enumerate()
        .filter(|(_, (c, sc))| *c == i && discrete_shapes_at_defaults(&sc.effect) != other_kind)
        .flat_map(|(j, (_, sc))| {
            sc.starts
                .iter()
                .enumerate()
                .map(move |(k, st)| (j, k, st.cost))
        })
        .collect();
    starts.sort_by(|a, b| a.2.total_cmp(&b.2));
    let lowest = starts.first().map_or(f64::INFINITY, |s| s.2);
    let chosen: Vec<(usize, usize, f64)> = starts
        .iter()
        .copied()
        .take(scan.refine.max(1))
        .filter(|s| s.2 <= lowest * (1.0 + scan.refine_within))
        .collect();
    let neutral = ctx.cands[i].neutral();
    let side =
        |&(j, k, _): &(usize, usize, f64)| (scans.ok[j].1.starts[k].strength - neutral).signum();
    let other: Vec<(usize, usize, f64)> = match chosen.first().map(side) {
        Some(first) => starts
            .iter()
            .copied()
            .filter(|s| side(s) != first)
            .take(scan.refine.max(1))
            .filter(|s| lin.ic(s.2, extra).0 < ctx.options.earn_threshold)
            .collect(),
        None => Vec::new(),
    };
    chosen
        .into_iter()
        .chain(other)
        .map(|(j, k, _)| (j, k))
        .collect()
}

/// A refinement job: candidate, scan, grid point, and the `(n, κ)` to start from instead of
/// the grid point's.
type Job = (usize, usize, usize, Option<[f64; 2]>);

/// Refines the best grid points of every searched candidate in parallel (refits that fail
/// are left out). The lowest grid point of each candidate is refined from several material
/// laws besides its own — the user's fit's and the diagnosis' start law — since a refit from
/// the grid point's law alone can end in a local minimum far from the truth (a co-flow that
/// drives `n` to 0); the best of all starts is kept and [`Candidate::refit_starts`] says how
/// many reached it.
pub(crate) fn refine_all(
    ctx: &Context<'_>,
    base: &Identification,
    lin: &Linearisation,
    scans: &Scans,
    searched: &[usize],
    records: &[Candidate],
) -> Vec<Refined> {
    let laws = [base.law(), ctx.law0];
    let jobs: Vec<Job> = searched
        .iter()
        .flat_map(|&i| [(i, false), (i, true)])
        .flat_map(|(i, kind)| {
            let extra = records[i].extra_parameters;
            let starts = refine_starts(ctx, lin, scans, i, kind, extra);
            // other material laws for the refit of a grid point that already earns its place
            // there (its refit can only be better): the candidates that may be named
            let first = starts.first().copied().filter(|&(j, k)| {
                lin.ic(scans.ok[j].1.starts[k].cost, extra).0 < ctx.options.earn_threshold
            });
            let mut jobs: Vec<Job> = starts.into_iter().map(|(j, k)| (i, j, k, None)).collect();
            if let Some((j, k)) = first {
                let own = scans.ok[j].1.starts[k].law;
                for law in laws {
                    let differs = (law[0] - own[0]).abs() > 0.02 || (law[1] - own[1]).abs() > 0.1;
                    if differs && !jobs.iter().any(|x| x.3 == Some(law)) {
                        jobs.push((i, j, k, Some(law)));
                    }
                }
            }
            jobs
        })
        .collect();
    let n_bounds = ctx
        .column("n")
        .map(|c| (ctx.layout.lower[c], ctx.layout.upper[c]));
    jobs.into_par_iter()
        .filter_map(|(i, j, k, law)| {
            let sc = &scans.ok[j].1;
            // a grid point whose n sits at a bound of its range (the Newtonian limit n = 1,
            // where κ has no effect: the fit cannot leave it) is refined from the diagnosis'
            // start law instead, with its own strength, shape and warm solutions
            let start = &sc.starts[k];
            let at_n_bound = n_bounds
                .is_some_and(|(lo, hi)| start.law[0] <= lo + 1e-6 || start.law[0] >= hi - 1e-6);
            let law = match law {
                Some(l) if ctx.spec.law == LawChoice::Carreau => Some(l),
                None if at_n_bound && ctx.spec.law == LawChoice::Carreau => Some(ctx.law0),
                _ => None,
            };
            let moved;
            let start = match law {
                Some(law) => {
                    moved = GridStart {
                        law,
                        ..start.clone()
                    };
                    &moved
                }
                None => start,
            };
            refine(sc, start, &ctx.opts).ok().map(|refit| Refined {
                candidate: i,
                scan: j,
                refit,
            })
        })
        .collect()
}

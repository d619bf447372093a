//! The mesh-growth limit of a fit's BVP solves (`IdentifyOptions::simulate.growth_limit`; the
//! diagnosis' refinements set `REFINE_GROWTH_LIMIT`, the user's fits none): a trial point whose
//! solve from the accepted solution would need many times its nodes fails early and the trial
//! step is rejected. On the shipped data, fits from a far start with no limit, with the
//! refinements' limit and with a limit so tight that it binds on ordinary steps reach the same
//! optimum.

use diffbvp::GrowthLimit;
use rheometer::data::input::load_experiments;
use rheometer::diagnostics::{ScanOptions, REFINE_GROWTH_LIMIT};
use rheometer::fit::{Identification, IdentifyOptions, Rheometer};
use std::path::Path;

fn fit(rh: &Rheometer, limit: Option<GrowthLimit>) -> Identification {
    let mut o = IdentifyOptions::default();
    o.simulate.growth_limit = limit;
    // far from the optimum (0.80, 11.6): strong thinning and a stiff melt; on the way the
    // tight limit rejects 2 trial steps the free fit takes
    rh.identify([0.2, 16.0], &o).unwrap()
}

#[test]
fn the_growth_limit_does_not_move_the_estimate() {
    let data = load_experiments(Path::new("data/pmma7n_synthetic/experiments.toml")).unwrap();
    let rh = Rheometer::new(&data).unwrap();
    assert_eq!(IdentifyOptions::default().simulate.growth_limit, None);
    assert_eq!(
        ScanOptions::default().refine_growth_limit,
        Some(REFINE_GROWTH_LIMIT)
    );
    let free = fit(&rh, None);
    let se = free.fit.standard_errors().unwrap();
    let tight = GrowthLimit {
        factor: 1.2,
        at_least: 30,
    };
    for (label, limit) in [("refine", REFINE_GROWTH_LIMIT), ("tight", tight)] {
        let id = fit(&rh, Some(limit));
        let worst = id
            .fit
            .p
            .iter()
            .zip(&free.fit.p)
            .zip(&se)
            .map(|((a, b), s)| (a - b).abs() / s)
            .fold(0.0f64, f64::max);
        eprintln!(
            "{label}: (n, κ) = ({:.5}, {:.5}), {} iterations, {} failed trial points; without a \
             limit {} iterations, {} failed; largest shift {worst:.2e} SE",
            id.law()[0],
            id.law()[1],
            id.fit.iterations,
            id.fit.failed_evaluations,
            free.fit.iterations,
            free.fit.failed_evaluations
        );
        // within the discretisation's own allowance (IdentifyOptions::max_discretisation_shift)
        assert!(worst <= 0.01, "{label}: estimate moved {worst:.2e} SE");
        if label == "tight" {
            // the tight limit did bind: steps rejected that the free fit took
            assert!(
                id.fit.failed_evaluations > free.fit.failed_evaluations,
                "the tight limit never bound"
            );
        }
    }
}

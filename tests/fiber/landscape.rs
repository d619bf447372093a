//! The cost landscape: its values agree with independent evaluations of the cost (the secant
//! warm starts change the path to a point, not the point's cost), its minimum lies next to the
//! truth of the synthetic data, and the strongly strain-thinning corner is marked missing.

use rheometer::data::input::load_experiments;
use rheometer::fit::{Estimator, FarRule, IdentifyOptions, Rheometer};
use std::path::Path;

#[test]
fn landscape_matches_direct_costs_and_finds_the_truth() {
    let set = load_experiments(Path::new("data/pmma7n_synthetic/experiments.toml")).unwrap();
    let rh = Rheometer::new(&set).unwrap();
    let mut o = IdentifyOptions::with_estimator(Estimator::Paper);
    o.simulate.tol = 1e-6;
    let ns = [1.0, 0.9, 0.8, 0.7, 0.6];
    let ks = [11.21, 11.71, 12.21];
    let mut calls = 0;
    let l = rh.landscape(&ns, &ks, &o, |_| calls += 1).unwrap();
    assert_eq!(calls, ks.len());
    assert_eq!(l.cost.len(), ns.len() * ks.len());
    // independent evaluations: a fresh objective per point, cold-started at the point itself
    for (j, &k) in ks.iter().enumerate() {
        for (i, &n) in ns.iter().enumerate().skip(1).step_by(2) {
            let mut obj = rh.objective([n, k], &o).unwrap();
            let direct = obj.cost_at(n, k).unwrap();
            let grid = l.cost[j * ns.len() + i];
            assert!(
                (grid - direct).abs() <= 1e-4 * direct,
                "J({n}, {k}): landscape {grid:e} vs direct {direct:e}"
            );
        }
    }
    let (n, k, _) = l.minimum().unwrap();
    assert_eq!(
        (n, k),
        (0.8, 11.71),
        "grid minimum away from the truth (0.8, 11.71)"
    );
}

#[test]
fn strongly_strain_thinning_corner_is_missing() {
    let set = load_experiments(Path::new("data/pmma7n_synthetic/experiments.toml")).unwrap();
    let rh = Rheometer::new(&set).unwrap();
    let mut o = IdentifyOptions::with_estimator(Estimator::Paper);
    o.simulate.tol = 1e-4;
    let ns = [1.0, 0.5, 0.2, 0.0];
    let ks = [9.0];
    let l = rh.landscape(&ns, &ks, &o, |_| {}).unwrap();
    assert!(l.cost[..3].iter().all(|c| c.is_finite()), "{:?}", l.cost);
    assert!(
        l.cost[3].is_nan(),
        "n = 0 should have no solution: {:?}",
        l.cost
    );
}

/// The sample rows behind the CLI's time estimate are the landscape's own rows: the landscape
/// continued from them is bit for bit the one computed without a sample (failed points
/// included), and its progress starts at the sample's points.
#[test]
fn a_landscape_keeps_its_sample_rows_unchanged() {
    use rheometer::fit::PointStatus;
    use std::sync::atomic::AtomicBool;
    let set = load_experiments(Path::new("data/pmma7n_synthetic/experiments.toml")).unwrap();
    let rh = Rheometer::new(&set).unwrap();
    let mut o = IdentifyOptions::with_estimator(Estimator::Paper);
    o.simulate.tol = 1e-4;
    // the last n has no solution: failed points are kept as well
    let ns = [1.0, 0.8, 0.6, 0.4, 0.0];
    let ks = [10.0, 11.0, 11.71, 12.5, 13.0];
    let never = AtomicBool::new(false);
    let bits = |c: &[f64]| c.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    let plain = rh.landscape_with(&ns, &ks, &o, |_| {}, &never).unwrap();
    let far = FarRule::for_tol(o.simulate.tol);
    let sample = rh.landscape_sample(&ns, &ks, &o, far, &never).unwrap();
    assert_eq!(sample.rows(), 3, "the smallest, middle and largest kappa");
    assert!(sample.row_s() > 0.0 && sample.remaining_s(2) > 0.0);
    let mut progress = Vec::new();
    let kept = rh
        .landscape_from(sample, |d| progress.push(d), &never)
        .unwrap();
    assert_eq!(progress.first(), Some(&(3 * ns.len())));
    assert_eq!(progress.last(), Some(&(ks.len() * ns.len())));
    assert_eq!(kept.status, plain.status);
    assert_eq!(bits(&kept.tol), bits(&plain.tol));
    assert!(kept.status.contains(&PointStatus::Failed));
    assert_eq!(bits(&kept.landscape.cost), bits(&plain.landscape.cost));
    assert_eq!(kept.landscape.kappa, ks);
}

/// Points far from their row's minimum (the cost before them more than twice the row's lowest
/// so far) are solved at ten times the tolerance, and say so; every point before the first far
/// one of its row is computed exactly as with one tolerance for all, and the far costs move by
/// less than 1e-3 relative.
#[test]
fn far_points_are_solved_looser_and_the_rest_as_with_one_tolerance() {
    use rheometer::fit::PointStatus;
    use std::sync::atomic::AtomicBool;
    assert_eq!(FarRule::for_tol(1e-4).tol, 1e-3);
    assert_eq!(FarRule::for_tol(1e-6).tol, 1e-5);
    assert_eq!(
        FarRule::for_tol(1e-2).tol,
        1e-2,
        "never tighter than the landscape's"
    );
    let set = load_experiments(Path::new("data/pmma7n_synthetic/experiments.toml")).unwrap();
    let rh = Rheometer::new(&set).unwrap();
    let mut o = IdentifyOptions::with_estimator(Estimator::Paper);
    o.simulate.tol = 1e-4;
    let ns = [1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2];
    let ks = [11.0, 12.5];
    let never = AtomicBool::new(false);
    let ruled = rh.landscape_with(&ns, &ks, &o, |_| {}, &never).unwrap();
    let uniform = rh
        .landscape_ruled(&ns, &ks, &o, FarRule::uniform(), |_| {}, &never)
        .unwrap();
    assert!(uniform.tol.iter().all(|&t| t == 1e-4), "{:?}", uniform.tol);
    let (mut near, mut far) = (0, 0);
    for j in 0..ks.len() {
        let row = |v: &[f64]| v[j * ns.len()..(j + 1) * ns.len()].to_vec();
        let (cost, tol, plain) = (
            row(&ruled.landscape.cost),
            row(&ruled.tol),
            row(&uniform.landscape.cost),
        );
        let (mut row_min, mut last, mut far_yet) = (f64::INFINITY, f64::NAN, false);
        for i in 0..ns.len() {
            assert_eq!(ruled.status[j * ns.len() + i], PointStatus::Computed);
            let expected = if last > 2.0 * row_min { 1e-3 } else { 1e-4 };
            assert_eq!(tol[i], expected, "n = {}, kappa = {}", ns[i], ks[j]);
            far_yet |= expected == 1e-3;
            if far_yet {
                far += 1;
                let rel = (cost[i] - plain[i]).abs() / plain[i];
                assert!(rel < 1e-3, "n = {}: {} vs {}", ns[i], cost[i], plain[i]);
            } else {
                near += 1;
                assert_eq!(cost[i].to_bits(), plain[i].to_bits(), "n = {}", ns[i]);
            }
            (last, row_min) = (cost[i], row_min.min(cost[i]));
        }
    }
    assert!(near >= 6 && far >= 4, "near {near}, far {far}");
}

//! Full identification of the 9 shipped experiments from a Table-3 start (0.7, 11.51),
//! including the cold starts: paper's estimator (target < 0.1 s) and principled (< 0.3 s); and
//! an 11×11 cost landscape (paper's estimator, n ∈ [0, 1], κ ∈ [9, 16], tol 1e-4 as the CLI).

use criterion::{criterion_group, criterion_main, Criterion};
use diffbvp::mesh::linspace;
use rheometer::data::input::load_experiments;
use rheometer::fit::{Estimator, IdentifyOptions, Rheometer};
use std::hint::black_box;
use std::path::Path;

fn identify(c: &mut Criterion) {
    let set = load_experiments(Path::new("data/pmma7n_synthetic/experiments.toml")).unwrap();
    let rh = Rheometer::new(&set).unwrap();
    let mut g = c.benchmark_group("identify_9_experiments");
    for est in [Estimator::Paper, Estimator::Principled] {
        let o = IdentifyOptions::with_estimator(est);
        g.bench_function(est.name(), |b| {
            b.iter(|| rh.identify(black_box([0.7, 11.51]), &o).unwrap())
        });
    }
    g.finish();
}

fn landscape(c: &mut Criterion) {
    let set = load_experiments(Path::new("data/pmma7n_synthetic/experiments.toml")).unwrap();
    let rh = Rheometer::new(&set).unwrap();
    let mut o = IdentifyOptions::with_estimator(Estimator::Paper);
    o.simulate.tol = 1e-4;
    let (ns, ks) = (linspace(0.0, 1.0, 11), linspace(9.0, 16.0, 11));
    c.bench_function("landscape_11x11_paper_tol1e-4", |b| {
        b.iter(|| rh.landscape(black_box(&ns), &ks, &o, |_| {}).unwrap())
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(5));
    targets = identify, landscape
}
criterion_main!(benches);

//! Full identification of the 9 shipped experiments from a Table-3 start (0.7, 11.51),
//! including the cold starts: paper's estimator (target < 0.1 s) and principled (< 0.3 s).

use criterion::{criterion_group, criterion_main, Criterion};
use diffbvp::fiber::input::load_experiments;
use diffbvp::fiber::rheometer::{Estimator, IdentifyOptions, Rheometer};
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

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(5));
    targets = identify
}
criterion_main!(benches);

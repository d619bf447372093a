//! A full `diagnose` (user's Carreau fit from the start heuristic, linearised scores of all six
//! built-in candidates, global search of every candidate (strength and shape profiles, refits of
//! the best grid points)) on the 9 shipped experiments. Target: < 10 s median on 2 cores.

use criterion::{criterion_group, criterion_main, Criterion};
use rheometer::data::input::load_experiments;
use rheometer::diagnostics::{diagnose, DiagnoseOptions};
use rheometer::model::ModelSpec;
use std::hint::black_box;
use std::path::Path;

fn full_diagnose(c: &mut Criterion) {
    let set = load_experiments(Path::new("data/pmma7n_synthetic/experiments.toml")).unwrap();
    let opts = DiagnoseOptions::default();
    let spec = ModelSpec::default();
    c.bench_function("diagnose_9_experiments", |b| {
        b.iter(|| diagnose(black_box(&set), &spec, &opts).unwrap())
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(std::time::Duration::from_secs(15));
    targets = full_diagnose
}
criterion_main!(benches);

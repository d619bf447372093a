//! Ansatz smoothing (paper eq. 5) on the shipped synthetic data set.

use rheometer::data::input::load_experiments;
use rheometer::data::smoothing::smooth;
use std::path::Path;

#[test]
fn smoothing_fits_every_shipped_experiment_without_user_input() {
    let set = load_experiments(Path::new("data/pmma7n_synthetic/experiments.toml")).unwrap();
    let truth =
        std::fs::read_to_string("data/pmma7n_synthetic/truth/noise_free_diameters_m.csv").unwrap();
    let rows: Vec<Vec<f64>> = truth
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.trim().parse().unwrap()).collect())
        .collect();
    // true take-up diameters from TRUTH.md
    let d_out = [
        110e-6, 70e-6, 55e-6, 140e-6, 90e-6, 70e-6, 180e-6, 120e-6, 95e-6,
    ];
    for (k, (exp, meas)) in set.experiments.iter().zip(&set.measurements).enumerate() {
        let m = meas.as_ref().unwrap();
        let f = smooth(&m.positions, &m.diameters).unwrap();
        println!(
            "{}: b = {:.4}, c = {:.5} m, v = {:.4e} 1/m², rms {:.4}, d_fit(L)/d_out = {:.4}, {} iterations",
            exp.name,
            f.b,
            f.c,
            f.v,
            f.rms,
            f.diameter(exp.spinline_length) / d_out[k],
            f.iterations
        );
        // measurement noise is 1.5% (3.5% near the take-up): the fit's RMS relative deviation
        // must be of that size, not larger
        assert!(f.rms < 0.05, "{}: rms {}", exp.name, f.rms);
        // the smoothed profile stays within 10% of the noise-free truth everywhere
        for (i, &s) in m.positions.iter().enumerate() {
            let t = rows[i][k + 1];
            assert!(
                (f.diameter(s) - t).abs() < 0.10 * t,
                "{} at s = {s}: {} vs {t}",
                exp.name,
                f.diameter(s)
            );
        }
        // d_fit(L) is a 1-cm extrapolation; it lands within 5% of the true take-up diameter
        assert!((f.diameter(exp.spinline_length) / d_out[k] - 1.0).abs() < 0.05);
    }
}

//! `FitOptions::x_scale`: the trust region in units of each parameter's characteristic scale.
//! With unit scales a parameter far from O(1) moves at most `max_radius` of its units per
//! iteration; with its scale given, the fit reaches the same optimum in a few iterations.

use super::decay_model;
use diffbvp::least_squares::{
    fit, FitError, FitOptions, FitResult, LeastSquaresProblem, Termination,
};

/// `y = a e^{−b x}` at 30 points of `[0, 3]` with a = 300 (a quantity in units whose useful
/// range spans hundreds, as an air speed in m/s does) and b = 1.3, plus a fixed small
/// perturbation so that the optimum is not the truth exactly.
struct Decay {
    x: Vec<f64>,
    y: Vec<f64>,
}

impl Decay {
    fn new() -> Self {
        let x: Vec<f64> = (0..30).map(|i| 3.0 * i as f64 / 29.0).collect();
        let y = x
            .iter()
            .enumerate()
            .map(|(i, &x)| 300.0 * (-1.3 * x).exp() + 0.5 * ((i as f64) * 2.1).sin())
            .collect();
        Decay { x, y }
    }
}

impl LeastSquaresProblem for Decay {
    type Error = String;
    fn num_params(&self) -> usize {
        2
    }
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
        Ok(decay_model::residuals(&self.x, &self.y, p, |_| 0.0))
    }
}

fn options(x_scale: Vec<f64>) -> FitOptions {
    FitOptions {
        x_scale,
        ..FitOptions::with_bounds(vec![0.0, 0.1], vec![1000.0, 10.0])
    }
}

fn run(x_scale: Vec<f64>) -> Result<FitResult, FitError> {
    fit(&mut Decay::new(), &[10.0, 1.0], &options(x_scale))
}

#[test]
fn a_parameter_of_large_units_reaches_its_optimum_in_few_iterations_with_its_scale() {
    let unit = run(Vec::new()).unwrap();
    let scaled = run(vec![100.0, 1.0]).unwrap();
    // with a's scale: converged, near the truth, in a handful of iterations
    assert_ne!(scaled.termination, Termination::MaxIterations);
    assert!(scaled.iterations <= 25, "{} iterations", scaled.iterations);
    assert!(
        (scaled.p[0] / 300.0 - 1.0).abs() < 0.01,
        "a = {}",
        scaled.p[0]
    );
    assert!(
        (scaled.p[1] / 1.3 - 1.0).abs() < 0.01,
        "b = {}",
        scaled.p[1]
    );
    // unit scales: at most max_radius = 1 of a's units per iteration, 290 to travel; the fit
    // lowers the cost by b instead and stops far from the optimum (b at its bound)
    assert!(
        unit.cost > 100.0 * scaled.cost,
        "unit scales: cost {} at {:?} ({:?}), scaled {}",
        unit.cost,
        unit.p,
        unit.termination,
        scaled.cost
    );
    assert!(unit.p[0] < 150.0, "a = {}", unit.p[0]);
    // the optimum itself: a fit from the scaled fit's end, with unit scales, stays there
    let polished = fit(&mut Decay::new(), &scaled.p, &options(Vec::new())).unwrap();
    let se = polished.standard_errors().unwrap();
    for (i, s) in se.iter().enumerate() {
        let d = ((scaled.p[i] - polished.p[i]) / s).abs();
        assert!(
            d < 1e-3,
            "parameter {i}: {d} standard errors from the optimum"
        );
    }
}

#[test]
fn unit_scales_are_the_default_exactly() {
    let none = run(Vec::new()).unwrap();
    let ones = run(vec![1.0, 1.0]).unwrap();
    assert_eq!(none.iterations, ones.iterations);
    for i in 0..2 {
        assert_eq!(none.p[i].to_bits(), ones.p[i].to_bits());
    }
}

#[test]
fn invalid_scales_are_refused_naming_the_option() {
    for (xs, what) in [
        (vec![1.0], "entries"),
        (vec![1.0, 0.0], "x_scale[1]"),
        (vec![f64::NAN, 1.0], "x_scale[0]"),
        (vec![1.0, -2.0], "x_scale[1]"),
        (vec![f64::INFINITY, 1.0], "x_scale[0]"),
    ] {
        match run(xs.clone()) {
            Err(FitError::InvalidInput(m)) => {
                assert!(
                    m.contains("FitOptions::x_scale") && m.contains(what),
                    "{xs:?}: {m}"
                )
            }
            other => panic!("{xs:?}: {other:?}"),
        }
    }
}

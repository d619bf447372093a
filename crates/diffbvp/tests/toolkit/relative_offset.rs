//! The relative-offset stopping test of Bates and Watts (`FitOptions::relative_offset`) on a
//! model evaluated with a small numerical error, as a BVP solved to a tolerance is: the cost
//! then carries noise that `ftol` lies below, and the trust region spends its iterations on it.

use super::decay_model;
use diffbvp::least_squares::{
    fit, FitError, FitOptions, FitResult, LeastSquaresProblem, Termination,
};

/// `y = a e^{−b x}` at 40 points of `[0, 2]`, with Gaussian-like noise of σ = 0.01 (a fixed
/// pseudo-random sequence, written here); the model's residuals carry a deterministic error of
/// RMS about `numerical` that changes with every bit of `p` (a discretisation whose mesh
/// changes between evaluations), the Jacobian is the smooth model's.
struct NoisyDecay {
    x: Vec<f64>,
    y: Vec<f64>,
    numerical: f64,
}

/// A uniform number in `[-1, 1)` from a 64-bit state (splitmix64).
fn unit(mut z: u64) -> f64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// A Gaussian-like number of unit variance: the sum of the four uniforms `unit(seed + k)`
/// (σ of U[-1, 1) is 1/√3).
fn normal(seed: u64) -> f64 {
    (0..4).map(|k| unit(seed + k)).sum::<f64>() * (3.0f64 / 4.0).sqrt()
}

impl NoisyDecay {
    fn new(numerical: f64) -> Self {
        let x: Vec<f64> = (0..40).map(|i| 2.0 * i as f64 / 39.0).collect();
        let y = x
            .iter()
            .enumerate()
            .map(|(i, &x)| 2.0 * (-1.3 * x).exp() + 0.01 * normal(1000 * i as u64))
            .collect();
        NoisyDecay { x, y, numerical }
    }
}

impl LeastSquaresProblem for NoisyDecay {
    type Error = String;
    fn num_params(&self) -> usize {
        2
    }
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
        let seed = p[0].to_bits() ^ p[1].to_bits().rotate_left(17);
        let numerical = self.numerical;
        Ok(decay_model::residuals(&self.x, &self.y, p, |i| {
            numerical * unit(seed ^ ((i as u64) << 40))
        }))
    }
}

fn options(relative_offset: Option<f64>) -> FitOptions {
    FitOptions {
        relative_offset,
        ..FitOptions::with_bounds(vec![0.1, 0.1], vec![10.0, 10.0])
    }
}

fn run(numerical: f64, relative_offset: Option<f64>) -> FitResult {
    fit(
        &mut NoisyDecay::new(numerical),
        &[1.0, 0.5],
        &options(relative_offset),
    )
    .unwrap()
}

/// `a`'s iterations, why it stopped and its distance from `exact`, for the test's output.
fn outcome(a: &FitResult, exact: &FitResult) -> String {
    format!(
        "{} iterations ({}), {:.2e} se off",
        a.iterations,
        a.termination,
        distance_se(a, exact)
    )
}

/// The largest distance of `a` from the exact optimum `b`, in `b`'s standard errors.
fn distance_se(a: &FitResult, b: &FitResult) -> f64 {
    let se = b.standard_errors().unwrap();
    (0..2)
        .map(|i| ((a.p[i] - b.p[i]) / se[i]).abs())
        .fold(0.0, f64::max)
}

#[test]
fn a_fit_ends_at_the_optimum_to_within_the_relative_offset_and_not_on_numerical_noise() {
    // the exact optimum: the smooth model, tight tolerances
    let exact = run(0.0, None);
    assert_ne!(exact.termination, Termination::MaxIterations);
    // a numerical error of 1e-7 per residual (1e-5 of the noise): ftol = 1e-10 lies below the
    // cost noise it makes (~ 2 |r| 1e-7 √N / ‖r‖² ≈ 1e-6 relative)
    let by_ftol = run(1e-7, None);
    let by_offset = run(1e-7, Some(1e-3));
    println!(
        "exact: {}; ftol: {}; relative offset: {}",
        outcome(&exact, &exact),
        outcome(&by_ftol, &exact),
        outcome(&by_offset, &exact)
    );
    assert_eq!(by_offset.termination, Termination::RelativeOffset);
    assert!(
        by_offset.iterations < by_ftol.iterations,
        "{} iterations with the relative offset, {} with ftol",
        by_offset.iterations,
        by_ftol.iterations
    );
    // within 1e-3 √P standard errors of the optimum, plus what the numerical error itself
    // moves it (1e-7 against σ = 0.01 over 40 points: ~1e-5 se)
    let bound = 1e-3 * 2f64.sqrt() + 1e-4;
    assert!(
        distance_se(&by_offset, &exact) <= bound,
        "{} se from the exact optimum",
        distance_se(&by_offset, &exact)
    );
    // on the smooth model it ends at the optimum as well, and no later than ftol does
    let smooth = run(0.0, Some(1e-3));
    assert!(distance_se(&smooth, &exact) <= 1e-3 * 2f64.sqrt());
    assert!(smooth.iterations <= exact.iterations);
}

#[test]
fn a_relative_offset_outside_zero_to_one_is_refused_naming_the_option() {
    for bad in [0.0, -1e-3, 1.0, f64::NAN, f64::INFINITY] {
        let e = fit(&mut NoisyDecay::new(0.0), &[1.0, 0.5], &options(Some(bad))).unwrap_err();
        let FitError::InvalidInput(m) = &e else {
            panic!("{bad}: {e}")
        };
        assert!(m.contains("FitOptions::relative_offset"), "{m}");
    }
}

/// [`NoisyDecay`] without numerical noise but with one jump of the cost: beyond `a = edge` every
/// residual carries an extra `offset` (as a BVP's adapted mesh gains nodes there), which makes
/// the cost rise by about `N offset² / 2` across the edge.
struct SteppedDecay {
    smooth: NoisyDecay,
    edge: f64,
    offset: f64,
}

impl LeastSquaresProblem for SteppedDecay {
    type Error = String;
    fn num_params(&self) -> usize {
        2
    }
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
        let (mut r, j) = self.smooth.evaluate(p)?;
        if p[0] > self.edge {
            r.iter_mut().for_each(|v| *v += self.offset);
        }
        Ok((r, j))
    }
}

#[test]
fn a_fit_against_a_jump_of_the_cost_ends_at_its_noise_floor_not_its_iteration_budget() {
    let exact = run(0.0, None);
    let se = exact.standard_errors().unwrap();
    // the edge 0.001 standard errors of `a` below the optimum, approached from a = 1; the
    // offset (10 % of the noise) makes the cost rise by ~2e-6 across it, far more than is left
    // to gain beyond it
    let stepped = |edge_se: f64, relative_offset| {
        let mut problem = SteppedDecay {
            smooth: NoisyDecay::new(0.0),
            edge: exact.p[0] - edge_se * se[0],
            offset: 1e-3,
        };
        fit(&mut problem, &[1.0, 0.5], &options(relative_offset)).unwrap()
    };
    let by_ftol = stepped(0.001, None);
    let by_floor = stepped(0.001, Some(1e-3));
    println!(
        "ftol: {}; noise floor: {}",
        outcome(&by_ftol, &exact),
        outcome(&by_floor, &exact)
    );
    assert_eq!(by_floor.termination, Termination::NoiseFloor);
    assert!(
        2 * by_floor.iterations <= by_ftol.iterations,
        "{} iterations at the noise floor, {} with ftol",
        by_floor.iterations,
        by_ftol.iterations
    );
    // it ends in front of the edge, within 0.01 standard errors of where the tight tests end
    assert!(by_floor.p[0] <= exact.p[0] - 0.001 * se[0]);
    assert!(
        distance_se(&by_floor, &by_ftol) <= 0.01,
        "{} se from the best point in front of the edge",
        distance_se(&by_floor, &by_ftol)
    );
    // an edge 0.01 standard errors of `a` before the optimum stalls the fit 0.25 standard errors
    // (of `b`) away from it: further than ten times the asked distance (1e-3 √2), so the fit
    // does not end at the noise floor there
    let stalled = stepped(0.01, Some(1e-3));
    println!("stalled: {}", outcome(&stalled, &exact));
    assert!(distance_se(&stalled, &exact) > 10.0 * 1e-3 * 2f64.sqrt());
    assert_ne!(stalled.termination, Termination::NoiseFloor);
    // where the cost has no jump (the edge 10 standard errors beyond the optimum) it never
    // ends at a noise floor
    assert_eq!(
        stepped(-10.0, Some(1e-3)).termination,
        Termination::RelativeOffset
    );
}

/// A narrow curved valley that the data determine only weakly along its length: the residuals
/// `1000 (q − p²)` (the valley `q = p²`), `w (1 − p)` (where along it the optimum lies, weight
/// `w`) and 40 residuals of fixed noise (σ = 0.01) that set the residual variance. The trust
/// region follows the valley in steps far shorter than the distance along it.
struct Banana {
    along: f64,
    noise: Vec<f64>,
}

impl Banana {
    fn new(along: f64) -> Self {
        let noise = (0..40).map(|i| 0.01 * normal(7000 + 100 * i)).collect();
        Banana { along, noise }
    }
}

impl LeastSquaresProblem for Banana {
    type Error = String;
    fn num_params(&self) -> usize {
        2
    }
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
        let mut r = vec![1000.0 * (p[1] - p[0] * p[0]), self.along * (1.0 - p[0])];
        let mut j = vec![-2000.0 * p[0], 1000.0, -self.along, 0.0];
        r.extend(&self.noise);
        j.extend(std::iter::repeat_n(0.0, 2 * self.noise.len()));
        Ok((r, j))
    }
}

#[test]
fn a_fit_crawling_along_a_curved_valley_ends_when_its_budget_would_no_longer_matter() {
    let options = |relative_offset| FitOptions {
        relative_offset,
        ..FitOptions::with_bounds(vec![-5.0, -5.0], vec![5.0, 5.0])
    };
    let run = |along: f64, relative_offset| {
        fit(
            &mut Banana::new(along),
            &[-1.2, 1.0],
            &options(relative_offset),
        )
        .unwrap()
    };
    // where the data pull hard along the valley the fit makes real progress on every step:
    // it runs as it would without the test
    for along in [1.0, 0.1] {
        let (full, tested) = (run(along, None), run(along, Some(1e-3)));
        println!(
            "along {along}: {} / {}",
            full.termination, tested.termination
        );
        assert_ne!(tested.termination, Termination::Stalled);
        assert_eq!(tested.p, full.p);
    }
    // weakly pulled, the trust region crawls and the budget ends far from the optimum (1, 1);
    // the test ends the crawl early with the cost the budget reaches, to within 0.01 of the
    // residual variance at the pace of the crawl (measured 1.1e-2, 9.9e-3, 7e-5; 0.015
    // allowed: the pace changes a little over the rest of the budget)
    for along in [0.01, 0.005, 0.001] {
        let (full, tested) = (run(along, None), run(along, Some(1e-3)));
        let variance = 2.0 * full.cost / (full.num_residuals() - 2) as f64;
        let dchi2 = 2.0 * (tested.cost - full.cost) / variance;
        println!(
            "along {along}: budget {} iterations ({}), p {:?}; stalled after {}, p {:?}, \
             d chi2 {dchi2:.2e}",
            full.iterations, full.termination, full.p, tested.iterations, tested.p
        );
        assert_eq!(full.termination, Termination::MaxIterations);
        assert!(full.p[0] < 0.5, "the crawl reached {:?}", full.p);
        assert_eq!(tested.termination, Termination::Stalled);
        assert!(
            4 * tested.iterations <= 3 * full.iterations,
            "{} iterations against {}",
            tested.iterations,
            full.iterations
        );
        assert!(dchi2 <= 0.015, "{dchi2}");
    }
}

//! The principled rheometer fits its per-experiment take-up factors through the Schur
//! complement (block-arrow normal equations); on the 9 shipped experiments it lands where the
//! dense driver lands, for the linear and a robust loss.

use diffbvp::least_squares::{fit, Accuracy, FitOptions, FitResult, LeastSquaresProblem, Loss};
use rheometer::data::input::load_experiments;
use rheometer::fit::Objective;
use rheometer::fit::{Estimator, FitStart, IdentifyOptions, Rheometer, RheometerError};
use std::path::Path;

fn rheometer() -> Rheometer {
    let set = load_experiments(Path::new("data/pmma7n_synthetic/experiments.toml")).unwrap();
    Rheometer::new(&set).unwrap()
}

/// The objective with only its dense evaluation (the driver's dense path).
struct Dense<'a>(Objective<'a>);
impl LeastSquaresProblem for Dense<'_> {
    type Error = RheometerError;
    fn num_params(&self) -> usize {
        self.0.num_params()
    }
    fn evaluate(&mut self, p: &[f64]) -> Result<(Vec<f64>, Vec<f64>), RheometerError> {
        self.0.evaluate(p)
    }
    fn accept(&mut self, p: &[f64]) {
        self.0.accept(p)
    }
    fn set_accuracy(&mut self, e: Option<f64>) -> bool {
        self.0.set_accuracy(e)
    }
}

/// The fit `identify` runs, on the dense path.
fn dense_fit(rh: &Rheometer, start: [f64; 2], opts: &IdentifyOptions, f_scale: f64) -> FitResult {
    let obj = rh.objective_from(&FitStart::at(start), opts).unwrap();
    let layout = obj.layout();
    let mut p0 = layout.shared_start();
    let (mut lo, mut hi) = (layout.lower.clone(), layout.upper.clone());
    for _ in 0..rh.len() {
        p0.push(1.0);
        lo.push(opts.take_up_bounds[0]);
        hi.push(opts.take_up_bounds[1]);
    }
    let fo = FitOptions {
        initial_radius: 0.3,
        max_radius: 1.0,
        max_iterations: opts.max_iterations,
        loss: opts.loss,
        f_scale,
        accuracy: Accuracy::scheduled(),
        // identify's stopping test: within `optimum_tolerance` standard errors of the optimum
        relative_offset: opts.relative_offset(p0.len()).unwrap(),
        ..FitOptions::with_bounds(lo, hi)
    };
    fit(&mut Dense(obj), &p0, &fo).unwrap()
}

#[test]
fn block_fit_of_the_shipped_experiments_is_the_dense_fit() {
    let rh = rheometer();
    let sigma = rh.relative_uncertainty.unwrap_or(1.0);
    for (loss, f_scale) in [(Loss::Linear, None), (Loss::SoftL1, Some(0.02))] {
        let opts = IdentifyOptions {
            loss,
            f_scale,
            ..IdentifyOptions::with_estimator(Estimator::Principled)
        };
        let start = [0.5, 11.51];
        let id = rh.identify(start, &opts).unwrap();
        assert!(
            id.fit.block_jacobian.is_some(),
            "the principled fit declares its blocks"
        );
        let gn_scale = f_scale.map_or(1.0, |c| c / sigma);
        let dense = dense_fit(&rh, start, &opts, gn_scale);
        let block = &id.fit;
        let se = dense.standard_errors().unwrap();
        let mut worst: f64 = 0.0;
        for (i, (a, b)) in block.p.iter().zip(&dense.p).enumerate() {
            let rel = (a - b).abs() / b.abs();
            let in_se = (a - b).abs() / se[i];
            worst = worst.max(in_se);
            assert!(
                rel <= 1e-10 || in_se <= 1e-6,
                "{loss}: parameter {i}: {a} vs {b}, {rel:e} relative, {in_se:e} SE"
            );
        }
        println!(
            "{loss}: largest difference {worst:e} SE; iterations {} vs {}",
            block.iterations, dense.iterations
        );
        let sb = block.standard_errors().unwrap();
        for (a, b) in sb.iter().zip(&se) {
            assert!((a - b).abs() <= 1e-6 * b, "{loss}: se {a} vs {b}");
        }
        let (cb, cd) = (block.covariance().unwrap(), dense.covariance().unwrap());
        for (a, b) in cb.iter().zip(&cd) {
            assert!(
                (a - b).abs() <= 1e-6 * b.abs().max(1e-12),
                "{loss}: cov {a} vs {b}"
            );
        }
        assert_eq!(block.dense_jacobian().len(), dense.jacobian.len());
    }
}

#[test]
fn progress_is_reported_and_the_plan_is_the_fit_size() {
    use rheometer::fit::{FitProgress, ProgressHook};
    use std::sync::{Arc, Mutex};
    let rh = rheometer();
    let start = [0.5, 11.51];
    let events: Arc<Mutex<(usize, usize, usize)>> = Arc::new(Mutex::new((0, 0, 0)));
    let seen = events.clone();
    let opts = IdentifyOptions {
        progress: Some(ProgressHook::new(move |e| {
            let mut s = seen.lock().unwrap();
            match e {
                FitProgress::Simulated { done, total } => {
                    s.0 += 1;
                    s.1 = s.1.max(*done);
                    assert_eq!(*total, 9);
                }
                FitProgress::Iteration(it) => {
                    s.2 += 1;
                    assert_eq!(it.iteration, s.2);
                }
            }
        })),
        ..IdentifyOptions::default()
    };
    let plan = rh.plan(start, &opts).unwrap();
    let id = rh.identify(start, &opts).unwrap();
    let (simulated, last, iterations) = *events.lock().unwrap();
    assert_eq!((simulated, last), (9, 9));
    assert_eq!(iterations, id.fit.iterations);
    assert_eq!(plan.experiments, 9);
    assert_eq!(plan.residuals, id.fit.num_residuals());
    assert_eq!(plan.parameters, id.fit.p.len());
    assert_eq!(plan.shared_parameters, id.names.len());
    assert!(plan.seconds > 0.0 && plan.cold_start_s > 0.0 && plan.evaluation_s > 0.0);
    // the memory planned: at least the final solutions with their linearisations, at most a
    // few times them (accepted, pending, workspaces) plus the Jacobian
    let held: usize = id.solutions.iter().map(|s| s.heap_bytes()).sum();
    assert!(held > 0);
    assert!(
        plan.bytes >= held && plan.bytes <= 4 * held + 1_000_000,
        "planned {} bytes, the solutions hold {held}",
        plan.bytes
    );
}

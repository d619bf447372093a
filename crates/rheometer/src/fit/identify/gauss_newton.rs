//! Identification of `(n, κ)`: the start heuristic (paper Algorithm 2) and the bounded
//! trust-region Gauss–Newton fit on the [`Objective`](crate::fit::objective::Objective).
//!
//! Every evaluation solves the `M` fiber BVPs in parallel (rayon), each warm-started from its
//! last accepted solution (no continuation inside the fit, as in the paper), and builds the exact
//! residual Jacobian from forward sensitivities (one extra solve with the kept factorisation per
//! experiment). A BVP that fails at a trial point makes the whole trial point fail, which the
//! driver treats as a rejected step.

pub use super::identification::Identification;
use super::identification::WarmFit;
use crate::fit::data::Rheometer;
use crate::fit::estimator::Estimator;
use crate::fit::layout::FitStart;
use crate::fit::options::{with_named_point, FitProgress, IdentifyOptions, RheometerError};
use crate::fit::summary::build::SummaryInput;
use crate::fit::summary::FitSummary;
use diffbvp::least_squares::{fit_observed, Accuracy, FitIteration, FitOptions};
use diffbvp::solution::Solution;
use std::time::Instant;

/// The eleven start points `(n, κ)` of the paper's Table 3 (κ = ln 10⁴, ln 10⁵, ln 10⁶).
pub const PAPER_TABLE3_STARTS: [[f64; 2]; 11] = [
    [0.5, 9.21],
    [0.7, 9.21],
    [0.9, 9.21],
    [0.3, 11.51],
    [0.5, 11.51],
    [0.7, 11.51],
    [0.9, 11.51],
    [0.3, 13.82],
    [0.5, 13.82],
    [0.7, 13.82],
    [0.9, 13.82],
];

impl Rheometer {
    /// Runs the identification from `start = (n, κ)`.
    pub fn identify(
        &self,
        start: [f64; 2],
        options: &IdentifyOptions,
    ) -> Result<Identification, RheometerError> {
        self.identify_from(&FitStart::at(start), options)
    }

    /// Runs the identification from a general start.
    pub fn identify_from(
        &self,
        start: &FitStart,
        options: &IdentifyOptions,
    ) -> Result<Identification, RheometerError> {
        self.identify_warm(start, options, &WarmFit::default())
    }

    /// [`identify_from`](Self::identify_from) with the take-up factors started at
    /// `warm.take_up` and, with `warm.stop_tolerance`, looser stopping tests (the strength
    /// scans of `diagnose`, which warm-start every grid point from its neighbour).
    pub(crate) fn identify_warm(
        &self,
        start: &FitStart,
        options: &IdentifyOptions,
        warm: &WarmFit,
    ) -> Result<Identification, RheometerError> {
        let id = self.identify_unchecked(start, options, warm)?;
        if warm.stop_tolerance.is_some() {
            // a grid point of a scan: no estimate of its own to report
            return Ok(id);
        }
        super::accuracy::matched(self, start, options, id)
    }

    /// [`identify_warm`](Self::identify_warm) without the discretisation check (see
    /// [`accuracy`](super::accuracy)).
    pub(crate) fn identify_unchecked(
        &self,
        start: &FitStart,
        options: &IdentifyOptions,
        warm: &WarmFit,
    ) -> Result<Identification, RheometerError> {
        let t0 = Instant::now();
        // checked before any simulation: the layout's size is known only with the objective,
        // the tolerance's range is not
        options.relative_offset(1)?;
        // the experiments solved where the fit starts: at the warm take-up factors (clamped to
        // their bounds) if given, so that the first evaluation re-solves nothing
        let take_up = self.warm_take_up(options, warm);
        let mut obj = self.objective_at_take_up(start, options, &take_up, warm.solve_at_take_up)?;
        let mut p0 = obj.initial_parameters();
        let (lower, upper) = obj.bounds();
        // within `optimum_tolerance` standard errors of the optimum
        let relative_offset = options.relative_offset(lower.len())?;
        let ns = obj.layout.num_shared();
        p0[ns..ns + take_up.len()].copy_from_slice(&take_up);
        let (f_scale, f_scale_source) = self.robust_margin(options)?;
        let fo = self.fit_options(
            options,
            warm,
            (&lower, &upper),
            obj.layout.x_scale(),
            f_scale,
            relative_offset,
        );
        let mut observer = |it: &FitIteration| {
            if let Some(hook) = &options.progress {
                hook.report(&FitProgress::Iteration(it));
            }
        };
        let fit_result = fit_observed(&mut obj, &p0, &fo, &mut observer)
            .map_err(|e| with_named_point(e, &obj.layout.names))?;
        let solutions: Vec<Solution> = obj.solutions();
        let residual_profiles = self.residual_profiles(&solutions);
        let local = obj
            .layout
            .local(&fit_result.p[..ns], 1.0, obj.layout.params.take_up_factor());
        let declared = options.relative_uncertainty.or(self.relative_uncertainty);
        let noise = self.noise_summary(&residual_profiles, declared)?;
        let mut summary = FitSummary::new(SummaryInput {
            estimator: options.estimator,
            law: self.spec.law,
            start: start.law,
            experiments: self.experiments.iter().map(|e| e.name.clone()).collect(),
            names: &obj.layout.names,
            effects: &obj.layout.effects,
            local_params: &local,
            law_params: obj.layout.law_of(&local),
            fit: &fit_result,
            lower: &lower,
            upper: &upper,
            take_up_factors: if options.estimator == Estimator::Principled {
                fit_result.p[ns..].to_vec()
            } else {
                vec![1.0; self.len()]
            },
            rms: rms_of(residual_profiles.iter().flat_map(|(_, r)| r)),
            rms_by_experiment: residual_profiles
                .iter()
                .map(|(_, r)| rms_of(r.iter()))
                .collect(),
            noise,
            data_warnings: self.data_warnings(),
            f_scale,
            f_scale_source,
            bvp_tolerance: options.simulate.tol,
            nodes: solutions.iter().map(|s| s.x.len()).collect(),
            wall_time_s: t0.elapsed().as_secs_f64(),
        });
        summary.strain_rates = self.strain_rate_coverage(&solutions);
        summary.data_digest =
            crate::fit::data_digest(self.experiments.iter().zip(&self.measurements));
        Ok(Identification {
            summary,
            names: obj.layout.names.clone(),
            effects: obj.layout.effects.clone(),
            local_params: local,
            lower,
            upper,
            residual_profiles,
            solutions,
            fit: fit_result,
        })
    }

    /// The take-up factors the fit starts from: the warm ones clamped to their bounds (for the
    /// principled estimator, one per experiment), else none.
    fn warm_take_up(&self, options: &IdentifyOptions, warm: &WarmFit) -> Vec<f64> {
        if options.estimator == Estimator::Principled && warm.take_up.len() == self.len() {
            let [lo, hi] = options.take_up_bounds;
            warm.take_up.iter().map(|t| t.clamp(lo, hi)).collect()
        } else {
            Vec::new()
        }
    }

    /// The driver's options of the fit within `(lower, upper)`: the trust region, the loss
    /// with its soft margin `f_scale` over the relative uncertainty, the accuracy schedule,
    /// the parameter scales `x_scale` (take-up factors: 1) and the stopping tests (loose at a
    /// grid point of a scan, `warm.stop_tolerance`; else `relative_offset`).
    fn fit_options(
        &self,
        options: &IdentifyOptions,
        warm: &WarmFit,
        (lower, upper): (&[f64], &[f64]),
        mut x_scale: Vec<f64>,
        f_scale: f64,
        relative_offset: Option<f64>,
    ) -> FitOptions {
        let sigma = options
            .relative_uncertainty
            .or(self.relative_uncertainty)
            .unwrap_or(1.0);
        let mut fo = FitOptions {
            initial_radius: 0.3,
            max_radius: 1.0,
            max_iterations: options.max_iterations,
            loss: options.loss,
            // the principled residual is the relative residual over σ
            f_scale: if options.loss.is_linear() {
                1.0
            } else {
                f_scale / sigma
            },
            accuracy: if options.loose_tolerance.is_some() {
                Accuracy::scheduled()
            } else {
                Accuracy::Fixed
            },
            cancel: options.cancel.clone(),
            ..FitOptions::with_bounds(lower.to_vec(), upper.to_vec())
        };
        // the effects' strengths and shapes in units of their ranges (take-up factors: 1)
        x_scale.resize(lower.len(), 1.0);
        fo.x_scale = x_scale;
        if let Some(t) = warm.stop_tolerance {
            (fo.gtol, fo.xtol, fo.ftol) = (t, t, t);
        }
        if warm.stop_tolerance.is_none() {
            fo.relative_offset = relative_offset;
        }
        fo
    }

    /// Each experiment's measured positions and relative residuals of `solutions`.
    fn residual_profiles(&self, solutions: &[Solution]) -> Vec<(Vec<f64>, Vec<f64>)> {
        solutions
            .iter()
            .enumerate()
            .map(|(k, sol)| {
                (
                    self.measurements[k].positions.clone(),
                    self.relative_residuals(k, sol),
                )
            })
            .collect()
    }

    /// The soft margin `C` \[-\] (relative residual) of a robust loss and where it comes from
    /// (`NaN` and `""` for the linear loss). Errors: a robust loss with the paper's estimator,
    /// a non-positive `f_scale`.
    pub(crate) fn robust_margin(
        &self,
        options: &IdentifyOptions,
    ) -> Result<(f64, String), RheometerError> {
        if options.loss.is_linear() {
            return Ok((f64::NAN, String::new()));
        }
        if options.estimator != Estimator::Principled {
            return Err(RheometerError::Data(format!(
                "the {} loss needs the principled estimator (relative residuals); the paper's \
                 estimator fits with the linear loss only",
                options.loss
            )));
        }
        match options.f_scale {
            Some(c) if c > 0.0 && c.is_finite() => Ok((c, "given".into())),
            Some(c) => Err(RheometerError::Data(format!(
                "f_scale must be a positive relative residual (e.g. 0.02), got {c}"
            ))),
            None => Ok((
                self.data_noise_scale()?,
                "robust noise scale of the data about the smoothing ansatz".into(),
            )),
        }
    }

    /// The Newtonian model (`n = 1`) at `kappa` with take-up factors 1, one solution per
    /// experiment (cold starts; paper Fig. 3 draws it against the identified law).
    pub fn newtonian_solutions(
        &self,
        kappa: f64,
        options: &IdentifyOptions,
    ) -> Result<Vec<Solution>, RheometerError> {
        let mut obj = self.objective([1.0, kappa], options)?;
        obj.cost_at(1.0, kappa)?;
        Ok(obj.solutions())
    }

    /// Paper Algorithm 2: with `n = n_init` (0.5), walk κ down from the upper bound in steps of
    /// 1 until the cost differs from the Newtonian cost by more than 10%.
    pub fn start_heuristic(&self, options: &IdentifyOptions) -> Result<StartPoint, RheometerError> {
        let n_init = 0.5;
        let (k_lo, k_hi) = (options.lower[1], options.upper[1]);
        let mut obj = self.objective([1.0, k_hi], options)?;
        let j1 = obj.cost_at(1.0, k_hi)?;
        let mut kappa = k_hi;
        let mut j2 = obj.cost_at(n_init, kappa)?;
        let mut trace = vec![(kappa, j2)];
        while ((j1 - j2) / j1).abs() < 0.1 && kappa > k_lo {
            kappa = (kappa - 1.0).max(k_lo);
            j2 = obj.cost_at(n_init, kappa)?;
            trace.push((kappa, j2));
        }
        Ok(StartPoint {
            start: [n_init, kappa],
            newtonian_cost: j1,
            trace,
        })
    }
}

/// Result of the start heuristic.
#[derive(Debug, Clone)]
pub struct StartPoint {
    /// The start point `(n_init, κ)`.
    pub start: [f64; 2],
    /// The Newtonian reference cost `J(1, κ_upper)`.
    pub newtonian_cost: f64,
    /// `(κ, J(n_init, κ))` for every κ tried.
    pub trace: Vec<(f64, f64)>,
}

/// RMS of `values` (0 for none).
fn rms_of<'a>(values: impl Iterator<Item = &'a f64>) -> f64 {
    let (mut s2, mut n) = (0.0, 0usize);
    for v in values {
        s2 += v * v;
        n += 1;
    }
    (s2 / n.max(1) as f64).sqrt()
}

//! The trust-region iteration of [`fit`] and [`fit_observed`]: the start point, then trial
//! steps (propose, choose the evaluation's accuracy, evaluate, accept or reject) until a
//! stopping test ends the fit (or, under [`Accuracy::Scheduled`], switches the loose phase to
//! full accuracy).

#[cfg(doc)]
use super::Accuracy;
use super::{
    contract, loss, AccuracySchedule, FitError, FitIteration, FitOptions, FitResult, Jacobian,
    LeastSquaresProblem, Observer, Termination,
};
use std::time::Instant;

mod step;

use step::{scaled_norm, Proposal, StepSize};

/// Runs the bounded trust-region Gauss–Newton iteration from `p0`.
///
/// Errors before any evaluation: lengths of `p0` and the bounds other than `num_params()`, a
/// start outside the bounds, invalid options (non-finite or negative tolerances and radii,
/// `xtol` or `ftol` of 1 or more, `max_iterations = 0`). Errors at the start point: a failed
/// evaluation ([`FitError::StartFailed`]), a mis-sized or non-finite result
/// ([`FitError::InvalidInput`], see [`LeastSquaresProblem::evaluate`]), fewer residuals than
/// parameters. A mis-sized result at a later point also ends the fit with
/// [`FitError::InvalidInput`]; nothing panics.
pub fn fit<L: LeastSquaresProblem>(
    problem: &mut L,
    p0: &[f64],
    options: &FitOptions,
) -> Result<FitResult, FitError> {
    fit_observed(problem, p0, options, &mut |_: &FitIteration| {})
}

/// [`fit`], calling `observer` once per iteration with its [`FitIteration`] record (the same
/// record [`FitResult::history`] keeps).
pub fn fit_observed<L: LeastSquaresProblem, O: Observer + ?Sized>(
    problem: &mut L,
    p0: &[f64],
    options: &FitOptions,
    observer: &mut O,
) -> Result<FitResult, FitError> {
    let t0 = Instant::now();
    let np = problem.num_params();
    let schedule = contract::check_options(np, p0, options)?;
    if options.cancelled() {
        return Err(FitError::Cancelled { iterations: 0 });
    }
    let mut fit = Driver::start(problem, p0, options, schedule, t0)?;
    loop {
        if options.cancelled() {
            return Err(FitError::Cancelled {
                iterations: fit.iterations,
            });
        }
        if let Some(t) = fit.stop.take() {
            if !fit.loose {
                return Ok(fit.finish(t));
            }
            fit.switch_to_full_accuracy(problem)?;
        }
        fit.trial_step(problem, observer)?;
    }
}

/// The state of a fit between its iterations.
struct Driver<'o> {
    options: &'o FitOptions,
    schedule: Option<AccuracySchedule>,
    t0: Instant,
    np: usize,
    nr: usize,
    /// The iterate, its residuals, Jacobian and cost.
    p: Vec<f64>,
    r: Vec<f64>,
    jac: Jacobian,
    cost: f64,
    /// The Gauss–Newton view (rescaled under a robust loss; `None`: `r`, `jac` themselves).
    scaled: Option<(Vec<f64>, Jacobian)>,
    radius: f64,
    history: Vec<FitIteration>,
    iterations: usize,
    accepted_steps: usize,
    failed: usize,
    /// Accuracy::Scheduled: whether the evaluations are loose, the iteration limit of the
    /// full-accuracy phase, the loose trial steps and the model error measured at the switch.
    loose: bool,
    tight_limit: Option<usize>,
    loose_iterations: usize,
    switch_model_error: Option<f64>,
    /// A stopping test met: ends the fit, or (loose) switches to full accuracy.
    stop: Option<Termination>,
    /// With [`FitOptions::relative_offset`]: the largest jump of the cost seen at a rejected
    /// short trial step (0: none yet), the numerical noise floor of the cost.
    noise_floor: f64,
}

/// A rejected trial step no longer than this in every scaled parameter (`|s_i| / x_scale_i`)
/// whose cost rose by more than [`JUMP_FACTOR`] times the reduction it was predicted to give
/// measures the cost's numerical noise: at so short a step a smooth model's gain ratio is close
/// to 1, a rise that large is a jump (a BVP whose adapted mesh changed between the two points).
const SHORT_STEP: f64 = 1e-2;

/// See [`SHORT_STEP`].
const JUMP_FACTOR: f64 = 10.0;

/// The fit ends ([`Termination::NoiseFloor`]) when the Gauss–Newton step's predicted gain is at
/// most this many times the noise floor: a trial would have to beat the noise at both of the
/// points it compares.
const NOISE_FLOOR_FACTOR: f64 = 2.0;

/// ... and when the relative offset is at most this many times its tolerance: a jump of the
/// cost measures the residuals' numerical error projected on the residuals themselves, not on
/// the estimates, and may be large where the estimates hardly move; the fit never stops further
/// than this many times the asked distance from the optimum.
const NOISE_FLOOR_OFFSET_FACTOR: f64 = 10.0;

/// Trial steps over which [`Termination::Stalled`] measures the fit's pace.
const STALL_WINDOW: usize = 10;

/// [`Termination::Stalled`]: the most the rest of the iteration budget may lower `‖r‖²` at the
/// pace of the last [`STALL_WINDOW`] trial steps, in units of the residual variance `σ̂²`, for
/// the fit to end now (a move of 0.1 standard errors along a direction of the cost's curvature
/// changes `‖r‖²` by that much).
const STALL_CHI2: f64 = 0.01;

/// A trial point's evaluation.
struct Evaluated {
    r: Vec<f64>,
    jac: Jacobian,
    /// The RMS model error it was allowed (`None`: full accuracy).
    allowed_error: Option<f64>,
}

impl<'o> Driver<'o> {
    /// Evaluates the start point: at the loosest accuracy the problem offers (no residuals yet
    /// to scale the allowed error by), at full accuracy if that fails or without a schedule.
    fn start<L: LeastSquaresProblem>(
        problem: &mut L,
        p0: &[f64],
        options: &'o FitOptions,
        schedule: Option<AccuracySchedule>,
        t0: Instant,
    ) -> Result<Self, FitError> {
        let np = problem.num_params();
        let p = p0.to_vec();
        let loose_start = schedule.is_some() && problem.set_accuracy(Some(f64::INFINITY));
        if !loose_start {
            problem.set_accuracy(None);
        }
        let start = match problem.evaluate_jacobian(&p) {
            Err(_) if loose_start => {
                problem.set_accuracy(None);
                problem.evaluate_jacobian(&p)
            }
            other => other,
        };
        let (r, jac) = start.map_err(|e| FitError::StartFailed {
            p: p.clone(),
            cause: e.to_string(),
        })?;
        contract::check_start(&r, &jac, np, &p)?;
        problem.accept(&p);
        let nr = r.len();
        if !jac.has_shape(nr, np) {
            return Err(FitError::InvalidInput(format!(
                "the problem returned {nr} residuals and a Jacobian that is not {nr} x {np}"
            )));
        }
        if nr < np {
            return Err(FitError::InvalidInput(format!(
                "{nr} residuals for {np} parameters: the fit is underdetermined"
            )));
        }
        let (loss, f_scale) = (options.loss, options.f_scale);
        Ok(Driver {
            options,
            schedule,
            t0,
            np,
            nr,
            scaled: jac.rescaled(loss, f_scale, &r, np),
            cost: loss::robust_cost(loss, f_scale, &r),
            p,
            r,
            jac,
            radius: options.initial_radius.min(options.max_radius),
            history: Vec::new(),
            iterations: 0,
            accepted_steps: 0,
            failed: 0,
            loose: schedule.is_some(),
            tight_limit: None,
            loose_iterations: 0,
            switch_model_error: None,
            stop: None,
            noise_floor: 0.0,
        })
    }

    /// Ends the loose phase: re-evaluates the iterate at full accuracy (measuring the loose
    /// phase's model error there) and gives the full-accuracy phase its radius and budget.
    fn switch_to_full_accuracy<L: LeastSquaresProblem>(
        &mut self,
        problem: &mut L,
    ) -> Result<(), FitError> {
        let (np, nr, o) = (self.np, self.nr, self.options);
        self.loose = false;
        problem.set_accuracy(None);
        let p = &self.p;
        let (r_t, j_t) =
            contract::check_trial(problem.evaluate_jacobian(p), np, nr, p)?.map_err(|cause| {
                FitError::RefineFailed {
                    p: p.clone(),
                    cause,
                }
            })?;
        problem.accept(p);
        let d2: f64 = r_t
            .iter()
            .zip(&self.r)
            .map(|(a, b)| (a - b) * (a - b))
            .sum();
        self.switch_model_error = Some((d2 / nr as f64).sqrt());
        self.set_iterate_values(r_t, j_t);
        self.radius = self.radius.max(o.initial_radius.min(o.max_radius));
        self.tight_limit = Some(
            o.max_iterations
                .max(self.iterations + self.schedule.map_or(0, |s| s.final_iterations)),
        );
        Ok(())
    }

    /// The residuals and Jacobian `r`, `jac` at the iterate: its Gauss–Newton view and cost.
    fn set_iterate_values(&mut self, r: Vec<f64>, jac: Jacobian) {
        let (loss, f_scale) = (self.options.loss, self.options.f_scale);
        self.scaled = jac.rescaled(loss, f_scale, &r, self.np);
        self.cost = loss::robust_cost(loss, f_scale, &r);
        self.r = r;
        self.jac = jac;
    }

    /// One iteration: a trial step proposed, its accuracy chosen, evaluated and judged (or a
    /// stopping test met on the way, left in `stop`).
    fn trial_step<L: LeastSquaresProblem, O: Observer + ?Sized>(
        &mut self,
        problem: &mut L,
        observer: &mut O,
    ) -> Result<(), FitError> {
        let proposal = match self.propose() {
            Ok(proposal) => proposal,
            Err(t) => {
                self.stop = Some(t);
                return Ok(());
            }
        };
        let size = self.step_size(&proposal.step);
        let allowed_error = match self.trial_accuracy(problem, size) {
            Ok(e) => e,
            Err(t) => {
                self.stop = Some(t);
                return Ok(());
            }
        };
        if allowed_error.is_some() {
            self.loose_iterations += 1;
        }
        self.iterations += 1;
        let trial = &proposal.trial;
        let evaluated = problem.evaluate_jacobian(trial);
        match contract::check_trial(evaluated, self.np, self.nr, trial)? {
            Ok((r_new, j_new)) => {
                let evaluated = Evaluated {
                    r: r_new,
                    jac: j_new,
                    allowed_error,
                };
                self.judge(problem, observer, proposal, evaluated, size);
            }
            Err(failure) => {
                self.failed += 1;
                self.radius = 0.25 * self.shrink_base(&proposal);
                let record = FitIteration {
                    iteration: self.iterations,
                    step_norm: proposal.step.norm(),
                    p: proposal.trial,
                    cost: None,
                    previous_cost: self.cost,
                    gain_ratio: None,
                    scaled_gradient: proposal.scaled_gradient,
                    accepted: false,
                    radius: self.radius,
                    failure: Some(failure),
                    allowed_error,
                    elapsed_s: self.t0.elapsed().as_secs_f64(),
                };
                self.record(observer, record);
            }
        }
        Ok(())
    }

    /// The RMS model error allowed for the trial point's evaluation (`None`: full accuracy),
    /// set on the problem; `Err(Termination::Step)` when the loose phase's step moves the
    /// estimate by less than `switch_below` standard errors.
    fn trial_accuracy<L: LeastSquaresProblem>(
        &mut self,
        problem: &mut L,
        size: StepSize,
    ) -> Result<Option<f64>, Termination> {
        match self.schedule {
            Some(sch) if self.loose => {
                if size.effect <= sch.switch_below * size.sigma {
                    // the step moves the estimate by less than `switch_below` standard errors
                    return Err(Termination::Step);
                }
                let e = sch.fraction * size.sigma.max(size.effect / (self.nr as f64).sqrt());
                if problem.set_accuracy(Some(e)) {
                    Ok(Some(e))
                } else {
                    // the problem has no loose evaluations: a fixed-accuracy fit
                    self.loose = false;
                    Ok(None)
                }
            }
            _ => Ok(None),
        }
    }

    /// Whether the fit has stalled ([`Termination::Stalled`]): at the pace of the last
    /// [`STALL_WINDOW`] trial steps (all at full accuracy), the trial steps left in the budget
    /// would lower `‖r‖²` by at most [`STALL_CHI2`] times the
    /// [`residual_variance`](Self::residual_variance).
    fn stalled(&self) -> bool {
        let k = self.history.len();
        let limit = self.tight_limit.unwrap_or(self.options.max_iterations);
        if k < STALL_WINDOW || self.iterations >= limit {
            return false;
        }
        let window = &self.history[k - STALL_WINDOW..];
        if window.iter().any(|h| h.allowed_error.is_some()) {
            return false;
        }
        let pace = 2.0 * (window[0].previous_cost - self.cost) / STALL_WINDOW as f64;
        pace * (limit - self.iterations) as f64 <= STALL_CHI2 * self.residual_variance()
    }

    /// `σ̂² = ‖r‖²/(N − P)` at the iterate, at most `f_scale²` under a robust loss: the
    /// residuals' scatter that step sizes and progress are measured against.
    fn residual_variance(&self) -> f64 {
        let variance = super::variance_of(super::cost_of(&self.r), self.nr, self.np);
        if self.options.loss.is_linear() {
            variance
        } else {
            variance.min(self.options.f_scale * self.options.f_scale)
        }
    }

    /// What a rejected or failed step shrinks the trust radius from: the step's own scaled
    /// length where it is shorter than the radius.
    fn shrink_base(&self, proposal: &Proposal) -> f64 {
        self.radius.min(scaled_norm(&proposal.step, &proposal.d))
    }

    /// The iteration's record to the observer and the history.
    fn record<O: Observer + ?Sized>(&mut self, observer: &mut O, record: FitIteration) {
        observer.observe(&record);
        self.history.push(record);
    }

    /// Judges an evaluated trial point by its gain ratio: the radius updated, the iteration
    /// recorded, the point accepted (becoming the iterate) or rejected, the stopping tests on
    /// the step.
    fn judge<L: LeastSquaresProblem, O: Observer + ?Sized>(
        &mut self,
        problem: &mut L,
        observer: &mut O,
        proposal: Proposal,
        evaluated: Evaluated,
        size: StepSize,
    ) {
        let o = self.options;
        let Evaluated {
            r: r_new,
            jac: j_new,
            allowed_error,
        } = evaluated;
        let pnorm = self.p.iter().map(|x| x * x).sum::<f64>().sqrt();
        let snorm = proposal.step.norm();
        let cost_new = loss::robust_cost(o.loss, o.f_scale, &r_new);
        let actual = self.cost - cost_new;
        let rho = if proposal.predicted > 0.0 {
            actual / proposal.predicted
        } else {
            -1.0
        };
        let accepted = rho > 1e-4;
        if rho < 0.25 {
            // a quarter of the step taken, not of the radius: a step shorter than the radius
            // (the Gauss–Newton step inside it, or one cut at the box) would otherwise be
            // proposed again unchanged until the radius fell below it
            self.radius = 0.25 * self.shrink_base(&proposal);
        } else if rho > 0.75
            && snorm * proposal.d.iter().fold(0.0f64, |m, x| m.max(*x)) >= 0.9 * self.radius
        {
            self.radius = (2.0 * self.radius).min(o.max_radius);
        }
        let record = FitIteration {
            iteration: self.iterations,
            p: proposal.trial.clone(),
            cost: Some(cost_new),
            previous_cost: self.cost,
            gain_ratio: Some(rho),
            step_norm: snorm,
            scaled_gradient: proposal.scaled_gradient,
            accepted,
            radius: self.radius,
            failure: None,
            allowed_error,
            elapsed_s: self.t0.elapsed().as_secs_f64(),
        };
        self.record(observer, record);
        let small_step = snorm <= o.xtol * (o.xtol + pnorm);
        if accepted {
            problem.accept(&proposal.trial);
            self.accepted_steps += 1;
            let rel_change = actual.abs() / self.cost.max(1e-300);
            self.p = proposal.trial;
            self.set_iterate_values(r_new, j_new);
            if rel_change < o.ftol {
                self.stop = Some(Termination::CostChange);
            } else if small_step {
                self.stop = Some(Termination::Step);
            }
        } else if small_step {
            self.stop = Some(Termination::Step);
        } else {
            if let (Some(sch), Some(_)) = (self.schedule, self.tight_limit) {
                if size.effect <= sch.negligible_step * size.sigma {
                    self.stop = Some(Termination::Step);
                }
            }
            if o.relative_offset.is_some() && !self.loose {
                // a jump of the cost at a short step: its numerical noise floor
                let short = (0..self.np).all(|i| proposal.step[i].abs() <= SHORT_STEP * o.scale(i));
                let rise = -actual;
                if short && rise > JUMP_FACTOR * proposal.predicted.max(0.0) {
                    self.noise_floor = self.noise_floor.max(rise);
                }
            }
        }
    }

    /// The result at the iterate, the fit having stopped for `termination`.
    fn finish(self, termination: Termination) -> FitResult {
        let (jacobian, block_jacobian) = match self.jac {
            Jacobian::Dense(j) => (j, None),
            Jacobian::Blocks(b) => (Vec::new(), Some(b)),
        };
        FitResult {
            p: self.p,
            cost: self.cost,
            residuals: self.r,
            jacobian,
            block_jacobian,
            iterations: self.iterations,
            accepted_steps: self.accepted_steps,
            failed_evaluations: self.failed,
            termination,
            wall_time_s: self.t0.elapsed().as_secs_f64(),
            history: self.history,
            loss: self.options.loss,
            f_scale: self.options.f_scale,
            loose_iterations: self.loose_iterations,
            switch_model_error: self.switch_model_error,
        }
    }
}

//! What an identification will cost before it starts ([`Rheometer::plan`]): the problem's size,
//! and its time and memory extrapolated from one experiment simulated and re-solved now.
//!
//! The fit's work is per experiment — one cold start at the start point, then per evaluation
//! one warm re-solve and its sensitivities — and the experiments are solved in parallel; its
//! memory is per experiment too (the accepted and the pending solution, each with its cached
//! linearisation) plus the fit's block-arrow Jacobian. Both therefore grow linearly with the
//! number of experiments, and one experiment measured on this machine calibrates them.

use super::data::Rheometer;
use super::estimator::Estimator;
use super::layout::{FitStart, Layout};
use super::options::{IdentifyOptions, RheometerError};
use crate::model::simulate::simulate_params;
use diffbvp::least_squares::BlockStructure;
use diffbvp::sensitivity::Sensitivities;
use std::time::Instant;

/// Evaluations (model solves with sensitivities) a fit is planned with: the fits of the shipped
/// data take 7–9 trial steps, plus the start, the calibration of the loose tolerance and the
/// re-evaluation at full accuracy.
pub const PLANNED_EVALUATIONS: usize = 12;

/// The size and the expected cost of an identification ([`Rheometer::plan`]).
#[derive(Debug, Clone, PartialEq)]
pub struct FitPlan {
    /// Experiments.
    pub experiments: usize,
    /// Residuals (measurements or optimisation points).
    pub residuals: usize,
    /// Fitted parameters, all.
    pub parameters: usize,
    /// Of those, shared by all experiments (the law, effect strengths, shapes).
    pub shared_parameters: usize,
    /// Threads the experiments are solved on.
    pub threads: usize,
    /// Mesh nodes of the probe experiment's solution at the start point.
    pub nodes: usize,
    /// Wall time of the probe's cold start \[s\] (the fastest of three).
    pub cold_start_s: f64,
    /// Wall time of one of the probe's evaluations (warm re-solve plus sensitivities; the
    /// fastest of three) \[s\].
    pub evaluation_s: f64,
    /// Expected wall time of the fit \[s\]: every experiment's cold start and
    /// `PLANNED_EVALUATIONS` evaluations, divided over [`threads`](Self::threads). The fit's
    /// loose early iterations make it an upper estimate on an otherwise idle machine.
    pub seconds: f64,
    /// Expected peak memory of the fit's state \[bytes\]: per experiment the accepted and the
    /// pending solution with their linearisations, the data and the fit's Jacobian.
    pub bytes: usize,
}

impl Rheometer {
    /// The size of an identification from `start` and its time and memory, extrapolated from
    /// the first experiment simulated at `start` (cold) and re-solved at a nearby law (warm,
    /// with its sensitivities) now: a few milliseconds. A caller decides from it whether to
    /// report progress ([`IdentifyOptions::progress`]) or to refuse a fit that would not fit
    /// in memory.
    pub fn plan(
        &self,
        start: [f64; 2],
        options: &IdentifyOptions,
    ) -> Result<FitPlan, RheometerError> {
        let model = &self.models[0];
        let fit_start = FitStart::at(start);
        let layout = Layout::new(model, &self.spec, &fit_start, options)?;
        let p = layout.local(&layout.shared_start(), 1.0, model.take_up_factor_index());
        let sim_err = |source| RheometerError::Simulation {
            experiment: self.experiments[0].name.clone(),
            n: start[0],
            kappa: start[1],
            source,
        };
        let sim = &options.simulate;
        // the fastest of three (the first pays for page faults and a cold thread workspace)
        let (mut cold_start_s, mut evaluation_s) = (f64::INFINITY, f64::INFINITY);
        let mut probe = None;
        for _ in 0..3 {
            let t0 = Instant::now();
            let cold = simulate_params(model, &p, None, sim).map_err(sim_err)?;
            cold_start_s = cold_start_s.min(t0.elapsed().as_secs_f64());
            // a nearby law (what a trial step asks), warm-started, with its sensitivities
            let mut near = p.clone();
            let ni = layout
                .params
                .law_param(crate::model::material_law::CarreauLike::N);
            near[ni] = (near[ni] - 0.01).max(options.lower[0]);
            let t1 = Instant::now();
            let warm = simulate_params(model, &near, Some(&cold.solution), sim).map_err(sim_err)?;
            Sensitivities::compute(model, &warm.solution)
                .map_err(|e| sim_err(crate::error::FiberError::from(e)))?;
            evaluation_s = evaluation_s.min(t1.elapsed().as_secs_f64());
            probe = Some(warm.solution);
        }
        let Some(warm) = probe else {
            return Err(RheometerError::Data("plan: no probe solution".into()));
        };
        let m = self.len();
        let principled = options.estimator == Estimator::Principled;
        let rows: Vec<usize> = (0..m)
            .map(|k| match options.estimator {
                Estimator::Principled => self.measurements[k].positions.len(),
                Estimator::Paper => options.n_opt_points,
            })
            .collect();
        let ns = layout.num_shared();
        let locals = usize::from(principled);
        let structure = BlockStructure::new(ns, rows.iter().map(|&r| (r, locals)));
        let threads = rayon::current_num_threads().max(1);
        let work = m as f64 * (cold_start_s + PLANNED_EVALUATIONS as f64 * evaluation_s);
        let per_experiment = 2 * warm.heap_bytes()
            + 8 * 4 * rows.iter().max().copied().unwrap_or(0)
            + std::mem::size_of_val(&self.models[0]);
        let jacobian = if principled {
            structure.driver_bytes()
        } else {
            // the paper's estimator: a dense Jacobian of the shared parameters only
            8 * 3 * structure.num_residuals() * (ns + 1)
        };
        Ok(FitPlan {
            experiments: m,
            residuals: structure.num_residuals(),
            parameters: structure.num_params(),
            shared_parameters: ns,
            threads,
            nodes: warm.nodes(),
            cold_start_s,
            evaluation_s,
            seconds: work / threads.min(m.max(1)) as f64,
            // the threads' solver workspaces: about one linearisation each
            bytes: m * per_experiment + jacobian + threads * warm.heap_bytes(),
        })
    }
}

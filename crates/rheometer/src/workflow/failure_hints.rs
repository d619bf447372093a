//! Simulation failures that name their experiment, with the likely input causes in words.
//!
//! A failed fiber solve reports what the numerics saw ("continuation stopped at c = 0.92",
//! "non-finite value in right-hand side: component 3"). [`ExperimentFailure`] puts the
//! experiment's name and its place in the TOML file in front of such an error (the original
//! error stays its [`source`](std::error::Error::source)), and [`hints`] translates it into
//! likely causes in the experiment's own terms: a melt or air temperature close to the VFT
//! law's divergence, air hotter than the melt, strong strain thinning, a very thin take-up,
//! a mesh limit to raise. A hint names the library's option and, after it, the `rheometer`
//! program's flag (a Python or Rust caller sets the option, a shell user the flag).

use crate::data::input::{LoadedExperiments, Location};
use crate::diagnostics::compare::CompareError;
use crate::error::FiberError;
use crate::fit::RheometerError;
use crate::model::setup::{Experiment, Inlet, Material, TakeUp};
use crate::report::format::show;
use diffbvp::error::BvpError;
use std::error::Error;
use std::f64::consts::PI;
use std::fmt;
use std::path::Path;

/// Below this distance \[K\] between the coldest prescribed temperature (inlet or air) and the
/// VFT temperature `T_VF`, a non-finite solve is blamed on the VFT law.
pub(crate) const VFT_MARGIN_K: f64 = 20.0;

/// Power index `n` \[-\] below which a stalled solve is blamed (also) on strong strain
/// thinning.
pub(crate) const STRONG_THINNING_N: f64 = 0.3;

/// Ratio of inlet to take-up diameter \[-\] above which a stalled solve is blamed (also) on a
/// very thin take-up.
pub(crate) const THIN_TAKE_UP_RATIO: f64 = 50.0;

/// The experiment an error in a chain belongs to: the first [`RheometerError::Simulation`] or
/// [`CompareError::Simulation`] in the chain of `error`, with the law parameters `(n, κ)` where
/// the error states them.
pub fn failed_experiment(error: &(dyn Error + 'static)) -> Option<(String, Option<[f64; 2]>)> {
    let mut cur: Option<&(dyn Error + 'static)> = Some(error);
    while let Some(e) = cur {
        if let Some(RheometerError::Simulation {
            experiment,
            n,
            kappa,
            ..
        }) = e.downcast_ref::<RheometerError>()
        {
            let law = (n.is_finite() && kappa.is_finite()).then_some([*n, *kappa]);
            return Some((experiment.clone(), law));
        }
        if let Some(CompareError::Simulation { experiment, .. }) = e.downcast_ref::<CompareError>()
        {
            return Some((experiment.clone(), None));
        }
        if let Some(f) = e.downcast_ref::<ExperimentFailure>() {
            return Some((f.experiment.clone(), f.law_params));
        }
        cur = e.source();
    }
    None
}

/// The first [`BvpError`] in the chain of `error` (also behind a [`FiberError::Solver`]).
pub(crate) fn solver_error<'a>(error: &'a (dyn Error + 'static)) -> Option<&'a BvpError> {
    let mut cur: Option<&'a (dyn Error + 'static)> = Some(error);
    while let Some(e) = cur {
        if let Some(b) = e.downcast_ref::<BvpError>() {
            return Some(b);
        }
        if let Some(FiberError::Solver(b)) = e.downcast_ref::<FiberError>() {
            return Some(b);
        }
        cur = e.source();
    }
    None
}

/// Inlet diameter \[m\] of `e` (from the inlet speed where the inlet gives one).
fn inlet_diameter(e: &Experiment, material: &Material) -> f64 {
    match e.inlet {
        Inlet::Diameter(d) => d,
        Inlet::Velocity(u) => {
            2.0 * (e.mass_flow / (PI * material.density(e.inlet_temperature) * u)).sqrt()
        }
    }
}

/// Take-up diameter \[m\] of `e`, if it has a take-up condition (a take-up speed is converted
/// with the density at the air temperature).
fn take_up_diameter(e: &Experiment, material: &Material) -> Option<f64> {
    match e.take_up? {
        TakeUp::Diameter(d) => Some(d),
        TakeUp::Velocity(u) => {
            Some(2.0 * (e.mass_flow / (PI * material.density(e.air_temperature) * u)).sqrt())
        }
    }
}

/// Likely input causes of the simulation failure `error` of `experiment` (with `material`
/// and, where known, the law parameters `law = (n, κ)`), in words; never empty.
pub fn hints(
    error: &(dyn Error + 'static),
    experiment: &Experiment,
    material: &Material,
    law: Option<[f64; 2]>,
) -> Vec<String> {
    let mut out = Vec::new();
    let solver = solver_error(error);
    let (stalled_at, root) = match solver {
        Some(BvpError::ContinuationStalled {
            reached,
            last_error,
            ..
        }) => (Some(*reached), Some(&**last_error)),
        other => (None, other),
    };
    let non_finite = matches!(root, Some(BvpError::NonFinite { .. }));
    let max_nodes = match (solver, root) {
        (Some(BvpError::MaxNodesExceeded { max_nodes, tol, .. }), _)
        | (_, Some(BvpError::MaxNodesExceeded { max_nodes, tol, .. })) => Some((*max_nodes, *tol)),
        _ => None,
    };
    if let Some(BvpError::MeshGrowthLimit {
        start_nodes, limit, ..
    }) = root.or(solver)
    {
        out.push(format!(
            "the solve started from a solution of {start_nodes} nodes and would have needed \
             more than {limit}: the parameters lie far from that solution, or beyond the region \
             where the fiber has a solution (a fit rejects such a trial step and takes a \
             shorter one); in the library, SimulateOptions::growth_limit = None lifts the limit"
        ));
    }
    if let Some((m, tol)) = max_nodes {
        out.push(format!(
            "the mesh needed more than {m} nodes: raise the limit with --max-nodes (in the \
             library the option max_nodes; default 20000, the landscape uses at most 1000), \
             loosen the tolerance (--tol; this solve asked for {}), or check this experiment's \
             inputs (a very thin take-up or strong strain thinning makes the profiles steep)",
            show(tol)
        ));
    }
    temperature_hints(&mut out, solver.is_some(), experiment, material);
    if let Some([n, _]) = law {
        if n < STRONG_THINNING_N && (stalled_at.is_some() || non_finite || max_nodes.is_some()) {
            out.push(format!(
                "n = {} is strong strain thinning: for this take-up the model may have no \
                 solution (the strain rate explodes towards the take-up); try a larger n",
                show(n)
            ));
        }
    }
    if let Some(d_out) = take_up_diameter(experiment, material) {
        let d_in = inlet_diameter(experiment, material);
        let ratio = d_in / d_out;
        if ratio.is_finite() && ratio > THIN_TAKE_UP_RATIO && solver.is_some() {
            out.push(format!(
                "the take-up diameter {d_out:.3e} m is {ratio:.0} times thinner than the inlet \
                 diameter {d_in:.3e} m: the take-up may be too thin for this law (check the \
                 take-up condition)"
            ));
        }
    }
    fallback_hints(&mut out, stalled_at, non_finite);
    out
}

/// The hints on the temperatures of `experiment`: within the VFT margin of `material` (for a
/// solver failure, `solver_failed`), or air hotter than the melt.
fn temperature_hints(
    out: &mut Vec<String>,
    solver_failed: bool,
    experiment: &Experiment,
    material: &Material,
) {
    let (t_in, t_air, t_vf) = (
        experiment.inlet_temperature,
        experiment.air_temperature,
        material.vft_t_vf,
    );
    if solver_failed && t_in.min(t_air) - t_vf < VFT_MARGIN_K {
        out.push(format!(
            "the {} temperature {:.3} K is within {VFT_MARGIN_K} K of the VFT temperature \
             vft_T_VF_K = {t_vf} K, where the zero-rate viscosity diverges: the law is not valid \
             this cold (check inlet_temperature_K, air_temperature_K and vft_T_VF_K)",
            if t_in <= t_air { "inlet" } else { "air" },
            t_in.min(t_air),
        ));
    }
    if t_air > t_in {
        out.push(format!(
            "the air ({t_air} K) is hotter than the melt at the inlet ({t_in} K): the fiber heats \
             up along the spin line; check inlet_temperature_K and air_temperature_K"
        ));
    }
}

/// The hints where no other applies: the continuation's stall point `stalled_at`, an overflow
/// (`non_finite`), or a check of the inputs.
fn fallback_hints(out: &mut Vec<String>, stalled_at: Option<f64>, non_finite: bool) {
    if let Some(c) = stalled_at {
        if out.is_empty() {
            out.push(format!(
                "the continuation from the stress-free fiber stalled at c = {c:.3} of 1: the \
                 model has no solution near these inputs; check n, kappa and this experiment's \
                 take-up condition"
            ));
        }
    }
    if non_finite && out.is_empty() {
        out.push(
            "a term of the model overflowed: check this experiment's temperatures, mass flow \
             and take-up condition for extreme values"
                .to_string(),
        );
    }
    if out.is_empty() {
        out.push(
            "check this experiment's inputs (temperatures, mass flow, take-up) and the law \
             parameters"
                .to_string(),
        );
    }
}

/// The failure `e` as an [`ExperimentFailure`] naming the experiment and its line in the
/// experiments file `path` of `loaded`, with hints, where the error chain names an experiment
/// whose simulation failed ([`failed_experiment`]); other errors (and failures already named)
/// unchanged. `law` are the law parameters `(n, κ)` of the solve where the error does not
/// state them.
pub fn name_experiment(
    e: Box<dyn Error + 'static>,
    loaded: &LoadedExperiments,
    path: &Path,
    law: Option<[f64; 2]>,
) -> Box<dyn Error + 'static> {
    if e.downcast_ref::<ExperimentFailure>().is_some() {
        return e;
    }
    let Some((name, stated)) = failed_experiment(e.as_ref()) else {
        return e;
    };
    let law = stated.or(law);
    let at = |line| Location {
        path: path.to_path_buf(),
        line,
    };
    match loaded.set.experiments.iter().position(|x| x.name == name) {
        Some(k) => Box::new(ExperimentFailure::new(
            &loaded.set.experiments[k],
            &loaded.set.material,
            at(loaded.details.get(k).and_then(|d| d.line)),
            law,
            e,
        )),
        None => Box::new(ExperimentFailure::unlocated(&name, at(None), e)),
    }
}

/// A failed simulation of one experiment: its name, its place in the TOML file, the law
/// parameters where known, likely causes, and the original error as source.
#[derive(Debug)]
pub struct ExperimentFailure {
    /// Experiment name.
    pub experiment: String,
    /// The TOML file and the line of the experiment's `name` key.
    pub at: Location,
    /// The law parameters `(n, κ)` of the failed solve, if known.
    pub law_params: Option<[f64; 2]>,
    /// Likely causes in words (see [`hints`]).
    pub hints: Vec<String>,
    source: Box<dyn Error + 'static>,
}

impl ExperimentFailure {
    /// A failure of `experiment` at `at` with `source` as the cause; the hints are computed
    /// from `source`, the experiment's conditions and the law parameters.
    pub fn new(
        experiment: &Experiment,
        material: &Material,
        at: Location,
        law_params: Option<[f64; 2]>,
        source: Box<dyn Error + 'static>,
    ) -> Self {
        let hints = hints(source.as_ref(), experiment, material, law_params);
        ExperimentFailure {
            experiment: experiment.name.clone(),
            at,
            law_params,
            hints,
            source,
        }
    }

    /// A failure without the experiment's conditions (one generic hint).
    pub fn unlocated(experiment: &str, at: Location, source: Box<dyn Error + 'static>) -> Self {
        ExperimentFailure {
            experiment: experiment.to_string(),
            at,
            law_params: None,
            hints: Vec::new(),
            source,
        }
    }
}

impl fmt::Display for ExperimentFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "experiment {} ({}): simulation",
            self.experiment, self.at
        )?;
        if let Some([n, kappa]) = self.law_params {
            write!(f, " at (n, kappa) = ({}, {})", show(n), show(kappa))?;
        }
        write!(f, " failed")
    }
}

impl Error for ExperimentFailure {
    fn source(&self) -> Option<&(dyn Error + 'static)> {
        Some(self.source.as_ref())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn experiment(t_in: f64, t_air: f64, take_up: f64) -> Experiment {
        Experiment {
            name: "e1".into(),
            mass_flow: 3.08e-5,
            inlet: Inlet::Diameter(1.134e-3),
            inlet_temperature: t_in,
            air_temperature: t_air,
            spinline_length: 0.51,
            take_up: Some(TakeUp::Diameter(take_up)),
        }
    }

    fn stalled(last: BvpError) -> FiberError {
        FiberError::Solver(BvpError::ContinuationStalled {
            reached: 0.92,
            target: 1.0,
            step: 6e-5,
            min_step: 1e-4,
            last_error: Box::new(last),
        })
    }

    #[test]
    fn cold_inlet_is_blamed_on_the_vft_law() {
        let m = Material::pmma7n();
        let e = experiment(m.vft_t_vf + 0.001, 293.15, 9e-5);
        let err = stalled(BvpError::NonFinite {
            what: "right-hand side",
            component: 3,
            x: 0.95,
        });
        let h = hints(&err, &e, &m, Some([0.8, 11.71]));
        assert!(h.iter().any(|s| s.contains("vft_T_VF_K")), "{h:?}");
        assert!(!h.iter().any(|s| s.contains("strain thinning")), "{h:?}");
    }

    #[test]
    fn small_n_and_max_nodes_are_named() {
        let m = Material::pmma7n();
        let e = experiment(513.15, 293.15, 9e-5);
        let err = stalled(BvpError::MaxNodesExceeded {
            nodes: 60,
            max_nodes: 50,
            max_residual: 1.0,
            tol: 1e-6,
        });
        let h = hints(&err, &e, &m, Some([0.0, 11.71]));
        assert!(h.iter().any(|s| s.contains("--max-nodes")), "{h:?}");
        assert!(h.iter().any(|s| s.contains("n = 0")), "{h:?}");
        let thin = experiment(513.15, 293.15, 1e-5);
        let h = hints(&err, &thin, &m, Some([0.8, 11.71]));
        assert!(h.iter().any(|s| s.contains("too thin")), "{h:?}");
    }

    #[test]
    fn a_growth_limit_is_explained_not_blamed_on_max_nodes() {
        let m = Material::pmma7n();
        let e = experiment(513.15, 293.15, 9e-5);
        let err = FiberError::Solver(BvpError::MeshGrowthLimit {
            start_nodes: 60,
            nodes: 900,
            limit: 480,
            max_residual: 1.0,
            tol: 1e-4,
        });
        let h = hints(&err, &e, &m, Some([0.8, 11.71]));
        assert!(
            h.iter()
                .any(|s| s.contains("60 nodes") && s.contains("more than 480")),
            "{h:?}"
        );
        assert!(!h.iter().any(|s| s.contains("--max-nodes")), "{h:?}");
    }

    #[test]
    fn failure_names_experiment_line_and_keeps_the_cause() {
        let m = Material::pmma7n();
        let e = experiment(513.15, 600.0, 9e-5);
        let cause = stalled(BvpError::NewtonFailed {
            iterations: 3,
            nodes: 21,
            reason: "diverged".into(),
            max_residual: 1.0,
            max_bc_residual: 1.0,
        });
        let at = Location {
            path: "x.toml".into(),
            line: Some(27),
        };
        let f = ExperimentFailure::new(&e, &m, at, Some([0.8, 11.71]), Box::new(cause));
        assert!(
            f.to_string().starts_with("experiment e1 (x.toml:27)"),
            "{f}"
        );
        let src = f.source().map(|s| s.to_string()).unwrap_or_default();
        assert!(src.contains("continuation stopped"), "{src}");
        assert!(
            f.hints.iter().any(|s| s.contains("hotter")),
            "{:?}",
            f.hints
        );
        assert_eq!(failed_experiment(&f).map(|x| x.0), Some("e1".to_string()));
    }
}

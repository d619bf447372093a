//! `simulate`: every experiment at given law parameters (and fixed effect strengths), profiles
//! as numpy arrays, optionally with exact forward sensitivities of the profiles.

use crate::convert::array2;
use crate::dataset::Dataset;
use crate::errors::{input_error, to_py_err, BoxError};
use crate::fit::profiles_dict;
use crate::options;
use crate::run::interruptible;
use diffbvp::fiber::effects::{physics_with, Effect};
use diffbvp::fiber::failure_hints::ExperimentFailure;
use diffbvp::fiber::input::Location;
use diffbvp::fiber::take_up::{resolve_take_up, MissingTakeUp, TakeUpError};
use diffbvp::fiber::{simulate as solve, CarreauLike, FiberModel, Profiles, SimulateOptions};
use diffbvp::sensitivity::{residual_jacobian, PointFunction, Sensitivities};
use diffbvp::{Bvp, DualNum};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::atomic::Ordering;

type Model = FiberModel<CarreauLike>;

/// The fiber diameter `d̃(y, p)` as a point function of the state and the full parameter
/// vector (unknowns first), for exact diameter sensitivities.
struct Diameter<'a> {
    model: &'a Model,
    unknowns: usize,
}

impl PointFunction for Diameter<'_> {
    fn eval<D: DualNum<Primitive = f64> + Copy>(&self, _i: usize, _x: f64, y: &[D], p: &[D]) -> D {
        self.model.fiber_diameter(y, &p[self.unknowns..])
    }
}

/// Exact derivatives of the SI profiles with respect to the law parameters and the strengths
/// at `positions` \[m\]: `(parameter names, {quantity: positions × parameters})`.
pub struct ProfileSensitivities {
    pub names: Vec<String>,
    pub columns: Vec<usize>,
    /// (key, row-major values) for diameter, velocity, temperature, force, strain rate.
    pub blocks: Vec<(&'static str, Vec<f64>)>,
}

fn sensitivities(
    model: &Model,
    sol: &diffbvp::Solution,
    positions: &[f64],
) -> Result<ProfileSensitivities, BoxError> {
    let sens = Sensitivities::compute(model, sol)?;
    let co = *model.coefficients();
    let si = co.si;
    let xs: Vec<f64> = positions.iter().map(|s| s / si.length).collect();
    let g = Diameter {
        model,
        unknowns: model.num_unknowns(),
    };
    let (_, jac) = residual_jacobian(model, sol, &sens, &xs, &g)?;
    let q = sol.params.len();
    // p = [c, n, κ, strengths..., take-up factor]: report n, κ and the strengths
    let mut names = vec!["n".to_string(), "kappa".to_string()];
    names.extend(
        model
            .physics
            .strength_parameters()
            .iter()
            .map(|(n, _)| n.to_string()),
    );
    let columns: Vec<usize> = (1..1 + names.len()).filter(|&j| j < q).collect();
    let m = columns.len();
    let pick = |row: &[f64], scale: f64, out: &mut Vec<f64>| {
        for &j in &columns {
            out.push(row[j] * scale);
        }
    };
    let mut diameter = Vec::with_capacity(xs.len() * m);
    for i in 0..xs.len() {
        pick(&jac[i * q..(i + 1) * q], si.diameter, &mut diameter);
    }
    let n = 4;
    let scales = [
        ("velocity_m_s", 0, si.velocity),
        ("force_N", 1, si.force),
        ("temperature_K", 2, si.temperature),
        ("strain_rate_1_s", 3, si.strain_rate),
    ];
    let mut blocks = vec![("diameter_m", diameter)];
    let mut states: Vec<Vec<f64>> = (0..n).map(|_| Vec::with_capacity(xs.len() * m)).collect();
    let mut dy = vec![0.0; n * q];
    let mut dyp = vec![0.0; n * q];
    for &x in &xs {
        sens.at_into(x, &mut dy, &mut dyp);
        for (c, &(_, comp, scale)) in scales.iter().enumerate() {
            pick(&dy[comp * q..(comp + 1) * q], scale, &mut states[c]);
        }
    }
    for ((key, _, _), v) in scales.iter().zip(states) {
        blocks.push((key, v));
    }
    names.truncate(m);
    Ok(ProfileSensitivities {
        names,
        columns,
        blocks,
    })
}

/// One simulated experiment.
pub struct Simulated {
    pub name: String,
    pub nodes: usize,
    pub take_up_from_data_m: Option<f64>,
    pub profiles: Profiles,
    pub sensitivities: Option<ProfileSensitivities>,
}

/// The settings of one `simulate` call.
pub struct SimulateSettings {
    pub law: [f64; 2],
    pub effects: Vec<(Effect, f64)>,
    pub missing: MissingTakeUp,
    pub points: usize,
    pub positions: Option<Vec<f64>>,
    pub sensitivities: bool,
    pub options: SimulateOptions,
}

fn take_up_error(err: TakeUpError, name: &str, at: &Location) -> BoxError {
    match err {
        TakeUpError::NoMeasurements => {
            format!("experiment {name}: take_up_from_data needs measurements").into()
        }
        TakeUpError::Smoothing(err) => format!(
            "experiment {name} ({at}): take_up_from_data: smoothing the measurements failed: {err}"
        )
        .into(),
        TakeUpError::Missing => format!(
            "experiment {name} has no take-up condition: give take_up_diameter_m or \
             take_up_velocity_m_s in {}, or take_up_diameter=M or take_up_from_data=True",
            at.path.display()
        )
        .into(),
    }
}

/// Why `simulate_all` stopped.
pub enum SimError {
    /// Experiment `k` failed (model or solve); named with its TOML line on the caller's thread.
    Failure {
        k: usize,
        take_up: Option<diffbvp::fiber::setup::TakeUp>,
        from_data: Option<f64>,
        source: BoxError,
    },
    /// Anything else.
    Other(BoxError),
}

impl SimError {
    /// The CLI's error: a failure names the experiment, its TOML line and likely causes.
    fn into_error(self, dataset: &Dataset, law: [f64; 2]) -> Box<dyn std::error::Error> {
        match self {
            SimError::Other(e) => e,
            SimError::Failure {
                k,
                take_up,
                from_data,
                source,
            } => {
                let loaded = &dataset.inner.loaded;
                let mut e = loaded.set.experiments[k].clone();
                e.take_up = take_up;
                let at = Location {
                    path: dataset.inner.path.clone(),
                    line: loaded.details[k].line,
                };
                let mut f = ExperimentFailure::new(&e, &loaded.set.material, at, Some(law), source);
                if let Some(d) = from_data {
                    f.hints.push(format!(
                        "the take-up diameter {d:.4e} m is d_fit(L) of the smoothed measurements \
                         (take_up_from_data)"
                    ));
                }
                Box::new(f)
            }
        }
    }
}

/// Simulates every experiment in order (as `rheometer simulate` does), stopping between
/// experiments once `cancel` is set.
// TODO(restructure): call the library's simulate workflow (take-up rules, failure naming).
pub fn simulate_all(
    dataset: &Dataset,
    s: &SimulateSettings,
    cancel: &std::sync::atomic::AtomicBool,
) -> Result<Vec<Simulated>, SimError> {
    let loaded = &dataset.inner.loaded;
    let set = &loaded.set;
    let mut out = Vec::with_capacity(set.experiments.len());
    for (k, e) in set.experiments.iter().enumerate() {
        if cancel.load(Ordering::SeqCst) {
            return Err(SimError::Other("interrupted".into()));
        }
        let at = Location {
            path: dataset.inner.path.clone(),
            line: loaded.details[k].line,
        };
        let mut e = e.clone();
        let resolved = resolve_take_up(&e, set.measurements[k].as_ref(), s.missing, None)
            .map_err(|err| SimError::Other(take_up_error(err, &e.name, &at)))?;
        e.take_up = Some(resolved.take_up);
        let failed = |source: BoxError| SimError::Failure {
            k,
            take_up: e.take_up,
            from_data: resolved.from_data,
            source,
        };
        let physics = physics_with(&s.effects).map_err(|x| SimError::Other(x.into()))?;
        let model = FiberModel::new(&set.material, &set.air, &e, CarreauLike::new(), physics)
            .map_err(|x| failed(Box::new(x)))?;
        let sol = solve(&model, &s.law, &s.options).map_err(|x| failed(Box::new(x)))?;
        let positions = match &s.positions {
            Some(p) => p.clone(),
            None => diffbvp::mesh::linspace(0.0, e.spinline_length, s.points),
        };
        let profiles = sol.profiles(&model, &positions);
        let sensitivities = if s.sensitivities {
            Some(sensitivities(&model, &sol.solution, &positions).map_err(&failed)?)
        } else {
            None
        };
        out.push(Simulated {
            name: e.name.clone(),
            nodes: sol.nodes(),
            take_up_from_data_m: resolved.from_data,
            profiles,
            sensitivities,
        });
    }
    Ok(out)
}

/// Simulates every experiment at `(n, κ)`. Returns `{"law", "effects", "experiments": [{"name",
/// "nodes", "take_up_from_data_m", "profiles": {...}, "sensitivities": {...} | None}]}`.
#[pyfunction]
#[pyo3(signature = (dataset, n=0.8, kappa=11.71, *, effects=Vec::new(), take_up_diameter=None,
    take_up_from_data=false, points=101, positions=None, sensitivities=false, tol=None,
    max_nodes=None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    dataset: &Dataset,
    n: f64,
    kappa: f64,
    effects: Vec<String>,
    take_up_diameter: Option<f64>,
    take_up_from_data: bool,
    points: usize,
    positions: Option<Vec<f64>>,
    sensitivities: bool,
    tol: Option<f64>,
    max_nodes: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let law = [options::check_n(n)?, options::check_kappa(kappa)?];
    let mut fixed = Vec::new();
    for w in options::effects(&effects)? {
        let v = w.value.ok_or_else(|| {
            input_error(format!(
                "effects: give {0}'s strength as \"{0}=VALUE\" (a simulation fits nothing)",
                w.effect.name()
            ))
        })?;
        fixed.push((w.effect, v));
    }
    physics_with(&fixed).map_err(|e| input_error(format!("effects: {e}")))?;
    let missing = match (take_up_diameter, take_up_from_data) {
        (Some(d), _) if !(1e-7..=0.02).contains(&d) => {
            return Err(input_error(format!(
                "a take-up diameter must lie in [1e-7, 0.02] m (got {d} m; the unit is metres)"
            )))
        }
        (Some(d), _) => MissingTakeUp::Diameter(d),
        (None, true) => MissingTakeUp::FromData,
        (None, false) => MissingTakeUp::Error,
    };
    if !(2..=100_000).contains(&points) {
        return Err(input_error(format!(
            "points: give 2 to 100000 output positions per profile (got {points})"
        )));
    }
    if let Some(p) = &positions {
        if p.is_empty() || p.iter().any(|x| !x.is_finite()) {
            return Err(input_error(
                "positions: give finite positions along the spin line (m)".into(),
            ));
        }
    }
    let mut sim_options = SimulateOptions {
        max_nodes: options::max_nodes(max_nodes)?,
        ..SimulateOptions::default()
    };
    if let Some(t) = tol {
        if !(1e-12..=0.1).contains(&t) {
            return Err(input_error(format!(
                "tol: the tolerance must lie in [1e-12, 0.1] (got {t})"
            )));
        }
        sim_options.tol = t;
    }
    let settings = SimulateSettings {
        law,
        effects: fixed,
        missing,
        points,
        positions,
        sensitivities,
        options: sim_options,
    };
    let out = interruptible(py, |cancel| simulate_all(dataset, &settings, &cancel))?;
    let runs = out.map_err(|e| {
        let e = e.into_error(dataset, law);
        to_py_err(py, e, Some(dataset.data()), Some(law))
    })?;
    let d = PyDict::new(py);
    d.set_item("law", (law[0], law[1]))?;
    d.set_item("effects", effects)?;
    let list = pyo3::types::PyList::empty(py);
    for r in &runs {
        let e = PyDict::new(py);
        e.set_item("name", &r.name)?;
        e.set_item("nodes", r.nodes)?;
        e.set_item("take_up_from_data_m", r.take_up_from_data_m)?;
        e.set_item("profiles", profiles_dict(py, &r.profiles)?)?;
        match &r.sensitivities {
            Some(s) => {
                let sd = PyDict::new(py);
                sd.set_item("parameters", s.names.clone())?;
                let rows = r.profiles.position.len();
                for (key, v) in &s.blocks {
                    sd.set_item(*key, array2(py, v, rows, s.columns.len())?)?;
                }
                e.set_item("sensitivities", sd)?;
            }
            None => e.set_item("sensitivities", py.None())?,
        }
        list.append(e)?;
    }
    d.set_item("experiments", list)?;
    Ok(d)
}

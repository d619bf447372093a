//! Simulating every experiment of a data set for a comparison: the law parameters, the take-up
//! conditions (from the data set, from the smoothed data, or as fitted) and the physics.

use super::{compare, CompareError, CompareOptions, Comparison, SimulatedExperiment};
use crate::fiber::effects::Effect;
use crate::fiber::error::Readable;
use crate::fiber::material_law::CarreauLike;
use crate::fiber::model::FiberModel;
use crate::fiber::setup::ExperimentSet;
use crate::fiber::simulate::{simulate_params, SimulateOptions};
pub use crate::fiber::take_up::MissingTakeUp;
use crate::fiber::take_up::{resolve_take_up, TakeUpError};
use crate::fiber::Physics;
use crate::mesh::linspace;
use rayon::prelude::*;

/// The model to compare with: Carreau-type law parameters, take-up conditions and physics.
pub struct ModelSetup<'a> {
    /// `(n, κ)` of the Carreau-type law (`n = 1`: Newtonian).
    pub law_params: [f64; 2],
    /// Take-up factors `φ_k` multiplying each experiment's take-up condition (as fitted by the
    /// principled estimator; `None`: all 1).
    pub take_up_factors: Option<Vec<f64>>,
    /// Experiments without a take-up condition in the data set.
    pub missing_take_up: MissingTakeUp,
    /// Builds the physics of each experiment's model (called once per experiment).
    pub physics: &'a (dyn Fn() -> Physics + Sync),
    /// BVP settings (cold start per experiment).
    pub simulate: SimulateOptions,
    /// Points of the fine model curve for figures (default 201).
    pub curve_points: usize,
}

impl<'a> ModelSetup<'a> {
    /// The Carreau-type law at `(n, κ)`, take-up conditions from the data set only.
    pub fn carreau(law_params: [f64; 2], physics: &'a (dyn Fn() -> Physics + Sync)) -> Self {
        ModelSetup {
            law_params,
            take_up_factors: None,
            missing_take_up: MissingTakeUp::Error,
            physics,
            simulate: SimulateOptions::default(),
            curve_points: 201,
        }
    }

    /// Missing take-up conditions from the smoothed data (`d_fit(L)`).
    pub fn take_up_from_data(mut self) -> Self {
        self.missing_take_up = MissingTakeUp::FromData;
        self
    }
}

/// Simulates every experiment of `set` with `setup` (in parallel) and evaluates the model at
/// the measurement positions. Experiments without measurements are an error.
pub fn simulate_experiments(
    set: &ExperimentSet,
    setup: &ModelSetup<'_>,
) -> Result<Vec<SimulatedExperiment>, CompareError> {
    if set.experiments.is_empty() {
        return Err(CompareError::Data("the data set has no experiments".into()));
    }
    if let Some(f) = &setup.take_up_factors {
        if f.len() != set.experiments.len() {
            return Err(CompareError::Data(format!(
                "{} take-up factors for {} experiments",
                f.len(),
                set.experiments.len()
            )));
        }
        if let Some(v) = f.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
            return Err(CompareError::Data(format!(
                "take-up factor {v} is not a positive number"
            )));
        }
    }
    set.experiments
        .par_iter()
        .enumerate()
        .map(|(k, e)| {
            let sim_err = |source| CompareError::Simulation {
                experiment: e.name.clone(),
                source,
            };
            let m = set.measurements[k].as_ref().ok_or_else(|| {
                CompareError::Data(format!(
                    "experiment {} has no measurements (no data file)",
                    e.name
                ))
            })?;
            let mut e = e.clone();
            let resolved = resolve_take_up(&e, Some(m), setup.missing_take_up, None).map_err(
                |err| match err {
                    TakeUpError::Smoothing(source) => CompareError::Smoothing {
                        experiment: e.name.clone(),
                        source,
                    },
                    TakeUpError::Missing | TakeUpError::NoMeasurements => {
                        CompareError::Data(format!(
                            "experiment {} has no take-up condition: give take_up_diameter_m \
                             or take_up_velocity_m_s in the TOML, or take it from the data",
                            e.name
                        ))
                    }
                },
            )?;
            if let Some(d) = resolved.from_data {
                if !(d.is_finite() && d > 0.0) {
                    return Err(CompareError::Data(format!(
                        "experiment {}: the take-up diameter d_fit(L) = {d} m of the \
                         smoothed measurements is not a positive number; give \
                         take_up_diameter_m in the TOML",
                        e.name
                    )));
                }
            }
            e.take_up = Some(resolved.take_up);
            let model = FiberModel::new(
                &set.material,
                &set.air,
                &e,
                CarreauLike::new(),
                (setup.physics)(),
            )
            .map_err(sim_err)?;
            let mut p = model.parameters(1.0, &setup.law_params).map_err(sim_err)?;
            if let Some(f) = &setup.take_up_factors {
                p[model.param_layout().take_up_factor()] = f[k];
            }
            let sol = simulate_params(&model, &p, None, &setup.simulate).map_err(sim_err)?;
            let curve = if setup.curve_points >= 2 {
                sol.profiles(
                    &model,
                    &linspace(0.0, e.spinline_length, setup.curve_points),
                )
            } else {
                Default::default()
            };
            Ok(SimulatedExperiment {
                name: e.name.clone(),
                positions: m.positions.clone(),
                measured: m.diameters.clone(),
                at_measurements: sol.profiles(&model, &m.positions),
                curve,
            })
        })
        .collect()
}

/// Simulates every experiment of `set` with `setup` and compares with the measurements
/// (the noise level from `options`, else the data set's `relative_uncertainty`, else
/// estimated).
pub fn compare_set(
    set: &ExperimentSet,
    setup: &ModelSetup<'_>,
    options: &CompareOptions,
) -> Result<Comparison, CompareError> {
    let runs = simulate_experiments(set, setup)?;
    compare(&runs, set.relative_uncertainty, options)
}

/// The parts of a fit report (`rheometer fit --json`, [`FitReport`](crate::fiber::rheometer::FitReport))
/// a comparison needs; other fields are ignored (so missing standard errors, written as `null`,
/// do not matter).
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
pub struct FitParameters {
    /// The estimator of the fit.
    pub estimator: crate::fiber::rheometer::Estimator,
    /// Power index `n` \[-\].
    pub n: f64,
    /// `κ = ln(K / 1 Pa)` \[-\].
    pub kappa: f64,
    /// Take-up factors `φ_k`, in the experiment order of the data set.
    #[serde(default)]
    pub take_up_factors: Vec<f64>,
    /// The extra effects of the fitted model with their strengths (empty for the paper's
    /// model).
    #[serde(default)]
    pub effects: Vec<FittedEffect>,
    /// Experiment names of the fit, in the order of `take_up_factors` (empty in reports
    /// written before this field existed).
    #[serde(default)]
    pub experiments: Vec<String>,
    /// The warnings of the fit (estimates at bounds, misfit, …): a comparison with a doubtful
    /// fit repeats them.
    #[serde(default)]
    pub warnings: Vec<crate::fiber::rheometer::FitWarning>,
}

/// The range of `n` accepted from a fit file (the rheometer's search range) \[-\].
pub const FIT_FILE_N_RANGE: [f64; 2] = [0.0, 1.0];
/// The range of `κ = ln(K / 1 Pa)` accepted from a fit file (`K` from 1 Pa to about
/// `5·10²¹` Pa) \[-\].
pub const FIT_FILE_KAPPA_RANGE: [f64; 2] = [0.0, 50.0];
/// The range of take-up factors accepted from a fit file: the rheometer's default search range
/// (`IdentifyOptions::take_up_bounds`), which every fit of the `rheometer` program uses \[-\].
pub const FIT_FILE_TAKE_UP_RANGE: [f64; 2] = [0.5, 1.5];

/// An effect of a fitted model as read from a fit report.
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
pub struct FittedEffect {
    /// Canonical name (e.g. `"radiation"`).
    pub effect: String,
    /// Strength in the effect's unit.
    pub strength: f64,
    /// Whether the strength was fitted (else fixed).
    #[serde(default)]
    pub fitted: bool,
    /// Its shape parameters (e.g. a fitted decay length), empty for effects without them.
    #[serde(default)]
    pub shapes: Vec<FittedShape>,
}

/// A shape parameter of a fitted effect (e.g. `{"name": "decay_length", "value": 0.07}`, in
/// the shape's unit, metres).
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
pub struct FittedShape {
    /// Shape name (`"decay_length"`, `"onset"`, `"ramp_width"`).
    pub name: String,
    /// Its value.
    pub value: f64,
}

impl FittedEffect {
    /// The effect with its shape parameters fixed at the fitted values; errors name the
    /// effect or shape.
    pub fn to_effect(&self) -> Result<Effect, String> {
        let mut effect: Effect = self.effect.parse()?;
        for sh in &self.shapes {
            effect = effect.with_shape(&sh.name, sh.value)?;
        }
        Ok(effect)
    }
}

impl FitParameters {
    /// Parses the JSON text of a fit report; `source` names it in errors.
    pub fn from_json(text: &str, source: &str) -> Result<Self, CompareError> {
        let not_report = |what: String| {
            CompareError::Data(format!(
                "{source} is not a fit report as written by `rheometer fit --json`: {what}"
            ))
        };
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| not_report(format!("not valid JSON: {e}")))?;
        let obj = value
            .as_object()
            .ok_or_else(|| not_report("expected a JSON object {...}".into()))?;
        // the fields a comparison needs, checked one by one so that errors name them
        let kind = |v: &serde_json::Value| match v {
            serde_json::Value::Null => "null",
            serde_json::Value::Bool(_) => "a boolean",
            serde_json::Value::Number(_) => "a number",
            serde_json::Value::String(_) => "a string",
            serde_json::Value::Array(_) => "an array",
            serde_json::Value::Object(_) => "an object",
        };
        let field_err = |field: &str, msg: String| {
            CompareError::Data(format!("{source}: field {field}: {msg}"))
        };
        for key in ["estimator", "n", "kappa"] {
            if !obj.contains_key(key) {
                return Err(field_err(
                    &format!("\"{key}\""),
                    "missing (a fit report from `rheometer fit --json` has it)".into(),
                ));
            }
        }
        for key in ["n", "kappa"] {
            if let Some(v) = obj.get(key).filter(|v| !v.is_number()) {
                return Err(field_err(
                    &format!("\"{key}\""),
                    format!("expected a number, found {} ({v})", kind(v)),
                ));
            }
        }
        if let Some(v) = obj.get("take_up_factors") {
            let arr = v.as_array().ok_or_else(|| {
                field_err(
                    "\"take_up_factors\"",
                    format!("expected an array of numbers, found {}", kind(v)),
                )
            })?;
            if let Some((i, x)) = arr.iter().enumerate().find(|(_, x)| !x.is_number()) {
                return Err(field_err(
                    &format!("\"take_up_factors\"[{i}]"),
                    format!("expected a number, found {} ({x})", kind(x)),
                ));
            }
        }
        if let Some(v) = obj.get("effects") {
            let arr = v.as_array().ok_or_else(|| {
                field_err(
                    "\"effects\"",
                    format!("expected an array of effects, found {}", kind(v)),
                )
            })?;
            for (i, e) in arr.iter().enumerate() {
                let f = format!("\"effects\"[{i}]");
                match e.get("effect") {
                    Some(serde_json::Value::String(_)) => {}
                    Some(x) => {
                        return Err(field_err(
                            &format!("{f}.effect"),
                            format!("expected an effect name, found {} ({x})", kind(x)),
                        ))
                    }
                    None => return Err(field_err(&format!("{f}.effect"), "missing".into())),
                }
                match e.get("strength") {
                    Some(x) if x.is_number() => {}
                    Some(x) => {
                        return Err(field_err(
                            &format!("{f}.strength"),
                            format!("expected a number, found {} ({x})", kind(x)),
                        ))
                    }
                    None => return Err(field_err(&format!("{f}.strength"), "missing".into())),
                }
            }
        }
        let p: FitParameters =
            serde_json::from_value(value).map_err(|e| not_report(e.to_string()))?;
        p.validate(source)?;
        Ok(p)
    }

    /// Checks the values (as read from a file `source`): `n` in [`FIT_FILE_N_RANGE`], `κ` in
    /// [`FIT_FILE_KAPPA_RANGE`], take-up factors in [`FIT_FILE_TAKE_UP_RANGE`], effects known,
    /// once each, with finite strengths inside their search ranges, and as many experiment
    /// names (if given) as take-up factors. Errors name the file and the field.
    pub fn validate(&self, source: &str) -> Result<(), CompareError> {
        let bad = |field: String, msg: String| {
            Err(CompareError::Data(format!(
                "{source}: field {field}: {msg}"
            )))
        };
        let in_range = |v: f64, r: [f64; 2]| v.is_finite() && v >= r[0] && v <= r[1];
        if !in_range(self.n, FIT_FILE_N_RANGE) {
            return bad(
                "\"n\"".into(),
                format!(
                    "n = {} must be a finite power index in [{}, {}]",
                    Readable(self.n),
                    FIT_FILE_N_RANGE[0],
                    FIT_FILE_N_RANGE[1]
                ),
            );
        }
        if !in_range(self.kappa, FIT_FILE_KAPPA_RANGE) {
            return bad(
                "\"kappa\"".into(),
                format!(
                    "kappa = ln(K / 1 Pa) = {} must be finite and in [{}, {}]",
                    Readable(self.kappa),
                    FIT_FILE_KAPPA_RANGE[0],
                    FIT_FILE_KAPPA_RANGE[1]
                ),
            );
        }
        for (i, &f) in self.take_up_factors.iter().enumerate() {
            if !in_range(f, FIT_FILE_TAKE_UP_RANGE) {
                return bad(
                    format!("\"take_up_factors\"[{i}]"),
                    format!(
                        "take-up factor {} must be finite and in [{}, {}]",
                        Readable(f),
                        FIT_FILE_TAKE_UP_RANGE[0],
                        FIT_FILE_TAKE_UP_RANGE[1]
                    ),
                );
            }
        }
        if !self.experiments.is_empty() && self.experiments.len() != self.take_up_factors.len() {
            return bad(
                "\"experiments\"".into(),
                format!(
                    "{} experiment names but {} take-up factors",
                    self.experiments.len(),
                    self.take_up_factors.len()
                ),
            );
        }
        for (i, e) in self.effects.iter().enumerate() {
            let field = format!("\"effects\"[{i}]");
            let effect: Effect = match e.to_effect() {
                Ok(effect) => effect,
                Err(msg) => return bad(format!("{field}.effect"), msg),
            };
            if self.effects[..i].iter().any(|o| o.effect == e.effect) {
                return bad(
                    format!("{field}.effect"),
                    format!("effect \"{}\" appears twice", e.effect),
                );
            }
            let (lo, hi) = effect.bounds();
            if !(e.strength.is_finite() && e.strength >= lo && e.strength <= hi) {
                return bad(
                    format!("{field}.strength"),
                    format!(
                        "{} strength {} must be finite and in [{lo}, {hi}] {}",
                        e.effect,
                        e.strength,
                        effect.unit()
                    ),
                );
            }
        }
        Ok(())
    }

    /// Checks the fit's experiment names (where the file has them) against the data set's
    /// `names`, in order; `source` names the fit file in errors.
    pub fn check_experiments(&self, names: &[String], source: &str) -> Result<(), CompareError> {
        if self.experiments.is_empty() {
            return Ok(());
        }
        if self.experiments.len() != names.len() {
            return Err(CompareError::Data(format!(
                "{source}: field \"experiments\": the fit has {} experiments, the data set {}; \
                 was the fit made on this data set?",
                self.experiments.len(),
                names.len()
            )));
        }
        for (i, (a, b)) in self.experiments.iter().zip(names).enumerate() {
            if a != b {
                return Err(CompareError::Data(format!(
                    "{source}: field \"experiments\"[{i}]: the fit's experiment \"{a}\" is \
                     \"{b}\" in the data set; was the fit made on this data set (same order)?"
                )));
            }
        }
        Ok(())
    }

    /// Number of parameters the fit adjusted to the data: `(n, κ)` and, for the principled
    /// estimator, one take-up factor per experiment.
    pub fn fitted_parameters(&self) -> usize {
        match self.estimator {
            crate::fiber::rheometer::Estimator::Principled => 2 + self.take_up_factors.len(),
            crate::fiber::rheometer::Estimator::Paper => 2,
        }
        .saturating_add(self.effects.iter().filter(|e| e.fitted).count())
    }

    /// Applies the fit to `setup`: law parameters, take-up factors (principled estimator;
    /// checked against `experiments`, the number of experiments) and the rheometer's take-up
    /// convention (`d_fit(L)` where the data set gives none).
    pub fn apply(
        &self,
        setup: &mut ModelSetup<'_>,
        experiments: usize,
        source: &str,
    ) -> Result<(), CompareError> {
        setup.law_params = [self.n, self.kappa];
        setup.missing_take_up = MissingTakeUp::FromData;
        setup.take_up_factors = None;
        if self.estimator == crate::fiber::rheometer::Estimator::Principled {
            if self.take_up_factors.len() != experiments {
                return Err(CompareError::Data(format!(
                    "{source}: field \"take_up_factors\": {} take-up factors for {experiments} \
                     experiments; was the fit made on this data set?",
                    self.take_up_factors.len()
                )));
            }
            setup.take_up_factors = Some(self.take_up_factors.clone());
        }
        Ok(())
    }
}

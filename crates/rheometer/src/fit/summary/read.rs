//! Reading a [`FitSummary`] back from its JSON (`rheometer fit --json`, or a diagnosis'
//! final fit): the next step (`compare --fit`, `fit --from`, `diagnose --from`) starts from
//! it. A file is read by [`FitSummary::read_file`], the one door of every such file (the
//! bounded, strict reader [`read_json`], the report's stamp [`check_report`], the field types
//! with their paths, the values' ranges); every error names the file and the field.

use crate::data::input::{parse_json, read_json, show_json_path, JsonSource};
use crate::error::Readable;
use crate::fit::estimator::Estimator;
use crate::fit::summary::{FitSummary, WarningCode};
use crate::model::effects::{Effect, EffectSetting};
use crate::model::setup::{Experiment, Measurements};
use crate::report::report_json::{check_report, ReportKind, SCHEMA_VERSION};
use serde_json::Value;
use std::path::Path;

/// The range of `n` accepted from a fit file (the rheometer's search range) \[-\].
pub const FIT_FILE_N_RANGE: [f64; 2] = [0.0, 1.0];
/// The range of `κ = ln(K / 1 Pa)` accepted from a fit file (`K` from 1 Pa to about
/// `5·10²¹` Pa) \[-\].
pub const FIT_FILE_KAPPA_RANGE: [f64; 2] = [0.0, 50.0];
/// The range of take-up factors accepted from a fit file: the rheometer's default search range
/// (`IdentifyOptions::take_up_bounds`), which every fit of the `rheometer` program uses \[-\].
pub const FIT_FILE_TAKE_UP_RANGE: [f64; 2] = [0.5, 1.5];

/// A previous fit's effects as the model of a next fit
/// ([`FitSummary::continued_effects`]).
#[derive(Debug, Clone)]
pub struct ContinuedEffects {
    /// The effects, strengths fitted or fixed as in the previous fit, fitted shapes free.
    pub effects: Vec<EffectSetting>,
    /// Start values of the fitted strengths (by effect name) and shapes (by model-parameter
    /// name).
    pub starts: Vec<(String, f64)>,
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// A number, or an estimate object with a numeric `value`.
fn is_estimate(v: &Value) -> bool {
    v.is_number() || v.get("value").is_some_and(Value::is_number)
}

/// The error of an estimate field `key` whose value `v` is neither a number nor an object with
/// a numeric `value`: names the inner field where the object is there but its value is not.
fn estimate_type_error(key: &str, v: &Value) -> String {
    match v.get("value") {
        Some(inner) => format!(
            "field `{key}.value` is {} ({}); it should be a number",
            kind(inner),
            short_json(inner)
        ),
        None if v.is_object() => format!("field `{key}.value`: missing (an estimate has a value)"),
        None => format!(
            "field `{key}` is {} ({}); it should be an estimate {{\"value\": number, ...}}",
            kind(v),
            short_json(v)
        ),
    }
}

/// `v` as JSON, cut to 60 characters for messages.
fn short_json(v: &Value) -> String {
    let s = v.to_string();
    if s.chars().count() > 60 {
        format!("{}…", s.chars().take(59).collect::<String>())
    } else {
        s
    }
}

/// Checks the shape of the fields the next step needs, one by one so that errors name them.
fn check_fields(obj: &serde_json::Map<String, Value>) -> Result<(), String> {
    for key in ["estimator", "n", "kappa"] {
        if !obj.contains_key(key) {
            return Err(format!(
                "field \"{key}\": missing (a fit report from `rheometer fit --json` has it)"
            ));
        }
    }
    for key in ["n", "kappa"] {
        if let Some(v) = obj.get(key).filter(|v| !is_estimate(v)) {
            return Err(estimate_type_error(key, v));
        }
    }
    if let Some(v) = obj.get("take_up_factors") {
        let arr = v.as_array().ok_or_else(|| {
            format!(
                "field \"take_up_factors\": expected an array of numbers, found {}",
                kind(v)
            )
        })?;
        if let Some((i, x)) = arr.iter().enumerate().find(|(_, x)| !x.is_number()) {
            return Err(format!(
                "field \"take_up_factors\"[{i}]: expected a number, found {} ({x})",
                kind(x)
            ));
        }
    }
    if let Some(v) = obj.get("effects") {
        let arr = v.as_array().ok_or_else(|| {
            format!(
                "field \"effects\": expected an array of effects, found {}",
                kind(v)
            )
        })?;
        for (i, e) in arr.iter().enumerate() {
            let f = format!("\"effects\"[{i}]");
            match e.get("effect") {
                Some(Value::String(_)) => {}
                Some(x) => {
                    return Err(format!(
                        "field {f}.effect: expected an effect name, found {} ({x})",
                        kind(x)
                    ))
                }
                None => return Err(format!("field {f}.effect: missing")),
            }
            match e.get("strength") {
                Some(x) if is_estimate(x) => {}
                Some(x) => return Err(estimate_type_error(&format!("effects[{i}].strength"), x)),
                None => return Err(format!("field {f}.strength: missing")),
            }
        }
    }
    Ok(())
}

/// The top-level fields of reports written before the layout of schema 1 (flat standard
/// errors and intervals, the noise level and solver statistics beside the estimates).
const EARLIER_LAYOUT_FIELDS: [&str; 11] = [
    "stderr_n",
    "stderr_kappa",
    "ci95_n",
    "ci95_kappa",
    "ci95_K_Pa",
    "noise_level",
    "noise_source",
    "iterations",
    "failed_evaluations",
    "termination",
    "wall_time_s",
];

/// Refuses a report of an earlier layout (see [`EARLIER_LAYOUT_FIELDS`]): its fields would
/// otherwise be left out silently.
fn refuse_earlier_layout(obj: &serde_json::Map<String, Value>) -> Result<(), String> {
    match EARLIER_LAYOUT_FIELDS.iter().find(|k| obj.contains_key(**k)) {
        Some(k) => Err(format!(
            "field `{k}`: a report of an earlier layout (written by a rheometer before schema \
             {SCHEMA_VERSION}, with its standard errors and solver statistics as flat fields); \
             this version reads only its own reports: fit the data again with this version \
             (`rheometer fit --json`, or `diffbvp.fit` in Python)"
        )),
        None => Ok(()),
    }
}

/// A digest of the data a fit is made on: FNV-1a (64 bit) over each experiment's name, mass
/// flow, inlet and air temperatures, spin-line length and measured positions and diameters
/// (their bit patterns), as 16 hex digits. It tells a fit's data from other data that merely
/// share the experiment names; it is no protection against deliberate forgery.
pub fn data_digest<'a>(
    data: impl IntoIterator<Item = (&'a Experiment, &'a Measurements)>,
) -> String {
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h ^= u64::from(b);
            h = h.wrapping_mul(PRIME);
        }
    };
    for (e, m) in data {
        eat(&(e.name.len() as u64).to_le_bytes());
        eat(e.name.as_bytes());
        for x in [
            e.mass_flow,
            e.inlet_temperature,
            e.air_temperature,
            e.spinline_length,
        ] {
            eat(&x.to_bits().to_le_bytes());
        }
        eat(&(m.positions.len() as u64).to_le_bytes());
        for (s, d) in m.positions.iter().zip(&m.diameters) {
            eat(&s.to_bits().to_le_bytes());
            eat(&d.to_bits().to_le_bytes());
        }
    }
    format!("{h:016x}")
}

/// How a fit read back relates to the data it is used with ([`FitSummary::check_data`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DataCheck {
    /// The digests agree: the fit was made on these data.
    Same,
    /// The same experiment names, other numbers: the message says so.
    Differs(String),
    /// The fit records no digest (a diagnosis' base fit made without one, or a report built
    /// in memory): nothing can be said.
    Unknown,
}

impl FitSummary {
    /// Reads the fit of a report file `path` (`-`: standard input): a fit report or, where
    /// `wanted` has [`ReportKind::Diagnosis`], a diagnosis' final fit (its base fit if it has
    /// none). The file is read bounded (at most `max_bytes`) and strictly (`read_json`),
    /// its stamp checked (`check_report`: the current schema version, a wanted kind), then
    /// its fields' types (errors name the path, `n.value`) and values
    /// ([`validate`](Self::validate)); `flag` names the option that gave the file.
    pub fn read_file(
        path: &Path,
        max_bytes: u64,
        flag: &str,
        wanted: &[ReportKind],
    ) -> Result<Self, String> {
        let source = show_json_path(path);
        let remedy = format!(
            "{} FILE",
            wanted
                .first()
                .map_or("rheometer fit --json", |k| k.command())
        );
        let value = read_json(
            path,
            JsonSource {
                max_bytes,
                remedy: &remedy,
            },
        )
        .map_err(|e| {
            let limit = matches!(e, crate::data::input::InputError::Limit { .. });
            format!(
                "{flag}: {e}{}",
                if limit {
                    " (on the command line: --allow-large-inputs)"
                } else {
                    ""
                }
            )
        })?;
        let kind = check_report(&value, wanted, &source, flag)?;
        if kind != ReportKind::Diagnosis {
            return Self::from_report_value(value, &source);
        }
        let Value::Object(mut obj) = value else {
            return Err(format!("{source}: a diagnosis is a JSON object"));
        };
        let (field, fit) = match obj.remove("final_fit").filter(|v| !v.is_null()) {
            Some(f) => ("final_fit", f),
            None => (
                "base_fit",
                obj.remove("base_fit")
                    .ok_or_else(|| format!("{source}: field `base_fit`: missing"))?,
            ),
        };
        Self::from_report_value(fit, &format!("{source} (the diagnosis' field `{field}`)"))
    }

    /// A fit from the JSON value of a report as this version writes it (no older forms):
    /// the fields the next step needs checked one by one, then every field's type (an error
    /// names its path, `experiments[2]`), then the values ([`validate`](Self::validate)).
    pub fn from_report_value(value: Value, source: &str) -> Result<Self, String> {
        let obj = value
            .as_object()
            .ok_or_else(|| format!("{source}: a fit report is a JSON object"))?;
        for key in ["experiments", "take_up_factors"] {
            if !obj.contains_key(key) {
                return Err(format!(
                    "{source}: field `{key}`: missing (a fit report of `rheometer fit --json` \
                     has it: it ties the fit to its data)"
                ));
            }
        }
        Self::from_value(value, source)
    }

    /// Whether this fit (read from `source`) was made on the data `data` (the experiments and
    /// their measurements, in order), by [`data_digest`].
    pub fn check_data<'a>(
        &self,
        data: impl IntoIterator<Item = (&'a Experiment, &'a Measurements)>,
        source: &str,
    ) -> DataCheck {
        if self.data_digest.is_empty() {
            return DataCheck::Unknown;
        }
        let now = data_digest(data);
        if now == self.data_digest {
            DataCheck::Same
        } else {
            DataCheck::Differs(format!(
                "{source} was fitted on other data than these (data digest {} there, {now} \
                 here): the experiment names agree, but conditions or measurements differ \
                 (another data set with the same names, or edited CSV files)",
                self.data_digest
            ))
        }
    }

    /// Reports written before the error budget became a table warned for every source that
    /// shifted an estimate by more than its statistical error; their budget's warnings are
    /// recomputed by today's rule ([`ErrorBudget::warnings`](crate::fit::ErrorBudget::warnings)).
    fn upgrade_systematic_warnings(&mut self) {
        let Some(b) = &self.error_budget else { return };
        let now = b.warnings();
        self.warnings.retain(|w| w.code != WarningCode::Systematic);
        self.warnings.extend(now);
    }

    /// Parses the JSON text of a fit summary held in memory (a Python dict, a test's text);
    /// `source` names it in errors. The text is parsed as strictly as a file
    /// (`parse_json`: duplicate keys, `NaN`, numbers out of range refused, naming the
    /// field), but needs no stamp; files are read by [`read_file`](Self::read_file), which
    /// checks it. Either way only this version's layout is read.
    pub fn from_json(text: &str, source: &str) -> Result<Self, String> {
        let value = parse_json(text, Path::new(source), "rheometer fit --json FILE")
            .map_err(|e| e.to_string())?;
        Self::from_value(value, source)
    }

    /// A fit to continue from: the JSON text of a fit report (`rheometer fit --json`) or of a
    /// diagnosis (`rheometer diagnose --json`: its final fit, the model with the effects it
    /// found, or without one its base fit), held in memory as [`from_json`](Self::from_json)
    /// takes it; `source` names it in errors.
    pub fn from_fit_or_diagnosis_json(text: &str, source: &str) -> Result<Self, String> {
        let value = parse_json(text, Path::new(source), "rheometer fit --json FILE")
            .map_err(|e| e.to_string())?;
        let diagnosis = value
            .as_object()
            .is_some_and(|o| o.contains_key("verdict") && o.contains_key("base_fit"));
        if !diagnosis {
            return Self::from_value(value, source);
        }
        let Value::Object(mut obj) = value else {
            return Err(format!("{source}: a diagnosis is a JSON object"));
        };
        let (field, fit) = match obj.remove("final_fit").filter(|v| !v.is_null()) {
            Some(f) => ("final_fit", f),
            None => ("base_fit", obj.remove("base_fit").unwrap_or(Value::Null)),
        };
        Self::from_value(fit, &format!("{source} (the diagnosis' field \"{field}\")"))
    }

    /// A fit from a parsed report: the fields the next step needs checked one by one, a report
    /// of an earlier layout refused, then every field's type (an error names its path,
    /// `experiments[2]`), then the values ([`validate`](Self::validate)).
    fn from_value(value: Value, source: &str) -> Result<Self, String> {
        let obj = value.as_object().ok_or_else(|| {
            format!(
                "{source}: the JSON is {}, not a report: a fit report is a JSON object {{...}}",
                kind(&value)
            )
        })?;
        check_fields(obj).map_err(|e| format!("{source}: {e}"))?;
        refuse_earlier_layout(obj).map_err(|e| format!("{source}: {e}"))?;
        let mut s: FitSummary = serde_path_to_error::deserialize(value).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner().to_string();
            format!("{source}: field `{path}`: {}", readable_type_error(&inner))
        })?;
        s.validate(source)?;
        s.upgrade_systematic_warnings();
        Ok(s)
    }

    /// The effects of this fit as the model of a next fit, and where its fitted parameters
    /// start: each effect with the strength fitted where it was fitted (else fixed at its
    /// value), its fitted shapes free again and the others fixed at their values; the start
    /// values of the fitted strengths (by effect name) and shapes (by model-parameter name),
    /// as [`FitStart::strengths`](crate::fit::FitStart::strengths) takes them.
    pub fn continued_effects(&self) -> Result<ContinuedEffects, String> {
        let mut effects = Vec::new();
        let mut starts = Vec::new();
        for e in &self.effects {
            let mut effect: Effect = e.effect.parse()?;
            let settings = effect.shape_settings();
            for sh in &e.shapes {
                let Some((sp, _)) = settings.iter().find(|(sp, _)| sp.name == sh.name) else {
                    return Err(format!(
                        "{} has no shape parameter \"{}\"",
                        e.effect, sh.name
                    ));
                };
                if sh.fitted {
                    starts.push((sp.model_param.to_string(), sh.value));
                } else {
                    effect = effect.with_shape(&sh.name, sh.value)?;
                }
            }
            if e.strength.fitted {
                starts.push((effect.name().to_string(), e.strength.value));
                effects.push(EffectSetting::fitted(effect));
            } else {
                effects.push(EffectSetting::fixed(effect, e.strength.value));
            }
        }
        Ok(ContinuedEffects { effects, starts })
    }

    /// [`continued_effects`](Self::continued_effects) joined with further effects `with`
    /// (each effect once): the model of a next fit that continues from this one. `with_label`
    /// names where `with` came from (`"--with"`, `"effects"`) and `source` this fit (`"--from
    /// fit.json"`) in errors.
    pub fn continued_with(
        &self,
        with: Vec<EffectSetting>,
        with_label: &str,
        source: &str,
    ) -> Result<ContinuedEffects, String> {
        let c = self
            .continued_effects()
            .map_err(|e| format!("{source}: {e}"))?;
        let mut effects = c.effects;
        for w in with {
            let name = w.effect.name();
            if effects.iter().any(|e| e.effect.id() == w.effect.id()) {
                return Err(format!(
                    "{with_label} {name}: {name} is in the model of {source} already (its \
                     strength is fitted from that fit's value); give it once: drop it from \
                     {with_label}, or start without {source} to give {name} yourself"
                ));
            }
            effects.push(w);
        }
        Ok(ContinuedEffects {
            effects,
            starts: c.starts,
        })
    }

    /// Checks the values (as read from a file `source`): `n` in `FIT_FILE_N_RANGE`, `κ` in
    /// `FIT_FILE_KAPPA_RANGE`, take-up factors in `FIT_FILE_TAKE_UP_RANGE`, effects known,
    /// once each, with finite strengths inside their search ranges, and as many experiment
    /// names (if given) as take-up factors. Errors name the file and the field.
    pub fn validate(&self, source: &str) -> Result<(), String> {
        let bad = |field: String, msg: String| Err(format!("{source}: field {field}: {msg}"));
        let in_range = |v: f64, r: [f64; 2]| v.is_finite() && v >= r[0] && v <= r[1];
        let (n, kappa) = (self.n.value, self.kappa.value);
        if !in_range(n, FIT_FILE_N_RANGE) {
            return bad(
                "\"n\"".into(),
                format!(
                    "n = {} must be a finite power index in [{}, {}]",
                    Readable(n),
                    FIT_FILE_N_RANGE[0],
                    FIT_FILE_N_RANGE[1]
                ),
            );
        }
        if !in_range(kappa, FIT_FILE_KAPPA_RANGE) {
            return bad(
                "\"kappa\"".into(),
                format!(
                    "kappa = ln(K / 1 Pa) = {} must be finite and in [{}, {}]",
                    Readable(kappa),
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
            if self.effects[..i].iter().any(|o| o.effect == e.effect) {
                return bad(
                    format!("{field}.effect"),
                    format!("effect \"{}\" appears twice", e.effect),
                );
            }
            if let Err(msg) = self.effect_of(i) {
                return bad(format!("{field}.effect"), msg);
            }
        }
        for (i, (effect, strength)) in self.model_effects()?.iter().enumerate() {
            let (lo, hi) = effect.bounds();
            if !(strength.is_finite() && *strength >= lo && *strength <= hi) {
                return bad(
                    format!("\"effects\"[{i}].strength"),
                    format!(
                        "{} strength {} must be finite and in [{lo}, {hi}] {}",
                        effect.name(),
                        strength,
                        effect.unit()
                    ),
                );
            }
        }
        Ok(())
    }

    /// The `i`-th effect with its shape parameters fixed at the fitted values.
    fn effect_of(&self, i: usize) -> Result<Effect, String> {
        let e = &self.effects[i];
        let mut effect: Effect = e.effect.parse()?;
        for sh in &e.shapes {
            effect = effect.with_shape(&sh.name, sh.value)?;
        }
        Ok(effect)
    }

    /// The fitted model's effects with their strengths (the effects' units), the shapes fixed
    /// at their fitted values: the model to simulate or compare.
    pub fn model_effects(&self) -> Result<Vec<(Effect, f64)>, String> {
        (0..self.effects.len())
            .map(|i| Ok((self.effect_of(i)?, self.effects[i].strength.value)))
            .collect()
    }

    /// Checks the fit's experiment names (where the file has them) against the data set's
    /// `names`, in order; `source` names the fit file in errors.
    pub fn check_experiments(&self, names: &[String], source: &str) -> Result<(), String> {
        if self.experiments.is_empty() {
            return Ok(());
        }
        if self.experiments.len() != names.len() {
            return Err(format!(
                "{source}: field \"experiments\": the fit has {} experiments, the data set {}; \
                 was the fit made on this data set?",
                self.experiments.len(),
                names.len()
            ));
        }
        for (i, (a, b)) in self.experiments.iter().zip(names).enumerate() {
            if a != b {
                return Err(format!(
                    "{source}: field \"experiments\"[{i}]: the fit's experiment \"{a}\" is \
                     \"{b}\" in the data set; was the fit made on this data set (same order)?"
                ));
            }
        }
        Ok(())
    }

    /// The take-up factors to simulate the `experiments` experiments of the fit's data set
    /// with: the fitted ones (principled estimator; their number checked), else `None` (all 1).
    pub fn take_up_for(
        &self,
        experiments: usize,
        source: &str,
    ) -> Result<Option<Vec<f64>>, String> {
        if self.estimator != Estimator::Principled {
            return Ok(None);
        }
        if self.take_up_factors.len() != experiments {
            return Err(format!(
                "{source}: field \"take_up_factors\": {} take-up factors for {experiments} \
                 experiments; was the fit made on this data set?",
                self.take_up_factors.len()
            ));
        }
        Ok(Some(self.take_up_factors.clone()))
    }
}

/// serde's `invalid type: string "x", expected a sequence` as `is a string ("x"); it should
/// be a sequence`; other messages unchanged.
fn readable_type_error(msg: &str) -> String {
    let Some(rest) = msg.strip_prefix("invalid type: ") else {
        return msg.to_string();
    };
    match rest.rsplit_once(", expected ") {
        Some((found, expected)) => format!("is {found}; it should be {expected}"),
        None => msg.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::summary::tests::refit_summary;
    use crate::fit::Estimate;

    /// A fit with a co-flow: strength 27 ± 3 m/s, decay length fitted, tail fixed at 0.5.
    fn coflow_fit(n: f64) -> FitSummary {
        let mut f = refit_summary("air_coflow", (27.0, 3.0), (n, 0.02), (11.6, 0.2));
        f.effects[0].shapes = vec![
            Estimate::fitted("decay_length", 0.19, "m", 0.012, None),
            Estimate {
                fitted: false,
                ..Estimate::fitted("tail", 0.5, "-", 0.0, None)
            },
        ];
        f
    }

    #[test]
    fn a_previous_fit_continues_with_its_fitted_shapes_free_and_its_values_as_starts() {
        let c = coflow_fit(0.8).continued_effects().unwrap();
        assert_eq!(c.effects.len(), 1);
        assert!(c.effects[0].value.is_none(), "the strength is fitted again");
        match &c.effects[0].effect {
            Effect::AirCoflow { decay_length, tail } => {
                assert_eq!((*decay_length, *tail), (None, Some(0.5)));
            }
            e => panic!("{e:?}"),
        }
        assert_eq!(
            c.starts,
            vec![
                ("air_coflow.decay_length".to_string(), 0.19),
                ("air_coflow".to_string(), 27.0)
            ]
        );
        // a fixed strength stays fixed, and starts nothing
        let mut fixed = coflow_fit(0.8);
        fixed.effects[0].strength.fitted = false;
        let c = fixed.continued_effects().unwrap();
        assert_eq!(c.effects[0].value, Some(27.0));
        assert_eq!(c.starts.len(), 1);
    }

    #[test]
    fn a_diagnosis_file_gives_its_final_fit_or_else_its_base_fit() {
        let base = serde_json::to_value(coflow_fit(0.3)).unwrap();
        let last = serde_json::to_value(coflow_fit(0.8)).unwrap();
        let doc = |final_fit: Value| {
            serde_json::json!({
                "verdict": {"kind": "explained"},
                "base_fit": base.clone(),
                "final_fit": final_fit,
            })
            .to_string()
        };
        let f = FitSummary::from_fit_or_diagnosis_json(&doc(last.clone()), "d.json").unwrap();
        assert_eq!(f.n.value, 0.8);
        let f = FitSummary::from_fit_or_diagnosis_json(&doc(Value::Null), "d.json").unwrap();
        assert_eq!(f.n.value, 0.3);
        // a fit report reads as itself
        let f = FitSummary::from_fit_or_diagnosis_json(&last.to_string(), "f.json").unwrap();
        assert_eq!(f.n.value, 0.8);
        // errors name the file and the diagnosis' field
        let mut broken = last.clone();
        broken["n"] = serde_json::json!("high");
        let e = FitSummary::from_fit_or_diagnosis_json(&doc(broken), "d.json").unwrap_err();
        assert!(
            e.contains("d.json") && e.contains("final_fit") && e.contains("field `n`"),
            "{e}"
        );
        let e = FitSummary::from_fit_or_diagnosis_json("{", "d.json").unwrap_err();
        assert!(
            e.contains("d.json") && e.contains("ends early (truncated?)"),
            "{e}"
        );
    }
}

//! `Dataset`: a loaded set of spinning experiments (material, air, conditions, measurements),
//! from a TOML file and its CSV files, from TOML text, or from a dict of conditions and arrays.
//! Every route goes through the library's readers, so the checks and messages are the CLI's.

use crate::convert::{array1, from_py, vec_f64};
use crate::errors::{input_error, to_py_err};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use rheometer::data::input::{
    load_experiments_with, parse_experiments_with, parse_measurements, InputError, LoadOptions,
    LoadedExperiments,
};
use rheometer::model::{Inlet, TakeUp};
use rheometer::workflow::request::{self, Door};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Minimum number of measurements per experiment (the CLI's).
const MIN_POINTS: usize = 4;

/// What a [`Dataset`] holds: the loaded set, the experiments file (or a label such as
/// `<conditions>`) and the TOML text it was read from.
pub struct DatasetInner {
    /// The experiments with their metadata and declared uncertainties.
    pub loaded: LoadedExperiments,
    /// The experiments file, or a label for text that came from Python.
    pub path: PathBuf,
    /// The TOML text (kept for pickling and `Dataset.toml`).
    pub toml: String,
    /// Whether it was made with `allow_large_inputs=True` (the input caps lifted); kept so
    /// that a pickled or re-measured copy is read under the same caps.
    pub allow_large_inputs: bool,
}

/// The loader's caps of a data set made from Python: the defaults (as `load()` and the
/// command line apply them), or none with `allow_large_inputs`.
fn caps(allow_large_inputs: bool) -> LoadOptions {
    request::load_options(LoadOptions::with_min_points(MIN_POINTS), allow_large_inputs)
}

/// A data set of spinning experiments (immutable; cheap to share between calls and threads).
#[pyclass(module = "diffbvp._native", name = "Dataset", frozen)]
pub struct Dataset {
    pub inner: Arc<DatasetInner>,
}

impl Dataset {
    /// The data set and its path, for error messages naming experiments.
    pub fn data(&self) -> (&LoadedExperiments, &Path) {
        (&self.inner.loaded, &self.inner.path)
    }
}

/// The reader's warnings about the data (a doubtful key, two experiments reading one file,
/// an extrapolated take-up), each a Python `UserWarning`, as the CLI prints them on stderr.
fn warn_about(py: Python<'_>, loaded: &LoadedExperiments) -> PyResult<()> {
    let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
    for w in &loaded.warnings {
        let text = std::ffi::CString::new(w.to_string().replace('\0', " "))
            .map_err(|e| input_error(format!("a warning could not be passed on: {e}")))?;
        PyErr::warn(py, &category, &text, 2)?;
    }
    Ok(())
}

/// Measurement arrays as the CSV text the library reads (Rust's `{}` prints the shortest
/// representation that reads back to the same `f64`, so nothing is rounded).
fn csv_text(positions: &[f64], diameters: &[f64]) -> String {
    let mut s = String::with_capacity(32 * positions.len() + 24);
    s.push_str("position_m,diameter_m\n");
    for (p, d) in positions.iter().zip(diameters) {
        s.push_str(&format!("{p},{d}\n"));
    }
    s
}

/// The number of rows of a measurement array as Python sees it (`len()`), before it is
/// converted; `None` when it has no length (the conversion then names the argument).
fn rows_of(obj: &Bound<'_, PyAny>) -> Option<usize> {
    obj.len().ok()
}

/// Parses `text` (labelled `path`) and fills the measurements: the arrays given in
/// `measurements` (name → (positions \[m\], diameters \[m\])), else the experiment's `data`
/// file. The caps of [`caps`] apply to both: the arrays' lengths are checked by the library's
/// request rule before any row is converted, the files while they are read. Ctrl-C is
/// honoured between experiments (`KeyboardInterrupt`).
fn build(
    py: Python<'_>,
    text: &str,
    path: &Path,
    measurements: Option<&Bound<'_, PyDict>>,
    allow_large_inputs: bool,
) -> PyResult<DatasetInner> {
    let options = caps(allow_large_inputs);
    if !allow_large_inputs && text.len() as u64 > options.max_toml_bytes {
        return Err(input_error(format!(
            "{}: the experiments text has {} bytes, more than the cap `max_toml_bytes` ({} \
             bytes); {}",
            path.display(),
            text.len(),
            options.max_toml_bytes,
            request::lift_caps(Door::Python)
        )));
    }
    let mut loaded = parse_experiments_with(text, path, &options).map_err(|e| {
        let lifted = matches!(e, InputError::Limit { .. });
        let err = to_py_err(py, Box::new(e), None, None);
        if lifted {
            input_error(format!(
                "{} ({})",
                err.value(py),
                request::lift_caps(Door::Python)
            ))
        } else {
            err
        }
    })?;
    let n_experiments = loaded.set.experiments.len();
    if let Some(m) = measurements {
        let mut rows: Vec<(String, usize)> = Vec::new();
        for (key, pair) in m.iter() {
            let name: String = key.extract()?;
            if !loaded.set.experiments.iter().any(|e| e.name == name) {
                let names: Vec<&str> = loaded
                    .set
                    .experiments
                    .iter()
                    .map(|e| e.name.as_str())
                    .collect();
                return Err(input_error(format!(
                    "measurements given for experiment \"{name}\", which the data set does not \
                     have (experiments: {})",
                    names.join(", ")
                )));
            }
            let longest = match pair.cast::<PyTuple>() {
                Ok(t) if t.len() == 2 => {
                    let a = rows_of(&t.get_item(0)?).unwrap_or(0);
                    let b = rows_of(&t.get_item(1)?).unwrap_or(0);
                    a.max(b)
                }
                _ => 0,
            };
            rows.push((name, longest));
        }
        let named: Vec<(&str, usize)> = rows.iter().map(|(n, r)| (n.as_str(), *r)).collect();
        request::measurement_rows(&named, n_experiments, &options)
            .map_err(|r| input_error(r.message(Door::Python)))?;
    }
    for k in 0..n_experiments {
        py.check_signals()?;
        let e = &loaded.set.experiments[k];
        let given = match measurements {
            Some(m) => m.get_item(&e.name)?,
            None => None,
        };
        let measured = match given {
            Some(pair) => {
                let what = format!("measurements of experiment \"{}\"", e.name);
                let pair = pair.cast::<PyTuple>().map_err(|_| {
                    input_error(format!("{what}: give a pair (positions_m, diameters_m)"))
                })?;
                if pair.len() != 2 {
                    return Err(input_error(format!(
                        "{what}: give a pair (positions_m, diameters_m)"
                    )));
                }
                let pos = vec_f64(&pair.get_item(0)?, &format!("{what}: positions_m"))?;
                let dia = vec_f64(&pair.get_item(1)?, &format!("{what}: diameters_m"))?;
                if pos.len() != dia.len() {
                    return Err(input_error(format!(
                        "{what}: {} positions but {} diameters",
                        pos.len(),
                        dia.len()
                    )));
                }
                py.check_signals()?;
                // rows are lines 2, 3, ... of this virtual CSV file (line 1 is its header)
                let label = PathBuf::from(format!("<arrays of experiment \"{}\">", e.name));
                let text = csv_text(&pos, &dia);
                Some(
                    parse_measurements(&text, &label, e.spinline_length, MIN_POINTS)
                        .map_err(|err| to_py_err(py, Box::new(err), None, None))?,
                )
            }
            None => match &loaded.details[k].data {
                Some(file) => Some(
                    rheometer::data::input::load_measurements_with(
                        file,
                        e.spinline_length,
                        &options,
                    )
                    .map_err(|err| {
                        let lift = if matches!(err, InputError::Limit { .. }) {
                            format!(" ({})", request::lift_caps(Door::Python))
                        } else {
                            String::new()
                        };
                        input_error(format!(
                            "{}: experiment \"{}\": {err}{lift}",
                            path.display(),
                            e.name
                        ))
                    })?,
                ),
                None => None,
            },
        };
        loaded.set.measurements[k] = measured;
    }
    warn_about(py, &loaded)?;
    Ok(DatasetInner {
        loaded,
        path: path.to_path_buf(),
        toml: text.to_string(),
        allow_large_inputs,
    })
}

/// Removes `null`s (Python `None`: "not given") from a JSON tree; TOML has no null.
fn strip_nulls(v: Value) -> Value {
    match v {
        Value::Object(m) => Value::Object(
            m.into_iter()
                .filter(|(_, x)| !x.is_null())
                .map(|(k, x)| (k, strip_nulls(x)))
                .collect(),
        ),
        Value::Array(a) => Value::Array(a.into_iter().map(strip_nulls).collect()),
        other => other,
    }
}

#[pymethods]
impl Dataset {
    /// Loads a TOML experiments file and the CSV files it names (the CLI's reader: every
    /// value checked, errors name file, line, table and key), under the input caps unless
    /// `allow_large_inputs` (the CLI's `--allow-large-inputs`).
    #[staticmethod]
    #[pyo3(signature = (path, allow_large_inputs=false))]
    fn load(py: Python<'_>, path: PathBuf, allow_large_inputs: bool) -> PyResult<Self> {
        let options = caps(allow_large_inputs);
        let result = py.detach(|| -> Result<DatasetInner, Box<InputError>> {
            let loaded = load_experiments_with(&path, &options).map_err(Box::new)?;
            let toml = std::fs::read_to_string(&path).map_err(|e| {
                Box::new(InputError::Io {
                    path: path.clone(),
                    source: e,
                    hint: String::new(),
                })
            })?;
            Ok(DatasetInner {
                loaded,
                path: path.clone(),
                toml,
                allow_large_inputs,
            })
        });
        match result {
            Ok(inner) => {
                warn_about(py, &inner.loaded)?;
                Ok(Dataset {
                    inner: Arc::new(inner),
                })
            }
            Err(e) if e.exceeded_limit().is_some() => {
                Err(input_error(request::input_message(&e, Door::Python)))
            }
            Err(e) => Err(to_py_err(py, e, None, None)),
        }
    }

    /// A data set from TOML text; `path` labels it in messages and resolves relative `data`
    /// files; `measurements` (name → (positions_m, diameters_m)) replaces data files; the
    /// input caps apply unless `allow_large_inputs`.
    #[staticmethod]
    #[pyo3(signature = (text, path, measurements=None, allow_large_inputs=false))]
    fn from_toml(
        py: Python<'_>,
        text: &str,
        path: PathBuf,
        measurements: Option<&Bound<'_, PyDict>>,
        allow_large_inputs: bool,
    ) -> PyResult<Self> {
        Ok(Dataset {
            inner: Arc::new(build(py, text, &path, measurements, allow_large_inputs)?),
        })
    }

    /// A data set from a dict in the TOML file's layout (`material`, optional `defaults`,
    /// `experiment` = a list of dicts, optional `relative_uncertainty`, `uncertainty`) and
    /// measurement arrays. Messages name `<conditions>` and the line of the generated TOML
    /// text (`Dataset.toml`). The input caps apply unless `allow_large_inputs`.
    #[staticmethod]
    #[pyo3(signature = (conditions, measurements=None, allow_large_inputs=false))]
    fn from_conditions(
        py: Python<'_>,
        conditions: &Bound<'_, PyAny>,
        measurements: Option<&Bound<'_, PyDict>>,
        allow_large_inputs: bool,
    ) -> PyResult<Self> {
        let value = strip_nulls(from_py(conditions, "conditions")?);
        if !value.is_object() {
            return Err(input_error(
                "conditions: expected a dict with the tables of an experiments file \
                 (material, defaults, experiment)"
                    .into(),
            ));
        }
        let text = toml::to_string(&value)
            .map_err(|e| input_error(format!("conditions: cannot be written as TOML: {e}")))?;
        Ok(Dataset {
            inner: Arc::new(build(
                py,
                &text,
                Path::new("<conditions>"),
                measurements,
                allow_large_inputs,
            )?),
        })
    }

    /// The experiments file (or `<conditions>`).
    #[getter]
    fn path(&self) -> String {
        self.inner.path.display().to_string()
    }

    /// The TOML text of the data set.
    #[getter]
    fn toml(&self) -> &str {
        &self.inner.toml
    }

    /// Whether the input caps were lifted (`allow_large_inputs=True`).
    #[getter]
    fn allow_large_inputs(&self) -> bool {
        self.inner.allow_large_inputs
    }

    /// The digest of the data (the library's `data_digest`: experiment names, conditions and
    /// measurements), as a fit made on them records it in its summary (`data_digest`).
    #[getter]
    fn data_digest(&self) -> String {
        let set = &self.inner.loaded.set;
        rheometer::fit::data_digest(
            set.experiments
                .iter()
                .zip(&set.measurements)
                .filter_map(|(e, m)| m.as_ref().map(|m| (e, m))),
        )
    }

    /// Experiment names, in file order.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.inner
            .loaded
            .set
            .experiments
            .iter()
            .map(|e| e.name.clone())
            .collect()
    }

    /// Declared relative measurement uncertainty \[-\], if any.
    #[getter]
    fn relative_uncertainty(&self) -> Option<f64> {
        self.inner.loaded.set.relative_uncertainty
    }

    /// Measurements: name → (positions \[m\], diameters \[m\]) as numpy arrays (experiments
    /// without measurements are left out).
    fn measurements<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let set = &self.inner.loaded.set;
        for (e, m) in set.experiments.iter().zip(&set.measurements) {
            if let Some(m) = m {
                d.set_item(
                    &e.name,
                    (array1(py, &m.positions), array1(py, &m.diameters)),
                )?;
            }
        }
        Ok(d)
    }

    /// The conditions of each experiment (SI units in the key names), with the TOML line of
    /// its `name` key and its data file.
    fn conditions<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let loaded = &self.inner.loaded;
        let mut out = Vec::new();
        for (e, det) in loaded.set.experiments.iter().zip(&loaded.details) {
            let d = PyDict::new(py);
            d.set_item("name", &e.name)?;
            d.set_item("mass_flow_kg_s", e.mass_flow)?;
            match e.inlet {
                Inlet::Diameter(v) => d.set_item("inlet_diameter_m", v)?,
                Inlet::Velocity(v) => d.set_item("inlet_velocity_m_s", v)?,
            }
            d.set_item("inlet_temperature_K", e.inlet_temperature)?;
            d.set_item("air_temperature_K", e.air_temperature)?;
            d.set_item("spinline_length_m", e.spinline_length)?;
            match e.take_up {
                Some(TakeUp::Diameter(v)) => d.set_item("take_up_diameter_m", v)?,
                Some(TakeUp::Velocity(v)) => d.set_item("take_up_velocity_m_s", v)?,
                None => {}
            }
            if let Some(v) = det.stencil_velocity_mm_s {
                d.set_item("stencil_velocity_mm_s", v)?;
            }
            if let Some(v) = det.take_up_pressure_bar {
                d.set_item("take_up_pressure_bar", v)?;
            }
            d.set_item("line", det.line)?;
            d.set_item("data", det.data.as_ref().map(|p| p.display().to_string()))?;
            out.push(d);
        }
        Ok(out)
    }

    /// Number of experiments.
    fn __len__(&self) -> usize {
        self.inner.loaded.set.experiments.len()
    }
}

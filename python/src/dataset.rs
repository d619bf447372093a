//! `Dataset`: a loaded set of spinning experiments (material, air, conditions, measurements),
//! from a TOML file and its CSV files, from TOML text, or from a dict of conditions and arrays.
//! Every route goes through the library's readers, so the checks and messages are the CLI's.

use crate::convert::{array1, from_py, vec_f64};
use crate::errors::{input_error, to_py_err};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use rheometer::input::{
    load_experiments_with, parse_experiments, parse_measurements, InputError, LoadedExperiments,
};
use rheometer::setup::{Inlet, TakeUp};
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

/// Parses `text` (labelled `path`) and fills the measurements: the arrays given in
/// `measurements` (name → (positions \[m\], diameters \[m\])), else the experiment's `data`
/// file.
fn build(
    text: &str,
    path: &Path,
    measurements: Option<&Bound<'_, PyDict>>,
) -> PyResult<DatasetInner> {
    let mut loaded = parse_experiments(text, path)
        .map_err(|e| Python::attach(|py| to_py_err(py, Box::new(e), None, None)))?;
    if let Some(m) = measurements {
        for key in m.keys() {
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
        }
    }
    for k in 0..loaded.set.experiments.len() {
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
                // rows are lines 2, 3, ... of this virtual CSV file (line 1 is its header)
                let label = PathBuf::from(format!("<arrays of experiment \"{}\">", e.name));
                let text = csv_text(&pos, &dia);
                Some(
                    parse_measurements(&text, &label, e.spinline_length, MIN_POINTS).map_err(
                        |err| Python::attach(|py| to_py_err(py, Box::new(err), None, None)),
                    )?,
                )
            }
            None => match &loaded.details[k].data {
                Some(file) => Some(
                    rheometer::input::load_measurements(file, e.spinline_length, MIN_POINTS)
                        .map_err(|err| {
                            input_error(format!(
                                "{}: experiment \"{}\": {err}",
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
    Ok(DatasetInner {
        loaded,
        path: path.to_path_buf(),
        toml: text.to_string(),
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
    /// value checked, errors name file, line, table and key).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let result = py.detach(|| -> Result<DatasetInner, Box<InputError>> {
            let loaded = load_experiments_with(&path, MIN_POINTS).map_err(Box::new)?;
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
            })
        });
        match result {
            Ok(inner) => Ok(Dataset {
                inner: Arc::new(inner),
            }),
            Err(e) => Err(to_py_err(py, e, None, None)),
        }
    }

    /// A data set from TOML text; `path` labels it in messages and resolves relative `data`
    /// files; `measurements` (name → (positions_m, diameters_m)) replaces data files.
    #[staticmethod]
    #[pyo3(signature = (text, path, measurements=None))]
    fn from_toml(
        text: &str,
        path: PathBuf,
        measurements: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        Ok(Dataset {
            inner: Arc::new(build(text, &path, measurements)?),
        })
    }

    /// A data set from a dict in the TOML file's layout (`material`, optional `defaults`,
    /// `experiment` = a list of dicts, optional `relative_uncertainty`, `uncertainty`) and
    /// measurement arrays. Messages name `<conditions>` and the line of the generated TOML
    /// text (`Dataset.toml`).
    #[staticmethod]
    #[pyo3(signature = (conditions, measurements=None))]
    fn from_conditions(
        conditions: &Bound<'_, PyAny>,
        measurements: Option<&Bound<'_, PyDict>>,
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
            inner: Arc::new(build(&text, Path::new("<conditions>"), measurements)?),
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

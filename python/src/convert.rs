//! Conversions between serde JSON values and Python objects, and numpy arrays.
//!
//! Every result goes to Python through its serde JSON form ([`to_py`]): objects become `dict`,
//! arrays `list`, numbers `float` (or `int` where JSON has an integer), `null` `None`. A `NaN`
//! that the library serialises as `null` (a standard error that does not exist) therefore
//! arrives as `None`; the Python result classes read such numeric fields as `nan`.

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde_json::{Map, Number, Value};

/// A serde JSON value as a Python object (dict, list, float, int, str, bool, None).
pub fn to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => match (n.as_i64(), n.as_u64()) {
            (Some(i), _) => PyInt::new(py, i).into_any(),
            (None, Some(u)) => PyInt::new(py, u).into_any(),
            _ => PyFloat::new(py, n.as_f64().unwrap_or(f64::NAN)).into_any(),
        },
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(a) => {
            let list = PyList::empty(py);
            for x in a {
                list.append(to_py(py, x)?)?;
            }
            list.into_any()
        }
        Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// A report as the dict the `rheometer` program writes with `--json`: the stamp of `kind`
/// (schema version, report kind, program version) first, then the report's fields; so that a
/// dict saved from Python is a file the program reads.
pub fn report_to_py<'py, T: serde::Serialize>(
    py: Python<'py>,
    kind: rheometer::report::report_json::ReportKind,
    v: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let fail = |e: serde_json::Error| {
        crate::errors::diffbvp_error(py, "DiffbvpError", format!("cannot convert a result: {e}"))
    };
    let text = rheometer::report::report_json::to_report_json(kind, v).map_err(fail)?;
    let value: serde_json::Value = serde_json::from_str(&text).map_err(fail)?;
    to_py(py, &value)
}

/// A Python object (dict, list, tuple, str, bool, int, float, None, numpy array) as a JSON
/// value; `what` names it in errors. Non-finite floats are refused (TOML and JSON have none).
pub fn from_py(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Value> {
    if obj.is_none() {
        return Ok(Value::Null);
    }
    if obj.is_instance_of::<PyBool>() {
        return Ok(Value::Bool(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        let i: i64 = obj.extract()?;
        return Ok(Value::Number(i.into()));
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(Value::String(obj.extract()?));
    }
    if obj.is_instance_of::<PyDict>() {
        let d = obj.cast::<PyDict>()?;
        let mut m = Map::new();
        for (k, v) in d.iter() {
            let key: String = k
                .extract()
                .map_err(|_| PyTypeError::new_err(format!("{what}: keys must be strings")))?;
            let inner = format!("{what}[{key:?}]");
            m.insert(key, from_py(&v, &inner)?);
        }
        return Ok(Value::Object(m));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() || obj.hasattr("tolist")? {
        let seq = if obj.hasattr("tolist")? && !obj.is_instance_of::<PyList>() {
            obj.call_method0("tolist")?
        } else {
            obj.clone()
        };
        if seq.is_instance_of::<PyList>() || seq.is_instance_of::<PyTuple>() {
            let mut out = Vec::new();
            for (i, x) in seq.try_iter()?.enumerate() {
                out.push(from_py(&x?, &format!("{what}[{i}]"))?);
            }
            return Ok(Value::Array(out));
        }
        return from_py(&seq, what);
    }
    // floats, numpy scalars and anything else with __float__
    let x: f64 = obj.extract().map_err(|_| {
        PyTypeError::new_err(format!(
            "{what}: expected a number, string, bool, list or dict, got {}",
            obj.get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default()
        ))
    })?;
    Number::from_f64(x)
        .map(Value::Number)
        .ok_or_else(|| crate::errors::input_error(format!("{what}: {x} is not a finite number")))
}

/// A 1-D numpy array (copied from `v`).
pub fn array1<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyAny> {
    PyArray1::from_slice(py, v).into_any()
}

/// A 2-D numpy array of `rows × cols` from row-major `v`.
pub fn array2<'py>(
    py: Python<'py>,
    v: &[f64],
    rows: usize,
    cols: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let a = PyArray1::from_slice(py, v);
    Ok(a.reshape([rows, cols])?.into_any())
}

/// A float vector from any sequence of numbers or a 1-D array (a copy; numpy arrays of other
/// dtypes are converted).
pub fn vec_f64(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    if let Ok(a) = obj.cast::<PyArray1<f64>>() {
        return Ok(a
            .readonly()
            .as_slice()
            .map(|s| s.to_vec())
            .unwrap_or_else(|_| a.readonly().as_array().iter().copied().collect()));
    }
    if obj.cast::<PyArray2<f64>>().is_ok() {
        return Err(PyTypeError::new_err(format!(
            "{what}: expected a 1-D array, got a 2-D one"
        )));
    }
    obj.extract::<Vec<f64>>()
        .map_err(|_| PyTypeError::new_err(format!("{what}: expected a 1-D sequence of numbers")))
}

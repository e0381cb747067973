//! Python values as scene values: a dict given to `load_dict` as the
//! scene document, each value located by its subscripts, and the values
//! of `load_file`'s overrides as the TOML text of a `--set`.

use std::sync::Arc;

use lumis_core::doc::{Entry, Node, Table, Value};
use lumis_core::{Error, Location};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use crate::errors::lumis_error;

/// A Python value as TOML: booleans, integers, floats, strings and paths
/// (`os.PathLike`), lists and tuples, dicts with string keys, and NumPy
/// arrays and scalars (through `tolist()`). `at` names the value in errors.
pub fn toml_of(value: &Bound<'_, PyAny>, at: &str) -> PyResult<toml::Value> {
    let py = value.py();
    let unusable = |what: String| lumis_error(py, &Error::at(&Location::Key(Arc::from(at)), what));
    // `bool` is a subclass of `int`: it is asked first.
    if let Ok(b) = value.cast::<PyBool>() {
        return Ok(toml::Value::Boolean(b.is_true()));
    }
    if value.is_instance_of::<PyInt>() {
        return value
            .extract::<i64>()
            .map(toml::Value::Integer)
            .map_err(|_| unusable(format!("{value} is beyond a 64-bit integer")));
    }
    if value.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(value.extract::<f64>()?));
    }
    if let Ok(s) = value.cast::<PyString>() {
        return Ok(toml::Value::String(s.extract::<String>()?));
    }
    if let Ok(dict) = value.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (key, item) in dict.iter() {
            let Ok(key) = key.cast::<PyString>() else {
                return Err(unusable(format!(
                    "the key {key:?} is not a string: a scene's keys are names"
                )));
            };
            let key = key.extract::<String>()?;
            let item = toml_of(&item, &format!("{at}[{key:?}]"))?;
            table.insert(key, item);
        }
        return Ok(toml::Value::Table(table));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let items = value
            .try_iter()?
            .enumerate()
            .map(|(i, item)| toml_of(&item?, &format!("{at}[{i}]")))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    if value.hasattr("__fspath__")? {
        let path = py.import("os")?.call_method1("fspath", (value,))?;
        return toml_of(&path, at);
    }
    if value.hasattr("tolist")? {
        return toml_of(&value.call_method0("tolist")?, at);
    }
    Err(unusable(format!(
        "a {} cannot be a scene value: expected a bool, int, float, str, path, list, tuple or dict",
        value.get_type().name()?
    )))
}

/// A TOML table as a scene document whose every value is located by its
/// subscripts from `at` (`scene["bsdf"][0]`).
pub fn document_of(table: &toml::Table, at: &str) -> Table {
    Table {
        entries: table
            .iter()
            .map(|(key, value)| {
                let at = format!("{at}[{key:?}]");
                Entry {
                    key: key.clone(),
                    key_location: Location::Key(Arc::from(at.as_str())),
                    node: node_of(value, at),
                }
            })
            .collect(),
    }
}

/// A TOML value as a scene value located by its subscripts `at`.
pub fn node_of(value: &toml::Value, at: String) -> Node {
    let value = match value {
        toml::Value::Boolean(b) => Value::Bool(*b),
        toml::Value::Integer(i) => Value::Int(*i),
        toml::Value::Float(f) => Value::Float(*f),
        toml::Value::String(s) => Value::String(s.clone()),
        toml::Value::Datetime(d) => Value::Datetime(d.to_string()),
        toml::Value::Array(items) => Value::Array(
            items
                .iter()
                .enumerate()
                .map(|(i, item)| node_of(item, format!("{at}[{i}]")))
                .collect(),
        ),
        toml::Value::Table(table) => Value::Table(document_of(table, &at)),
    };
    Node {
        value,
        location: Location::Key(Arc::from(at)),
    }
}

/// `key=VALUE` with the value as TOML: what `--set key=VALUE` would be.
/// A string stays a string (`--set` takes text that is no TOML value as a
/// string too).
pub fn assignment(key: &str, value: &Bound<'_, PyAny>) -> PyResult<String> {
    let value = toml_of(value, key)?;
    Ok(format!("{key}={value}"))
}

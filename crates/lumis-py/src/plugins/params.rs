//! A Python plugin's parameters: declared from Python values, read from a
//! scene's table by the host's own checks, and handed to the class as
//! keyword arguments.

use lumis_api::params::{ParamDefault, ParamType, ParamValue};
use lumis_api::{Error, ParamSpec, Params, Result, Rgb, Vec3};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use pyo3::IntoPyObjectExt;

/// The types a Python plugin's parameter may have, by the names it is
/// declared with.
const TYPES: [(&str, ParamType); 6] = [
    ("bool", ParamType::Bool),
    ("int", ParamType::Int),
    ("float", ParamType::Float),
    ("string", ParamType::String),
    ("rgb", ParamType::Rgb),
    ("vec3", ParamType::Vec3),
];

/// The parameter `name` as declared: a default value, whose type is that
/// of the value (a list of three numbers is an `rgb`), or a dict with
/// `type`, and optionally `default`, `range` (numbers), `choices`
/// (strings) and `doc`. Without a default the parameter is required.
pub fn spec(name: &str, declaration: &Bound<'_, PyAny>) -> Result<ParamSpec> {
    let bad = |why: String| Error::msg(format!("parameter '{name}': {why}"));
    let py_error = |e: PyErr| bad(e.to_string());
    let (ty, default, range, choices, doc) = match declaration.cast::<PyDict>() {
        Ok(d) => {
            let text = |key: &str| -> Result<Option<String>> {
                d.get_item(key)
                    .map_err(py_error)?
                    .map(|v| v.extract::<String>().map_err(py_error))
                    .transpose()
            };
            let type_name = text("type")?.ok_or_else(|| {
                bad("a declaration as a dict needs \"type\" (bool, int, float, string, rgb or vec3)".into())
            })?;
            let ty = TYPES
                .iter()
                .find(|(n, _)| *n == type_name)
                .map(|(_, t)| *t)
                .ok_or_else(|| bad(format!("unknown type \"{type_name}\": expected bool, int, float, string, rgb or vec3")))?;
            let default = d.get_item("default").map_err(py_error)?;
            let range = match d.get_item("range").map_err(py_error)? {
                None => None,
                Some(r) => match r.extract::<Vec<f64>>().map_err(py_error)?[..] {
                    [min, max] if min <= max => Some((min, max)),
                    _ => return Err(bad(format!("range {r}: expected [min, max]"))),
                },
            };
            let choices = d
                .get_item("choices")
                .map_err(py_error)?
                .map(|c| c.extract::<Vec<String>>().map_err(py_error))
                .transpose()?
                .unwrap_or_default();
            (ty, default, range, choices, text("doc")?.unwrap_or_default())
        }
        Err(_) => (type_of(declaration).ok_or_else(|| bad(format!("cannot tell the type of the default {declaration}; declare it as {{\"type\": ..., \"default\": ...}}")))?, Some(declaration.clone()), None, Vec::new(), String::new()),
    };
    if range.is_some() && !matches!(ty, ParamType::Int | ParamType::Float) {
        return Err(bad(
            "a range is declared on a parameter that is not a number".into(),
        ));
    }
    if !choices.is_empty() && ty != ParamType::String {
        return Err(bad(
            "choices are declared on a parameter that is not a string".into(),
        ));
    }
    let default = match default {
        None => ParamDefault::Required,
        Some(value) => ParamDefault::Value(
            value_of(ty, &value)
                .ok_or_else(|| bad(format!("the default {value} is not a {}", ty.name())))?,
        ),
    };
    let default_number = match default {
        ParamDefault::Value(ParamValue::Float(v)) => Some(v),
        ParamDefault::Value(ParamValue::Int(i)) => Some(i as f64),
        _ => None,
    };
    if let (Some((min, max)), Some(v)) = (range, default_number) {
        if !(min..=max).contains(&v) {
            return Err(bad(format!(
                "the default {v} is outside the range [{min}, {max}]"
            )));
        }
    }
    let choices: Vec<&'static str> = choices
        .into_iter()
        .map(|c| &*Box::leak(c.into_boxed_str()))
        .collect();
    Ok(ParamSpec {
        name: Box::leak(name.to_string().into_boxed_str()),
        ty,
        default,
        doc: Box::leak(doc.into_boxed_str()),
        range,
        choices: Box::leak(choices.into_boxed_slice()),
    })
}

/// The type a default value declares.
fn type_of(value: &Bound<'_, PyAny>) -> Option<ParamType> {
    if value.is_instance_of::<PyBool>() {
        Some(ParamType::Bool)
    } else if value.is_instance_of::<PyInt>() {
        Some(ParamType::Int)
    } else if value.is_instance_of::<PyFloat>() {
        Some(ParamType::Float)
    } else if value.is_instance_of::<PyString>() {
        Some(ParamType::String)
    } else if (value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>())
        && value.len().ok() == Some(3)
    {
        Some(ParamType::Rgb)
    } else {
        None
    }
}

/// A Python default as the host's default value of type `ty`.
fn value_of(ty: ParamType, value: &Bound<'_, PyAny>) -> Option<ParamValue> {
    let number = |v: &Bound<'_, PyAny>| -> Option<f64> {
        (!v.is_instance_of::<PyBool>()).then(|| v.extract::<f64>().ok())?
    };
    Some(match ty {
        ParamType::Bool => ParamValue::Bool(value.cast::<PyBool>().ok()?.is_true()),
        ParamType::Int if !value.is_instance_of::<PyBool>() => {
            ParamValue::Int(value.extract::<i64>().ok()?)
        }
        ParamType::Float => ParamValue::Float(number(value)?),
        ParamType::String => {
            ParamValue::Str(Box::leak(value.extract::<String>().ok()?.into_boxed_str()))
        }
        ParamType::Rgb | ParamType::Vec3 => {
            let items: Vec<Bound<'_, PyAny>> =
                value.try_iter().ok()?.collect::<PyResult<_>>().ok()?;
            let components = items
                .iter()
                .map(|v| number(v).map(ParamValue::Float))
                .collect::<Option<Vec<_>>>()?;
            if components.len() != 3 {
                return None;
            }
            ParamValue::Array(Box::leak(components.into_boxed_slice()))
        }
        _ => return None,
    })
}

/// The value of the declared parameter `spec` in `params` (its default
/// where the scene leaves it out), as a keyword argument: checked against
/// its range and choices as a built-in plugin's is.
pub fn keyword<'py>(
    py: Python<'py>,
    spec: &ParamSpec,
    params: &Params,
) -> Result<Option<Bound<'py, PyAny>>> {
    fn object<'py>(py: Python<'py>, value: impl IntoPyObject<'py>) -> Result<Bound<'py, PyAny>> {
        value
            .into_bound_py_any(py)
            .map_err(|e| Error::msg(e.to_string()))
    }
    let name = spec.name;
    match spec.ty {
        ParamType::Bool => params.optional_value::<bool>(name)?.map(|v| object(py, v)),
        ParamType::Int => params.optional_value::<i64>(name)?.map(|v| object(py, v)),
        ParamType::Float => params.optional_value::<f64>(name)?.map(|v| object(py, v)),
        ParamType::String if !spec.choices.is_empty() => Some(object(py, params.get_choice(name)?)),
        ParamType::String => params
            .optional_value::<String>(name)?
            .map(|v| object(py, v)),
        ParamType::Rgb => params
            .optional_value::<Rgb>(name)?
            .map(|c| object(py, (c.r, c.g, c.b))),
        ParamType::Vec3 => params
            .optional_value::<Vec3>(name)?
            .map(|v| object(py, (v.x, v.y, v.z))),
        other => unreachable!("a Python plugin declares no {} parameter", other.name()),
    }
    .transpose()
}

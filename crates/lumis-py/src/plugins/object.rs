//! A Python plugin's object, and what a call into it does when Python
//! raises.

use std::sync::{Arc, Mutex};

use lumis_api::registrar::PluginSpec;
use lumis_api::{Error, Params, Result};
use pyo3::call::PyCallArgs;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::params::keyword;

/// The first exception a Python plugin's method raised since it was last
/// taken.
static RAISED: Mutex<Option<PyErr>> = Mutex::new(None);

/// The first exception a Python plugin raised since the last call, if
/// any; the next starts afresh.
pub fn take_exception() -> Option<PyErr> {
    RAISED.lock().unwrap_or_else(|e| e.into_inner()).take()
}

/// An object of a class registered from Python.
pub struct PluginObject {
    pub instance: Py<PyAny>,
    /// `bsdf 'name'`, for messages.
    pub label: Arc<str>,
}

impl PluginObject {
    /// `class(**params)`: the object a scene's table asks for, with every
    /// declared parameter (or its default) as a keyword argument.
    pub fn make(class: &Py<PyAny>, spec: PluginSpec, params: &Params) -> Result<Self> {
        let label: Arc<str> = Arc::from(format!("{} '{}'", spec.kind, spec.name));
        Python::attach(|py| {
            let kwargs = PyDict::new(py);
            for declared in spec.params {
                let value = keyword(py, declared, params)?;
                kwargs
                    .set_item(declared.name, value)
                    .map_err(|e| Error::msg(e.to_string()))?;
            }
            let instance = class.bind(py).call((), Some(&kwargs)).map_err(|e| {
                Error::msg(format!("{label}: its class raised {}", described(py, &e)))
            })?;
            Ok(Self {
                instance: instance.unbind(),
                label: label.clone(),
            })
        })
    }

    /// A copy for another thread (`copy.deepcopy`).
    pub fn deep_copy(&self) -> Self {
        let instance = self.answer("__deepcopy__", |py, instance| {
            py.import("copy")?
                .call_method1("deepcopy", (instance,))
                .map(Bound::unbind)
        });
        Self {
            instance,
            label: self.label.clone(),
        }
    }

    /// The attribute `name` of the object, read as `read` says.
    pub fn attribute<T>(
        &self,
        name: &str,
        read: impl FnOnce(&Bound<'_, PyAny>) -> PyResult<T>,
    ) -> Result<T> {
        Python::attach(|py| {
            self.instance
                .bind(py)
                .getattr(name)
                .and_then(|a| read(&a))
                .map_err(|e| Error::msg(format!("{}: {name}: {}", self.label, described(py, &e))))
        })
    }

    /// `method(*args)`, its result read by `read`. Where Python raises (in
    /// the method, or because its result is not what `read` expects), the
    /// exception is kept for the caller of the render and the call panics:
    /// the plugin's guard turns the panic into this plugin's fault.
    pub fn call<T>(
        &self,
        method: &str,
        args: impl for<'py> PyCallArgs<'py>,
        read: impl FnOnce(&Bound<'_, PyAny>) -> PyResult<T>,
    ) -> T {
        self.answer(method, |_, instance| {
            instance
                .call_method1(method, args)
                .and_then(|result| read(&result))
        })
    }

    /// Runs `work` on the object under the GIL, as [`Self::call`] does.
    fn answer<T>(
        &self,
        method: &str,
        work: impl FnOnce(Python<'_>, &Bound<'_, PyAny>) -> PyResult<T>,
    ) -> T {
        let outcome = Python::attach(|py| {
            work(py, self.instance.bind(py)).map_err(|e| {
                let message = described(py, &e);
                let mut raised = RAISED.lock().unwrap_or_else(|p| p.into_inner());
                raised.get_or_insert(e);
                message
            })
        });
        match outcome {
            Ok(answer) => answer,
            Err(message) => panic!("{}.{method} raised {message}", self.label),
        }
    }
}

/// `TypeError: ...`: an exception as Python prints its last line.
fn described(py: Python<'_>, e: &PyErr) -> String {
    let name = e
        .get_type(py)
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "exception".into());
    format!("{name}: {}", e.value(py))
}

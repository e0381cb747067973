//! lumis's errors as Python exceptions: the command line's message, with
//! where in the scene it was found as attributes.

use lumis_core::Location;
use pyo3::exceptions::{PyException, PyKeyboardInterrupt};
use pyo3::prelude::*;

pyo3::create_exception!(
    lumis,
    Error,
    PyException,
    "A lumis error, with the command line's message. `message` is the message alone; \
     `location` says where it was found (`scene.toml:12:5`, `--set KEY=VALUE`, or a \
     dict's subscripts), and `file`, `line` and `column` are set for a scene file's \
     line; each is None where it does not apply."
);

pyo3::create_exception!(
    lumis,
    Interrupted,
    PyKeyboardInterrupt,
    "Ctrl-C (or a notebook's interrupt) stopped a render or a study: `render` holds the \
     passes finished before it, as a Render (None before the first), and a study's \
     `study` what it measured."
);

/// The [`Error`] exception for a lumis error.
pub fn lumis_error(py: Python<'_>, error: &lumis_core::Error) -> PyErr {
    let exception = Error::new_err(error.to_string());
    let value = exception.value(py);
    let (file, line, column) = match &error.location {
        Some(Location::File { path, line, column }) => {
            (Some(path.to_string()), Some(*line), Some(*column))
        }
        _ => (None, None, None),
    };
    // An exception instance takes any attribute: none of these can fail.
    let _ = value.setattr("message", &error.message);
    let _ = value.setattr("location", error.location.as_ref().map(|l| l.to_string()));
    let _ = value.setattr("file", file);
    let _ = value.setattr("line", line);
    let _ = value.setattr("column", column);
    exception
}

/// A lumis result as a Python one.
pub trait OrRaise<T> {
    fn or_raise(self, py: Python<'_>) -> PyResult<T>;
}

impl<T> OrRaise<T> for lumis_core::Result<T> {
    fn or_raise(self, py: Python<'_>) -> PyResult<T> {
        self.map_err(|e| lumis_error(py, &e))
    }
}

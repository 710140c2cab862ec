//! mlt's errors as Python exceptions. The classes are defined in `mlt/_errors.py` (so that
//! `InvalidArgumentError` can be both an `MltError` and a `ValueError`) and looked up once.

use mlt::MltStatus;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;

static MLT_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static INVALID_ARGUMENT: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static UNSUPPORTED: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static LOAD_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

/// An instance of `mlt._errors.<class>(status, code, message)`; an error finding the class
/// is returned in its place.
fn raise(
    py: Python<'_>,
    cell: &PyOnceLock<Py<PyType>>,
    class: &str,
    status: &str,
    code: Option<i32>,
    message: &str,
) -> PyErr {
    let error = cell
        .import(py, "mlt._errors", class)
        .and_then(|class| class.call1((status, code, message)));
    match error {
        Ok(error) => PyErr::from_value(error),
        Err(error) => error,
    }
}

/// An `mlt::Error` as `mlt.MltError` or the subclass its status calls for.
pub fn from_mlt(py: Python<'_>, error: &mlt::Error) -> PyErr {
    let code = Some(error.status as i32);
    let message = &error.message;
    match error.status {
        MltStatus::MLT_STATUS_INVALID_ARGUMENT => invalid(py, message),
        MltStatus::MLT_STATUS_UNSUPPORTED => raise(
            py,
            &UNSUPPORTED,
            "UnsupportedError",
            "unsupported",
            code,
            message,
        ),
        status => {
            let name = match status {
                MltStatus::MLT_STATUS_OUT_OF_MEMORY => "out_of_memory",
                MltStatus::MLT_STATUS_CANCELLED => "cancelled",
                MltStatus::MLT_STATUS_TIME_LIMIT_REACHED => "time_limit_reached",
                MltStatus::MLT_STATUS_OK => "ok",
                _ => "internal_error",
            };
            raise(py, &MLT_ERROR, "MltError", name, code, message)
        }
    }
}

/// `mlt.InvalidArgumentError` (a `ValueError`) with `message`: what the Rust API returns
/// for invalid input, and what the bindings raise for arrays of the wrong shape or dtype.
pub fn invalid(py: Python<'_>, message: &str) -> PyErr {
    raise(
        py,
        &INVALID_ARGUMENT,
        "InvalidArgumentError",
        "invalid_argument",
        Some(MltStatus::MLT_STATUS_INVALID_ARGUMENT as i32),
        message,
    )
}

/// `mlt.LoadError` for a file a loader could not read.
pub fn load_error(py: Python<'_>, message: &str) -> PyErr {
    raise(py, &LOAD_ERROR, "LoadError", "load_error", None, message)
}

/// `error` with `context` before its message, so that a field's failed conversion says
/// which field: a `TypeError` stays one, any other failure (a sequence of the wrong length,
/// a negative count) becomes `InvalidArgumentError`. The original is kept as the cause.
pub fn with_context(py: Python<'_>, error: PyErr, context: &str) -> PyErr {
    let message = format!("{context}: {}", error.value(py));
    let new = if error.is_instance_of::<PyTypeError>(py) {
        PyTypeError::new_err(message)
    } else {
        invalid(py, &message)
    };
    new.set_cause(py, Some(error));
    new
}

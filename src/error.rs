//! Status codes and errors shared by the Rust API and the C ABI.

use std::fmt;

/// Result of every fallible mlt call. Values are stable: hosts may store them.
#[repr(C)]
#[allow(non_camel_case_types)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MltStatus {
    /// The call succeeded.
    MLT_STATUS_OK = 0,
    /// A pointer, count, index, float or enum value the host passed is invalid; the
    /// message names it.
    MLT_STATUS_INVALID_ARGUMENT = 1,
    /// The request is valid but not supported by this build (e.g. a backend not compiled in).
    MLT_STATUS_UNSUPPORTED = 2,
    /// Memory for the scene or image could not be allocated.
    MLT_STATUS_OUT_OF_MEMORY = 3,
    /// The progress callback asked to stop. The image is valid: every pixel is normalized by
    /// the samples actually taken.
    MLT_STATUS_CANCELLED = 4,
    /// The time limit was reached before the requested samples. The image is valid: every
    /// pixel is normalized by the samples actually taken.
    MLT_STATUS_TIME_LIMIT_REACHED = 5,
    /// A bug inside mlt (a caught panic). The message says where; please report it.
    MLT_STATUS_INTERNAL_ERROR = 6,
}

pub use MltStatus::*;

impl MltStatus {
    /// A short, static description of the status.
    pub fn description(self) -> &'static str {
        match self {
            MLT_STATUS_OK => "success",
            MLT_STATUS_INVALID_ARGUMENT => "invalid argument",
            MLT_STATUS_UNSUPPORTED => "unsupported",
            MLT_STATUS_OUT_OF_MEMORY => "out of memory",
            MLT_STATUS_CANCELLED => "cancelled by the progress callback",
            MLT_STATUS_TIME_LIMIT_REACHED => "time limit reached",
            MLT_STATUS_INTERNAL_ERROR => "internal error",
        }
    }
}

/// An error with its status and a sentence naming the offending field, index and value.
#[derive(Clone, Debug, PartialEq)]
pub struct Error {
    pub status: MltStatus,
    pub message: String,
    /// The index of the material in the scene description the error is about, if any: a
    /// front end that loaded the scene from a file names it (`SceneData::describe_error`).
    pub material: Option<usize>,
}

impl Error {
    pub fn new(status: MltStatus, message: impl Into<String>) -> Self {
        Error {
            status,
            message: message.into(),
            material: None,
        }
    }

    /// The error, as about the scene description's material `index`.
    pub fn about_material(self, index: usize) -> Self {
        Error {
            material: Some(index),
            ..self
        }
    }

    pub fn invalid(message: impl Into<String>) -> Self {
        Error::new(MLT_STATUS_INVALID_ARGUMENT, message)
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.status.description(), self.message)
    }
}

impl std::error::Error for Error {}

pub type Result<T> = std::result::Result<T, Error>;

/// Checks that a float the host passed is finite, naming it otherwise.
pub(crate) fn check_finite(name: &dyn fmt::Display, value: f32) -> Result<()> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(Error::invalid(format!(
            "{name} is {value}; it must be a finite number"
        )))
    }
}

/// Checks the three components of a vector, naming the bad component.
pub(crate) fn check_finite3(name: &str, value: [f32; 3]) -> Result<()> {
    for (axis, v) in ["x", "y", "z"].iter().zip(value) {
        check_finite(&format_args!("{name}.{axis}"), v)?;
    }
    Ok(())
}

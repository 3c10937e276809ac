//! sillage errors as Python exceptions, chosen by kind.

use pyo3::PyErr;
use pyo3::exceptions::{
    PyFileNotFoundError, PyOSError, PyPermissionError, PyRuntimeError, PyValueError,
};
use sillage::core::Error;

/// The Python exception of a sillage error: a missing file is `FileNotFoundError`, other file
/// system errors `PermissionError` or `OSError`, bad parameters (the message names the key),
/// malformed files and unusable input `ValueError`, a missing external program
/// `FileNotFoundError`. The message is the sillage one.
pub fn to_py(error: Error) -> PyErr {
    let message = error.to_string();
    match &error {
        Error::Io { cause, .. } => match cause.kind() {
            std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(message),
            std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(message),
            _ => PyOSError::new_err(message),
        },
        Error::MissingProgram { .. } => PyFileNotFoundError::new_err(message),
        Error::Parameter { .. } | Error::Format { .. } | Error::Frame { .. } | Error::Input(_) => {
            PyValueError::new_err(message)
        }
        _ => PyRuntimeError::new_err(message),
    }
}

//! Hooke's errors as Python exceptions, in the terms of the Python call.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(
    hooke,
    HookeError,
    PyException,
    "A scene, file or value Hooke cannot use; the message names the file and line or the key."
);
create_exception!(
    hooke,
    DivergenceError,
    HookeError,
    "A run stopped because its state stopped making sense; the message names the step, the \
     particle and a stable step size."
);

/// The command line's option names in the library's messages, as the Python arguments
/// that carry the same values.
const ARGUMENT_NAMES: [(&str, &str); 10] = [
    ("--format ply", "format=\"ply\""),
    ("--format obj", "format=\"obj\""),
    ("--format pc2", "format=\"pc2\""),
    ("--format", "format"),
    ("--export (its mesh)", "export (its mesh)"),
    ("--export", "export path"),
    ("--body", "body"),
    ("--table", "table"),
    ("--dt", "dt"),
    ("--duration", "duration"),
];

/// `message` with the command line's option names replaced by [`ARGUMENT_NAMES`].
fn in_python_terms(message: &str) -> String {
    let mut out = message.to_string();
    for (option, argument) in ARGUMENT_NAMES {
        out = out.replace(option, argument);
    }
    out
}

/// A Rust error as the Python exception that says the same as the command would, in the
/// terms of the Python call.
pub(crate) fn error(e: hooke::Error) -> PyErr {
    let message = in_python_terms(&e.to_string());
    match e {
        hooke::Error::Diverged { .. } => DivergenceError::new_err(message),
        _ => HookeError::new_err(message),
    }
}

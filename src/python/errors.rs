//! Library errors as Python exceptions. The classes live in `pmvc/_errors.py`
//! (so that they can derive from `ValueError` or `OSError` as well as
//! `PmvcError`, and carry `path` and `line`); this module raises them.

use crate::formats::{CageLoadError, LoadError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::Path;

/// Which `pmvc` exception a failure raises.
#[derive(Clone, Copy, Debug)]
pub(super) enum Kind {
    /// Bad arrays or arguments: shapes, dtypes, non-finite values, indices.
    Input,
    /// A parameter out of its family's range, an unknown method or backend.
    Parameter,
    /// A file that cannot be read or written, or does not parse.
    File,
    /// Vertices and faces that are not a valid cage.
    Cage,
    /// Weights that do not fit the points and cage they are applied to.
    Weights,
    /// No GPU where one was asked for.
    Backend,
    /// A bind or a cage generation that failed.
    Bind,
    /// More memory or disk than is available.
    TooLarge,
}

impl Kind {
    fn class_name(self) -> &'static str {
        match self {
            Kind::Input => "InputError",
            Kind::Parameter => "ParameterError",
            Kind::File => "FileError",
            Kind::Cage => "CageError",
            Kind::Weights => "WeightsError",
            Kind::Backend => "BackendError",
            Kind::Bind => "BindError",
            Kind::TooLarge => "TooLargeError",
        }
    }
}

/// A `pmvc` exception of `kind` with `message`.
pub(super) fn error(kind: Kind, message: impl Into<String>) -> PyErr {
    raise(kind, message.into(), None, None)
}

/// A `pmvc` exception about a file (and a 1-based line of it, when known).
pub(super) fn file_error(
    kind: Kind,
    message: impl Into<String>,
    path: &Path,
    line: Option<usize>,
) -> PyErr {
    raise(kind, message.into(), Some(path), line)
}

fn raise(kind: Kind, message: String, path: Option<&Path>, line: Option<usize>) -> PyErr {
    Python::attach(|py| {
        let made = (|| -> PyResult<PyErr> {
            let class = py.import("pmvc._errors")?.getattr(kind.class_name())?;
            let keywords = PyDict::new(py);
            if let Some(path) = path {
                keywords.set_item("path", path.to_string_lossy().into_owned())?;
            }
            if let Some(line) = line {
                keywords.set_item("line", line)?;
            }
            Ok(PyErr::from_value(
                class.call((message.clone(),), Some(&keywords))?,
            ))
        })();
        // Only a broken installation lacks the classes; say what was wrong anyway.
        made.unwrap_or_else(|_| pyo3::exceptions::PyRuntimeError::new_err(message))
    })
}

/// A `pmvc.BackendWarning` (through Python's `warnings`, so that filters and
/// `pytest.warns` see it), pointing at the caller's line.
pub(super) fn backend_warning(py: Python<'_>, message: &str) -> PyResult<()> {
    let category = py.import("pmvc._errors")?.getattr("BackendWarning")?;
    py.import("warnings")?
        .call_method1("warn", (message, category, 1))
        .map(|_| ())
}

/// A `pmvc.PmvcWarning`: which object of a file with several was read.
pub(super) fn object_warning(py: Python<'_>, message: &str) -> PyResult<()> {
    let category = py.import("pmvc._errors")?.getattr("PmvcWarning")?;
    py.import("warnings")?
        .call_method1("warn", (message, category, 1))
        .map(|_| ())
}

/// A mesh file that could not be read, naming the file and line.
pub(super) fn load_error(error: &LoadError) -> PyErr {
    let message = error.to_string();
    let (path, line) = match error {
        LoadError::Parse { path, line, .. }
        | LoadError::NonFinite { path, line, .. }
        | LoadError::IndexOutOfRange { path, line, .. } => (path, Some(*line)),
        LoadError::Io { path, .. }
        | LoadError::Empty { path }
        | LoadError::Binary { path, .. }
        | LoadError::UnknownFormat { path }
        | LoadError::NoVertices { path }
        | LoadError::Obj { path, .. }
        | LoadError::Npy { path, .. }
        | LoadError::Gltf { path, .. }
        | LoadError::Object { path, .. }
        | LoadError::TooLarge { path, .. } => (path, None),
    };
    let kind = match error {
        LoadError::Io { source, .. } if source.kind() == std::io::ErrorKind::OutOfMemory => {
            Kind::TooLarge
        }
        _ => Kind::File,
    };
    file_error(kind, message, path, line)
}

/// A cage file that could not be read or is not a valid cage.
pub(super) fn cage_load_error(error: &CageLoadError) -> PyErr {
    match error {
        CageLoadError::Load(error) => load_error(error),
        CageLoadError::Invalid { path, .. } => {
            file_error(Kind::Cage, error.to_string(), path, None)
        }
    }
}

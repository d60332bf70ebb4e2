//! Arguments that are not arrays: names, flags, numbers, file paths and
//! objects of this package. Each is taken as any Python object and checked
//! here, so that a value of the wrong type raises a `pmvc` exception naming the
//! argument, as a wrong value does, not the TypeError of the argument parser.

use super::errors::{error, Kind};
use pyo3::prelude::*;
use std::path::PathBuf;

/// How a message shows a value it refuses: its repr (cut at 60 characters)
/// and its type.
pub(super) fn shown(value: &Bound<'_, PyAny>) -> String {
    let repr = value
        .repr()
        .map(|repr| repr.to_string())
        .unwrap_or_else(|_| "?".into());
    let repr = if repr.chars().count() > 60 {
        format!("{}…", repr.chars().take(60).collect::<String>())
    } else {
        repr
    };
    let type_name = value
        .get_type()
        .name()
        .map(|name| name.to_string())
        .unwrap_or_else(|_| "?".into());
    format!("{repr} ({type_name})")
}

/// A string argument such as `method` or `backend`.
pub(super) fn text(value: &Bound<'_, PyAny>, what: &str) -> PyResult<String> {
    value.extract::<String>().map_err(|_| {
        error(
            Kind::Parameter,
            format!("{what} must be a string, not {}", shown(value)),
        )
    })
}

/// A flag such as `strict`: True or False (a numpy bool too), nothing else.
pub(super) fn flag(value: &Bound<'_, PyAny>, what: &str) -> PyResult<bool> {
    value.extract::<bool>().map_err(|_| {
        error(
            Kind::Parameter,
            format!("{what} must be True or False, not {}", shown(value)),
        )
    })
}

/// An integer argument such as `target`.
pub(super) fn integer(value: &Bound<'_, PyAny>, what: &str) -> PyResult<i64> {
    value.extract::<i64>().map_err(|_| {
        error(
            Kind::Parameter,
            format!("{what} must be an integer, not {}", shown(value)),
        )
    })
}

/// A number or None, such as `clearance`.
pub(super) fn optional_number(
    value: Option<&Bound<'_, PyAny>>,
    what: &str,
) -> PyResult<Option<f64>> {
    match value.filter(|value| !value.is_none()) {
        None => Ok(None),
        Some(value) => value.extract::<f64>().map(Some).map_err(|_| {
            error(
                Kind::Parameter,
                format!("{what} must be a number or None, not {}", shown(value)),
            )
        }),
    }
}

/// A file path: a str or any os.PathLike (pathlib.Path...).
pub(super) fn path(value: &Bound<'_, PyAny>, what: &str) -> PyResult<PathBuf> {
    value.extract::<PathBuf>().map_err(|_| {
        error(
            Kind::Input,
            format!(
                "{what}: {} is not a file path (a str or os.PathLike)",
                shown(value)
            ),
        )
    })
}

/// `object=`: None, or an object's name, checked as `--mesh-object` is.
pub(super) fn object_name(value: Option<Bound<'_, PyAny>>) -> PyResult<Option<String>> {
    let Some(value) = value.filter(|v| !v.is_none()) else {
        return Ok(None);
    };
    let name = text(&value, "object")?;
    crate::formats::check_object_name(&name).map_err(|message| error(Kind::Parameter, message))?;
    Ok(Some(name))
}

//! The arguments `bind` and `deform` share, each read by the one parser the
//! command line uses for it (a family id, a parameter's spec, a dtype, a quad
//! split, PMVC's GPU kernel).

use super::arguments::{shown, text};
use super::errors::{error, Kind};
use crate::coords::{BindOptions, Dtype, Method, Parameter, QuadSplit};
use crate::gpu::PmvcKernel;
use pyo3::prelude::*;

/// `triangulate`: "shorter" or "longer" (None keeps quads as bilinear patches).
pub(super) fn quad_split_from(value: &Bound<'_, PyAny>) -> PyResult<QuadSplit> {
    let bad = || {
        error(
            Kind::Parameter,
            format!("triangulate must be None, \"shorter\" or \"longer\", not {value}"),
        )
    };
    let id: String = value.extract().map_err(|_| bad())?;
    match QuadSplit::from_id(&id) {
        Some(split) if split != QuadSplit::None => Ok(split),
        _ => Err(bad()),
    }
}

/// The family named `id`, or an error listing the known ones.
pub(super) fn method_from(id: &str) -> PyResult<Method> {
    Method::from_id(id).ok_or_else(|| {
        let known: Vec<&str> = Method::ALL.iter().map(|m| m.id()).collect();
        error(
            Kind::Parameter,
            format!(
                "method \"{id}\" is not a family; known: {}",
                known.join(", ")
            ),
        )
    })
}

/// A parameter's value from Python, checked by its spec's one `validate`.
pub(super) fn parameter_value(parameter: Parameter, value: &Bound<'_, PyAny>) -> PyResult<u32> {
    let spec = parameter.spec();
    let refused = || {
        let names: Vec<String> = spec
            .named
            .iter()
            .map(|n| format!(" or \"{}\"", n.name))
            .collect();
        error(
            Kind::Parameter,
            format!(
                "{} must be {}{}, not {value}",
                parameter.id(),
                if spec.scale > 1 {
                    "a number"
                } else {
                    "an integer"
                },
                names.concat()
            ),
        )
    };
    // A string is a value's name ("exact"); numbers come as numbers.
    if let Ok(name) = value.extract::<String>() {
        return spec
            .named
            .iter()
            .find(|named| named.name.eq_ignore_ascii_case(name.trim()))
            .map(|named| named.value)
            .ok_or_else(refused);
    }
    if spec.scale > 1 {
        // A decimal (Somigliana's Poisson ratio), held in 1/scale units.
        let number: f64 = value.extract().map_err(|_| refused())?;
        return (spec.validate_decimal(number)).map_err(|message| error(Kind::Parameter, message));
    }
    let value: i128 = value.extract().map_err(|_| refused())?;
    // Below zero or past u64 it is out of range all the same; the spec's
    // message gives the range.
    let clamped = u64::try_from(value).unwrap_or(u64::MAX);
    spec.validate_number(clamped).map_err(|cause| {
        let message = cause
            .to_string()
            .replacen(&clamped.to_string(), &value.to_string(), 1);
        error(Kind::Parameter, message)
    })
}

/// The options of a bind of `method` with `resolution`, `grid` and
/// `poisson_ratio`: the
/// family's own parameter is checked, the others are not read.
/// A parameter not given keeps its default.
pub(super) fn bind_options(
    method: Method,
    resolution: Option<&Bound<'_, PyAny>>,
    grid: Option<&Bound<'_, PyAny>>,
    poisson_ratio: Option<&Bound<'_, PyAny>>,
    triangulate: Option<&Bound<'_, PyAny>>,
) -> PyResult<BindOptions> {
    let mut options = BindOptions::for_method(method);
    if let Some(given) = triangulate.filter(|value| !value.is_none()) {
        options.quads = quad_split_from(given)?;
    }
    if let Some(spec) = method.spec().parameter {
        let given = match spec.key {
            Parameter::Resolution => resolution,
            Parameter::Grid => grid,
            Parameter::PoissonRatio => poisson_ratio,
            // Read when deforming (`deform(..., bulging=)`), not binding.
            Parameter::Bulging | Parameter::LocalBlend => None,
        };
        if let Some(given) = given.filter(|value| !value.is_none()) {
            options.set(spec.key, parameter_value(spec.key, given)?);
        }
    }
    options
        .validate()
        .map_err(|cause| error(Kind::Parameter, cause.to_string()))?;
    Ok(options)
}

/// `dtype=`: numpy.float32 or numpy.float64 (any form numpy.dtype takes: the
/// type, a numpy.dtype, "float64", "<f8"), or "f32"/"f64" as `--dtype` takes
/// them; read by the one parser of a dtype ([`Dtype::parse`]).
pub(super) fn dtype_argument(value: &Bound<'_, PyAny>, function: &str) -> PyResult<Dtype> {
    let refused = || {
        error(
            Kind::Parameter,
            format!(
                "{function}: dtype must be numpy.float32 or numpy.float64, not {}",
                shown(value)
            ),
        )
    };
    if let Ok(text) = value.extract::<String>() {
        if let Ok(dtype) = Dtype::parse(&text) {
            return Ok(dtype);
        }
    }
    let name: String = value
        .py()
        .import("numpy")?
        .call_method1("dtype", (value,))
        .and_then(|dtype| dtype.getattr("name"))
        .and_then(|name| name.extract())
        .map_err(|_| refused())?;
    Dtype::parse(&name).map_err(|_| refused())
}

/// `pmvc_kernel=` checked by the command line's one parser.
pub(super) fn pmvc_kernel_from(function: &str, text: &str) -> PyResult<PmvcKernel> {
    PmvcKernel::parse(text).map_err(|cause| error(Kind::Parameter, format!("{function}: {cause}")))
}

/// `method=`: a family id, "pmvc" when not given.
pub(super) fn method_argument(value: Option<&Bound<'_, PyAny>>) -> PyResult<Method> {
    match value.filter(|value| !value.is_none()) {
        Some(value) => method_from(&text(value, "method")?),
        None => Ok(Method::Pmvc),
    }
}

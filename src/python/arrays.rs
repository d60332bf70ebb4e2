//! Arrays in and out. Points come in as any array-like of real numbers with
//! shape (n, 3) (converted by numpy, so lists, tuples and arrays of any float or
//! integer dtype work); faces as a sequence of index sequences, so that quads
//! stay quads. Everything that comes out is a numpy array.

use super::errors::{error, Kind};
use crate::budget::{bytes_for, check_memory};
use glam::DVec3;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyList;

/// `value` as float64 positions of shape (n, 3); `what` names the argument in
/// messages ("points", "cage vertices").
pub(super) fn positions(value: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<DVec3>> {
    let py = value.py();
    let numpy = py.import("numpy")?;
    let array = numpy.call_method1("asarray", (value,)).map_err(|cause| {
        error(
            Kind::Input,
            format!("{what}: not an array of numbers of shape (n, 3) ({cause})"),
        )
    })?;
    let dtype = array.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "f" | "i" | "u") {
        return Err(error(
            Kind::Input,
            format!(
                "{what}: dtype {} is not a real number type (use floats, e.g. numpy.float64)",
                dtype.str()?
            ),
        ));
    }
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    if shape.len() != 2 || shape[1] != 3 {
        return Err(error(
            Kind::Input,
            format!(
                "{what}: shape {} is not (n, 3)",
                crate::formats::npy::header::shape_text(
                    &shape.iter().map(|&n| n as u64).collect::<Vec<_>>()
                )
            ),
        ));
    }
    let rows = shape[0];
    check_memory(
        || format!("{what}: a copy of {rows} positions"),
        bytes_for(rows as u64, 2 * std::mem::size_of::<DVec3>() as u64),
    )
    .map_err(|too_large| error(Kind::TooLarge, format!("{what}: {too_large}")))?;
    let contiguous = aligned(&array, "float64")?;
    let contiguous = contiguous.cast_into::<PyArray2<f64>>()?;
    let readonly = contiguous.readonly();
    let values = readonly
        .as_slice()
        .map_err(|cause| error(Kind::Input, format!("{what}: {cause}")))?;
    let points: Vec<DVec3> = values.chunks_exact(3).map(DVec3::from_slice).collect();
    if let Some(row) = points.iter().position(|p| !p.is_finite()) {
        let p = points[row];
        return Err(error(
            Kind::Input,
            format!(
                "{what}: row {row} is not finite ({}, {}, {})",
                p.x, p.y, p.z
            ),
        ));
    }
    Ok(points)
}

/// `value` as a C-contiguous, aligned numpy array of `dtype`: the array itself
/// when it is one, else a copy. Arrays rebuilt from a buffer (a Dask worker's,
/// one from `numpy.frombuffer` at an odd offset) can be contiguous but
/// misaligned, which Rust cannot read in place.
pub(super) fn aligned<'py>(value: &Bound<'py, PyAny>, dtype: &str) -> PyResult<Bound<'py, PyAny>> {
    let numpy = value.py().import("numpy")?;
    numpy.call_method1("require", (value, numpy.getattr(dtype)?, ("C", "A")))
}

/// `value` as polygons of vertex indices (0-based) into `vertex_count` vertices,
/// each of at least 3 corners: a numpy integer array of shape (m, k), k ≥ 3
/// (libigl's `F`: triangles for k = 3), or any sequence of index sequences
/// (polygons of mixed sizes, quads staying quads).
pub(super) fn faces(
    value: &Bound<'_, PyAny>,
    vertex_count: usize,
    what: &str,
) -> PyResult<Vec<Vec<u32>>> {
    if let Some(faces) = integer_array_faces(value, vertex_count, what)? {
        return Ok(faces);
    }
    let not_faces = |cause: PyErr| {
        error(
            Kind::Input,
            format!("{what}: not a sequence of faces, each a sequence of vertex indices ({cause})"),
        )
    };
    if let Ok(count) = value.len() {
        check_memory(
            || format!("{what}: {count} faces"),
            bytes_for(count as u64, 64),
        )
        .map_err(|too_large| error(Kind::TooLarge, format!("{what}: {too_large}")))?;
    }
    let mut faces = Vec::new();
    for (face, item) in value.try_iter().map_err(not_faces)?.enumerate() {
        let item = item?;
        let mut corners = Vec::new();
        for corner in item.try_iter().map_err(not_faces)? {
            let corner = corner?;
            let index: i64 = corner.extract().map_err(|_| {
                let shown = corner
                    .repr()
                    .map(|r| r.to_string())
                    .unwrap_or_else(|_| "?".into());
                error(
                    Kind::Input,
                    format!("{what}: face {face}: {shown} is not an integer vertex index"),
                )
            })?;
            corners.push(vertex_index(index, face, vertex_count, what)?);
        }
        check_corner_count(corners.len(), face, what)?;
        faces.push(corners);
    }
    Ok(faces)
}

/// A face's corner `index`, checked against the `vertex_count` vertices.
fn vertex_index(index: i64, face: usize, vertex_count: usize, what: &str) -> PyResult<u32> {
    if index < 0 || index as u64 >= vertex_count as u64 {
        return Err(error(
            Kind::Input,
            format!(
                "{what}: face {face} refers to vertex {index}, but there are {vertex_count} vertices (indices count from 0)"
            ),
        ));
    }
    Ok(index as u32)
}

/// A face needs three corners or more.
fn check_corner_count(corners: usize, face: usize, what: &str) -> PyResult<()> {
    if corners < 3 {
        return Err(error(
            Kind::Input,
            format!("{what}: face {face} has {corners} corners; a face needs at least 3"),
        ));
    }
    Ok(())
}

/// `value` as faces when it is a numpy array of integers of shape (m, k), read
/// in one piece (no Python object per index); None for anything else, which
/// [`faces`] reads as a sequence of sequences. Checked as every face is.
fn integer_array_faces(
    value: &Bound<'_, PyAny>,
    vertex_count: usize,
    what: &str,
) -> PyResult<Option<Vec<Vec<u32>>>> {
    let py = value.py();
    let numpy = py.import("numpy")?;
    if !value.is_instance(&numpy.getattr("ndarray")?)? {
        return Ok(None);
    }
    let kind: String = value.getattr("dtype")?.getattr("kind")?.extract()?;
    let shape: Vec<usize> = value.getattr("shape")?.extract()?;
    if !matches!(kind.as_str(), "i" | "u") || shape.len() != 2 {
        return Ok(None);
    }
    let (count, corners) = (shape[0], shape[1]);
    if count > 0 {
        check_corner_count(corners, 0, what)?;
    }
    check_memory(
        || format!("{what}: {count} faces"),
        bytes_for(count as u64, 64),
    )
    .map_err(|too_large| error(Kind::TooLarge, format!("{what}: {too_large}")))?;
    // 64-bit unsigned indices past i64 are out of range all the same; clip
    // them there (narrower ones fit).
    let itemsize: usize = value.getattr("dtype")?.getattr("itemsize")?.extract()?;
    let clipped = if kind == "u" && itemsize >= 8 {
        numpy.call_method1("minimum", (value, i64::MAX as u64))?
    } else {
        value.clone()
    };
    let contiguous = aligned(&clipped, "int64")?;
    let contiguous = contiguous.cast_into::<PyArray2<i64>>()?;
    let readonly = contiguous.readonly();
    let values = readonly
        .as_slice()
        .map_err(|cause| error(Kind::Input, format!("{what}: {cause}")))?;
    let mut faces = Vec::with_capacity(count);
    for (face, row) in values.chunks_exact(corners.max(1)).enumerate() {
        let corners = row
            .iter()
            .map(|&index| vertex_index(index, face, vertex_count, what))
            .collect::<PyResult<Vec<u32>>>()?;
        faces.push(corners);
    }
    Ok(Some(faces))
}

/// Positions as a float64 array of shape (n, 3).
pub(super) fn positions_array<'py>(
    py: Python<'py>,
    points: &[DVec3],
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let flat: Vec<f64> = points.iter().flat_map(|p| p.to_array()).collect();
    PyArray1::from_vec(py, flat).reshape([points.len(), 3])
}

/// Row-major values as an array of shape (rows, cols), without a copy.
pub(super) fn matrix<'py, T: numpy::Element>(
    py: Python<'py>,
    values: Vec<T>,
    rows: usize,
    cols: usize,
) -> PyResult<Bound<'py, PyArray2<T>>> {
    PyArray1::from_vec(py, values).reshape([rows, cols])
}

/// Triangles as an int64 array of shape (t, 3).
pub(super) fn triangles_array<'py>(
    py: Python<'py>,
    triangles: &[[u32; 3]],
) -> PyResult<Bound<'py, PyArray2<i64>>> {
    let flat: Vec<i64> = triangles.iter().flatten().map(|&i| i64::from(i)).collect();
    matrix(py, flat, triangles.len(), 3)
}

/// Polygons as a list of lists of indices.
pub(super) fn faces_list<'py>(py: Python<'py>, faces: &[Vec<u32>]) -> PyResult<Bound<'py, PyList>> {
    PyList::new(py, faces.iter().map(|face| face.to_vec()))
}

//! Which file format a family's weights take: one `.npy` matrix, or Green
//! coordinates' two arrays in a `.npz`; checked before any work, and applied when
//! `pmvc deform --weights` reads a file.

use super::commands::BoundInput;
use super::BindArgs;
use crate::coords::family::ColumnLayout;
use crate::coords::{AnyWeights, Dtype, Method};
use crate::formats::npy::{read_npy, read_npy_f64, ExpectedArray};
use crate::formats::npz::{read_npz, read_npz_f64};
use crate::formats::shown_path;
use anyhow::{bail, Result};

/// Whether `method`'s weights are written as two arrays in a `.npz` (φ and ψ)
/// rather than one `.npy`.
pub(super) fn writes_npz(method: Method) -> bool {
    method.spec().columns == ColumnLayout::CageVerticesThenTriangles
}

/// The output's extension decides its format, so one that does not fit the
/// family is an error before any work.
pub(super) fn check_weights_format(args: &BindArgs) -> Result<()> {
    let extension = args
        .out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let method = args.method.method;
    match (writes_npz(method), extension.as_deref()) {
        (true, Some("npy")) => bail!(
            "{}: {} coordinates are two arrays (phi: mesh vertices × cage vertices, psi: mesh vertices × cage triangles) and are written as .npz; use --out {}",
            shown_path(&args.out),
            method.name(),
            shown_path(&args.out.with_extension("npz"))
        ),
        (false, Some("npz")) => bail!(
            "{}: {} weights are one array, written as .npy; use --out {} (only Green coordinates, --method green, are written as .npz)",
            shown_path(&args.out),
            method.name(),
            shown_path(&args.out.with_extension("npy"))
        ),
        _ => Ok(()),
    }
}

/// Whether `path` names a `.npz` (Green coordinates' φ and ψ).
pub(super) fn is_npz(path: &std::path::Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npz"))
}

/// The family stored weights apply as: a `.npz` holds Green coordinates (φ and
/// ψ), a `.npy` one weight per cage vertex, whatever `--method` says, except
/// that Green coordinates cannot come from a `.npy`.
pub(super) fn stored_family(path: &std::path::Path, asked: Method) -> Result<Method> {
    if is_npz(path) {
        return Ok(Method::Green);
    }
    if writes_npz(asked) {
        bail!(
            "{}: {} coordinates are read from a .npz with arrays phi and psi (what `pmvc bind --method {}` writes), not from a .npy",
            shown_path(path),
            asked.name(),
            asked.id()
        );
    }
    Ok(asked)
}

/// Weights of `method` ([`stored_family`]) from a file. The file's arrays must
/// have this mesh's and cage's shape, finite values, and rows of cage-vertex
/// weights that sum to 1 (checked as they are read).
/// The file's values are float32, or float64 where its metadata says so (`dtype`).
pub(super) fn read_weights_for(
    path: &std::path::Path,
    input: &BoundInput,
    method: Method,
    dtype: Dtype,
) -> Result<AnyWeights> {
    let rows = input.mesh.mesh.positions.len();
    let (vertices, triangles) = (input.cage.vertex_count(), input.cage.triangle_count());
    let expected = ExpectedArray::of_layout(method.spec().columns, rows, vertices, triangles);
    Ok(match (dtype, writes_npz(method)) {
        (Dtype::Float32, true) => AnyWeights::F32(read_npz(path, rows, vertices, triangles)?),
        (Dtype::Float32, false) => AnyWeights::F32(read_npy(path, expected)?),
        (Dtype::Float64, true) => AnyWeights::F64(read_npz_f64(path, rows, vertices, triangles)?),
        (Dtype::Float64, false) => AnyWeights::F64(read_npy_f64(path, expected)?),
    })
}

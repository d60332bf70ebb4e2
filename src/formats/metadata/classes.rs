//! The class mask beside weights, `W.classes.npy`: one int8 code per row
//! saying whether its point is inside the cage, on it, or outside, so that rows
//! a family filled by its outside policy can be told from the rest.

use super::MetadataError;
use crate::geometry::PointClass;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Class codes in `W.classes.npy` (int8).
pub const CLASS_INSIDE: i8 = 0;
pub const CLASS_ON_CAGE: i8 = 1;
pub const CLASS_OUTSIDE: i8 = 2;

/// `W.classes.npy` for weights `W.npy` or `W.npz`.
pub fn classes_path(weights: &Path) -> PathBuf {
    weights.with_extension("classes.npy")
}

pub fn class_code(class: &PointClass) -> i8 {
    match class {
        PointClass::Inside => CLASS_INSIDE,
        PointClass::OnSurface { .. } => CLASS_ON_CAGE,
        PointClass::Outside => CLASS_OUTSIDE,
    }
}

pub fn class_codes(classes: &[PointClass]) -> Vec<i8> {
    classes.iter().map(class_code).collect()
}

/// The bytes of the class mask: a 1-D int8 `.npy` of `codes`.
pub fn write_classes_npy_to(out: &mut dyn Write, codes: &[i8]) -> std::io::Result<()> {
    // A 1-D header is well under 64 KiB, whatever the length.
    let preamble = crate::formats::npy::header::header_bytes("|i1", &[codes.len() as u64])
        .map_err(std::io::Error::other)?;
    out.write_all(&preamble)?;
    let bytes: Vec<u8> = codes.iter().map(|&c| c as u8).collect();
    out.write_all(&bytes)
}

/// Read a class mask of `rows` rows: a 1-D int8 (or uint8) `.npy` whose values
/// are class codes.
pub fn read_classes_npy(path: &Path, rows: usize) -> Result<Vec<i8>, MetadataError> {
    let classes = |reason: String| MetadataError::Classes {
        path: path.to_owned(),
        reason,
    };
    let read_error = |source| MetadataError::Read {
        path: path.to_owned(),
        source,
    };
    // The header (at most a few kilobytes) plus one byte a row.
    let limit = rows as u64 + 65_536 + 16;
    let bytes = crate::budget::read_limited(path, limit).map_err(read_error)?;
    let header =
        crate::formats::npy::header::read_header(&mut bytes.as_slice(), Some(bytes.len() as u64))
            .map_err(|error| classes(error.to_string()))?;
    if !matches!(header.descr.as_str(), "|i1" | "|u1" | "i1" | "u1") {
        return Err(classes(format!(
            "expected an int8 class mask ('|i1'), found dtype '{}'",
            header.descr.escape_debug()
        )));
    }
    if header.shape != [rows as u64] {
        return Err(classes(format!(
            "expected shape ({rows},), one class per weights row, found {}",
            crate::formats::npy::header::shape_text(&header.shape)
        )));
    }
    let start = usize::try_from(header.data_offset).unwrap_or(usize::MAX);
    let values = bytes.get(start..).unwrap_or_default();
    if values.len() != rows {
        return Err(classes(format!(
            "holds {} class values after its header; its shape needs {rows}",
            values.len()
        )));
    }
    let codes: Vec<i8> = values.iter().map(|&b| b as i8).collect();
    if let Some(row) = codes
        .iter()
        .position(|c| !(CLASS_INSIDE..=CLASS_OUTSIDE).contains(c))
    {
        return Err(classes(format!(
            "row {}: class {} is none of 0 (inside), 1 (on the cage), 2 (outside)",
            row + 1,
            codes[row]
        )));
    }
    Ok(codes)
}

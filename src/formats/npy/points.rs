//! Point sets as NumPy `.npy` files: an (n, 3) array of float32 or float64 in C
//! order, read wherever a mesh is (a point set has no faces), and points
//! written as little-endian float64 (n, 3), so that scripts get every bit of
//! a deformed position.

use super::header::{header_bytes, read_fully, read_header, shape_text};
use crate::budget::{bytes_for, check_memory};
use crate::formats::{write_atomically, LoadError, MeshFile, MeshFormat, WriteError};
use crate::geometry::TriMesh;
use glam::DVec3;
use std::io::Read;
use std::path::Path;

/// Points decoded per read: 4096 rows of at most 24 bytes.
const ROWS_PER_READ: usize = 4096;

/// How the file stores one coordinate.
#[derive(Clone, Copy)]
struct Scalar {
    bytes: usize,
    big_endian: bool,
}

impl Scalar {
    fn of(descr: &str) -> Option<Scalar> {
        let (bytes, big_endian) = match descr {
            "<f4" => (4, false),
            "<f8" => (8, false),
            ">f4" => (4, true),
            ">f8" => (8, true),
            _ => return None,
        };
        Some(Scalar { bytes, big_endian })
    }

    fn decode(self, raw: &[u8]) -> f64 {
        match (self.bytes, self.big_endian) {
            (4, false) => f64::from(f32::from_le_bytes([raw[0], raw[1], raw[2], raw[3]])),
            (4, true) => f64::from(f32::from_be_bytes([raw[0], raw[1], raw[2], raw[3]])),
            (_, false) => f64::from_le_bytes(raw[..8].try_into().unwrap_or([0; 8])),
            (_, true) => f64::from_be_bytes(raw[..8].try_into().unwrap_or([0; 8])),
        }
    }
}

/// Read an (n, 3) float32 or float64 point set from a `.npy` file, as
/// `numpy.save` writes it. The header is checked against the bytes present and
/// the points' memory before anything of the declared size is allocated; every
/// coordinate must be finite. Errors name the file and what is wrong (the dtype,
/// the shape, the 1-based row of a NaN).
pub(crate) fn read_points_npy(path: &Path, max_points: usize) -> Result<MeshFile, LoadError> {
    let wrong = |message: String| LoadError::Npy {
        path: path.to_owned(),
        message,
    };
    let io_error = |source| LoadError::Io {
        path: path.to_owned(),
        source,
    };
    let file = std::fs::File::open(path).map_err(io_error)?;
    let metadata = file.metadata().map_err(io_error)?;
    if metadata.is_dir() {
        return Err(io_error(std::io::Error::other(
            "it is a folder, not a file",
        )));
    }
    let present = metadata.is_file().then_some(metadata.len());
    if present == Some(0) {
        return Err(LoadError::Empty {
            path: path.to_owned(),
        });
    }
    let mut reader = std::io::BufReader::new(file);
    let header = read_header(&mut reader, present).map_err(|error| wrong(error.to_string()))?;
    let scalar = Scalar::of(&header.descr).ok_or_else(|| {
        wrong(format!(
            "expected float32 or float64 points ('<f4' or '<f8'), found dtype '{}'; convert with .astype('<f8')",
            header.descr.escape_debug()
        ))
    })?;
    if header.fortran_order {
        return Err(wrong(
            "expected C (row-major) order, found fortran_order True; write it with numpy.ascontiguousarray".to_owned(),
        ));
    }
    let rows = match header.shape[..] {
        [rows, 3] => rows,
        _ => {
            return Err(wrong(format!(
                "expected points of shape (n, 3), found shape {}",
                shape_text(&header.shape)
            )))
        }
    };
    if rows == 0 {
        return Err(LoadError::NoVertices {
            path: path.to_owned(),
        });
    }
    if rows > max_points as u64 {
        return Err(LoadError::TooLarge {
            path: path.to_owned(),
            count: usize::try_from(rows).unwrap_or(usize::MAX),
            limit: max_points,
        });
    }
    let row_bytes = 3 * scalar.bytes;
    let needed = bytes_for(rows, row_bytes as u64);
    if let Some(data) = present.map(|present| present.saturating_sub(header.data_offset)) {
        if data != needed {
            let (state, relation) = if data < needed {
                ("truncated", "but the file holds")
            } else {
                ("too long", "and the file holds")
            };
            return Err(wrong(format!(
                "{state}: its shape ({rows}, 3) needs {needed} bytes of values, {relation} {data}"
            )));
        }
    }
    let rows = rows as usize; // at most max_points
    check_memory(|| format!("its {rows} points"), bytes_for(rows as u64, 24)).map_err(|error| {
        io_error(std::io::Error::new(
            std::io::ErrorKind::OutOfMemory,
            error.to_string(),
        ))
    })?;
    let mut positions = Vec::with_capacity(rows);
    let mut block = vec![0u8; ROWS_PER_READ * row_bytes];
    while positions.len() < rows {
        let count = (rows - positions.len()).min(ROWS_PER_READ);
        let bytes = &mut block[..count * row_bytes];
        let filled = read_fully(&mut reader, bytes).map_err(io_error)?;
        if filled < bytes.len() {
            let held = positions.len() as u64 * row_bytes as u64 + filled as u64;
            return Err(wrong(format!(
                "truncated: its shape ({rows}, 3) needs {needed} bytes of values, but it holds {held}"
            )));
        }
        for raw in bytes.chunks_exact(row_bytes) {
            let p = DVec3::new(
                scalar.decode(&raw[..scalar.bytes]),
                scalar.decode(&raw[scalar.bytes..2 * scalar.bytes]),
                scalar.decode(&raw[2 * scalar.bytes..]),
            );
            if !p.is_finite() {
                let value = [p.x, p.y, p.z].into_iter().find(|v| !v.is_finite());
                return Err(wrong(format!(
                    "row {} has a non-finite coordinate ({}); points must be finite",
                    positions.len() + 1,
                    value.unwrap_or(f64::NAN)
                )));
            }
            positions.push(p);
        }
    }
    // A device or pipe has no size to check beforehand: nothing may follow.
    if present.is_none() && reader.read(&mut [0u8; 1]).map_err(io_error)? > 0 {
        return Err(wrong(format!(
            "too long: it holds more than the {needed} bytes of values its shape ({rows}, 3) needs"
        )));
    }
    Ok(MeshFile {
        path: path.to_owned(),
        format: MeshFormat::Npy,
        mesh: TriMesh {
            positions,
            ..Default::default()
        },
        obj_text: None,
        node_transform: None,
        object_note: None,
        objects: Default::default(),
    })
}

/// Write `points` as a little-endian float64 (n, 3) `.npy` (version 1.0), by the
/// output rules of [`crate::formats::write_atomically`].
pub fn write_points_npy(path: &Path, points: &[DVec3]) -> Result<(), WriteError> {
    let preamble =
        header_bytes("<f8", &[points.len() as u64, 3]).map_err(|message| WriteError {
            path: path.to_owned(),
            source: std::io::Error::new(std::io::ErrorKind::InvalidInput, message),
        })?;
    write_atomically(path, |out| {
        out.write_all(&preamble)?;
        let mut block = Vec::with_capacity(ROWS_PER_READ * 24);
        for rows in points.chunks(ROWS_PER_READ) {
            block.clear();
            block.extend(
                rows.iter()
                    .flat_map(|p| p.to_array())
                    .flat_map(f64::to_le_bytes),
            );
            out.write_all(&block)?;
        }
        Ok(())
    })
}

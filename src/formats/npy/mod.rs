//! Weights as NumPy `.npy` files (little-endian float32, or float64 where asked
//! for, C order, shape (rows, columns)): what `pmvc bind` writes (version 1.0)
//! and `pmvc deform --weights` reads (versions 1.0 to 3.0, header in [`header`]). Writing goes
//! through a temporary file that is renamed over the target; reading checks every
//! declared size before anything that size is allocated.

pub mod header;
pub(crate) mod points;

use crate::budget::{bytes_for, check_memory, TooLarge};
use crate::coords::{Dtype, WeightValue, Weights, WeightsF64};
use crate::formats::{shown_path, PendingOutput, WriteError};
use header::{read_fully, read_header, shape_text, HeaderError, NpyHeader};
use std::io::Read;
use std::path::{Path, PathBuf};

/// A weights file could not be written or read. Every variant names the file
/// (and, in a `.npz`, the array).
#[derive(Debug, thiserror::Error)]
pub enum NpyError {
    #[error(transparent)]
    Write(#[from] WriteError),
    #[error("{}: cannot read: {source}", shown_path(path))]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{at}: {source}")]
    Header { at: ArrayAt, source: HeaderError },
    #[error(
        "{at}: expected a 2-D weights array, found shape {}",
        shape_text(shape)
    )]
    Shape { at: ArrayAt, shape: Vec<u64> },
    #[error("{at}: expected C (row-major) order, found fortran_order True; write it with numpy.ascontiguousarray")]
    FortranOrder { at: ArrayAt },
    #[error("{at}: expected little-endian float32 weights ('<f4'), found dtype '{}'; convert with .astype('<f4')", dtype.escape_debug())]
    Dtype { at: ArrayAt, dtype: String },
    #[error("{at}: expected little-endian {} weights ('{}'), as its metadata says, found dtype '{}'", expected.id(), expected.descr(), dtype.escape_debug())]
    DtypeOf {
        at: ArrayAt,
        dtype: String,
        expected: Dtype,
    },
    #[error("{at}: declares shape {}, but the mesh has {} vertices and the cage {} {}, so it must be ({}, {})", shape_text(declared), expected.rows, expected.cols, expected.columns, expected.rows, expected.cols)]
    ShapeMismatch {
        at: ArrayAt,
        declared: Vec<u64>,
        expected: ExpectedArray,
    },
    #[error("{at}: truncated: its shape ({rows}, {cols}) needs {needed} bytes of {} values, but the file holds {present}", dtype.id())]
    Truncated {
        at: ArrayAt,
        rows: usize,
        cols: usize,
        needed: u64,
        present: u64,
        dtype: Dtype,
    },
    #[error("{at}: holds more than the {needed} bytes of values its shape ({rows}, {cols}) needs{}", present.map(|p| format!(" ({p})")).unwrap_or_default())]
    TrailingBytes {
        at: ArrayAt,
        rows: usize,
        cols: usize,
        needed: u64,
        present: Option<u64>,
    },
    #[error("{at}: {source}")]
    TooLarge { at: ArrayAt, source: TooLarge },
    #[error("{at}: row {row}, column {column} is {value}; weights must be finite")]
    NonFinite {
        at: ArrayAt,
        /// 1-based, as the message shows it.
        row: usize,
        column: usize,
        value: f64,
    },
    #[error("{at}: row {row}'s weights sum to {sum}, not 1 (allowed: ±{tolerance:.1e}); every row of {} must sum to 1", expected.what_sums())]
    RowSum {
        at: ArrayAt,
        /// 1-based.
        row: usize,
        sum: f64,
        tolerance: f64,
        expected: ExpectedArray,
    },
    #[error("{}: not a .npz archive: {source}", shown_path(path))]
    NotNpz {
        path: PathBuf,
        source: zip::result::ZipError,
    },
    #[error("{at}: is compressed (the file was written with numpy.savez_compressed); write it with numpy.savez")]
    Compressed { at: ArrayAt },
    #[error("{}: has no array '{name}' (it holds: {found})", shown_path(path))]
    MissingArray {
        path: PathBuf,
        name: &'static str,
        found: String,
    },
    #[error(
        "{}: shape ({rows}, {cols}) is too long for a .npy header",
        shown_path(path)
    )]
    HeaderTooLong {
        path: PathBuf,
        rows: usize,
        cols: usize,
    },
}

/// Where an array is read from, as messages name it: the file and, in a `.npz`,
/// the array.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ArrayAt {
    pub path: PathBuf,
    pub array: Option<&'static str>,
}

impl std::fmt::Display for ArrayAt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", shown_path(&self.path))?;
        match self.array {
            Some(array) => write!(f, ", array '{array}'"),
            None => Ok(()),
        }
    }
}

/// What an array must be to deform a given mesh with a given cage.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExpectedArray {
    /// One per mesh vertex.
    pub rows: usize,
    pub cols: usize,
    /// What the columns stand for: the cage's "vertices" or "triangles".
    pub columns: &'static str,
    /// Whether each row must sum to 1 ([`check_row_sum`]): true for the weights of
    /// cage vertices, false for Green coordinates' ψ.
    pub rows_sum_to_one: bool,
}

impl ExpectedArray {
    /// One weight per cage vertex, rows summing to 1.
    pub fn cage_vertices(rows: usize, cage_vertices: usize) -> Self {
        Self {
            rows,
            cols: cage_vertices,
            columns: "vertices",
            rows_sum_to_one: true,
        }
    }

    /// The one array of a family whose columns are not all cage vertices'
    /// weights and that writes a .npy: 9 per cage vertex and triangle
    /// (Somigliana blocks; the vertex blocks sum to I, not their entries to 1).
    /// Other layouts: [`Self::cage_vertices`].
    pub fn of_layout(
        layout: crate::coords::family::ColumnLayout,
        rows: usize,
        cage_vertices: usize,
        cage_triangles: usize,
    ) -> Self {
        match layout {
            crate::coords::family::ColumnLayout::BlocksPerVertexThenTriangle => Self {
                rows,
                cols: crate::coords::somigliana::BLOCK_COLUMNS * (cage_vertices + cage_triangles),
                columns: "block columns (9 per vertex and per triangle)",
                rows_sum_to_one: false,
            },
            _ => Self::cage_vertices(rows, cage_vertices),
        }
    }

    fn what_sums(&self) -> &'static str {
        if self.rows_sum_to_one {
            "the weights of the cage vertices"
        } else {
            "this array"
        }
    }
}

/// Write `weights` to `path`.
pub fn write_npy(path: &Path, weights: &Weights) -> Result<(), NpyError> {
    write_npy_to(PendingOutput::create(path)?, path, weights)
}

/// The size of the `.npy` file [`write_npy`] writes for a `rows` × `cols` matrix.
pub fn npy_file_bytes(rows: usize, cols: usize) -> u64 {
    npy_file_bytes_of(rows, cols, Dtype::Float32)
}

/// [`npy_file_bytes`] for values of `dtype`.
pub fn npy_file_bytes_of(rows: usize, cols: usize, dtype: Dtype) -> u64 {
    (npy_header(rows, cols, dtype).len() + 10) as u64
        + dtype.size() as u64 * rows as u64 * cols as u64
}

fn npy_header(rows: usize, cols: usize, dtype: Dtype) -> String {
    let mut header = format!(
        "{{'descr': '{}', 'fortran_order': False, 'shape': ({rows}, {cols}), }}",
        dtype.descr()
    );
    // Magic, version, length and header end on a 64-byte boundary, with a newline.
    let padded = (10 + header.len() + 1).div_ceil(64) * 64 - 10;
    header.extend(std::iter::repeat_n(' ', padded - 1 - header.len()));
    header.push('\n');
    header
}

/// The bytes before the values of a `rows` × `cols` float32 `.npy` file: magic,
/// version, header length and header. For writers that stream the values.
pub fn npy_preamble(path: &Path, rows: usize, cols: usize) -> Result<Vec<u8>, NpyError> {
    npy_preamble_of(path, rows, cols, Dtype::Float32)
}

/// [`npy_preamble`] for values of `dtype`.
pub fn npy_preamble_of(
    path: &Path,
    rows: usize,
    cols: usize,
    dtype: Dtype,
) -> Result<Vec<u8>, NpyError> {
    let header = npy_header(rows, cols, dtype);
    let header_len = u16::try_from(header.len()).map_err(|_| NpyError::HeaderTooLong {
        path: path.to_owned(),
        rows,
        cols,
    })?;
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&header_len.to_le_bytes());
    bytes.extend_from_slice(header.as_bytes());
    Ok(bytes)
}

/// `values` as little-endian float32.
pub fn write_f32_values(out: &mut dyn std::io::Write, values: &[f32]) -> std::io::Result<()> {
    write_values(out, values)
}

/// A value's little-endian bytes, for [`write_values`] and the readers.
pub trait LeBytes: WeightValue + bytemuck::Pod {
    fn extend_le(self, bytes: &mut Vec<u8>);
    fn from_le(bytes: &[u8]) -> Self;
}

impl LeBytes for f32 {
    fn extend_le(self, bytes: &mut Vec<u8>) {
        bytes.extend(self.to_le_bytes());
    }
    fn from_le(bytes: &[u8]) -> Self {
        f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])
    }
}

impl LeBytes for f64 {
    fn extend_le(self, bytes: &mut Vec<u8>) {
        bytes.extend(self.to_le_bytes());
    }
    fn from_le(bytes: &[u8]) -> Self {
        let mut array = [0u8; 8];
        array.copy_from_slice(&bytes[..8]);
        f64::from_le_bytes(array)
    }
}

/// `values` as little-endian float32 or float64.
pub fn write_values<T: LeBytes>(out: &mut dyn std::io::Write, values: &[T]) -> std::io::Result<()> {
    if cfg!(target_endian = "little") {
        // The values' own bytes: one write, past the writer's buffer, with no copy.
        return out.write_all(bytemuck::cast_slice(values));
    }
    // In blocks rather than element by element, which took tens of milliseconds.
    let mut block = Vec::with_capacity(1 << 16);
    for values in values.chunks(1 << 14) {
        block.clear();
        for &value in values {
            value.extend_le(&mut block);
        }
        out.write_all(&block)?;
    }
    Ok(())
}

/// [`write_npy`] into an output opened before the weights were computed.
pub fn write_npy_to(output: PendingOutput, path: &Path, weights: &Weights) -> Result<(), NpyError> {
    let preamble = npy_preamble(path, weights.rows, weights.cols)?;
    output.finish(|out| {
        out.write_all(&preamble)?;
        write_f32_values(out, &weights.values)
    })?;
    Ok(())
}

/// How far a row of cage-vertex weights may sum from 1, as a share of the larger
/// of 1 and the row's Σ|w|. Storing a weight as f32 rounds it by up to 2⁻²⁴ of
/// itself (6e-8), and the GPU kernels sum hundreds of terms in f32: rows bound by
/// pmvc are off by at most 2.6e-6 (GPU MVC; 3.7e-7 on the CPU, harmonic), so 1e-4
/// leaves a margin of 40 while still refusing rows that were never normalised
/// (all zeros, raw MVC sums). In the displacement form a row off by δ moves its
/// vertex by (1 + δ) times a translation of the cage.
pub const ROW_SUM_TOLERANCE: f64 = 1e-4;

/// The sum of `row` and the tolerance it was held to, when it is further from 1
/// than [`ROW_SUM_TOLERANCE`] allows.
pub fn row_sum_off<T: WeightValue>(row: &[T]) -> Option<(f64, f64)> {
    let (sum, magnitude) = row.iter().fold((0.0f64, 0.0f64), |(sum, magnitude), &w| {
        (sum + w.to_f64(), magnitude + w.to_f64().abs())
    });
    let tolerance = ROW_SUM_TOLERANCE * magnitude.max(1.0);
    let off = sum.is_nan() || (sum - 1.0).abs() > tolerance;
    off.then_some((sum, tolerance))
}

/// Read the weights `expected` describes from a `.npy` file (float32, C order,
/// two dimensions), as `pmvc bind` and NumPy's `np.save` write it. The header is
/// checked against `expected` and against the bytes the file holds before the
/// matrix is allocated (and that allocation against the memory available); every
/// value must be finite and, where `expected` says so, every row must sum to 1.
pub fn read_npy(path: &Path, expected: ExpectedArray) -> Result<Weights, NpyError> {
    let values = read_npy_values::<f32>(path, expected)?;
    Ok(Weights {
        rows: expected.rows,
        cols: expected.cols,
        values,
    })
}

/// [`read_npy`] of a float64 file (`'<f8'`), as `pmvc bind --dtype f64` writes it.
pub fn read_npy_f64(path: &Path, expected: ExpectedArray) -> Result<WeightsF64, NpyError> {
    let values = read_npy_values::<f64>(path, expected)?;
    Ok(WeightsF64 {
        rows: expected.rows,
        cols: expected.cols,
        values,
    })
}

fn read_npy_values<T: LeBytes>(path: &Path, expected: ExpectedArray) -> Result<Vec<T>, NpyError> {
    let at = ArrayAt {
        path: path.to_owned(),
        array: None,
    };
    let (file, present) = open(path)?;
    let mut reader = std::io::BufReader::new(file);
    let data_present = read_array_header(&mut reader, present, &at, expected, T::DTYPE)?;
    let mut values = allocate::<T>(&at, expected.rows, expected.cols)?;
    read_values(
        &mut reader,
        &at,
        expected,
        data_present,
        (&mut values, expected.cols),
        0,
    )?;
    Ok(values)
}

/// The file and, for a regular file, its size.
pub(super) fn open(path: &Path) -> Result<(std::fs::File, Option<u64>), NpyError> {
    let read_error = |source| NpyError::Read {
        path: path.to_owned(),
        source,
    };
    let file = std::fs::File::open(path).map_err(read_error)?;
    let metadata = file.metadata().map_err(read_error)?;
    if metadata.is_dir() {
        return Err(read_error(std::io::Error::other(
            "it is a folder, not a file",
        )));
    }
    Ok((file, metadata.is_file().then_some(metadata.len())))
}

/// Read the header of an array of `dtype` whose stream holds `present` bytes
/// (when known) and check it against `expected`; returns the bytes of values
/// present.
pub(super) fn read_array_header(
    reader: &mut impl Read,
    present: Option<u64>,
    at: &ArrayAt,
    expected: ExpectedArray,
    dtype: Dtype,
) -> Result<Option<u64>, NpyError> {
    let header = read_header(reader, present).map_err(|source| NpyError::Header {
        at: at.clone(),
        source,
    })?;
    let data_present = present.map(|present| present.saturating_sub(header.data_offset));
    check_header(&header, at, expected, data_present, dtype)?;
    Ok(data_present)
}

fn check_header(
    header: &NpyHeader,
    at: &ArrayAt,
    expected: ExpectedArray,
    data_present: Option<u64>,
    dtype: Dtype,
) -> Result<(), NpyError> {
    let at = || at.clone();
    if header.descr != dtype.descr() {
        return Err(match dtype {
            Dtype::Float32 => NpyError::Dtype {
                at: at(),
                dtype: header.descr.clone(),
            },
            Dtype::Float64 => NpyError::DtypeOf {
                at: at(),
                dtype: header.descr.clone(),
                expected: dtype,
            },
        });
    }
    if header.fortran_order {
        return Err(NpyError::FortranOrder { at: at() });
    }
    let [rows, cols] = header.shape[..] else {
        return Err(NpyError::Shape {
            at: at(),
            shape: header.shape.clone(),
        });
    };
    if (rows, cols) != (expected.rows as u64, expected.cols as u64) {
        return Err(NpyError::ShapeMismatch {
            at: at(),
            declared: header.shape.clone(),
            expected,
        });
    }
    let needed = value_bytes(expected.rows, expected.cols, dtype);
    let (rows, cols) = (expected.rows, expected.cols);
    match data_present {
        Some(present) if present < needed => Err(NpyError::Truncated {
            at: at(),
            rows,
            cols,
            needed,
            present,
            dtype,
        }),
        Some(present) if present > needed => Err(NpyError::TrailingBytes {
            at: at(),
            rows,
            cols,
            needed,
            present: Some(present),
        }),
        _ => Ok(()),
    }
}

fn value_bytes(rows: usize, cols: usize, dtype: Dtype) -> u64 {
    bytes_for(rows as u64, bytes_for(cols as u64, dtype.size() as u64))
}

/// A zero matrix of `rows` × `cols` values, once the memory for it is known to
/// be there.
pub(super) fn allocate<T: WeightValue>(
    at: &ArrayAt,
    rows: usize,
    cols: usize,
) -> Result<Vec<T>, NpyError> {
    check_memory(
        || format!("the weights ({rows} × {cols} {})", T::DTYPE.id()),
        value_bytes(rows, cols, T::DTYPE),
    )
    .map_err(|source| NpyError::TooLarge {
        at: at.clone(),
        source,
    })?;
    Ok(vec![T::default(); rows * cols])
}

/// Read the values of an array whose header [`read_array_header`] accepted into
/// columns `first_column..` of a row-major matrix (its values and its number of
/// columns), row by row, checking each value and
/// (where `expected` says so) each row's sum.
pub(super) fn read_values<T: LeBytes>(
    reader: &mut impl Read,
    at: &ArrayAt,
    expected: ExpectedArray,
    data_present: Option<u64>,
    (values, total_cols): (&mut [T], usize),
    first_column: usize,
) -> Result<(), NpyError> {
    let (rows, cols) = (expected.rows, expected.cols);
    let dtype = T::DTYPE;
    let size = dtype.size();
    let read_error = |source| NpyError::Read {
        path: at.path.clone(),
        source,
    };
    let mut buffer = vec![0u8; cols * size];
    // Rows of no columns hold nothing to read (and may be many); an empty row
    // that must sum to 1 is refused at the first.
    let rows_to_read = if cols == 0 && !expected.rows_sum_to_one {
        0
    } else {
        rows
    };
    for row in 0..rows_to_read {
        let filled = read_fully(reader, &mut buffer).map_err(read_error)?;
        if filled < buffer.len() {
            return Err(NpyError::Truncated {
                at: at.clone(),
                rows,
                cols,
                needed: value_bytes(rows, cols, dtype),
                present: value_bytes(row, cols, dtype) + filled as u64,
                dtype,
            });
        }
        let start = row * total_cols + first_column;
        let out = &mut values[start..start + cols];
        for (column, (value, bytes)) in out.iter_mut().zip(buffer.chunks_exact(size)).enumerate() {
            *value = T::from_le(bytes);
            if !value.to_f64().is_finite() {
                return Err(NpyError::NonFinite {
                    at: at.clone(),
                    row: row + 1,
                    column: column + 1,
                    value: value.to_f64(),
                });
            }
        }
        if let Some((sum, tolerance)) = row_sum_off(out).filter(|_| expected.rows_sum_to_one) {
            return Err(NpyError::RowSum {
                at: at.clone(),
                row: row + 1,
                sum,
                tolerance,
                expected,
            });
        }
    }
    // A stream whose size was not known, or that grew, is refused as well.
    if read_fully(reader, &mut [0u8; 1]).map_err(read_error)? > 0 {
        return Err(NpyError::TrailingBytes {
            at: at.clone(),
            rows,
            cols,
            needed: value_bytes(rows, cols, dtype),
            present: data_present,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests;

//! Weights as NumPy `.npy` files (version 1, little-endian float32, C order,
//! shape (rows, columns)): what `pmvc bind` writes and `pmvc deform --weights`
//! reads. Writing goes through a temporary file that is renamed over the target.

use super::Weights;
use crate::geometry::{PendingOutput, WriteError};
use std::path::{Path, PathBuf};

/// A weights file could not be written or read. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum NpyError {
    #[error(transparent)]
    Write(#[from] WriteError),
    #[error("{path}: cannot read: {source}", path = path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: not a .npy file: {source}", path = path.display())]
    NotNpy {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: expected a 2-D weights array, found shape {shape:?}", path = path.display())]
    Shape { path: PathBuf, shape: Vec<u64> },
    #[error("{path}: expected C (row-major) order", path = path.display())]
    FortranOrder { path: PathBuf },
    #[error("{path}: expected float32 weights, found dtype {dtype}", path = path.display())]
    Dtype { path: PathBuf, dtype: String },
    #[error("{path}: not a .npz archive: {source}", path = path.display())]
    NotNpz {
        path: PathBuf,
        source: zip::result::ZipError,
    },
    #[error("{path}: has no array '{name}' (it holds: {found})", path = path.display())]
    MissingArray {
        path: PathBuf,
        name: &'static str,
        found: String,
    },
    #[error("{path}: 'phi' has {phi_rows} rows but 'psi' has {psi_rows}; both need one row per mesh vertex", path = path.display())]
    RowMismatch {
        path: PathBuf,
        phi_rows: usize,
        psi_rows: usize,
    },
    #[error("{path}: shape ({rows}, {cols}) is too long for a .npy header", path = path.display())]
    HeaderTooLong {
        path: PathBuf,
        rows: usize,
        cols: usize,
    },
}

/// Write `weights` to `path`.
pub fn write_npy(path: &Path, weights: &Weights) -> Result<(), NpyError> {
    write_npy_to(PendingOutput::create(path)?, path, weights)
}

/// The size of the `.npy` file [`write_npy`] writes for a `rows` × `cols` matrix.
pub fn npy_file_bytes(rows: usize, cols: usize) -> u64 {
    (npy_header(rows, cols).len() + 10) as u64 + 4 * rows as u64 * cols as u64
}

fn npy_header(rows: usize, cols: usize) -> String {
    let mut header =
        format!("{{'descr': '<f4', 'fortran_order': False, 'shape': ({rows}, {cols}), }}");
    // Magic, version, length and header end on a 64-byte boundary, with a newline.
    let padded = (10 + header.len() + 1).div_ceil(64) * 64 - 10;
    header.extend(std::iter::repeat_n(' ', padded - 1 - header.len()));
    header.push('\n');
    header
}

/// The bytes before the values of a `rows` × `cols` float32 `.npy` file: magic,
/// version, header length and header. For writers that stream the values.
pub fn npy_preamble(path: &Path, rows: usize, cols: usize) -> Result<Vec<u8>, NpyError> {
    let header = npy_header(rows, cols);
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
    // In blocks rather than element by element, which took tens of milliseconds.
    let mut block = Vec::with_capacity(1 << 16);
    for values in values.chunks(1 << 14) {
        block.clear();
        block.extend(values.iter().flat_map(|v| v.to_le_bytes()));
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

/// Read weights written by [`write_npy`] (or NumPy): float32, C order, two dimensions.
pub fn read_npy(path: &Path) -> Result<Weights, NpyError> {
    let file = std::fs::File::open(path).map_err(|source| NpyError::Read {
        path: path.to_owned(),
        source,
    })?;
    read_npy_from(std::io::BufReader::new(file), path)
}

/// [`read_npy`] from any reader (an archive's entry); `path` names it in errors.
pub(super) fn read_npy_from(reader: impl std::io::Read, path: &Path) -> Result<Weights, NpyError> {
    let npy = npyz::NpyFile::new(reader).map_err(|source| NpyError::NotNpy {
        path: path.to_owned(),
        source,
    })?;
    let shape = npy.shape().to_vec();
    let [rows, cols] = shape[..] else {
        return Err(NpyError::Shape {
            path: path.to_owned(),
            shape,
        });
    };
    if npy.order() != npyz::Order::C {
        return Err(NpyError::FortranOrder {
            path: path.to_owned(),
        });
    }
    let dtype = npy.dtype().descr();
    let values: Vec<f32> = npy.into_vec().map_err(|_| NpyError::Dtype {
        path: path.to_owned(),
        dtype,
    })?;
    Ok(Weights {
        rows: rows as usize,
        cols: cols as usize,
        values,
    })
}

//! Green coordinates as a NumPy `.npz` archive, what `pmvc bind --method green`
//! writes and `pmvc deform --weights` reads: two float32 arrays in C order
//! (float64 with `--dtype f64`),
//! `phi` (points × cage vertices) and `psi` (points × cage triangles, in the order
//! the cage's faces are triangulated, [`crate::geometry::Cage::triangles`]).
//! Entries are stored uncompressed, as `numpy.savez` writes them; `np.load` reads
//! the file. In memory the two are one [`Weights`] matrix, φ columns then ψ.

use super::npy::{
    allocate, npy_preamble_of, open, read_array_header, read_values, write_values, ArrayAt,
    ExpectedArray, LeBytes, NpyError,
};
use crate::coords::{Dtype, Weights, WeightsF64};
use crate::formats::{PendingOutput, WriteSeek};
use std::io::{Read, Seek, Write as _};
use std::path::Path;

/// The archive's array names.
pub const PHI: &str = "phi";
pub const PSI: &str = "psi";

/// The size of the archive [`write_npz_to`] writes, less the zip headers (a few
/// hundred bytes): for the free-space check.
pub fn npz_payload_bytes(rows: usize, cols: usize) -> u64 {
    npz_payload_bytes_of(rows, cols, Dtype::Float32)
}

/// [`npz_payload_bytes`] for values of `dtype`.
pub fn npz_payload_bytes_of(rows: usize, cols: usize, dtype: Dtype) -> u64 {
    super::npy::npy_file_bytes_of(rows, cols, dtype)
}

/// Write `weights` (φ in the first `vertex_columns` columns, ψ after them) as the
/// arrays `phi` and `psi` into an output opened before the bind.
pub fn write_npz_to(
    output: PendingOutput,
    path: &Path,
    weights: &Weights,
    vertex_columns: usize,
) -> Result<(), NpyError> {
    // The preambles are checked before anything is written.
    npz_preambles(
        path,
        weights.rows,
        weights.cols,
        vertex_columns,
        Dtype::Float32,
    )?;
    output.finish_seekable(|out| write_npz(out, path, weights, vertex_columns))?;
    Ok(())
}

/// The two arrays' names, column ranges and `.npy` preambles.
type NpzParts = [(&'static str, std::ops::Range<usize>, Vec<u8>); 2];

fn npz_preambles(
    path: &Path,
    rows: usize,
    cols: usize,
    vertex_columns: usize,
    dtype: Dtype,
) -> Result<NpzParts, NpyError> {
    let vertex_columns = vertex_columns.min(cols);
    let phi = 0..vertex_columns;
    let psi = vertex_columns..cols;
    Ok([
        (
            PHI,
            phi.clone(),
            npy_preamble_of(path, rows, phi.len(), dtype)?,
        ),
        (
            PSI,
            psi.clone(),
            npy_preamble_of(path, rows, psi.len(), dtype)?,
        ),
    ])
}

/// The archive's bytes, written into `out` (which the zip writer seeks back in).
pub fn write_npz(
    out: &mut dyn WriteSeek,
    path: &Path,
    weights: &Weights,
    vertex_columns: usize,
) -> std::io::Result<()> {
    write_npz_values(out, path, (&weights.values, weights.cols), vertex_columns)
}

/// [`write_npz`] of a row-major matrix of either dtype, given as its values and
/// its number of columns.
pub fn write_npz_values<T: LeBytes>(
    out: &mut dyn WriteSeek,
    path: &Path,
    (values, cols): (&[T], usize),
    vertex_columns: usize,
) -> std::io::Result<()> {
    let rows = values.len() / cols.max(1);
    let parts =
        npz_preambles(path, rows, cols, vertex_columns, T::DTYPE).map_err(std::io::Error::other)?;
    let mut zip = zip::ZipWriter::new(out);
    for (name, columns, preamble) in &parts {
        let bytes = preamble.len() as u64 + (T::DTYPE.size() * rows * columns.len()) as u64;
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored)
            .large_file(bytes >= u64::from(u32::MAX));
        zip.start_file(format!("{name}.npy"), options)
            .map_err(std::io::Error::other)?;
        zip.write_all(preamble)?;
        // Row by row: each array is a column range of the joint matrix.
        for row in values.chunks(cols.max(1)).take(rows) {
            write_values(&mut zip, &row[columns.clone()])?;
        }
    }
    zip.finish().map_err(std::io::Error::other)?;
    Ok(())
}

/// Read the Green coordinates of `rows` mesh vertices in a cage of
/// `cage_vertices` vertices and `cage_triangles` triangles from an archive written
/// by [`write_npz_to`] (or `numpy.savez(path, phi=…, psi=…)`), as one matrix, φ
/// columns then ψ. Both arrays' headers are checked against those sizes and the
/// bytes the archive holds before the matrix is allocated; values must be finite
/// and each row of φ must sum to 1 (as for [`super::npy::read_npy`]).
pub fn read_npz(
    path: &Path,
    rows: usize,
    cage_vertices: usize,
    cage_triangles: usize,
) -> Result<Weights, NpyError> {
    let values = read_npz_values::<f32>(path, rows, cage_vertices, cage_triangles)?;
    Ok(Weights {
        rows,
        cols: cage_vertices + cage_triangles,
        values,
    })
}

/// [`read_npz`] of float64 arrays, as `pmvc bind --dtype f64` writes them.
pub fn read_npz_f64(
    path: &Path,
    rows: usize,
    cage_vertices: usize,
    cage_triangles: usize,
) -> Result<WeightsF64, NpyError> {
    let values = read_npz_values::<f64>(path, rows, cage_vertices, cage_triangles)?;
    Ok(WeightsF64 {
        rows,
        cols: cage_vertices + cage_triangles,
        values,
    })
}

fn read_npz_values<T: LeBytes>(
    path: &Path,
    rows: usize,
    cage_vertices: usize,
    cage_triangles: usize,
) -> Result<Vec<T>, NpyError> {
    let (file, file_bytes) = open(path)?;
    let mut archive =
        zip::ZipArchive::new(std::io::BufReader::new(file)).map_err(|source| NpyError::NotNpz {
            path: path.to_owned(),
            source,
        })?;
    let arrays = [
        (PHI, ExpectedArray::cage_vertices(rows, cage_vertices), 0),
        (
            PSI,
            ExpectedArray {
                rows,
                cols: cage_triangles,
                columns: "triangles",
                rows_sum_to_one: false,
            },
            cage_vertices,
        ),
    ];
    let at = |name| ArrayAt {
        path: path.to_owned(),
        array: Some(name),
    };
    // Both headers before anything is allocated.
    for (name, expected, _) in arrays {
        let (mut entry, present) = open_entry(&mut archive, path, name, file_bytes)?;
        read_array_header(&mut entry, present, &at(name), expected, T::DTYPE)?;
    }
    let whole = ArrayAt {
        path: path.to_owned(),
        array: None,
    };
    let columns = cage_vertices + cage_triangles;
    let mut values = allocate::<T>(&whole, rows, columns)?;
    for (name, expected, first_column) in arrays {
        let (mut entry, present) = open_entry(&mut archive, path, name, file_bytes)?;
        let mut entry = std::io::BufReader::new(&mut entry);
        let data_present = read_array_header(&mut entry, present, &at(name), expected, T::DTYPE)?;
        read_values(
            &mut entry,
            &at(name),
            expected,
            data_present,
            (&mut values, columns),
            first_column,
        )?;
    }
    Ok(values)
}

/// The entry `name`.npy, stored (not compressed), and the bytes it holds: the
/// least of its declared sizes and what the archive has after its start.
fn open_entry<'a, R: Read + Seek>(
    archive: &'a mut zip::ZipArchive<R>,
    path: &Path,
    name: &'static str,
    file_bytes: Option<u64>,
) -> Result<(zip::read::ZipFile<'a, R>, Option<u64>), NpyError> {
    let not_npz = |source| NpyError::NotNpz {
        path: path.to_owned(),
        source,
    };
    let Some(index) = archive.index_for_name(&format!("{name}.npy")) else {
        return Err(NpyError::MissingArray {
            path: path.to_owned(),
            name,
            found: archive_names(archive),
        });
    };
    let compression = archive.by_index_raw(index).map_err(not_npz)?.compression();
    if compression != zip::CompressionMethod::Stored {
        return Err(NpyError::Compressed {
            at: ArrayAt {
                path: path.to_owned(),
                array: Some(name),
            },
        });
    }
    let entry = archive.by_index(index).map_err(not_npz)?;
    let in_archive = file_bytes.map(|bytes| bytes.saturating_sub(entry.data_start()));
    let present = entry
        .size()
        .min(entry.compressed_size())
        .min(in_archive.unwrap_or(u64::MAX));
    Ok((entry, Some(present)))
}

/// The archive's entries as a message lists them: escaped, without `.npy`, the
/// first few.
fn archive_names<R: Read + Seek>(archive: &zip::ZipArchive<R>) -> String {
    const SHOWN: usize = 8;
    let mut names: Vec<String> = archive
        .file_names()
        .map(|name| {
            let name = name.strip_suffix(".npy").unwrap_or(name);
            name.chars()
                .take(64)
                .collect::<String>()
                .escape_debug()
                .to_string()
        })
        .collect();
    names.sort();
    match names.len() {
        0 => "nothing".to_owned(),
        n if n > SHOWN => format!("{} and {} more", names[..SHOWN].join(", "), n - SHOWN),
        _ => names.join(", "),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phi_and_psi_round_trip_as_two_arrays() {
        let folder = tempfile::tempdir().expect("temporary folder");
        let path = folder.path().join("w.npz");
        let weights = Weights {
            rows: 2,
            cols: 5,
            values: vec![0.25, 0.25, 0.5, 7.0, -3.0, 1.5, -1.0, 0.5, 0.125, 2.0],
        };
        write_npz_to(
            PendingOutput::create(&path).expect("output"),
            &path,
            &weights,
            3,
        )
        .expect("written");
        assert_eq!(read_npz(&path, 2, 3, 2).expect("read back"), weights);
    }

    #[test]
    fn a_missing_array_is_named_with_what_the_archive_holds() {
        let folder = tempfile::tempdir().expect("temporary folder");
        let path = folder.path().join("w.npz");
        let file = std::fs::File::create(&path).expect("create");
        let mut zip = zip::ZipWriter::new(file);
        zip.start_file("phi.npy", zip::write::SimpleFileOptions::default())
            .expect("entry");
        zip.write_all(&npy_preamble_of(&path, 1, 1, Dtype::Float32).expect("preamble"))
            .expect("write");
        zip.write_all(&1f32.to_le_bytes()).expect("write");
        zip.start_file("weights.npy", zip::write::SimpleFileOptions::default())
            .expect("entry");
        zip.finish().expect("finish");
        let message = read_npz(&path, 1, 1, 1).expect_err("no psi").to_string();
        assert!(
            message.contains("no array 'psi'") && message.contains("phi, weights"),
            "{message}"
        );
    }

    #[test]
    fn a_file_that_is_not_a_zip_is_refused_by_name() {
        let folder = tempfile::tempdir().expect("temporary folder");
        let path = folder.path().join("w.npz");
        std::fs::write(&path, b"\x93NUMPY not a zip").expect("write");
        let message = read_npz(&path, 1, 4, 4).expect_err("not a zip").to_string();
        assert!(
            message.contains("w.npz") && message.contains("not a .npz archive"),
            "{message}"
        );
    }
}

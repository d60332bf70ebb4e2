//! Green coordinates as a NumPy `.npz` archive, what `pmvc bind --method green`
//! writes and `pmvc deform --weights` reads: two float32 arrays in C order,
//! `phi` (points × cage vertices) and `psi` (points × cage triangles, in the order
//! the cage's faces are triangulated, [`crate::geometry::Cage::triangles`]).
//! Entries are stored uncompressed, as `numpy.savez` writes them; `np.load` reads
//! the file. In memory the two are one [`Weights`] matrix, φ columns then ψ.

use super::npy::{
    allocate, npy_preamble, open, read_array_header, read_values, write_f32_values, ArrayAt,
    ExpectedArray, NpyError,
};
use crate::coords::Weights;
use crate::formats::{PendingOutput, WriteSeek};
use std::io::{Read, Seek, Write as _};
use std::path::Path;

/// The archive's array names.
pub const PHI: &str = "phi";
pub const PSI: &str = "psi";

/// The size of the archive [`write_npz_to`] writes, less the zip headers (a few
/// hundred bytes): for the free-space check.
pub fn npz_payload_bytes(rows: usize, cols: usize) -> u64 {
    super::npy::npy_file_bytes(rows, cols)
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
    npz_preambles(path, weights, vertex_columns)?;
    output.finish_seekable(|out| write_npz(out, path, weights, vertex_columns))?;
    Ok(())
}

/// The two arrays' names, column ranges and `.npy` preambles.
type NpzParts = [(&'static str, std::ops::Range<usize>, Vec<u8>); 2];

fn npz_preambles(
    path: &Path,
    weights: &Weights,
    vertex_columns: usize,
) -> Result<NpzParts, NpyError> {
    let vertex_columns = vertex_columns.min(weights.cols);
    let phi = 0..vertex_columns;
    let psi = vertex_columns..weights.cols;
    Ok([
        (
            PHI,
            phi.clone(),
            npy_preamble(path, weights.rows, phi.len())?,
        ),
        (
            PSI,
            psi.clone(),
            npy_preamble(path, weights.rows, psi.len())?,
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
    let parts = npz_preambles(path, weights, vertex_columns).map_err(std::io::Error::other)?;
    let mut zip = zip::ZipWriter::new(out);
    for (name, columns, preamble) in &parts {
        let bytes = preamble.len() as u64 + 4 * (weights.rows * columns.len()) as u64;
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored)
            .large_file(bytes >= u64::from(u32::MAX));
        zip.start_file(format!("{name}.npy"), options)
            .map_err(std::io::Error::other)?;
        zip.write_all(preamble)?;
        // Row by row: each array is a column range of the joint matrix.
        for row in weights
            .values
            .chunks(weights.cols.max(1))
            .take(weights.rows)
        {
            write_f32_values(&mut zip, &row[columns.clone()])?;
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
/// and each row of φ must sum to 1 (as for [`read_npy`]).
pub fn read_npz(
    path: &Path,
    rows: usize,
    cage_vertices: usize,
    cage_triangles: usize,
) -> Result<Weights, NpyError> {
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
        read_array_header(&mut entry, present, &at(name), expected)?;
    }
    let whole = ArrayAt {
        path: path.to_owned(),
        array: None,
    };
    let mut weights = allocate(&whole, rows, cage_vertices + cage_triangles)?;
    for (name, expected, first_column) in arrays {
        let (mut entry, present) = open_entry(&mut archive, path, name, file_bytes)?;
        let mut entry = std::io::BufReader::new(&mut entry);
        let data_present = read_array_header(&mut entry, present, &at(name), expected)?;
        read_values(
            &mut entry,
            &at(name),
            expected,
            data_present,
            &mut weights,
            first_column,
        )?;
    }
    Ok(weights)
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
        zip.write_all(&npy_preamble(&path, 1, 1).expect("preamble"))
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

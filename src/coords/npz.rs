//! Green coordinates as a NumPy `.npz` archive, what `pmvc bind --method green`
//! writes and `pmvc deform --weights` reads: two float32 arrays in C order,
//! `phi` (points × cage vertices) and `psi` (points × cage triangles, in the order
//! the cage's faces are triangulated, [`crate::geometry::Cage::triangles`]).
//! Entries are stored uncompressed, as `numpy.savez` writes them; `np.load` reads
//! the file. In memory the two are one [`Weights`] matrix, φ columns then ψ.

use super::npy::{npy_preamble, read_npy_from, write_f32_values, NpyError};
use super::Weights;
use crate::geometry::PendingOutput;
use std::io::Write as _;
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
    let vertex_columns = vertex_columns.min(weights.cols);
    let parts = [
        (PHI, 0..vertex_columns),
        (PSI, vertex_columns..weights.cols),
    ];
    let mut preambles = Vec::new();
    for (_, columns) in &parts {
        preambles.push(npy_preamble(path, weights.rows, columns.len())?);
    }
    output.finish_seekable(|out| {
        let mut zip = zip::ZipWriter::new(out);
        for ((name, columns), preamble) in parts.iter().zip(&preambles) {
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
    })?;
    Ok(())
}

/// Read an archive written by [`write_npz_to`] (or `numpy.savez(path, phi=…,
/// psi=…)`) into one matrix, φ columns then ψ; also returns φ's column count.
pub fn read_npz(path: &Path) -> Result<(Weights, usize), NpyError> {
    let file = std::fs::File::open(path).map_err(|source| NpyError::Read {
        path: path.to_owned(),
        source,
    })?;
    let mut archive =
        zip::ZipArchive::new(std::io::BufReader::new(file)).map_err(|source| NpyError::NotNpz {
            path: path.to_owned(),
            source,
        })?;
    let names = archive_names(&archive);
    let found = if names.is_empty() {
        "nothing".to_owned()
    } else {
        names.join(", ")
    };
    let mut read = |name: &'static str| -> Result<Weights, NpyError> {
        let missing = NpyError::MissingArray {
            path: path.to_owned(),
            name,
            found: found.clone(),
        };
        let entry = match archive.by_name(&format!("{name}.npy")) {
            Ok(entry) => entry,
            Err(zip::result::ZipError::FileNotFound) => return Err(missing),
            Err(source) => {
                return Err(NpyError::NotNpz {
                    path: path.to_owned(),
                    source,
                })
            }
        };
        read_npy_from(std::io::BufReader::new(entry), &path.join(name))
    };
    let phi = read("phi")?;
    let psi = read("psi")?;
    if phi.rows != psi.rows {
        return Err(NpyError::RowMismatch {
            path: path.to_owned(),
            phi_rows: phi.rows,
            psi_rows: psi.rows,
        });
    }
    Ok((join_columns(&phi, &psi), phi.cols))
}

fn archive_names<R: std::io::Read + std::io::Seek>(archive: &zip::ZipArchive<R>) -> Vec<String> {
    let mut names: Vec<String> = archive
        .file_names()
        .map(|name| name.strip_suffix(".npy").unwrap_or(name).to_owned())
        .collect();
    names.sort();
    names
}

/// Rows of `left` followed by the same rows of `right`.
fn join_columns(left: &Weights, right: &Weights) -> Weights {
    let cols = left.cols + right.cols;
    let mut values = Vec::with_capacity(left.rows * cols);
    for row in 0..left.rows {
        values.extend_from_slice(left.row(row));
        values.extend_from_slice(right.row(row));
    }
    Weights {
        rows: left.rows,
        cols,
        values,
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
            values: (0..10).map(|v| v as f32 * 0.5 - 1.0).collect(),
        };
        write_npz_to(
            PendingOutput::create(&path).expect("output"),
            &path,
            &weights,
            3,
        )
        .expect("written");
        let (read, vertex_columns) = read_npz(&path).expect("read back");
        assert_eq!((read.clone(), vertex_columns), (weights, 3));
        // Each array on its own, as NumPy sees it.
        let file = std::fs::File::open(&path).expect("open");
        let mut archive = zip::ZipArchive::new(file).expect("a zip");
        let psi = read_npy_from(archive.by_name("psi.npy").expect("psi"), &path).expect("npy");
        assert_eq!((psi.rows, psi.cols), (2, 2));
        assert_eq!(psi.values, [0.5, 1.0, 3.0, 3.5]);
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
        let message = read_npz(&path).expect_err("no psi").to_string();
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
        let message = read_npz(&path).expect_err("not a zip").to_string();
        assert!(
            message.contains("w.npz") && message.contains("not a .npz archive"),
            "{message}"
        );
    }
}

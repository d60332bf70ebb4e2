//! Bad input, one test per case, through the real binary: each fails with exit
//! status 1 and one error line naming the file and what is wrong, never a panic.

use crate::common;
use common::*;

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

fn bind_with_cage(cage_text: &str, name: &str) -> (std::process::Output, String) {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "mesh.obj", "v 0.1 0.1 0.1\n");
    let cage = write(dir.path(), name, cage_text);
    let out = dir.path().join("w.npy");
    let output = pmvc(&[
        "bind",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage),
        "--out",
        path_str(&out),
    ]);
    assert_eq!(
        out.exists(),
        output.status.success(),
        "output is written exactly when the command succeeds"
    );
    (output, cage.display().to_string())
}

#[test]
fn missing_file() {
    let (output, _) = bind_with_cage(TETRA, "cage.obj");
    assert!(
        output.status.success(),
        "the valid tetrahedron binds: {}",
        stderr(&output)
    );
    let output = pmvc(&[
        "bind",
        "--mesh",
        "/nonexistent/mesh.obj",
        "--cage",
        "/nonexistent/cage.obj",
        "--out",
        "/tmp/never.npy",
    ]);
    assert_clean_failure(&output, "/nonexistent/mesh.obj", "cannot read");
}

#[test]
fn empty_file() {
    let (output, cage) = bind_with_cage("", "cage.obj");
    assert_clean_failure(&output, &cage, "empty");
}

#[test]
fn binary_garbage() {
    let garbage: String = (0..512u32)
        .map(|i| char::from_u32(i % 7).unwrap())
        .collect();
    let (output, cage) = bind_with_cage(&garbage, "cage.obj");
    assert_clean_failure(&output, &cage, "binary");
}

#[test]
fn open_cage() {
    let open = TETRA.replace("f 2 3 4\n", "");
    let (output, cage) = bind_with_cage(&open, "cage.obj");
    assert_clean_failure(&output, &cage, "not closed");
}

#[test]
fn non_manifold_cage() {
    // A second tetrahedron hung on edge 1–2 of the first: that edge has four faces.
    let text = format!("{TETRA}v 0 -1 0\nv 0 0 -1\nf 1 5 2\nf 1 2 6\nf 1 6 5\nf 2 5 6\n");
    let (output, cage) = bind_with_cage(&text, "cage.obj");
    assert_clean_failure(&output, &cage, "not edge-manifold");
}

#[test]
fn inconsistent_orientation() {
    let text = TETRA.replace("f 2 3 4\n", "f 2 4 3\n");
    let (output, cage) = bind_with_cage(&text, "cage.obj");
    assert_clean_failure(&output, &cage, "oriented inconsistently");
}

#[test]
fn nan_coordinate() {
    let text = TETRA.replace("v 0 0 1\n", "v 0 nan 1\n");
    let (output, cage) = bind_with_cage(&text, "cage.obj");
    assert_clean_failure(&output, &cage, "non-finite");
    assert!(
        stderr(&output).contains(":4:"),
        "names the line: {}",
        stderr(&output)
    );
}

#[test]
fn face_index_out_of_range() {
    let text = TETRA.replace("f 2 3 4\n", "f 2 3 9\n");
    let (output, cage) = bind_with_cage(&text, "cage.obj");
    assert_clean_failure(&output, &cage, "face 4 refers to vertex 9");
}

#[test]
fn degenerate_triangle() {
    // A fifth vertex on edge 1–2 makes face 4 a zero-area sliver.
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 0.5 0 0\nf 1 3 2\nf 1 5 4\nf 5 2 4\nf 1 4 3\nf 2 3 4\nf 1 2 5\n";
    let (output, cage) = bind_with_cage(text, "cage.obj");
    assert_clean_failure(&output, &cage, "degenerate");
}

#[test]
fn too_few_cage_vertices() {
    let (output, cage) =
        bind_with_cage("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 2\n", "cage.obj");
    assert_clean_failure(&output, &cage, "at least 4 vertices");
}

#[test]
fn off_parse_error_names_the_line() {
    let (output, cage) = bind_with_cage("OFF\n4 4 0\n0 0 0\n1 0 0\n0 one 0\n0 0 1\n", "cage.off");
    assert_clean_failure(&output, &cage, ":5:");
}

#[test]
fn deformed_cage_with_another_vertex_count() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "mesh.obj", "v 0.1 0.1 0.1\n");
    let cage = write(dir.path(), "cage.obj", TETRA);
    let pose = write(dir.path(), "pose.obj", &format!("{TETRA}v 2 2 2\n"));
    let out = dir.path().join("out.obj");
    let output = deform_with(&mesh, &cage, &pose, &out, &[]);
    assert_clean_failure(&output, path_str(&pose), "has 5 vertices, but the cage");
    assert!(!out.exists());
}

#[test]
fn existing_output_survives_a_failure_and_is_replaced_on_success() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "mesh.obj", "v 0.1 0.1 0.1\n");
    let good = write(dir.path(), "good.obj", TETRA);
    let bad = write(dir.path(), "bad.obj", &TETRA.replace("f 2 3 4\n", ""));
    let out = write(dir.path(), "w.npy", "precious");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o640)).unwrap();
    }
    let output = pmvc(&[
        "bind",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&bad),
        "--out",
        path_str(&out),
    ]);
    assert_clean_failure(&output, path_str(&bad), "not closed");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "precious");
    // A missing output folder fails before anything is written, too.
    let output = pmvc(&[
        "bind",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&good),
        "--out",
        "/nonexistent/dir/w.npy",
    ]);
    assert_clean_failure(&output, "/nonexistent/dir/w.npy", "cannot write");
    let output = pmvc(&[
        "bind",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&good),
        "--out",
        path_str(&out),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(std::fs::read(&out).unwrap().starts_with(b"\x93NUMPY"));
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&out).unwrap().permissions().mode() & 0o777;
        assert_eq!(
            mode, 0o640,
            "the replaced file keeps its permissions, got {mode:o}"
        );
    }
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left behind");
}

#[test]
fn strict_rejects_vertices_outside_the_cage() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "mesh.obj", "v 0.1 0.1 0.1\nv 5 5 5\n");
    let cage = write(dir.path(), "cage.obj", TETRA);
    let out = dir.path().join("w.npy");
    let args = [
        "bind",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage),
        "--out",
        path_str(&out),
    ];
    let output = pmvc(&args);
    assert!(output.status.success());
    assert!(
        stderr(&output).contains("1 of 2 vertices (50.00%) lie outside the cage (first: 1)"),
        "{}",
        stderr(&output)
    );
    std::fs::remove_file(&out).unwrap();
    let output = pmvc(&[&args[..], &["--strict"]].concat());
    assert_clean_failure(&output, path_str(&mesh), "lie outside the cage");
    assert!(!out.exists());
}

/// A `.npy` of float32 values under the header NumPy would write for `shape`.
fn npy_bytes(shape: &str, values: &[f32]) -> Vec<u8> {
    let header = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {shape}, }}\n");
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.as_bytes());
    bytes.extend(values.iter().flat_map(|v| v.to_le_bytes()));
    bytes
}

/// A `.npz` as `numpy.savez` writes it: stored entries `phi.npy` and `psi.npy`.
fn npz_bytes(phi: &[u8], psi: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for (name, bytes) in [("phi.npy", phi), ("psi.npy", psi)] {
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored);
        zip.start_file(name, options).unwrap();
        zip.write_all(bytes).unwrap();
    }
    zip.finish().unwrap().into_inner()
}

/// `pmvc deform` of two points inside the tetrahedron, three of its corners moved,
/// with the weights file `name` holding `bytes`: its output, the weights' path
/// and whether the deformed mesh was written.
fn deform_with_weights(name: &str, bytes: &[u8]) -> (std::process::Output, String, bool) {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "mesh.obj", "v 0.1 0.1 0.1\nv 0.2 0.3 0.1\n");
    let cage = write(dir.path(), "cage.obj", TETRA);
    let pose = write(dir.path(), "pose.obj", &TETRA.replace("v 0 ", "v 2 "));
    let weights = dir.path().join(name);
    std::fs::write(&weights, bytes).unwrap();
    let out = dir.path().join("out.obj");
    let output = common::deform_with_weights(&mesh, &cage, &pose, &weights, &out);
    (output, weights.display().to_string(), out.exists())
}

/// Weights of the two points in [`deform_with_weights`]: rows that sum to 1.
const GOOD_ROWS: [f32; 8] = [0.7, 0.1, 0.1, 0.1, 0.4, 0.1, 0.4, 0.1];

#[test]
fn weights_as_written_deform_the_mesh() {
    let (output, _, written) = deform_with_weights("w.npy", &npy_bytes("(2, 4)", &GOOD_ROWS));
    assert!(output.status.success() && written, "{}", stderr(&output));
    let psi = npy_bytes("(2, 4)", &[0.0; 8]);
    let (output, _, written) =
        deform_with_weights("w.npz", &npz_bytes(&npy_bytes("(2, 4)", &GOOD_ROWS), &psi));
    assert!(output.status.success() && written, "{}", stderr(&output));
}

#[test]
fn npz_declaring_huge_shapes_is_refused_naming_the_array() {
    // 2^32 × 2^32 in a file of a few hundred bytes; this used to panic (exit 101)
    // slicing rows that were not there.
    let huge = npy_bytes("(4294967296, 4294967296)", &[]);
    let bytes = npz_bytes(&huge, &huge);
    assert!(bytes.len() < 600, "{}", bytes.len());
    let (output, weights, written) = deform_with_weights("w.npz", &bytes);
    assert_clean_failure(
        &output,
        &weights,
        "array 'phi': declares shape (4294967296, 4294967296), but the mesh has 2 vertices and the cage 4 vertices, so it must be (2, 4)",
    );
    assert!(!written);
}

#[test]
fn npz_declaring_a_trillion_rows_is_refused_before_reading() {
    // (10^12, 0) used to be read row by row for about 17 minutes before its shape
    // was compared with the mesh.
    let empty = npy_bytes("(1000000000000, 0)", &[]);
    let (output, weights, _) = deform_with_weights("w.npz", &npz_bytes(&empty, &empty));
    assert_clean_failure(&output, &weights, "declares shape (1000000000000, 0)");
    // The right shape with too few bytes is truncated, whatever the archive says.
    let short = npy_bytes("(2, 4)", &GOOD_ROWS[..5]);
    let (output, weights, _) = deform_with_weights("w.npz", &npz_bytes(&short, &short));
    assert_clean_failure(
        &output,
        &weights,
        "array 'phi': truncated: its shape (2, 4) needs 32 bytes of float32 values, but the file holds 20",
    );
}

#[test]
fn truncated_npy_is_reported_as_truncated() {
    let mut bytes = npy_bytes("(2, 4)", &GOOD_ROWS);
    bytes.truncate(bytes.len() - 13);
    let (output, weights, _) = deform_with_weights("w.npy", &bytes);
    assert_clean_failure(
        &output,
        &weights,
        "truncated: its shape (2, 4) needs 32 bytes of float32 values, but the file holds 19",
    );
}

#[test]
fn non_finite_weights_are_refused_by_row_and_column() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut rows = GOOD_ROWS;
        rows[6] = bad;
        let (output, weights, written) = deform_with_weights("w.npy", &npy_bytes("(2, 4)", &rows));
        assert_clean_failure(&output, &weights, "row 2, column 3 is");
        assert!(
            stderr(&output).contains("must be finite"),
            "{}",
            stderr(&output)
        );
        assert!(!written);
    }
    let mut psi = [0.0f32; 8];
    psi[1] = f32::INFINITY;
    let bytes = npz_bytes(&npy_bytes("(2, 4)", &GOOD_ROWS), &npy_bytes("(2, 4)", &psi));
    let (output, weights, _) = deform_with_weights("w.npz", &bytes);
    assert_clean_failure(&output, &weights, "array 'psi': row 1, column 2 is inf");
}

#[test]
fn rows_that_do_not_sum_to_one_are_refused() {
    // All zeros used to give back the undeformed mesh.
    let (output, weights, written) = deform_with_weights("w.npy", &npy_bytes("(2, 4)", &[0.0; 8]));
    assert_clean_failure(
        &output,
        &weights,
        "row 1's weights sum to 0, not 1 (allowed: ±1.0e-4)",
    );
    assert!(!written);
    let mut rows = GOOD_ROWS;
    rows[5] += 1e-3;
    let psi = npy_bytes("(2, 4)", &[0.0; 8]);
    let bytes = npz_bytes(&npy_bytes("(2, 4)", &rows), &psi);
    let (output, weights, _) = deform_with_weights("w.npz", &bytes);
    assert_clean_failure(
        &output,
        &weights,
        "array 'phi': row 2's weights sum to 1.001",
    );
}

#[test]
fn a_compressed_npz_is_refused_with_advice() {
    let psi = npy_bytes("(2, 4)", &[0.0; 8]);
    let mut bytes = npz_bytes(&npy_bytes("(2, 4)", &GOOD_ROWS), &psi);
    // Mark both entries deflated (method 8), as numpy.savez_compressed writes them:
    // the local headers' method at offset 8, the central directory's at 10.
    for (signature, offset) in [(b"PK\x03\x04", 8), (b"PK\x01\x02", 10)] {
        let starts: Vec<usize> = bytes
            .windows(4)
            .enumerate()
            .filter(|(_, window)| window == signature)
            .map(|(at, _)| at)
            .collect();
        assert_eq!(starts.len(), 2);
        for start in starts {
            bytes[start + offset] = 8;
        }
    }
    let (output, weights, _) = deform_with_weights("w.npz", &bytes);
    assert_clean_failure(
        &output,
        &weights,
        "array 'phi': is compressed (the file was written with numpy.savez_compressed); write it with numpy.savez",
    );
}

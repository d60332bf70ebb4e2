use super::*;

fn expected(rows: usize, cols: usize) -> ExpectedArray {
    ExpectedArray::cage_vertices(rows, cols)
}

fn write_file(header: &str, values: &[f32]) -> (tempfile::TempDir, PathBuf) {
    let folder = tempfile::tempdir().expect("temporary folder");
    let path = folder.path().join("w.npy");
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.as_bytes());
    bytes.extend(values.iter().flat_map(|v| v.to_le_bytes()));
    std::fs::write(&path, bytes).expect("write");
    (folder, path)
}

fn header(shape: &str) -> String {
    format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {shape}, }}\n")
}

#[test]
fn written_weights_read_back() {
    let folder = tempfile::tempdir().expect("temporary folder");
    let path = folder.path().join("w.npy");
    let weights = Weights {
        rows: 2,
        cols: 3,
        values: vec![0.25, 0.25, 0.5, -0.5, 1.0, 0.5],
    };
    write_npy(&path, &weights).expect("written");
    assert_eq!(
        npy_file_bytes(2, 3),
        std::fs::metadata(&path).unwrap().len()
    );
    assert_eq!(read_npy(&path, expected(2, 3)).expect("read"), weights);
}

/// Float64 weights are written as '<f8' and read back exactly; each dtype's
/// reader refuses the other's files, naming what it expected.
#[test]
fn float64_weights_read_back_and_dtypes_are_not_mixed() {
    let folder = tempfile::tempdir().expect("temporary folder");
    let path = folder.path().join("w64.npy");
    let values = vec![0.1, 0.2, 0.7, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0];
    let mut bytes = npy_preamble_of(&path, 2, 3, Dtype::Float64).expect("preamble");
    write_values(&mut bytes, &values).expect("written");
    std::fs::write(&path, &bytes).expect("file");
    assert_eq!(npy_file_bytes_of(2, 3, Dtype::Float64), bytes.len() as u64);
    let read = read_npy_f64(&path, expected(2, 3)).expect("read");
    assert_eq!(read.values, values);
    let message = read_npy(&path, expected(2, 3)).unwrap_err().to_string();
    assert!(message.contains("found dtype '<f8'"), "{message}");
    let (_folder, path32) = write_file(&header("(1, 2)"), &[0.5, 0.5]);
    let message = read_npy_f64(&path32, expected(1, 2))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("expected little-endian float64 weights ('<f8')"),
        "{message}"
    );
    let truncated = &bytes[..bytes.len() - 4];
    std::fs::write(&path, truncated).expect("file");
    let message = read_npy_f64(&path, expected(2, 3)).unwrap_err().to_string();
    assert!(message.contains("bytes of float64 values"), "{message}");
}

#[test]
fn a_truncated_file_is_reported_as_truncated() {
    let (_folder, path) = write_file(&header("(2, 2)"), &[0.5, 0.5, 0.25]);
    let message = read_npy(&path, expected(2, 2)).unwrap_err().to_string();
    assert!(
        message.contains("truncated")
            && message.contains("(2, 2)")
            && message.contains("needs 16 bytes")
            && message.contains("holds 12"),
        "{message}"
    );
}

#[test]
fn a_shape_that_does_not_fit_is_refused_before_anything_is_allocated() {
    let (_folder, path) = write_file(&header("(4294967296, 4294967296)"), &[1.0]);
    let message = read_npy(&path, expected(8, 8)).unwrap_err().to_string();
    assert!(
        message.contains("(4294967296, 4294967296)") && message.contains("must be (8, 8)"),
        "{message}"
    );
}

#[test]
fn non_finite_weights_are_refused_by_row_and_column() {
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let (_folder, path) = write_file(&header("(2, 2)"), &[0.5, 0.5, 1.0, bad]);
        let message = read_npy(&path, expected(2, 2)).unwrap_err().to_string();
        assert!(
            message.contains("w.npy: row 2, column 2 is") && message.contains("finite"),
            "{message}"
        );
    }
}

#[test]
fn rows_must_sum_to_one() {
    let (_folder, path) = write_file(&header("(2, 2)"), &[0.5, 0.5, 0.0, 0.0]);
    let message = read_npy(&path, expected(2, 2)).unwrap_err().to_string();
    assert!(
        message.contains("row 2's weights sum to 0, not 1") && message.contains("1.0e-4"),
        "{message}"
    );
    // Within f32 rounding is accepted; negative weights count by magnitude.
    let near = [0.3f32, 0.7 + 4e-5, 3.0, -2.0];
    let (_folder, path) = write_file(&header("(2, 2)"), &near);
    assert_eq!(read_npy(&path, expected(2, 2)).expect("read").values, near);
}

#[test]
fn other_dtypes_orders_and_extra_bytes_are_named() {
    let cases = [
        (
            "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 1), }",
            "found dtype '<f8'",
        ),
        (
            "{'descr': '<f4', 'fortran_order': True, 'shape': (1, 1), }",
            "fortran_order True",
        ),
        (
            "{'descr': '<f4', 'fortran_order': False, 'shape': (1,), }",
            "found shape (1,)",
        ),
    ];
    for (text, expected_text) in cases {
        let (_folder, path) = write_file(text, &[1.0]);
        let message = read_npy(&path, expected(1, 1)).unwrap_err().to_string();
        assert!(message.contains(expected_text), "{message}");
    }
    let (_folder, path) = write_file(&header("(1, 1)"), &[1.0, 1.0]);
    let message = read_npy(&path, expected(1, 1)).unwrap_err().to_string();
    assert!(message.contains("more than the 4 bytes"), "{message}");
}

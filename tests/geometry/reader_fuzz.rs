//! A bounded, seeded mutation fuzz of the OBJ and OFF readers on stable Rust:
//! thousands of damaged copies of small valid files (bytes flipped, tokens
//! deleted, duplicated or replaced by huge, negative, NaN or non-numeric ones,
//! lines joined, split, truncated, CR and BOM inserted). Every read must end in
//! a clean error or in a mesh that is what the file says: positions equal to an
//! independent reading of its `v` lines (OBJ), every index in range, every
//! coordinate finite.

use crate::common;

use common::Random;
use glam::DVec3;
use pmvc::formats::{parse_mesh, LoadError, MeshFile};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

const OBJ: &str = "# a quad and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0.5\nv 0.5 0.5 1 1\nvt 0 0\nvn 0 0 1\ng part\nf 1 2 3 4\nf 1/1 2/1 5/1\nf -5 -3 -1\n";
const OFF: &str = "OFF\n# comment\n5 3 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0.5\n0.5 0.5 1\n4 0 1 2 3\n3 0 1 4\n3 2 3 4 255 0 0\n";
const CASES_PER_FILE: usize = 4000;

const REPLACEMENTS: &[&str] = &[
    "1e308",
    "-1e309",
    "nan",
    "inf",
    "-0",
    "0",
    "-1",
    "-99",
    "99999999999999999999",
    "1.5",
    "x",
    "",
    "/",
    "//",
    "1//",
    "3/",
    "v",
    "f",
    "\u{feff}",
    "\r",
    "é",
    "1e-320",
];

fn mutate(text: &str, random: &mut Random) -> String {
    let mut tokens: Vec<String> = text
        .split_inclusive(|c: char| c.is_whitespace())
        .map(str::to_owned)
        .collect();
    for _ in 0..1 + random.below(3) {
        let at = random.below(tokens.len());
        match random.below(8) {
            0 => {
                tokens.remove(at);
            }
            1 => {
                let copy = tokens[at].clone();
                tokens.insert(at, copy);
            }
            2 => {
                let replacement = REPLACEMENTS[random.below(REPLACEMENTS.len())];
                tokens[at] = format!("{replacement} ");
            }
            3 => tokens[at] = tokens[at].replace('\n', " "),
            4 => tokens[at].push('\n'),
            5 => tokens.truncate(at.max(1)),
            6 => tokens.insert(at, "\r".into()),
            _ => {
                let mut bytes = tokens[at].clone().into_bytes();
                if !bytes.is_empty() {
                    let i = random.below(bytes.len());
                    bytes[i] ^= 1 << random.below(7);
                }
                tokens[at] = String::from_utf8_lossy(&bytes).into_owned();
            }
        }
        if tokens.is_empty() {
            tokens.push(String::new());
        }
    }
    tokens.concat()
}

/// The positions an OBJ text's `v` lines give, read independently of the
/// product's reader: three numbers after `v`, or `None` if a `v` line is not
/// `x y z`, `x y z w` or `x y z r g b` with finite numbers.
fn reference_obj_positions(text: &str) -> Option<Vec<DVec3>> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let text = text.replace("\r\n", "\n").replace('\r', "\n");
    let mut positions = Vec::new();
    for line in text.lines() {
        let mut tokens = line.split_whitespace();
        if tokens.next() != Some("v") {
            continue;
        }
        let numbers: Vec<f64> = tokens.map(|t| t.parse().ok()).collect::<Option<_>>()?;
        if !matches!(numbers.len(), 3 | 4 | 6) || !numbers.iter().all(|n| n.is_finite()) {
            return None;
        }
        positions.push(DVec3::new(numbers[0], numbers[1], numbers[2]));
    }
    Some(positions)
}

fn check_consistent(file: &MeshFile, case: &str) {
    let mesh = &file.mesh;
    assert!(
        mesh.positions.iter().all(|p| p.is_finite()),
        "non-finite position accepted:\n{case}"
    );
    assert!(
        mesh.triangles
            .iter()
            .flatten()
            .all(|&i| (i as usize) < mesh.positions.len()),
        "index out of range accepted:\n{case}"
    );
    assert_eq!(mesh.triangle_faces.len(), mesh.triangles.len(), "{case}");
}

fn fuzz(name: &str, valid: &str, seed: u64) -> (usize, usize) {
    let mut random = Random(seed);
    let (mut accepted, mut refused) = (0, 0);
    for _ in 0..CASES_PER_FILE {
        let case = mutate(valid, &mut random);
        let result = catch_unwind(AssertUnwindSafe(|| {
            parse_mesh(Path::new(name), case.clone())
        }))
        .unwrap_or_else(|_| panic!("the reader panicked on:\n{case:?}"));
        match result {
            Ok(file) => {
                accepted += 1;
                check_consistent(&file, &case);
                if name.ends_with(".obj") {
                    let expected = reference_obj_positions(&case);
                    assert_eq!(
                        Some(&file.mesh.positions),
                        expected.as_ref(),
                        "positions differ from the file's v lines:\n{case:?}"
                    );
                }
            }
            Err(error) => {
                refused += 1;
                let text = error.to_string();
                assert!(text.starts_with(name), "{text}");
                assert!(text.len() < 400, "an overlong message: {text}");
                if let LoadError::Io { .. } = error {
                    panic!("an I/O error from text: {text}");
                }
            }
        }
    }
    (accepted, refused)
}

#[test]
fn mutated_obj_files_read_cleanly_or_as_written() {
    let (accepted, refused) = fuzz("fuzz.obj", OBJ, 0x9e37_79b9_7f4a_7c15);
    eprintln!("OBJ: {accepted} accepted, {refused} refused");
    assert!(accepted > 100 && refused > 100, "{accepted} / {refused}");
}

#[test]
fn mutated_off_files_read_cleanly_or_consistently() {
    let (accepted, refused) = fuzz("fuzz.off", OFF, 0xd1b5_4a32_d192_ed03);
    eprintln!("OFF: {accepted} accepted, {refused} refused");
    assert!(accepted > 100 && refused > 100, "{accepted} / {refused}");
}

#[test]
fn the_unmutated_files_read_as_written() {
    for (name, text) in [("ok.obj", OBJ), ("ok.off", OFF)] {
        let file = parse_mesh(Path::new(name), text.to_owned()).unwrap();
        assert_eq!(file.mesh.positions.len(), 5, "{name}");
        assert_eq!(file.mesh.triangles.len(), 4, "{name}");
    }
}

// Weights files: `.npy` and `.npz` headers and lengths, mutated.

use pmvc::formats::npy::{read_npy, ExpectedArray, NpyError};
use pmvc::formats::npz::read_npz;

/// The shape every valid case has: 2 mesh vertices, a cage of 4 vertices and 4
/// triangles.
const ROWS: usize = 2;
const COLS: usize = 4;
const VALUES: [f32; 8] = [0.7, 0.1, 0.1, 0.1, 0.25, 0.25, 0.25, 0.25];

const SHAPES: &[&str] = &[
    "(2, 4)",
    "(2, 4,)",
    "(4, 2)",
    "(2,)",
    "()",
    "(2, 4, 1)",
    "(4294967296, 4294967296)",
    "(1000000000000, 0)",
    "(0, 4)",
    "(2, 0)",
    "(9223372036854775807, 2)",
    "(18446744073709551615, 18446744073709551615)",
    "(99999999999999999999, 4)",
    "(-2, 4)",
    "(2, 4",
    "[2, 4]",
];
const DESCRS: &[&str] = &[
    "'<f4'",
    "'<f4'",
    "'<f8'",
    "'>f4'",
    "'|u1'",
    "'f4'",
    "'<f2'",
    "'<i4'",
    "\"<f4\"",
    "'<f4",
    "[('a', '<f4')]",
    "'O'",
];
const ORDERS: &[&str] = &["False", "False", "True", "0", "None"];

/// A `.npy` with a header from mutated parts, a mutated version and length
/// field, and values cut short, extended or made non-finite.
fn mutated_npy(random: &mut Random) -> Vec<u8> {
    let pick = |random: &mut Random, list: &[&'static str]| list[random.below(list.len())];
    let (descr, order, shape) = if random.below(3) == 0 {
        (
            pick(random, DESCRS),
            pick(random, ORDERS),
            pick(random, SHAPES),
        )
    } else {
        ("'<f4'", "False", "(2, 4)")
    };
    let mut header = format!("{{'descr': {descr}, 'fortran_order': {order}, 'shape': {shape}, }}");
    if random.below(8) == 0 {
        header = header.replacen(", ", ", 'extra': 1, ", 1);
    }
    header.push_str(&" ".repeat(random.below(80)));
    header.push('\n');
    let version = [1u8, 1, 1, 2, 3, 0, 4][random.below(7)];
    let mut bytes = b"\x93NUMPY".to_vec();
    bytes.extend([version, 0]);
    let mut length = header.len() as u32;
    if random.below(8) == 0 {
        length = [0, 1, header.len() as u32 + 1, 0xffff, 0x1_0001, u32::MAX][random.below(6)];
    }
    if version >= 2 {
        bytes.extend(length.to_le_bytes());
    } else {
        bytes.extend((length as u16).to_le_bytes());
    }
    bytes.extend(header.as_bytes());
    let mut values = VALUES;
    if random.below(8) == 0 {
        values[random.below(values.len())] =
            [f32::NAN, f32::INFINITY, -f32::INFINITY, 0.0, 1e30][random.below(5)];
    }
    bytes.extend(values.iter().flat_map(|v| v.to_le_bytes()));
    match random.below(6) {
        0 => bytes.truncate(random.below(bytes.len())),
        1 => bytes.extend(std::iter::repeat_n(0u8, 1 + random.below(8))),
        2 => {
            let at = random.below(bytes.len());
            bytes[at] ^= 1 << random.below(8);
        }
        _ => {}
    }
    bytes
}

/// What an accepted `.npy` must be, read independently: version 1.0–3.0, a
/// header naming little-endian float32 in C order and shape (2, 4), and exactly
/// 32 bytes of finite values after it.
fn reference_npy_values(bytes: &[u8]) -> Option<Vec<f32>> {
    if bytes.get(..6)? != b"\x93NUMPY" {
        return None;
    }
    let (length, start) = match bytes.get(6..8)? {
        [1, 0] => (
            u16::from_le_bytes(bytes.get(8..10)?.try_into().ok()?) as usize,
            10usize,
        ),
        [2 | 3, 0] => (
            u32::from_le_bytes(bytes.get(8..12)?.try_into().ok()?) as usize,
            12,
        ),
        _ => return None,
    };
    let header = std::str::from_utf8(bytes.get(start..start.checked_add(length)?)?).ok()?;
    // Python's blanks: space, tab, form feed and line ends; either quote.
    let compact: String = header
        .chars()
        .filter(|c| !matches!(c, ' ' | '\t' | '\x0c' | '\n' | '\r'))
        .map(|c| if c == '"' { '\'' } else { c })
        .collect();
    let valid = ["(2,4)", "(2,4,)"]
        .map(|shape| format!("{{'descr':'<f4','fortran_order':False,'shape':{shape},}}"));
    if !valid.contains(&compact) {
        return None;
    }
    let data = &bytes[start + length..];
    if data.len() != ROWS * COLS * 4 {
        return None;
    }
    let values: Vec<f32> = data
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    values.iter().all(|v| v.is_finite()).then_some(values)
}

fn check_refusal(error: &NpyError, name: &str, case: &[u8]) {
    let text = error.to_string();
    assert!(text.starts_with(name), "{text}\n{case:?}");
    assert!(text.len() < 400, "an overlong message: {text}");
    assert!(!text.contains('\n'), "a message of several lines: {text}");
}

/// Every case read with the sizes fixed, so an allocation can only be as large
/// as the valid file's; a declared size is never allocated.
#[test]
fn mutated_npy_headers_read_cleanly_or_as_written() {
    let folder = tempfile::tempdir().unwrap();
    let path = folder.path().join("fuzz.npy");
    let mut random = Random(0x2545_f491_4f6c_dd1d);
    let (mut accepted, mut refused) = (0, 0);
    for _ in 0..CASES_PER_FILE {
        let case = mutated_npy(&mut random);
        std::fs::write(&path, &case).unwrap();
        let expected = ExpectedArray::cage_vertices(ROWS, COLS);
        let result = catch_unwind(AssertUnwindSafe(|| read_npy(&path, expected)))
            .unwrap_or_else(|_| panic!("the reader panicked on:\n{case:?}"));
        let reference = reference_npy_values(&case);
        match result {
            Ok(weights) => {
                accepted += 1;
                assert_eq!((weights.rows, weights.cols), (ROWS, COLS));
                assert_eq!(Some(weights.values), reference, "{case:?}");
            }
            Err(error) => {
                refused += 1;
                check_refusal(&error, &path.display().to_string(), &case);
                // A file the reference accepts is refused only for its rows' sums.
                if reference.is_some() {
                    assert!(
                        matches!(error, NpyError::RowSum { .. }),
                        "{error}: {case:?}"
                    );
                }
            }
        }
    }
    eprintln!(".npy: {accepted} accepted, {refused} refused");
    assert!(accepted > 100 && refused > 100, "{accepted} / {refused}");
}

fn valid_npy() -> Vec<u8> {
    let header = "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 4), }\n";
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.as_bytes());
    bytes.extend(VALUES.iter().flat_map(|v| v.to_le_bytes()));
    bytes
}

fn npz_of(entries: &[(&str, &[u8])]) -> Vec<u8> {
    use std::io::Write;
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for (name, bytes) in entries {
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored);
        zip.start_file(*name, options).unwrap();
        zip.write_all(bytes).unwrap();
    }
    zip.finish().unwrap().into_inner()
}

/// Archives of mutated `.npy` entries, and valid archives with bytes flipped
/// (sizes, offsets, methods, checksums) or cut short.
#[test]
fn mutated_npz_archives_read_cleanly_or_as_written() {
    let folder = tempfile::tempdir().unwrap();
    let path = folder.path().join("fuzz.npz");
    let mut random = Random(0x9e37_79b9_7f4a_7c15 ^ 0x5bd1_e995);
    let (mut accepted, mut refused) = (0, 0);
    for _ in 0..CASES_PER_FILE {
        // One array mutated, the other as NumPy writes it.
        let (mutated, valid) = (mutated_npy(&mut random), valid_npy());
        let (phi, psi) = if random.below(2) == 0 {
            (mutated, valid)
        } else {
            (valid, mutated)
        };
        let mut case = npz_of(&[("phi.npy", &phi), ("psi.npy", &psi)]);
        let archive_mutated = random.below(3) == 0;
        if archive_mutated {
            match random.below(3) {
                0 => case.truncate(random.below(case.len())),
                _ => {
                    for _ in 0..1 + random.below(3) {
                        let at = random.below(case.len());
                        case[at] ^= 1 << random.below(8);
                    }
                }
            }
        }
        std::fs::write(&path, &case).unwrap();
        let result = catch_unwind(AssertUnwindSafe(|| read_npz(&path, ROWS, COLS, COLS)))
            .unwrap_or_else(|_| panic!("the reader panicked on:\n{case:?}"));
        match result {
            Ok(weights) => {
                accepted += 1;
                assert_eq!((weights.rows, weights.cols), (ROWS, 2 * COLS));
                // Whatever was flipped, what is accepted is what the entries hold
                // (a flipped value byte fails the entry's checksum).
                let phi = reference_npy_values(&phi).expect("phi accepted");
                let psi = reference_npy_values(&psi).expect("psi accepted");
                for row in 0..ROWS {
                    assert_eq!(weights.row(row)[..COLS], phi[row * COLS..][..COLS]);
                    assert_eq!(weights.row(row)[COLS..], psi[row * COLS..][..COLS]);
                }
            }
            Err(error) => {
                refused += 1;
                check_refusal(&error, &path.display().to_string(), &case);
            }
        }
    }
    eprintln!(".npz: {accepted} accepted, {refused} refused");
    assert!(accepted > 100 && refused > 100, "{accepted} / {refused}");
}

/// A declared size past anything addressable, with sizes that agree with it, is
/// refused by the memory check rather than allocated.
#[test]
fn a_huge_shape_that_fits_what_is_expected_is_refused_before_allocation() {
    let folder = tempfile::tempdir().unwrap();
    let path = folder.path().join("huge.npy");
    let header = "{'descr': '<f4', 'fortran_order': False, 'shape': (4294967296, 4294967296), }\n";
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((header.len() as u16).to_le_bytes());
    bytes.extend(header.as_bytes());
    std::fs::write(&path, &bytes).unwrap();
    let huge = ExpectedArray::cage_vertices(1 << 32, 1 << 32);
    // The file holds no values: refused as truncated, before any allocation.
    let error = read_npy(&path, huge).unwrap_err();
    assert!(matches!(error, NpyError::Truncated { .. }), "{error}");
    // A stream with no size (a pipe) reaches the memory check.
    #[cfg(unix)]
    {
        let fifo = folder.path().join("huge-fifo.npy");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|status| status.success()) {
            let writer = {
                let (fifo, bytes) = (fifo.clone(), bytes.clone());
                std::thread::spawn(move || {
                    let _ = std::fs::write(&fifo, &bytes);
                })
            };
            let error = read_npy(&fifo, huge).unwrap_err();
            let _ = writer.join();
            assert!(matches!(error, NpyError::TooLarge { .. }), "{error}");
            assert!(error.to_string().contains("address"), "{error}");
        }
    }
}

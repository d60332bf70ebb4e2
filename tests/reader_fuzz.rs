//! A bounded, seeded mutation fuzz of the OBJ and OFF readers on stable Rust:
//! thousands of damaged copies of small valid files (bytes flipped, tokens
//! deleted, duplicated or replaced by huge, negative, NaN or non-numeric ones,
//! lines joined, split, truncated, CR and BOM inserted). Every read must end in
//! a clean error or in a mesh that is what the file says: positions equal to an
//! independent reading of its `v` lines (OBJ), every index in range, every
//! coordinate finite.

use glam::DVec3;
use pmvc::geometry::{parse_mesh, LoadError, MeshFile};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

const OBJ: &str = "# a quad and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0.5\nv 0.5 0.5 1 1\nvt 0 0\nvn 0 0 1\ng part\nf 1 2 3 4\nf 1/1 2/1 5/1\nf -5 -3 -1\n";
const OFF: &str = "OFF\n# comment\n5 3 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0.5\n0.5 0.5 1\n4 0 1 2 3\n3 0 1 4\n3 2 3 4 255 0 0\n";
const CASES_PER_FILE: usize = 4000;

/// xorshift64*: deterministic, so a failure names a reproducible case.
struct Random(u64);

impl Random {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

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

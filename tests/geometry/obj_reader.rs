//! The OBJ reader against the one it replaced (the same checks, then tobj for the
//! faces; tests/common/tobj_reference.rs): identical meshes on the bundled
//! assets, the shared meshes, hand-written edge cases and mutated files, the
//! same files refused, and every refusal naming its line.

use crate::tobj_reference::parse_obj_with_tobj;
use pmvc::formats::{parse_mesh, LoadError, MeshFile};
use std::path::{Path, PathBuf};

/// What `parse_mesh` hands the OBJ reader: no byte-order mark, `\n` line ends.
fn normalised(text: &str) -> String {
    text.trim_start_matches('\u{feff}')
        .replace("\r\n", "\n")
        .replace('\r', "\n")
}

fn assert_same_file(new: &MeshFile, old: &MeshFile, case: &str) {
    assert_eq!(new.path, old.path, "{case}");
    assert_eq!(new.format, old.format, "{case}");
    assert_eq!(new.obj_text, old.obj_text, "{case}");
    assert_eq!(new.mesh.positions.len(), old.mesh.positions.len(), "{case}");
    assert_eq!(new.mesh, old.mesh, "{case}");
}

/// Both readers on `text`: the same mesh, or both refuse it. Where the old one
/// refused through tobj (no line), the new message names a line; otherwise the
/// messages are the same. Returns whether it was accepted.
fn compare(name: &str, text: &str, case: &str) -> bool {
    let path = Path::new(name);
    let new = parse_mesh(path, text.to_owned());
    let old = parse_obj_with_tobj(path, normalised(text));
    match (new, old) {
        (Ok(new), Ok(old)) => {
            assert_same_file(&new, &old, case);
            true
        }
        (Err(new), Err(LoadError::Obj { .. })) => {
            let message = new.to_string();
            let line = message
                .strip_prefix(&format!("{name}:"))
                .and_then(|rest| rest.split(':').next())
                .and_then(|line| line.parse::<usize>().ok());
            assert!(line.is_some(), "{case}: no line in {message:?}");
            false
        }
        (Err(new), Err(old)) => {
            assert_eq!(new.to_string(), old.to_string(), "{case}");
            false
        }
        (new, old) => panic!(
            "{case}: the readers disagree:\nnew: {:?}\nold: {:?}",
            new.map(|file| file.mesh.triangles.len()),
            old.map(|file| file.mesh.triangles.len())
        ),
    }
}

fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets")
}

fn obj_files_in(folder: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .unwrap()
        .filter_map(|entry| entry.ok().map(|entry| entry.path()))
        .filter(|path| path.extension().is_some_and(|e| e == "obj"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_bundled_asset_reads_as_tobj_read_it() {
    let files = obj_files_in(&assets());
    assert!(files.len() >= 4, "{files:?}");
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        let name = file.to_string_lossy();
        assert!(compare(&name, &text, &name), "{name} was refused");
    }
}

fn qmvc_data() -> Option<PathBuf> {
    let candidates = [
        std::env::var_os("PMVC_QMVC_DATA").map(PathBuf::from),
        Some(Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/qmvc")),
    ];
    candidates.into_iter().flatten().find(|path| path.is_dir())
}

#[test]
fn every_shared_mesh_reads_as_tobj_read_it() {
    let Some(data) = qmvc_data() else {
        eprintln!("not run: ../shared/data/qmvc is missing");
        return;
    };
    let files = obj_files_in(&data);
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        let name = file.to_string_lossy();
        assert!(compare(&name, &text, &name), "{name} was refused");
    }
    eprintln!("{} shared meshes read alike", files.len());
}

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";

#[test]
fn hand_written_edge_cases_read_as_tobj_read_them() {
    let cases = [
        (
            "negative indices",
            format!("{TETRA}f -4 -2 -3\nf -1 -3 -4\n"),
        ),
        (
            "v/vt/vn",
            format!("{TETRA}vt 0 0\nvt 1 0\nvn 0 0 1\nf 1/1/1 2/2/1 3/1/1\n"),
        ),
        ("v//vn", format!("{TETRA}vn 0 0 1\nf 1//1 2//1 4//1\n")),
        ("v/vt", format!("{TETRA}vt 0 0 0\nf 1/1 2/1 4/1\n")),
        (
            "tabs",
            "v\t0 0\t0\nv 1\t0 0\nv 0 1 0\n\tf\t1\t2 3\n".to_owned(),
        ),
        ("CRLF", format!("{TETRA}f 1 2 3\n").replace('\n', "\r\n")),
        ("CR alone", format!("{TETRA}f 1 2 3\n").replace('\n', "\r")),
        ("byte-order mark", format!("\u{feff}{TETRA}f 1 2 3\n")),
        (
            "comments",
            format!("# a\n{TETRA}#f 1 2 3\n# f 1 2 3\nf 1 2 3\n"),
        ),
        (
            "empty groups",
            format!("g\no\ng empty\n{TETRA}g\nf 1 2 3\ng\ng last\n"),
        ),
        (
            "groups, objects and materials",
            format!(
                "mtllib a b.mtl\no one\n{TETRA}usemtl red\nf 1 2 3\ng two\nusemtl blue\nf 1 3 4\n"
            ),
        ),
        ("quad", format!("{TETRA}f 1 2 3 4\n")),
        (
            "polygon",
            format!("{TETRA}v 1 1 0\nf 1 2 5 3 4\nf 5 4 3 2 1\n"),
        ),
        (
            "a face ahead of its vertex, same group",
            "f 1 2 4\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n".to_owned(),
        ),
        (
            "a quad ahead of its vertices",
            "f 1 2 3 4\nv 0 0 0\nv 2 0 0\nv 2 1 1\nv 0 1 0\n".to_owned(),
        ),
        (
            "texture index 0 (tobj: none)",
            format!("{TETRA}vt 0 0\nf 1/0 2/1 3/1\n"),
        ),
        (
            "texture index one before the start",
            format!("{TETRA}vt 0 0\nf 1/-2 2/1 3/1\n"),
        ),
        (
            "texture indices with no vt lines",
            format!("{TETRA}f 1/7 2/8 3/-9\n"),
        ),
        (
            "normal index ahead within the group",
            format!("{TETRA}f 1//2 2//1 3//1\nvn 0 0 1\nvn 0 1 0\n"),
        ),
        (
            "texture ahead within the group",
            format!("{TETRA}f 1/2 2/1 3/1\nvt 0 0\nvt 1 1\n"),
        ),
        (
            "trailing slash",
            format!("{TETRA}f 1/ 2/ 3/\nf 1// 2// 3//\nf 1/1/1/ 2 3\n"),
        ),
        (
            "vertex colours and w",
            "v 0 0 0 1 0 0\nv 1 0 0 2\nv 0 1 0\nf 1 2 3\n".to_owned(),
        ),
        ("polyline", format!("{TETRA}l 1 2 3 4\nf 1 2 3\n")),
        (
            "non-ASCII whitespace",
            format!("{TETRA}f\u{3000}1 2\u{a0}3\n"),
        ),
        ("non-ASCII comment", format!("# é\n{TETRA}f 1 2 3\n")),
        (
            "vertical tab and form feed",
            format!("{TETRA}f 1\u{b}2\u{c}3\n"),
        ),
        ("plus signs", format!("{TETRA}f +1 +2 +3\n")),
        (
            "leading-space usemtl",
            format!("{TETRA}  usemtl\nf 1 2 3\n"),
        ),
        // Refused:
        ("one texture number", format!("{TETRA}vt 0.5\nf 1 2 3\n")),
        ("four-part corner", format!("{TETRA}f 1/1/1/1 2 3\n")),
        (
            "texture part not an integer",
            format!("{TETRA}vt 0 0\nf 1/x 2 3\n"),
        ),
        (
            "normal part not an integer",
            format!("{TETRA}vn 0 0 1\nf 1//1.5 2 3\n"),
        ),
        ("usemtl without a name", format!("{TETRA}usemtl\nf 1 2 3\n")),
        (
            "usemtl after a tab",
            format!("{TETRA}usemtl\tred\nf 1 2 3\n"),
        ),
        (
            "a face ahead of its group's end",
            "f 1 2 4\ng next\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n".to_owned(),
        ),
        (
            "texture index past the end",
            format!("{TETRA}vt 0 0\nf 1/1 2/2 3/1\n"),
        ),
        (
            "normal index past the end",
            format!("{TETRA}vn 0 0 1\nf 1//1 2//1 3//-3\n"),
        ),
        (
            "normal defined after the group",
            format!("{TETRA}vn 0 0 1\nf 1//2 2//1 3//1\no next\nvn 0 1 0\n"),
        ),
        ("vertex index 0", format!("{TETRA}f 0 1 2\n")),
        ("vertex past the end", format!("{TETRA}f 1 2 5\n")),
        (
            "relative vertex before the start",
            format!("{TETRA}f -5 1 2\n"),
        ),
        ("two corners", format!("{TETRA}f 1 2\n")),
        ("not an index", format!("{TETRA}f 1 2 x\n")),
        (
            "two errors: tobj's first, then a checked one",
            format!("{TETRA}vt 1\nf 1 2 9\n"),
        ),
        ("no vertices", "f 1 2 3\n".to_owned()),
        (
            "a comment after a face",
            format!("{TETRA}f 1 2 3 # trailing\n"),
        ),
    ];
    let refused: Vec<&str> = cases
        .iter()
        .filter(|(case, text)| !compare("case.obj", text, case))
        .map(|(case, _)| *case)
        .collect();
    let first_refused = cases
        .iter()
        .position(|(case, _)| *case == "one texture number");
    assert_eq!(
        refused,
        cases[first_refused.unwrap()..]
            .iter()
            .map(|(case, _)| *case)
            .collect::<Vec<_>>()
    );
}

/// Errors the OBJ library made without a line now name it.
#[test]
fn refusals_by_tobjs_rules_name_the_line() {
    let cases = [
        (format!("{TETRA}vt 0.5\nf 1 2 3\n"), ":5: texture coordinate has 1 number; expected u v or u v w"),
        (format!("{TETRA}f 1 2/1/1/1 3\n"), ":5: face 1: '2/1/1/1' has more than three parts (v/vt/vn)"),
        (format!("{TETRA}vt 0 0\nf 1/x 2 3\n"), ":6: face 1: '1/x' has a texture coordinate index that is not an integer"),
        (format!("{TETRA}f 1 2 3\nusemtl\n"), ":6: usemtl names no material"),
        (
            "v 0 0 0\nf 1 2 3\ng next\nv 1 0 0\nv 0 1 0\n".to_owned(),
            ":2: face 1 refers to vertex 2, but only 1 are defined by the end of its group",
        ),
        (
            format!("{TETRA}vt 0 0\nf 1 2 3\nf 1/1 2/3 3/1\n"),
            ":7: face 2 refers to texture coordinate 3, but only 1 are defined by the end of its group",
        ),
    ];
    for (text, expected) in cases {
        let message = parse_mesh(Path::new("t.obj"), text)
            .unwrap_err()
            .to_string();
        assert_eq!(message, format!("t.obj{expected}"));
    }
}

/// Words the mutations put in: OBJ keywords, corner forms and bad numbers.
const WORDS: &[&str] = &[
    "v", "vt", "vn", "f", "g", "o", "l", "usemtl", "#", "0", "-1", "-2", "1", "2", "3", "9", "1/1",
    "2//1", "3/1/1", "1/0", "1/-1", "1/2/3/4", "1/x", "-1/-1/-1", "4/", "x", "1.5", "nan", "\n",
    "\t",
];

const RICH: &str = "# rich\nmtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0.5\nv 0.5 0.5 1 1\nvt 0 0\nvt 1 0\nvn 0 0 1\ng part\nusemtl a\nf 1/1/1 2/2/1 3/1/1 4/2/1\nf 1//1 2//1 5//1\no other\nf -5/-2 -3/-1 -1/-2\nf 2 3 5 4 1\nl 1 2\n";

/// xorshift*: a fixed sequence of cases.
struct Random(u64);

impl Random {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) % n.max(1) as u64) as usize
    }
}

fn mutated(random: &mut Random) -> String {
    let mut words: Vec<String> = RICH
        .split_inclusive(|c: char| c.is_whitespace())
        .map(str::to_owned)
        .collect();
    for _ in 0..1 + random.below(3) {
        let at = random.below(words.len());
        let word = WORDS[random.below(WORDS.len())];
        match random.below(4) {
            0 => {
                words.remove(at);
            }
            1 => words.insert(at, format!("{word} ")),
            2 => words[at] = format!("{word} "),
            _ => {
                // Move a line elsewhere: faces ahead of vertices, across groups.
                let text: String = words.concat();
                let mut lines: Vec<&str> = text.lines().collect();
                let line = lines.remove(random.below(lines.len()));
                lines.insert(random.below(lines.len() + 1), line);
                let moved = lines.join("\n") + "\n";
                words = moved
                    .split_inclusive(|c: char| c.is_whitespace())
                    .map(str::to_owned)
                    .collect();
            }
        }
    }
    words.concat()
}

#[test]
fn mutated_files_read_as_tobj_read_them() {
    let mut random = Random(0x2545_f491_4f6c_dd1d);
    let (mut accepted, mut refused) = (0, 0);
    for case in 0..6000 {
        let text = mutated(&mut random);
        if compare("fuzz.obj", &text, &format!("case {case}: {text:?}")) {
            accepted += 1;
        } else {
            refused += 1;
        }
    }
    // Both outcomes are exercised.
    assert!(
        accepted > 500 && refused > 500,
        "{accepted} accepted, {refused} refused"
    );
}

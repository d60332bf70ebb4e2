//! Reading in pieces gives what reading the whole text at once gives (which
//! tests/geometry/obj_reader.rs compares with tobj), wherever the pieces are cut.

use super::read_in_pieces;
use std::path::Path;

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";

const RICH: &str = "# rich\nmtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0.5\nv 0.5 0.5 1 1\nvt 0 0\nvt 1 0\nvn 0 0 1\ng part\nusemtl a\nf 1/1/1 2/2/1 3/1/1 4/2/1\nf 1//1 2//1 5//1\no other\nf -5/-2 -3/-1 -1/-2\nf 2 3 5 4 1\nl 1 2\nf 6 7 8 9\nv 0 0 2\nv 1 0 2\nv 1 1 2\nv 0 1 2\ng\nf 1 6 7 2\n";

fn assert_same_in_pieces(text: &str, case: &str) {
    let path = Path::new("p.obj");
    let whole = read_in_pieces(path, text, usize::MAX).map_err(|e| e.to_string());
    for bytes in [1, 2, 5, 13, 40] {
        let cut = read_in_pieces(path, text, bytes).map_err(|e| e.to_string());
        assert_eq!(cut, whole, "{case}, pieces of {bytes} bytes");
    }
}

#[test]
fn pieces_read_as_the_whole_text() {
    let cases = [
        RICH.to_owned(),
        format!("{TETRA}f -4 -2 -3\nf -1 -3 -4\nf 1 2 3 4\n"),
        "f 1 2 3 4\ng a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n".to_owned(),
        "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n".to_owned(),
        format!("{TETRA}f 1/2 2/1 3/1\nvt 0 0\no x\nvt 1 1\n"),
        format!("{TETRA}f 1/2 2/1 3/1\nvt 0 0\nvt 1 1\n"),
        format!("{TETRA}vt 1\nf 1/9 2 3\ng\nusemtl\nf 1 2 9\n"),
        format!("{TETRA}f 1//2 2 3\ng\nvn 0 0 1\nvt 1\n"),
        format!("{TETRA}usemtl\nf 1 2 3\nf 1 2 3/1/1/1\n"),
        format!("# é\n{TETRA}f\u{3000}1 2 3\n"),
        "f 1 2 3\n".to_owned(),
        String::new(),
    ];
    for (index, text) in cases.iter().enumerate() {
        assert_same_in_pieces(text, &format!("case {index}"));
    }
}

/// Lines of RICH moved, dropped and repeated: faces ahead of vertices, across
/// groups and pieces.
#[test]
fn shuffled_files_read_in_pieces_as_whole() {
    let lines: Vec<&str> = RICH.lines().collect();
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut below = |n: usize| {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_f491_4f6c_dd1d) % n as u64) as usize
    };
    for case in 0..400 {
        let mut shuffled = lines.clone();
        for _ in 0..1 + below(4) {
            let line = shuffled.remove(below(shuffled.len()));
            match below(3) {
                0 => {}
                1 => shuffled.insert(below(shuffled.len() + 1), line),
                _ => {
                    shuffled.insert(below(shuffled.len() + 1), line);
                    shuffled.insert(below(shuffled.len() + 1), line);
                }
            }
        }
        let text = shuffled.join("\n") + "\n";
        assert_same_in_pieces(&text, &format!("case {case}: {text:?}"));
    }
}

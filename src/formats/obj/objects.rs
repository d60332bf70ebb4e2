//! The objects of an OBJ file (`o NAME` lines) and one of them picked by
//! name: its faces and the vertices they use, re-indexed in file order, as
//! OBJ text of its own that the reader then reads. Texture coordinates,
//! groups, materials and material libraries come along; normals do not (a
//! deformation recomputes them). An `o` name written twice is one object.

use super::super::error::ObjectError;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// The names of the file's `o` lines, in order of first appearance.
pub(in crate::formats) fn object_names(text: &str) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for line in text.lines() {
        if let Some(name) = object_line(line) {
            if !names.iter().any(|n| n == name) {
                names.push(name.to_owned());
            }
        }
    }
    names
}

/// The name an `o` line gives, if `line` is one.
fn object_line(line: &str) -> Option<&str> {
    let line = line.trim_start();
    let rest = line.strip_prefix('o')?;
    (rest.is_empty() || rest.starts_with(char::is_whitespace)).then(|| rest.trim())
}

/// An index as written resolved to 0-based, counting back from `so_far` when
/// negative; `None` for what the reader would refuse (it read the file first).
fn resolve(written: &str, so_far: usize) -> Option<usize> {
    let index: i64 = written.parse().ok()?;
    match index {
        0 => None,
        i if i < 0 => usize::try_from(so_far as i64 + i).ok(),
        i => Some(i as usize - 1),
    }
}

/// Object `name` of the OBJ `text` (which the reader has read whole) as OBJ
/// text of its own.
pub(in crate::formats) fn object_text(text: &str, name: &str) -> Result<String, ObjectError> {
    let names = object_names(text);
    if !names.iter().any(|n| n == name) {
        return Err(ObjectError::NotFound {
            name: name.to_owned(),
            names,
        });
    }
    let (mut vertices, mut uvs) = (Vec::new(), Vec::new());
    let mut inside = false;
    // Lines of the object after its `o` lines, its faces' corners resolved.
    let mut body: Vec<Line> = Vec::new();
    let mut libraries = String::new();
    let mut own_vertices = Vec::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                if inside {
                    own_vertices.push(vertices.len());
                }
                vertices.push(line);
            }
            Some("vt") => uvs.push(line),
            Some("mtllib") => {
                let _ = writeln!(libraries, "{line}");
            }
            Some("o") => inside = object_line(line) == Some(name),
            Some("f") if inside => {
                let corners = words
                    .map(|corner| {
                        let mut parts = corner.split('/');
                        let v = parts.next().and_then(|v| resolve(v, vertices.len()));
                        let t = parts.next().and_then(|t| resolve(t, uvs.len()));
                        (v.unwrap_or(usize::MAX), t)
                    })
                    .collect();
                body.push(Line::Face(corners));
            }
            Some("g" | "usemtl" | "s") if inside => body.push(Line::Kept(line)),
            _ => {}
        }
    }
    let faces = body.iter().any(|l| matches!(l, Line::Face(_)));
    // Used vertices and texture coordinates, new indices in file order.
    let mut new_vertex: BTreeMap<usize, usize> = BTreeMap::new();
    let mut new_uv: BTreeMap<usize, usize> = BTreeMap::new();
    if faces {
        for line in &body {
            if let Line::Face(corners) = line {
                for &(v, t) in corners {
                    new_vertex.insert(v, 0);
                    if let Some(t) = t {
                        new_uv.insert(t, 0);
                    }
                }
            }
        }
    } else {
        // An object of points: the vertices written under its name.
        new_vertex.extend(own_vertices.iter().map(|&v| (v, 0)));
    }
    for (k, slot) in new_vertex.values_mut().enumerate() {
        *slot = k + 1;
    }
    for (k, slot) in new_uv.values_mut().enumerate() {
        *slot = k + 1;
    }
    let mut out = format!("# object '{name}', read by pmvc: its faces and the vertices they use\n");
    out.push_str(&libraries);
    let _ = writeln!(out, "o {name}");
    for &old in new_vertex.keys() {
        if let Some(line) = vertices.get(old) {
            let _ = writeln!(out, "{line}");
        }
    }
    for &old in new_uv.keys() {
        if let Some(line) = uvs.get(old) {
            let _ = writeln!(out, "{line}");
        }
    }
    for line in &body {
        match line {
            Line::Kept(text) => {
                let _ = writeln!(out, "{text}");
            }
            Line::Face(corners) => {
                out.push('f');
                for (v, t) in corners {
                    let _ = write!(out, " {}", new_vertex[v]);
                    if let Some(t) = t {
                        let _ = write!(out, "/{}", new_uv[t]);
                    }
                }
                out.push('\n');
            }
        }
    }
    Ok(out)
}

/// A line of the picked object.
enum Line<'a> {
    /// `g`, `usemtl` or `s`, as written.
    Kept(&'a str),
    /// Corners: 0-based vertex and texture coordinate.
    Face(Vec<(usize, Option<usize>)>),
}

#[cfg(test)]
mod tests {
    use super::*;

    const TWO: &str = "mtllib m.mtl\no first\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\
        o second\nv 5 0 0\nv 6 0 0\nv 5 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl red\nf -3/1 -2/2 -1/3\n";

    #[test]
    fn a_picked_object_is_its_faces_and_vertices_reindexed() {
        assert_eq!(object_names(TWO), ["first", "second"]);
        let second = object_text(TWO, "second").unwrap();
        let lines: Vec<&str> = second.lines().skip(1).collect();
        assert_eq!(
            lines,
            [
                "mtllib m.mtl",
                "o second",
                "v 5 0 0",
                "v 6 0 0",
                "v 5 1 0",
                "vt 0 0",
                "vt 1 0",
                "vt 0 1",
                "usemtl red",
                "f 1/1 2/2 3/3"
            ]
        );
        let error = object_text(TWO, "third").unwrap_err().to_string();
        assert_eq!(
            error,
            "no object is named 'third'; the file has 2 objects: 'first', 'second'"
        );
    }
}

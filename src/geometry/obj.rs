//! Wavefront OBJ, read in one pass over the text, keeping the file's vertex order.
//!
//! Read: `v` (x y z, x y z w, or x y z r g b; the coordinates in f64), `f` with
//! `v`, `v/vt`, `v//vn` and `v/vt/vn` corners and negative (relative) indices,
//! polygons (cut by [`triangulate_polygon`]). Checked, then dropped: `vt`, `vn`,
//! `o`/`g` groups and `usemtl`. Skipped: comments, `l` polylines, `mtllib` and
//! unknown keywords. OBJ has no line continuations here, as it had none in tobj.
//!
//! This reader replaced tobj, which made a copy of the text and a hash map per
//! group; it accepts and refuses the same files, tobj's rules included
//! (tests/obj_reader.rs compares the two on the bundled and shared meshes and on
//! mutated files), and names the line in every message:
//! - a `vt` line has two or three numbers;
//! - a corner's texture and normal parts, when written, are integers, and a
//!   corner has at most three parts;
//! - indices are checked against what the file has defined by the end of the
//!   face's group (`o` or `g` after faces, or the end of the file): a face may
//!   refer ahead within its group, not past it. Texture and normal indices are
//!   checked only where the file has any, and index 0, or a relative one just
//!   past the start, means "none", as tobj read them;
//! - `usemtl` names a material (after the first space, as tobj split it).
//!
//! tobj stays as the reference of those tests, not as a fallback: nothing it read
//! is left to it.

use super::{triangulate_polygon, LoadError, MeshFile, MeshFormat, TriMesh};
use glam::DVec3;
use std::path::Path;

/// The most vertices a mesh file may have (so that every index fits a `u32`
/// with room, and as many as pmvc has always read).
pub(super) const MAX_VERTICES: usize = 1 << 24;

/// What tobj read a corner part of `0` (or a relative index one before the
/// first element) as: no index.
const NO_INDEX: usize = usize::MAX;

pub(super) fn parse_obj(path: &Path, text: String) -> Result<MeshFile, LoadError> {
    let mesh = Reader::new(path, &text).read()?;
    Ok(MeshFile {
        path: path.to_owned(),
        format: MeshFormat::Obj,
        mesh,
        obj_text: Some(text),
    })
}

/// What a face refers to, for the checks made when its group ends.
#[derive(Clone, Copy)]
enum Element {
    Vertex,
    TextureCoordinate,
    Normal,
}

/// An index a face wrote ahead of what the file had defined at its line.
struct Ahead {
    line: usize,
    /// 1-based.
    face: usize,
    element: Element,
    /// 0-based, as resolved against the counts at the face's line.
    index: usize,
    written: i64,
}

struct Reader<'a> {
    path: &'a Path,
    text: &'a str,
    mesh: TriMesh,
    faces: usize,
    texture_coordinates: usize,
    normals: usize,
    /// `v` lines in the whole file, counted when a face first refers past the
    /// vertices read so far.
    total_vertices: Option<usize>,
    /// Faces since the last group started.
    group_faces: usize,
    ahead: Vec<Ahead>,
    /// Quads referring to vertices not read yet: their two triangles' slot and
    /// corners, cut once every position is known.
    quads_ahead: Vec<(usize, [u32; 4])>,
    /// The first error by tobj's rules; errors of the checks made at each line
    /// come first, as they did when those checks ran before tobj.
    group_error: Option<LoadError>,
    corners: Vec<u32>,
}

/// Whitespace as `str::split_whitespace` splits ASCII text.
fn is_space(byte: u8) -> bool {
    matches!(byte, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
}

/// The words of `line`, split as `str::split_whitespace` splits them; ASCII text
/// byte by byte.
#[derive(Clone)]
enum Words<'a> {
    Ascii(&'a str, usize),
    Unicode(std::str::SplitWhitespace<'a>),
}

impl<'a> Iterator for Words<'a> {
    type Item = &'a str;

    fn next(&mut self) -> Option<&'a str> {
        match self {
            Words::Unicode(words) => words.next(),
            Words::Ascii(line, at) => {
                let bytes = line.as_bytes();
                let mut start = *at;
                while start < bytes.len() && is_space(bytes[start]) {
                    start += 1;
                }
                if start == bytes.len() {
                    *at = start;
                    return None;
                }
                let mut end = start + 1;
                while end < bytes.len() && !is_space(bytes[end]) {
                    end += 1;
                }
                *at = end;
                Some(&line[start..end])
            }
        }
    }
}

impl<'a> Reader<'a> {
    fn new(path: &'a Path, text: &'a str) -> Self {
        Reader {
            path,
            text,
            mesh: TriMesh::default(),
            faces: 0,
            texture_coordinates: 0,
            normals: 0,
            total_vertices: None,
            group_faces: 0,
            ahead: Vec::new(),
            quads_ahead: Vec::new(),
            group_error: None,
            corners: Vec::new(),
        }
    }

    fn parse_error(&self, line: usize, message: String) -> LoadError {
        LoadError::Parse {
            path: self.path.to_owned(),
            line,
            message,
        }
    }

    fn read(mut self) -> Result<TriMesh, LoadError> {
        let text = self.text;
        let ascii = text.is_ascii();
        for (line_index, line) in text.lines().enumerate() {
            let line_number = line_index + 1;
            let mut words = if ascii {
                Words::Ascii(line, 0)
            } else {
                Words::Unicode(line.split_whitespace())
            };
            match words.next() {
                Some("v") => self.vertex(line_number, words)?,
                Some("f") => self.face(line_number, words)?,
                Some(keyword @ ("vn" | "vt")) => self.attribute(line_number, keyword, words)?,
                Some("o" | "g") if self.group_faces > 0 => self.end_group(),
                Some("usemtl") if self.group_error.is_none() => {
                    // tobj took the name after the first space, and refused none.
                    let name = line.split_once(' ').unwrap_or_default().1.trim();
                    if name.is_empty() {
                        self.group_error = Some(
                            self.parse_error(line_number, "usemtl names no material".to_owned()),
                        );
                    }
                }
                _ => {}
            }
        }
        self.end_group();
        if self.mesh.positions.is_empty() {
            return Err(LoadError::NoVertices {
                path: self.path.to_owned(),
            });
        }
        if self.mesh.positions.len() > MAX_VERTICES {
            return Err(LoadError::TooLarge {
                path: self.path.to_owned(),
                count: self.mesh.positions.len(),
                limit: MAX_VERTICES,
            });
        }
        if let Some(error) = self.group_error {
            return Err(error);
        }
        let mut triangles = Vec::with_capacity(2);
        for &(slot, quad) in &self.quads_ahead {
            triangles.clear();
            triangulate_polygon(&quad, &self.mesh.positions, &mut triangles);
            self.mesh.triangles[slot..slot + 2].copy_from_slice(&triangles);
        }
        Ok(self.mesh)
    }

    fn vertex(&mut self, line_number: usize, mut words: Words) -> Result<(), LoadError> {
        let vertex = self.mesh.positions.len();
        let mut coordinate = [0.0f64; 3];
        for (axis, value) in coordinate.iter_mut().enumerate() {
            let word = words.next().ok_or_else(|| {
                self.parse_error(
                    line_number,
                    format!("vertex {vertex} has {axis} coordinates, expected 3"),
                )
            })?;
            *value = word.parse().map_err(|_| {
                self.parse_error(
                    line_number,
                    format!("vertex {vertex}: '{}' is not a number", quoted(word)),
                )
            })?;
        }
        // Accepted: x y z, x y z w, and x y z r g b (vertex colours).
        let mut extra = [""; 3];
        let mut extras = 0;
        for word in words {
            if extras < extra.len() {
                extra[extras] = word;
            }
            extras += 1;
        }
        if !matches!(extras, 0 | 1 | 3) {
            return Err(self.parse_error(
                line_number,
                format!(
                    "vertex {vertex} has {} numbers; expected x y z, x y z w or x y z r g b",
                    3 + extras
                ),
            ));
        }
        if let Some(word) = extra[..extras]
            .iter()
            .find(|word| word.parse::<f64>().is_err())
        {
            return Err(self.parse_error(
                line_number,
                format!("vertex {vertex}: '{}' is not a number", quoted(word)),
            ));
        }
        if !coordinate.iter().all(|c| c.is_finite()) {
            return Err(LoadError::NonFinite {
                path: self.path.to_owned(),
                line: line_number,
                vertex: vertex + 1,
            });
        }
        self.mesh.positions.push(DVec3::from_array(coordinate));
        Ok(())
    }

    /// `vn` and `vt`: checked so that a bad number names its line.
    fn attribute(
        &mut self,
        line_number: usize,
        keyword: &str,
        words: Words,
    ) -> Result<(), LoadError> {
        let (element, counts) = if keyword == "vn" {
            ("normal", 3..=3)
        } else {
            ("texture coordinate", 1..=3)
        };
        let count = words.clone().count();
        if !counts.contains(&count) {
            return Err(self.parse_error(line_number, format!("{element} has {count} numbers")));
        }
        if let Some(word) = words.clone().find(|word| word.parse::<f64>().is_err()) {
            return Err(self.parse_error(
                line_number,
                format!("{element}: '{}' is not a number", quoted(word)),
            ));
        }
        if keyword == "vn" {
            self.normals += 1;
        } else if count == 1 {
            self.refuse_by_group_rules(
                line_number,
                "texture coordinate has 1 number; expected u v or u v w".to_owned(),
            );
        } else {
            self.texture_coordinates += 1;
        }
        Ok(())
    }

    /// Record the first error of tobj's rules; reading goes on, as the checks
    /// made at each line came first.
    fn refuse_by_group_rules(&mut self, line_number: usize, message: String) {
        if self.group_error.is_none() {
            self.group_error = Some(self.parse_error(line_number, message));
        }
    }

    /// `v` lines in the whole file.
    fn total_vertices(&mut self) -> usize {
        let text = self.text;
        *self.total_vertices.get_or_insert_with(|| {
            text.lines()
                .filter(|line| line.split_whitespace().next() == Some("v"))
                .count()
        })
    }

    fn face(&mut self, line_number: usize, words: Words) -> Result<(), LoadError> {
        // The face's number in messages, from 1; its triangles' face from 0.
        let face = self.faces + 1;
        let corner_count = words.clone().count();
        if corner_count < 3 {
            return Err(self.parse_error(
                line_number,
                format!("face {face} has {corner_count} corners; a face needs at least 3"),
            ));
        }
        let read = self.mesh.positions.len();
        self.corners.clear();
        for word in words {
            let mut parts = word.split('/');
            let vertex_text = parts.next().unwrap_or("");
            let index: i64 = vertex_text.parse().map_err(|_| {
                self.parse_error(
                    line_number,
                    // 0-based, as this message has always numbered it.
                    format!(
                        "face {}: '{}' is not a vertex index",
                        face - 1,
                        quoted(word)
                    ),
                )
            })?;
            let resolved = if index < 0 {
                read as i64 + index
            } else {
                index - 1
            };
            let behind = index != 0 && resolved >= 0 && (index < 0 || resolved < read as i64);
            if !behind {
                let count = self.total_vertices();
                if index == 0 || resolved < 0 || resolved >= count as i64 {
                    return Err(LoadError::IndexOutOfRange {
                        path: self.path.to_owned(),
                        line: line_number,
                        face,
                        index,
                        count,
                    });
                }
                self.ahead.push(Ahead {
                    line: line_number,
                    face,
                    element: Element::Vertex,
                    index: resolved as usize,
                    written: index,
                });
            }
            self.corners.push(resolved as u32);
            if self.group_error.is_none() {
                self.corner_parts(line_number, face, word, parts);
            }
        }
        self.faces += 1;
        self.group_faces += 1;
        let first = self.mesh.triangles.len();
        let corners = std::mem::take(&mut self.corners);
        match corners[..] {
            [a, b, c, d] if [a, b, c, d].iter().any(|&i| i as usize >= read) => {
                // Cut once the positions it needs are read.
                self.quads_ahead.push((first, [a, b, c, d]));
                self.mesh.triangles.extend([[a, b, c], [a, c, d]]);
            }
            _ => triangulate_polygon(&corners, &self.mesh.positions, &mut self.mesh.triangles),
        }
        self.corners = corners;
        let added = self.mesh.triangles.len() - first;
        self.mesh
            .triangle_faces
            .extend(std::iter::repeat_n((face - 1) as u32, added));
        Ok(())
    }

    /// A corner's texture and normal parts, by tobj's rules: integers where
    /// written, at most three parts; indices past what is defined are checked
    /// when the group ends.
    fn corner_parts<'w>(
        &mut self,
        line_number: usize,
        face: usize,
        word: &str,
        parts: impl Iterator<Item = &'w str>,
    ) {
        for (part, text) in parts.enumerate() {
            if text.is_empty() {
                continue;
            }
            let (element, count, what) = match part {
                0 => (
                    Element::TextureCoordinate,
                    self.texture_coordinates,
                    "texture coordinate",
                ),
                1 => (Element::Normal, self.normals, "normal"),
                _ => {
                    return self.refuse_by_group_rules(
                        line_number,
                        format!(
                            "face {face}: '{}' has more than three parts (v/vt/vn)",
                            quoted(word)
                        ),
                    )
                }
            };
            let Ok(written) = text.parse::<isize>() else {
                return self.refuse_by_group_rules(
                    line_number,
                    format!(
                        "face {face}: '{}' has a {what} index that is not an integer",
                        quoted(word)
                    ),
                );
            };
            // As tobj resolved them, wrapping: 0 and one before the start are "none".
            let index = if written < 0 {
                (count as isize).wrapping_add(written) as usize
            } else {
                (written - 1) as usize
            };
            if index != NO_INDEX && index >= count {
                self.ahead.push(Ahead {
                    line: line_number,
                    face,
                    element,
                    index,
                    written: written as i64,
                });
            }
        }
    }

    /// An `o` or `g` line after faces, or the end of the file: what the group's
    /// faces referred to ahead must be defined by now.
    fn end_group(&mut self) {
        self.group_faces = 0;
        let ahead = std::mem::take(&mut self.ahead);
        if self.group_error.is_some() {
            return;
        }
        for ahead in ahead {
            let (count, what) = match ahead.element {
                Element::Vertex => (self.mesh.positions.len(), "vertex"),
                Element::TextureCoordinate => (self.texture_coordinates, "texture coordinate"),
                Element::Normal => (self.normals, "normal"),
            };
            // Texture and normal indices count only where the file has any.
            let checked = matches!(ahead.element, Element::Vertex) || count > 0;
            if checked && ahead.index >= count {
                let error = self.parse_error(
                    ahead.line,
                    format!(
                        "face {} refers to {what} {}, but only {count} are defined by the end of its group",
                        ahead.face, ahead.written
                    ),
                );
                self.group_error = Some(error);
                return;
            }
        }
    }
}

/// A token as messages quote it: at most 40 characters, so that a runaway token
/// (a 2 MB line of digits) does not flood the terminal.
fn quoted(token: &str) -> String {
    const SHOWN: usize = 40;
    match token.char_indices().nth(SHOWN) {
        Some((end, _)) => format!("{}… ({} bytes)", &token[..end], token.len()),
        None => token.to_owned(),
    }
}

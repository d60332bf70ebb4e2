//! One piece of an OBJ file's text, read line by line (see the parent module for
//! what is read and the rules kept from tobj).

use crate::formats::LoadError;
use crate::geometry::{triangulate_polygon, TriMesh};
use glam::DVec3;
use std::path::Path;

/// What tobj read a corner part of `0` (or a relative index one before the
/// first element) as: no index.
const NO_INDEX: usize = usize::MAX;

/// What a face refers to, for the checks made when its group ends.
#[derive(Clone, Copy)]
enum Element {
    Vertex,
    TextureCoordinate,
    Normal,
}

/// An index a face wrote ahead of what the file had defined at its line.
pub(super) struct Ahead {
    line: usize,
    /// 1-based.
    face: usize,
    element: Element,
    /// 0-based, as resolved against the counts at the face's line.
    index: usize,
    written: i64,
}

/// Elements defined so far in the file.
#[derive(Clone, Copy, Default)]
pub(super) struct Counts {
    pub vertices: usize,
    pub texture_coordinates: usize,
    pub normals: usize,
}

/// What comes before a piece of text: its lines, elements and faces.
#[derive(Clone, Copy, Default)]
pub(super) struct Start {
    pub lines: usize,
    pub counts: Counts,
    pub faces: usize,
}

/// An `o` or `g` line: where a group ends, with the counts there.
pub(super) struct GroupEnd {
    pub line: usize,
    pub counts: Counts,
}

/// A piece read: its share of the mesh, and what is left to check against the
/// pieces after it.
#[derive(Default)]
pub(super) struct Piece {
    pub mesh: TriMesh,
    /// Quads, cut once every position is known: their first triangle's slot in
    /// `mesh.triangles` and their corners.
    pub quads: Vec<(usize, [u32; 4])>,
    /// The piece's first `o` or `g` line, where indices written ahead before
    /// the piece are checked.
    pub first_group_end: Option<GroupEnd>,
    /// Indices written ahead after the piece's last `o` or `g` line.
    pub carried: Vec<Ahead>,
    /// The first error by tobj's rules, and the line where tobj met it (a
    /// group's end for an index past it); errors of the checks made at each
    /// line come before any of these, as they did when they ran before tobj.
    pub group_error: Option<(usize, LoadError)>,
}

/// The first of `ahead` past what `counts` has, as an error.
pub(super) fn check_ahead(path: &Path, ahead: &[Ahead], counts: Counts) -> Option<LoadError> {
    ahead.iter().find_map(|ahead| {
        let (count, what) = match ahead.element {
            Element::Vertex => (counts.vertices, "vertex"),
            Element::TextureCoordinate => (counts.texture_coordinates, "texture coordinate"),
            Element::Normal => (counts.normals, "normal"),
        };
        // Texture and normal indices count only where the file has any.
        let checked = matches!(ahead.element, Element::Vertex) || count > 0;
        (checked && ahead.index >= count).then(|| LoadError::Parse {
            path: path.to_owned(),
            line: ahead.line,
            message: format!(
                "face {} refers to {what} {}, but only {count} are defined by the end of its group",
                ahead.face, ahead.written
            ),
        })
    })
}

/// The first word of `line`: what kind of line it is.
pub(super) fn keyword(line: &str, ascii: bool) -> Option<&str> {
    words(line, ascii).next()
}

fn words(line: &str, ascii: bool) -> Words<'_> {
    if ascii {
        Words::Ascii(line, 0)
    } else {
        Words::Unicode(line.split_whitespace())
    }
}

pub(super) struct Reader<'a> {
    path: &'a Path,
    start: Start,
    /// `v` lines in the whole file.
    total_vertices: usize,
    piece: Piece,
    /// Counts within the piece.
    local: Counts,
    faces: usize,
    ahead: Vec<Ahead>,
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
    /// A reader of the text after `start`, in a file of `total_vertices`;
    /// `holds` is what the piece's lines hold, counted before.
    pub fn new(path: &'a Path, start: Start, total_vertices: usize, holds: &Start) -> Self {
        let mut piece = Piece::default();
        piece.mesh.positions.reserve_exact(holds.counts.vertices);
        // Each face makes at least a triangle.
        piece.mesh.triangles.reserve(holds.faces);
        piece.mesh.triangle_faces.reserve(holds.faces);
        Reader {
            path,
            start,
            total_vertices,
            piece,
            local: Counts::default(),
            faces: 0,
            ahead: Vec::new(),
            corners: Vec::new(),
        }
    }

    /// What the file has defined so far.
    fn counts(&self) -> Counts {
        let (start, local) = (self.start.counts, self.local);
        Counts {
            vertices: start.vertices + local.vertices,
            texture_coordinates: start.texture_coordinates + local.texture_coordinates,
            normals: start.normals + local.normals,
        }
    }

    fn parse_error(&self, line: usize, message: String) -> LoadError {
        LoadError::Parse {
            path: self.path.to_owned(),
            line,
            message,
        }
    }

    /// Read `text`, the piece, checking every line; an error of the checks made
    /// at each line ends it.
    pub fn read(mut self, text: &str) -> Result<Piece, LoadError> {
        let ascii = text.is_ascii();
        for (line_index, line) in text.lines().enumerate() {
            let line_number = self.start.lines + line_index + 1;
            let mut words = words(line, ascii);
            match words.next() {
                Some("v") => self.vertex(line_number, words)?,
                Some("f") => self.face(line_number, words)?,
                Some(keyword @ ("vn" | "vt")) => self.attribute(line_number, keyword, words)?,
                // Indices written ahead exist only where the group has faces, and
                // tobj ended a group with faces at any `o` or `g` line.
                Some("o" | "g") => self.end_group(line_number),
                Some("usemtl") => {
                    // tobj took the name after the first space and refused an empty one.
                    let name = line.split_once(' ').unwrap_or_default().1.trim();
                    if name.is_empty() {
                        self.refuse_by_group_rules(
                            line_number,
                            line_number,
                            "usemtl names no material".to_owned(),
                        );
                    }
                }
                _ => {}
            }
        }
        self.piece.carried = std::mem::take(&mut self.ahead);
        Ok(self.piece)
    }

    fn vertex(&mut self, line_number: usize, mut words: Words) -> Result<(), LoadError> {
        let vertex = self.counts().vertices;
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
        self.piece
            .mesh
            .positions
            .push(DVec3::from_array(coordinate));
        self.local.vertices += 1;
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
            self.local.normals += 1;
        } else {
            if count == 1 {
                self.refuse_by_group_rules(
                    line_number,
                    line_number,
                    "texture coordinate has 1 number; expected u v or u v w".to_owned(),
                );
            }
            // Counted as the census before reading counts it.
            self.local.texture_coordinates += 1;
        }
        Ok(())
    }

    /// Record the first error of tobj's rules, met at `at`; reading goes on, as
    /// the checks made at each line came first.
    fn refuse_by_group_rules(&mut self, at: usize, line_number: usize, message: String) {
        if self.piece.group_error.is_none() {
            let error = LoadError::Parse {
                path: self.path.to_owned(),
                line: line_number,
                message,
            };
            self.piece.group_error = Some((at, error));
        }
    }

    /// An `o` or `g` line: what the group's faces wrote ahead must be defined
    /// by now.
    fn end_group(&mut self, line_number: usize) {
        let counts = self.counts();
        self.piece.first_group_end.get_or_insert(GroupEnd {
            line: line_number,
            counts,
        });
        let ahead = std::mem::take(&mut self.ahead);
        if self.piece.group_error.is_none() {
            if let Some(error) = check_ahead(self.path, &ahead, counts) {
                self.piece.group_error = Some((line_number, error));
            }
        }
    }

    fn face(&mut self, line_number: usize, words: Words) -> Result<(), LoadError> {
        // The face's number in messages, from 1; its triangles' face from 0.
        let face = self.start.faces + self.faces + 1;
        let corner_count = words.clone().count();
        if corner_count < 3 {
            return Err(self.parse_error(
                line_number,
                format!("face {face} has {corner_count} corners; a face needs at least 3"),
            ));
        }
        let read = self.counts().vertices;
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
                let count = self.total_vertices;
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
            if self.piece.group_error.is_none() {
                self.corner_parts(line_number, face, word, parts);
            }
        }
        self.faces += 1;
        let triangles = &mut self.piece.mesh.triangles;
        let first = triangles.len();
        match self.corners[..] {
            // Cut once every position is known: it may refer to any vertex.
            [a, b, c, d] => {
                self.piece.quads.push((first, [a, b, c, d]));
                triangles.extend([[a, b, c], [a, c, d]]);
            }
            // Triangles and fans need no positions.
            _ => triangulate_polygon(&self.corners, &[], triangles),
        }
        let added = triangles.len() - first;
        self.piece
            .mesh
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
                    self.counts().texture_coordinates,
                    "texture coordinate",
                ),
                1 => (Element::Normal, self.counts().normals, "normal"),
                _ => {
                    return self.refuse_by_group_rules(
                        line_number,
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

//! Wavefront OBJ, read directly, keeping the file's vertex order.
//!
//! Read: `v` (x y z, x y z w, or x y z r g b; the coordinates in f64), `f` with
//! `v`, `v/vt`, `v//vn` and `v/vt/vn` corners and negative (relative) indices,
//! polygons (cut by [`triangulate_polygon`]). Checked, then dropped: `vt`, `vn`,
//! `o`/`g` groups and `usemtl`. Skipped: comments, `l` polylines, `mtllib` and
//! unknown keywords. There are no line continuations, as tobj had none.
//! One `o` object is read alone by name through [`pick_object`] ([`objects`]).
//!
//! The text is cut into pieces at line ends and read on every core: a first pass
//! counts each piece's lines, vertices, texture coordinates, normals and faces, so
//! that the second can read each piece knowing what comes before it
//! ([`reader`]); quads are cut once every position is known.
//!
//! This reader replaced tobj, which read a copy of the text with every `v` line
//! rewritten as its ordinal, into a hash map per group. It accepts and refuses
//! the same files, tobj's rules included (tests/geometry/obj_reader.rs compares the two on
//! the bundled and shared meshes, hand-written cases and mutated files), and
//! names the line in every message:
//! - a `vt` line has two or three numbers;
//! - a corner's texture and normal parts, when written, are integers, and a
//!   corner has at most three parts;
//! - indices are checked against what the file has defined by the end of the
//!   face's group (an `o` or `g` line after faces, or the end of the file): a
//!   face may refer ahead within its group, not past it. Texture and normal
//!   indices are checked only where the file has any; index 0, or a relative one
//!   just before the first, means "none", as tobj read them;
//! - `usemtl` names a material (after the first space, as tobj split the line).
//!
//! Errors of the checks made at each line come first (the first in the file),
//! then a file with no vertices or too many, then the first error by tobj's
//! rules, in the order tobj met them. tobj stays only as the tests' reference:
//! nothing it read is left to it, so it is no fallback.

mod objects;
mod reader;

use super::{LoadError, MeshFile, MeshFormat};
use crate::geometry::{triangulate_polygon, TriMesh};
use rayon::prelude::*;
use reader::{check_ahead, keyword, Counts, Piece, Reader, Start};
use std::path::Path;

/// The most vertices a mesh file may have (so that every index fits a `u32`
/// with room, and as many as pmvc has always read).
pub(super) const MAX_VERTICES: usize = 1 << 24;

/// The smallest piece worth a task of its own.
const PIECE_BYTES: usize = 1 << 20;

pub(super) fn parse_obj(path: &Path, text: String) -> Result<MeshFile, LoadError> {
    let piece_bytes = PIECE_BYTES.max(text.len() / (4 * rayon::current_num_threads()));
    let mesh = read_in_pieces(path, &text, piece_bytes)?;
    Ok(MeshFile {
        path: path.to_owned(),
        format: MeshFormat::Obj,
        mesh,
        obj_text: Some(text),
        node_transform: None,
        object_note: None,
        objects: Default::default(),
    })
}

pub(in crate::formats) use objects::object_names;

/// Object `object` of the OBJ `file` (read whole) as a mesh file of its own,
/// or, without a name, `file` with a note where it has several objects.
pub(super) fn pick_object(
    path: &Path,
    mut file: MeshFile,
    object: Option<&str>,
) -> Result<MeshFile, LoadError> {
    let Some(text) = file.obj_text.as_deref() else {
        return Ok(file);
    };
    let names = object_names(text);
    let Some(name) = object else {
        if names.len() > 1 {
            file.object_note = Some(format!(
                "the file has {}, read together as one mesh",
                super::object_list(&names)
            ));
            file.objects.names = names;
        }
        return Ok(file);
    };
    let picked = objects::object_text(text, name).map_err(|source| LoadError::Object {
        path: path.to_owned(),
        source,
    })?;
    let mut file = parse_obj(path, picked)?;
    file.objects = super::FileObjects {
        read: Some(name.to_owned()),
        names: if names.len() > 1 { names } else { Vec::new() },
    };
    Ok(file)
}

/// `text` cut after the first line end past every `bytes` bytes.
fn pieces(text: &str, bytes: usize) -> Vec<&str> {
    let mut pieces = Vec::new();
    let mut rest = text;
    while rest.len() > bytes {
        let Some(end) = rest.as_bytes()[bytes..].iter().position(|&b| b == b'\n') else {
            break;
        };
        let (piece, after) = rest.split_at(bytes + end + 1);
        pieces.push(piece);
        rest = after;
    }
    if !rest.is_empty() || pieces.is_empty() {
        pieces.push(rest);
    }
    pieces
}

/// What `piece`'s lines hold, by their first word.
fn census(piece: &str) -> Start {
    let ascii = piece.is_ascii();
    let mut holds = Start::default();
    for line in piece.lines() {
        holds.lines += 1;
        match keyword(line, ascii) {
            Some("v") => holds.counts.vertices += 1,
            Some("vt") => holds.counts.texture_coordinates += 1,
            Some("vn") => holds.counts.normals += 1,
            Some("f") => holds.faces += 1,
            _ => {}
        }
    }
    holds
}

fn read_in_pieces(path: &Path, text: &str, piece_bytes: usize) -> Result<TriMesh, LoadError> {
    let pieces = pieces(text, piece_bytes);
    let holds: Vec<Start> = pieces.par_iter().map(|piece| census(piece)).collect();
    let mut starts = Vec::with_capacity(holds.len());
    let mut total = Start::default();
    for held in &holds {
        starts.push(total);
        total.lines += held.lines;
        total.faces += held.faces;
        total.counts.vertices += held.counts.vertices;
        total.counts.texture_coordinates += held.counts.texture_coordinates;
        total.counts.normals += held.counts.normals;
    }
    let read: Vec<Result<Piece, LoadError>> = (0..pieces.len())
        .into_par_iter()
        .map(|i| Reader::new(path, starts[i], total.counts.vertices, &holds[i]).read(pieces[i]))
        .collect();
    // The first error of the checks made at each line.
    let mut read = read
        .into_iter()
        .collect::<Result<Vec<Piece>, LoadError>>()?;
    if total.counts.vertices == 0 {
        return Err(LoadError::NoVertices {
            path: path.to_owned(),
        });
    }
    if total.counts.vertices > MAX_VERTICES {
        return Err(LoadError::TooLarge {
            path: path.to_owned(),
            count: total.counts.vertices,
            limit: MAX_VERTICES,
        });
    }
    if let Some(error) = first_group_error(path, &mut read, total.counts) {
        return Err(error);
    }
    let mut positions = Vec::with_capacity(total.counts.vertices);
    for piece in &mut read {
        positions.append(&mut piece.mesh.positions);
    }
    read.par_iter_mut().for_each(|piece| {
        let mut cut = Vec::with_capacity(2);
        for &(slot, quad) in &piece.quads {
            cut.clear();
            triangulate_polygon(&quad, &positions, &mut cut);
            piece.mesh.triangles[slot..slot + 2].copy_from_slice(&cut);
        }
    });
    let triangles: usize = read.iter().map(|piece| piece.mesh.triangles.len()).sum();
    let mut mesh = TriMesh {
        positions,
        triangles: Vec::with_capacity(triangles),
        triangle_faces: Vec::with_capacity(triangles),
    };
    for piece in &mut read {
        mesh.triangles.append(&mut piece.mesh.triangles);
        mesh.triangle_faces.append(&mut piece.mesh.triangle_faces);
    }
    Ok(mesh)
}

/// The first error by tobj's rules, in the order tobj met them: indices written
/// ahead in one piece are checked at the first group end in a later one, or at
/// the end of the file (`totals`).
fn first_group_error(path: &Path, read: &mut [Piece], totals: Counts) -> Option<LoadError> {
    let mut first: Option<(usize, LoadError)> = None;
    let mut keep = |at: usize, error: LoadError| {
        if first.as_ref().is_none_or(|(earlier, _)| at < *earlier) {
            first = Some((at, error));
        }
    };
    let mut carried = Vec::new();
    for piece in read.iter_mut() {
        if let Some(end) = &piece.first_group_end {
            if let Some(error) = check_ahead(path, &carried, end.counts) {
                keep(end.line, error);
            }
            carried.clear();
        }
        if let Some((at, error)) = piece.group_error.take() {
            keep(at, error);
        }
        carried.append(&mut piece.carried);
    }
    if let Some(error) = check_ahead(path, &carried, totals) {
        keep(usize::MAX, error);
    }
    first.map(|(_, error)| error)
}

#[cfg(test)]
mod tests;

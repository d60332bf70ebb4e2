//! The OBJ reader pmvc had before its own (`geometry/obj.rs`): the checks it made
//! itself, then tobj for the faces. Kept here as the reference the direct reader
//! is compared with (tests/geometry/obj_reader.rs).
//!
//! tobj splits a file into one model per `o`/`g` group and re-indexes each model's
//! vertices in first-use order, which loses the file's `v` order. To undo that, tobj
//! is given a copy of the text in which every `v` line carries its own ordinal
//! instead of its coordinates; each model's positions then name the original rows.
//! The coordinates themselves are read here, in f64.

use glam::DVec3;
use pmvc::formats::{LoadError, MeshFile, MeshFormat};
use pmvc::geometry::{triangulate_polygon, TriMesh};
use std::path::Path;

/// Largest vertex ordinal that survives the round trip through tobj's f32 positions.
pub const MAX_VERTICES: usize = 1 << 24;

pub fn parse_obj_with_tobj(path: &Path, text: String) -> Result<MeshFile, LoadError> {
    let parse_error = |line: usize, message: String| LoadError::Parse {
        path: path.to_owned(),
        line,
        message,
    };
    let mut positions = Vec::new();
    let mut ordinal_text = String::with_capacity(text.len());
    let mut face_count = 0usize;
    let total_vertices = count_vertices(&text);
    for (line_index, line) in text.lines().enumerate() {
        let line_number = line_index + 1;
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("v") => {
                let mut coordinate = [0.0f64; 3];
                for (axis, value) in coordinate.iter_mut().enumerate() {
                    let token = tokens.next().ok_or_else(|| {
                        parse_error(
                            line_number,
                            format!(
                                "vertex {} has {axis} coordinates, expected 3",
                                positions.len()
                            ),
                        )
                    })?;
                    *value = token.parse().map_err(|_| {
                        parse_error(
                            line_number,
                            format!(
                                "vertex {}: '{}' is not a number",
                                positions.len(),
                                quoted(token)
                            ),
                        )
                    })?;
                }
                // Accepted: x y z, x y z w, and x y z r g b (vertex colours).
                let extra: Vec<&str> = tokens.collect();
                if !matches!(extra.len(), 0 | 1 | 3) {
                    return Err(parse_error(
                        line_number,
                        format!(
                            "vertex {} has {} numbers; expected x y z, x y z w or x y z r g b",
                            positions.len(),
                            3 + extra.len()
                        ),
                    ));
                }
                if let Some(token) = extra.iter().find(|token| token.parse::<f64>().is_err()) {
                    return Err(parse_error(
                        line_number,
                        format!(
                            "vertex {}: '{}' is not a number",
                            positions.len(),
                            quoted(token)
                        ),
                    ));
                }
                if !coordinate.iter().all(|c| c.is_finite()) {
                    return Err(LoadError::NonFinite {
                        path: path.to_owned(),
                        line: line_number,
                        vertex: positions.len() + 1,
                    });
                }
                ordinal_text.push_str(&format!("v {} 0 0\n", positions.len()));
                positions.push(DVec3::from_array(coordinate));
                continue;
            }
            Some(keyword @ ("vn" | "vt")) => {
                // Checked here so that a bad number names its line; the OBJ
                // library's own message would not.
                let (element, counts) = if keyword == "vn" {
                    ("normal", 3..=3)
                } else {
                    ("texture coordinate", 1..=3)
                };
                let values: Vec<&str> = tokens.collect();
                if !counts.contains(&values.len()) {
                    return Err(parse_error(
                        line_number,
                        format!("{element} has {} numbers", values.len()),
                    ));
                }
                if let Some(token) = values.iter().find(|token| token.parse::<f64>().is_err()) {
                    return Err(parse_error(
                        line_number,
                        format!("{element}: '{}' is not a number", quoted(token)),
                    ));
                }
            }
            Some("l") => {
                // A polyline, not a face; the OBJ library would read it as one.
                ordinal_text.push('\n');
                continue;
            }
            Some("f") => {
                // Checked here so that the error can name the line and the face.
                // The OBJ library drops faces of fewer than three corners, which
                // would shift the numbers of all later faces in messages.
                let corners = tokens.clone().count();
                if corners < 3 {
                    return Err(parse_error(
                        line_number,
                        format!(
                            "face {} has {corners} corners; a face needs at least 3",
                            face_count + 1
                        ),
                    ));
                }
                for token in tokens {
                    let index_text = token.split('/').next().unwrap_or("");
                    let index: i64 = index_text.parse().map_err(|_| {
                        parse_error(
                            line_number,
                            format!(
                                "face {face_count}: '{}' is not a vertex index",
                                quoted(token)
                            ),
                        )
                    })?;
                    let resolved = if index < 0 {
                        positions.len() as i64 + index
                    } else {
                        index - 1
                    };
                    let in_range = index != 0
                        && resolved >= 0
                        && (index < 0 || resolved < total_vertices as i64);
                    if !in_range {
                        return Err(LoadError::IndexOutOfRange {
                            path: path.to_owned(),
                            line: line_number,
                            face: face_count + 1,
                            index,
                            count: total_vertices,
                        });
                    }
                }
                face_count += 1;
            }
            _ => {}
        }
        ordinal_text.push_str(line);
        ordinal_text.push('\n');
    }
    if positions.is_empty() {
        return Err(LoadError::NoVertices {
            path: path.to_owned(),
        });
    }
    if positions.len() > MAX_VERTICES {
        return Err(LoadError::TooLarge {
            path: path.to_owned(),
            count: positions.len(),
            limit: MAX_VERTICES,
        });
    }

    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) = tobj::load_obj_buf(&mut ordinal_text.as_bytes(), &options, |_| {
        Ok((Vec::new(), Default::default()))
    })
    .map_err(|error| LoadError::Obj {
        path: path.to_owned(),
        message: error.to_string(),
    })?;

    let mut mesh = TriMesh {
        positions,
        ..Default::default()
    };
    let mut corners = Vec::new();
    let mut face = 0u32;
    for model in &models {
        let to_file_row = |local: u32| model.mesh.positions[3 * local as usize] as u32;
        let arities: Vec<u32> = if model.mesh.face_arities.is_empty() {
            vec![3; model.mesh.indices.len() / 3]
        } else {
            model.mesh.face_arities.clone()
        };
        let mut next = 0usize;
        for arity in arities {
            corners.clear();
            corners.extend(
                model.mesh.indices[next..next + arity as usize]
                    .iter()
                    .map(|&i| to_file_row(i)),
            );
            next += arity as usize;
            let before = mesh.triangles.len();
            triangulate_polygon(&corners, &mesh.positions, &mut mesh.triangles);
            mesh.triangle_faces
                .extend(std::iter::repeat_n(face, mesh.triangles.len() - before));
            face += 1;
        }
    }
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

fn count_vertices(text: &str) -> usize {
    text.lines()
        .filter(|line| line.split_whitespace().next() == Some("v"))
        .count()
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

//! Object File Format (OFF), as used by the CC0 meshes of CGAL's demos.
//! Accepts `OFF`/`COFF`/`NOFF` headers, `#` comments and extra per-vertex or
//! per-face values (colours), which are ignored.

use super::{LoadError, MeshFile, MeshFormat};
use crate::geometry::{triangulate_polygon, TriMesh};
use glam::DVec3;
use std::path::Path;

pub(super) fn parse_off(path: &Path, text: &str) -> Result<MeshFile, LoadError> {
    let error = |line: usize, message: String| LoadError::Parse {
        path: path.to_owned(),
        line,
        message,
    };
    // Meaningful lines with their 1-based numbers, comments stripped.
    let mut lines = text.lines().enumerate().filter_map(|(index, line)| {
        let content = line.split('#').next().unwrap_or("").trim();
        (!content.is_empty()).then_some((index + 1, content))
    });

    let (header_line, header) = lines.next().ok_or_else(|| LoadError::Empty {
        path: path.to_owned(),
    })?;
    let mut header_tokens = header.split_whitespace();
    let keyword = header_tokens.next().unwrap_or("");
    if !keyword.ends_with("OFF") {
        return Err(error(
            header_line,
            format!("expected an OFF header, found '{keyword}'"),
        ));
    }
    // Counts may follow the keyword on the same line.
    let rest: Vec<&str> = header_tokens.collect();
    let (count_line, count_tokens): (usize, Vec<&str>) = if rest.is_empty() {
        let (number, line) = lines
            .next()
            .ok_or_else(|| error(header_line, "missing vertex and face counts".into()))?;
        (number, line.split_whitespace().collect())
    } else {
        (header_line, rest)
    };
    let parse_count = |index: usize, what: &str| -> Result<usize, LoadError> {
        count_tokens
            .get(index)
            .and_then(|token| token.parse().ok())
            .ok_or_else(|| error(count_line, format!("missing or invalid {what} count")))
    };
    let vertex_count = parse_count(0, "vertex")?;
    let face_count = parse_count(1, "face")?;

    let mut mesh = TriMesh::default();
    for vertex in 0..vertex_count {
        let (number, line) = lines.next().ok_or_else(|| {
            error(
                count_line,
                format!("the header promises {vertex_count} vertices, the file has {vertex}"),
            )
        })?;
        let mut coordinate = [0.0f64; 3];
        let mut tokens = line.split_whitespace();
        for value in &mut coordinate {
            let token = tokens.next().ok_or_else(|| {
                error(
                    number,
                    format!("vertex {vertex} has fewer than 3 coordinates"),
                )
            })?;
            *value = token.parse().map_err(|_| {
                error(
                    number,
                    format!("vertex {}: '{token}' is not a number", vertex + 1),
                )
            })?;
        }
        if !coordinate.iter().all(|c| c.is_finite()) {
            return Err(LoadError::NonFinite {
                path: path.to_owned(),
                line: number,
                vertex: vertex + 1,
            });
        }
        mesh.positions.push(DVec3::from_array(coordinate));
    }
    if mesh.positions.is_empty() {
        return Err(LoadError::NoVertices {
            path: path.to_owned(),
        });
    }

    let mut corners = Vec::new();
    for face in 0..face_count {
        let (number, line) = lines.next().ok_or_else(|| {
            error(
                count_line,
                format!("the header promises {face_count} faces, the file has {face}"),
            )
        })?;
        let mut tokens = line.split_whitespace();
        let arity: usize = tokens
            .next()
            .and_then(|token| token.parse().ok())
            .ok_or_else(|| error(number, format!("face {}: missing corner count", face + 1)))?;
        corners.clear();
        for _ in 0..arity {
            let token = tokens.next().ok_or_else(|| {
                error(
                    number,
                    format!("face {} lists fewer than {arity} corners", face + 1),
                )
            })?;
            let index: i64 = token.parse().map_err(|_| {
                error(
                    number,
                    format!("face {}: '{token}' is not a vertex index", face + 1),
                )
            })?;
            if index < 0 || index as usize >= mesh.positions.len() {
                return Err(LoadError::IndexOutOfRange {
                    path: path.to_owned(),
                    line: number,
                    face: face + 1,
                    index,
                    count: mesh.positions.len(),
                });
            }
            corners.push(index as u32);
        }
        let before = mesh.triangles.len();
        triangulate_polygon(&corners, &mesh.positions, &mut mesh.triangles);
        mesh.triangle_faces.extend(std::iter::repeat_n(
            face as u32,
            mesh.triangles.len() - before,
        ));
    }
    Ok(MeshFile {
        path: path.to_owned(),
        format: MeshFormat::Off,
        mesh,
        obj_text: None,
        node_transform: None,
        object_note: None,
        objects: Default::default(),
    })
}

//! From a mesh read from a file to glTF's vertices: the OBJ text's texture
//! coordinates and groups per triangle corner ([`Surface`]), then one glTF
//! vertex per (group, mesh vertex, texture coordinate) used ([`Layout`]).

use crate::budget::{bytes_for, check_memory, TooLarge};
use crate::formats::MeshFile;
use rayon::prelude::*;
use std::collections::HashMap;
use std::ops::Range;

/// No texture coordinate at a corner (a `vt` that is not finite counts as none).
const NONE: [f32; 2] = [f32::NAN, f32::NAN];

/// A group of faces: an OBJ's `g` or `o` name and its `usemtl` material.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub(super) struct Group {
    pub name: String,
    pub material: Option<String>,
}

/// What the file says of each triangle's corners beyond their vertices.
pub(super) struct Surface {
    pub groups: Vec<Group>,
    /// Per triangle, its group.
    pub triangle_groups: Vec<u32>,
    /// Per corner (three per triangle), its texture coordinate as OBJ writes it
    /// (v up), or [`NONE`]; empty where the file has none.
    pub corner_uvs: Vec<[f32; 2]>,
}

/// Memory [`Surface::of`] and [`Layout::of`] hold at their peak for a mesh of
/// `triangles`: the surface (4 + 3 · 8 bytes a triangle), the sorted keys
/// (24 bytes a corner) and each corner's vertex (4), then the layout's vertices
/// (at most one a corner: 12 bytes) and indices (4 a corner).
pub(super) fn layout_memory(triangles: usize) -> u64 {
    bytes_for(triangles as u64, 4 + 24 + 3 * (24 + 4 + 12 + 4))
}

impl Surface {
    /// The surface of `file`: from its OBJ text where it has one, else one
    /// unnamed group and no texture coordinates.
    pub fn of(file: &MeshFile) -> Surface {
        let triangles = file.mesh.triangles.len();
        let plain = Surface {
            groups: vec![Group::default()],
            triangle_groups: vec![0; triangles],
            corner_uvs: Vec::new(),
        };
        match &file.obj_text {
            Some(text) if file.mesh.triangle_faces.len() == triangles => {
                read_surface(text, file).unwrap_or(plain)
            }
            _ => plain,
        }
    }
}

/// An OBJ index as the reader resolves it: negative counts back from `so_far`,
/// positive from 1; `None` for 0, text that is no integer, or out of `0..count`.
fn resolve(text: &str, so_far: usize, count: usize) -> Option<usize> {
    let written: i64 = text.parse().ok()?;
    let index = match written {
        0 => return None,
        w if w < 0 => so_far as i64 + w,
        w => w - 1,
    };
    (0..count as i64).contains(&index).then_some(index as usize)
}

/// The words after an OBJ line's keyword, as one name.
fn rest_of_line<'a>(line: &'a str, keyword: &str) -> &'a str {
    line.trim_start()[keyword.len()..].trim()
}

/// Walk the OBJ text as the reader did: each `f` line is the next face, whose
/// triangles are the next run of `triangle_faces`; a triangle's corner takes
/// the texture coordinate written at the face's corner of the same vertex.
/// `None` where the text and the triangles disagree (never, for a file the
/// reader read), and the caller falls back to a plain surface.
fn read_surface(text: &str, file: &MeshFile) -> Option<Surface> {
    let mesh = &file.mesh;
    let texture_coordinates: Vec<[f32; 2]> = text
        .lines()
        .filter_map(|line| {
            let mut words = line.split_whitespace();
            (words.next() == Some("vt")).then(|| {
                let mut number = || words.next().and_then(|w| w.parse::<f64>().ok());
                let uv = [
                    number().unwrap_or(0.0) as f32,
                    number().unwrap_or(0.0) as f32,
                ];
                if uv.iter().all(|c| c.is_finite()) {
                    uv
                } else {
                    NONE
                }
            })
        })
        .collect();
    let has_uvs = !texture_coordinates.is_empty();
    let mut surface = Surface {
        groups: Vec::new(),
        triangle_groups: Vec::with_capacity(mesh.triangles.len()),
        corner_uvs: if has_uvs {
            Vec::with_capacity(3 * mesh.triangles.len())
        } else {
            Vec::new()
        },
    };
    let mut group_ids: HashMap<Group, u32> = HashMap::new();
    let mut current = Group::default();
    let mut current_id: Option<u32> = None;
    let (mut vertices, mut uvs_so_far, mut face) = (0usize, 0usize, 0u32);
    let mut next_triangle = 0usize;
    let mut corners: Vec<(Option<usize>, [f32; 2])> = Vec::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => vertices += 1,
            Some("vt") => uvs_so_far += 1,
            Some(keyword @ ("g" | "o")) => {
                current.name = rest_of_line(line, keyword).to_owned();
                current_id = None;
            }
            Some("usemtl") => {
                current.material = Some(rest_of_line(line, "usemtl").to_owned());
                current_id = None;
            }
            Some("f") => {
                corners.clear();
                for word in words {
                    let mut parts = word.split('/');
                    let vertex = resolve(parts.next()?, vertices, mesh.positions.len());
                    let uv = parts
                        .next()
                        .and_then(|t| resolve(t, uvs_so_far, texture_coordinates.len()))
                        .map_or(NONE, |i| texture_coordinates[i]);
                    corners.push((vertex, uv));
                }
                let id = *current_id.get_or_insert_with(|| {
                    let next = group_ids.len() as u32;
                    *group_ids.entry(current.clone()).or_insert_with(|| {
                        surface.groups.push(current.clone());
                        next
                    })
                });
                while mesh.triangle_faces.get(next_triangle) == Some(&face) {
                    surface.triangle_groups.push(id);
                    if has_uvs {
                        for vertex in mesh.triangles[next_triangle] {
                            let corner = corners.iter().find(|c| c.0 == Some(vertex as usize))?;
                            surface.corner_uvs.push(corner.1);
                        }
                    }
                    next_triangle += 1;
                }
                face += 1;
            }
            _ => {}
        }
    }
    if next_triangle != mesh.triangles.len() {
        return None;
    }
    if surface.groups.is_empty() {
        surface.groups.push(Group::default());
    }
    if surface.corner_uvs.iter().all(|uv| uv[0].is_nan()) {
        surface.corner_uvs = Vec::new();
    }
    Some(surface)
}

/// One primitive: its group, its vertices (a range of [`Layout::source`]) and
/// its triangles in indices from the range's start (empty for points).
pub(super) struct Primitive {
    pub group: Group,
    pub vertices: Range<usize>,
    pub indices: Vec<u32>,
    /// Whether any of its vertices has a texture coordinate.
    pub has_uvs: bool,
}

/// glTF's vertices for a mesh: primitive by primitive, each vertex once per
/// distinct texture coordinate at its corners.
pub(super) struct Layout {
    /// Per glTF vertex, the mesh vertex it is.
    pub source: Vec<u32>,
    /// Per glTF vertex, its texture coordinate, OBJ's way up ([`NONE`] where it
    /// has none); empty where the mesh has none.
    pub uvs: Vec<[f32; 2]>,
    pub primitives: Vec<Primitive>,
    /// Whether the primitives are points (a mesh with no triangles).
    pub points: bool,
}

impl Layout {
    /// The layout of `file`'s mesh, its memory checked first ([`layout_memory`]).
    pub fn of(file: &MeshFile) -> Result<Layout, TooLarge> {
        let mesh = &file.mesh;
        if mesh.triangles.is_empty() {
            return Ok(Layout {
                source: (0..mesh.positions.len() as u32).collect(),
                uvs: Vec::new(),
                primitives: vec![Primitive {
                    group: Group::default(),
                    vertices: 0..mesh.positions.len(),
                    indices: Vec::new(),
                    has_uvs: false,
                }],
                points: true,
            });
        }
        check_memory(
            || {
                format!(
                    "splitting its {} triangles into glTF's vertices",
                    mesh.triangles.len()
                )
            },
            layout_memory(mesh.triangles.len()),
        )?;
        let surface = Surface::of(file);
        Ok(split(file, surface))
    }
}

/// A corner's key: group, vertex, then its texture coordinate's bits.
fn corner_key(group: u32, vertex: u32, uv: [f32; 2]) -> (u32, u32, u64) {
    let bits = if uv[0].is_nan() {
        u64::MAX
    } else {
        // -0.0 and 0.0 are one coordinate.
        let [u, v] = uv.map(|c| (c + 0.0).to_bits() as u64);
        (u << 32) | v
    };
    (group, vertex, bits)
}

fn split(file: &MeshFile, surface: Surface) -> Layout {
    let triangles = &file.mesh.triangles;
    let has_uvs = !surface.corner_uvs.is_empty();
    let corner_uv = |corner: usize| {
        if has_uvs {
            surface.corner_uvs[corner]
        } else {
            NONE
        }
    };
    // Every corner's key and the corner, sorted: equal keys are one vertex.
    let mut keyed: Vec<((u32, u32, u64), u32)> = (0..3 * triangles.len())
        .into_par_iter()
        .map(|corner| {
            let triangle = corner / 3;
            let vertex = triangles[triangle][corner % 3];
            let group = surface.triangle_groups[triangle];
            (corner_key(group, vertex, corner_uv(corner)), corner as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    let mut source = Vec::new();
    let mut uvs = Vec::new();
    let mut corner_vertex = vec![0u32; keyed.len()];
    let mut group_starts = vec![usize::MAX; surface.groups.len()];
    let mut last = None;
    for &(key, corner) in &keyed {
        if last != Some(key) {
            last = Some(key);
            let group = key.0 as usize;
            if group_starts[group] == usize::MAX {
                group_starts[group] = source.len();
            }
            source.push(key.1);
            if has_uvs {
                uvs.push(corner_uv(corner as usize));
            }
        }
        corner_vertex[corner as usize] = (source.len() - 1) as u32;
    }
    drop(keyed);
    // Groups are numbered in the order the file first uses them, so their
    // vertices follow one another in that order; each group's triangles stay
    // in file order, numbered from its first vertex.
    let used: Vec<usize> = (0..surface.groups.len())
        .filter(|&g| group_starts[g] != usize::MAX)
        .collect();
    let mut indices: Vec<Vec<u32>> = vec![Vec::new(); surface.groups.len()];
    for (triangle, &group) in surface.triangle_groups.iter().enumerate() {
        let start = group_starts[group as usize] as u32;
        let corners = &corner_vertex[3 * triangle..3 * triangle + 3];
        indices[group as usize].extend(corners.iter().map(|&v| v - start));
    }
    let primitives = used
        .iter()
        .enumerate()
        .map(|(k, &g)| {
            let end = used
                .get(k + 1)
                .map_or(source.len(), |&next| group_starts[next]);
            let vertices = group_starts[g]..end;
            Primitive {
                group: surface.groups[g].clone(),
                has_uvs: has_uvs && uvs[vertices.clone()].iter().any(|uv| !uv[0].is_nan()),
                vertices,
                indices: std::mem::take(&mut indices[g]),
            }
        })
        .collect();
    Layout {
        source,
        uvs,
        primitives,
        points: false,
    }
}

//! Meshes, cages, file I/O and validation. Nothing here touches the GPU or the UI.
//!
//! Vertex order is always the file's order: row *i* of any weights matrix is the
//! *i*-th `v` line of the mesh file, column *j* the *j*-th `v` line of the cage file.

pub mod autocage;
pub mod budget;
mod cage;
mod classify;
mod classify_patches;
mod error;
pub mod gltf;
mod intersect;
mod io;
mod normals;
pub mod npy_header;
mod obj;
mod off;
mod output;
mod ply;
mod points_npy;
mod polygons;
pub mod procedural;
pub mod procedural_quads;
pub mod quads;
pub mod subdivide;
pub mod twisted_bar;

pub use cage::{Cage, CageReport};
pub use classify::{
    classify_points, closest_offset_on_triangle, closest_point_on_triangle,
    generalized_winding_number, PointClass, PointClasses,
};
pub use error::{shown_path, CageError, CageLoadError, LoadError, WriteError};
pub use intersect::{find_crossing, Crossing};
pub use io::{
    cage_from_file, load_cage, load_mesh, parse_mesh, write_cage_and_pose, write_deformed_mesh,
    write_mesh_with_normals, write_obj, write_obj_to, write_polygons_obj_to,
};
pub use normals::vertex_normals;
pub use output::{
    extension_warning, human_bytes, refuse_same_file, refuse_unwritable, remove_unfinished_outputs,
    resolve_output, write_atomically, OutputSet, OutputTarget, PendingOutput, WriteSeek,
};
pub use ply::{colour_byte, write_coloured_ply};
pub use points_npy::write_points_npy;
pub use polygons::{polygon_edges, polygons_of, triangulate_faces};
pub use quads::{CageQuad, QuadSplit};
pub use subdivide::{subdivide_midpoint, SubdivideError, Subdivided};

use glam::DVec3;
use std::path::PathBuf;

/// A triangle mesh (or a point set, when it has no triangles) in f64.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    /// For each triangle, the file face (0-based, file order) it was cut from.
    pub triangle_faces: Vec<u32>,
}

impl TriMesh {
    /// Axis-aligned bounds; `(ZERO, ZERO)` for an empty mesh.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        bounds_of(&self.positions)
    }

    /// Length of the bounding-box diagonal.
    pub fn diagonal(&self) -> f64 {
        let (lo, hi) = self.bounds();
        (hi - lo).length()
    }
}

/// Axis-aligned bounds of a point list; `(ZERO, ZERO)` when empty.
pub fn bounds_of(points: &[DVec3]) -> (DVec3, DVec3) {
    if points.is_empty() {
        return (DVec3::ZERO, DVec3::ZERO);
    }
    points
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        })
}

/// The file format a mesh was read from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    Obj,
    Off,
    /// An (n, 3) float32 or float64 NumPy array: a point set.
    Npy,
    /// glTF 2.0, binary (`.glb`) or JSON (`.gltf`): one mesh of it ([`gltf`]).
    Gltf,
}

/// A mesh as read from a file, with what is needed to write it back deformed.
#[derive(Clone, Debug)]
pub struct MeshFile {
    pub path: PathBuf,
    pub format: MeshFormat,
    pub mesh: TriMesh,
    /// The original text of an OBJ file: a deformed copy keeps its faces, texture
    /// coordinates, groups and materials by rewriting only the `v` lines. For a
    /// glTF file, OBJ text written from its mesh (positions, texture coordinates,
    /// primitives as groups), which is what was parsed.
    pub obj_text: Option<String>,
}

/// Split a polygon into triangles. Triangles pass through. A quad is cut along its
/// shorter diagonal, which for a non-planar quad gives the flatter of the two folds
/// and keeps thin quads from making sliver triangles. Larger polygons are fanned
/// from their first corner.
pub fn triangulate_polygon(corners: &[u32], positions: &[DVec3], out: &mut Vec<[u32; 3]>) {
    match corners {
        [a, b, c] => out.push([*a, *b, *c]),
        [a, b, c, d] => {
            let p = |i: u32| positions.get(i as usize).copied().unwrap_or(DVec3::ZERO);
            if p(*a).distance_squared(p(*c)) <= p(*b).distance_squared(p(*d)) {
                out.push([*a, *b, *c]);
                out.push([*a, *c, *d]);
            } else {
                out.push([*a, *b, *d]);
                out.push([*b, *c, *d]);
            }
        }
        _ if corners.len() > 4 => {
            for k in 1..corners.len() - 1 {
                out.push([corners[0], corners[k], corners[k + 1]]);
            }
        }
        _ => {}
    }
}

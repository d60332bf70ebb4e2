//! Meshes and cages: the triangle mesh, the validated `Cage` with its quads as
//! bilinear patches, inside/outside classification, self-intersection checks,
//! subdivision and procedural shapes. Owns no file format (see `formats`) and
//! imports nothing of the crate but `budget`; never wgpu or egui.
//!
//! Vertex order is always the file's order: row *i* of any weights matrix is the
//! *i*-th vertex of the mesh, column *j* the *j*-th vertex of the cage.

pub(crate) mod cage;
pub(crate) mod classify;
mod classify_patches;
mod error;
pub(crate) mod intersect;
mod normals;
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
pub use error::CageError;
pub use intersect::{find_crossing, Crossing};
pub use normals::vertex_normals;
pub use polygons::{polygon_edges, polygons_of, triangulate_faces};
pub use quads::{CageQuad, QuadSplit};
pub use subdivide::{subdivide_midpoint, SubdivideError, Subdivided};

use glam::DVec3;

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

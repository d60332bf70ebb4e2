//! 1-to-4 midpoint subdivision of a cage, applied alike to its rest positions and to
//! a pose, so that a finer cage can take over from a coarse one without moving anything.

use super::{Cage, CageError, TriMesh};
use glam::DVec3;
use std::collections::HashMap;

/// A cage subdivided 1-to-4 at edge midpoints, with the same rule applied to a pose.
#[derive(Clone, Debug, PartialEq)]
pub struct Subdivided {
    pub cage: Cage,
    pub pose: Vec<DVec3>,
}

/// Why a cage could not be subdivided.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SubdivideError {
    #[error("the pose has {pose} positions, but the cage has {cage} vertices")]
    PoseLength { pose: usize, cage: usize },
    #[error("the subdivided cage is not valid: {0}")]
    Invalid(#[from] CageError),
}

/// Every triangle becomes four through its edge midpoints. The original vertices keep
/// their indices; each edge's midpoint is appended once (shared by its two faces), in a
/// deterministic order. `pose` (one position per cage vertex: the current deformed cage)
/// gets the midpoints of its own edges, so the posed shape is unchanged.
///
/// Midpoints are numbered in order of first use: triangle by triangle, and within a
/// triangle along the edges (a, b), (b, c), (c, a). Each child triangle keeps its
/// parent's winding and its parent's `triangle_faces` entry: the children still lie
/// in the parent's file polygon, so errors and anything grouping triangles by face
/// keep naming the polygon the user drew.
pub fn subdivide_midpoint(cage: &Cage, pose: &[DVec3]) -> Result<Subdivided, SubdivideError> {
    if pose.len() != cage.vertex_count() {
        return Err(SubdivideError::PoseLength {
            pose: pose.len(),
            cage: cage.vertex_count(),
        });
    }
    let mut positions = cage.positions().to_vec();
    let mut posed = pose.to_vec();
    let mut midpoints: HashMap<(u32, u32), u32> =
        HashMap::with_capacity(cage.triangles().len() * 3 / 2);
    let mut midpoint = |a: u32, b: u32| {
        *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
            let (a, b) = (a as usize, b as usize);
            positions.push(0.5 * (positions[a] + positions[b]));
            posed.push(0.5 * (posed[a] + posed[b]));
            positions.len() as u32 - 1
        })
    };
    let mut triangles = Vec::with_capacity(cage.triangles().len() * 4);
    let mut triangle_faces = Vec::with_capacity(cage.triangles().len() * 4);
    for (t, &[a, b, c]) in cage.triangles().iter().enumerate() {
        let (ab, bc, ca) = (midpoint(a, b), midpoint(b, c), midpoint(c, a));
        triangles.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        let face = cage.triangle_faces().get(t).copied().unwrap_or(t as u32);
        triangle_faces.extend([face; 4]);
    }
    // A `Cage` is only made by validation; a valid cage subdivides into a valid one
    // unless its triangles become too small for the degeneracy test.
    let mesh = TriMesh {
        positions,
        triangles,
        triangle_faces,
    };
    let (cage, _report) = Cage::new(mesh)?;
    Ok(Subdivided { cage, pose: posed })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::procedural;
    use std::collections::HashSet;

    fn edge_count(cage: &Cage) -> usize {
        let edges: HashSet<(u32, u32)> = cage
            .triangles()
            .iter()
            .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
            .map(|(u, v)| (u.min(v), u.max(v)))
            .collect();
        edges.len()
    }

    /// A pose that is not just a scaled copy: every vertex moved differently.
    fn twisted(cage: &Cage) -> Vec<DVec3> {
        cage.positions()
            .iter()
            .map(|p| {
                let angle = 0.3 * p.z;
                let (s, c) = angle.sin_cos();
                DVec3::new(c * p.x - s * p.y, s * p.x + c * p.y, 1.2 * p.z) + DVec3::X * 0.1
            })
            .collect()
    }

    #[test]
    fn a_cube_gets_one_vertex_per_edge_and_four_triangles_per_triangle() {
        let cube = procedural::cube_cage(1.0);
        let edges = edge_count(&cube);
        assert_eq!(edges, 18);
        let result = subdivide_midpoint(&cube, cube.positions()).unwrap();
        assert_eq!(result.cage.vertex_count(), 8 + edges);
        assert_eq!(result.cage.triangles().len(), 4 * cube.triangles().len());
        assert_eq!(result.pose.len(), result.cage.vertex_count());
        assert_eq!(result.cage.positions()[..8], cube.positions()[..]);
        // Unchanged pose in, unchanged pose out.
        assert_eq!(result.pose, result.cage.positions());
    }

    #[test]
    fn children_keep_the_parents_winding_and_face() {
        let cube = procedural::cube_cage(1.0);
        let result = subdivide_midpoint(&cube, cube.positions()).unwrap();
        for (t, parent) in cube.triangles().iter().enumerate() {
            let [a, b, c] = cube.triangle(t);
            let normal = (b - a).cross(c - a).normalize();
            for child in 4 * t..4 * t + 4 {
                let [p, q, r] = result.cage.triangle(child);
                let child_normal = (q - p).cross(r - p).normalize();
                assert!(
                    child_normal.dot(normal) > 1.0 - 1e-12,
                    "{parent:?} → {child}"
                );
                assert_eq!(
                    result.cage.triangle_faces()[child],
                    cube.triangle_faces()[t]
                );
            }
        }
    }

    #[test]
    fn volumes_of_rest_and_pose_are_unchanged() {
        let cage = procedural::extrude(&procedural::comb_outline(3, 1.0, 0.25, 2.0), -0.5, 0.5);
        let pose = twisted(&cage);
        let result = subdivide_midpoint(&cage, &pose).unwrap();
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(1.0);
        assert!(close(result.cage.signed_volume(), cage.signed_volume()));
        let posed_before = cage.with_positions(pose.clone()).signed_volume();
        let posed_after = result
            .cage
            .with_positions(result.pose.clone())
            .signed_volume();
        assert!(
            close(posed_before, posed_after),
            "{posed_before} {posed_after}"
        );
        assert_eq!(result.pose[..pose.len()], pose[..]);
    }

    #[test]
    fn a_pose_of_the_wrong_length_is_an_error() {
        let cube = procedural::cube_cage(1.0);
        let error = subdivide_midpoint(&cube, &cube.positions()[..7]).unwrap_err();
        assert_eq!(error, SubdivideError::PoseLength { pose: 7, cage: 8 });
        let message = error.to_string();
        assert!(message.contains('7') && message.contains('8'), "{message}");
    }

    #[test]
    fn subdividing_twice_is_deterministic_and_valid() {
        let cube = procedural::cube_cage(1.0);
        let pose = twisted(&cube);
        let once = subdivide_midpoint(&cube, &pose).unwrap();
        let twice = subdivide_midpoint(&once.cage, &once.pose).unwrap();
        assert_eq!(twice.cage.vertex_count(), 26 + edge_count(&once.cage));
        assert_eq!(twice.cage.triangles().len(), 16 * cube.triangles().len());
        assert_eq!(twice, subdivide_midpoint(&once.cage, &once.pose).unwrap());
        let before = cube.with_positions(pose).signed_volume();
        let after = twice.cage.with_positions(twice.pose).signed_volume();
        assert!((before - after).abs() <= 1e-12 * before.abs());
    }
}

//! The file's polygons from a triangulated mesh, for writing a cage as the
//! artist made it (quads kept) and for the Python package's faces. The readers
//! keep, for each triangle, the face it was cut from (`TriMesh::triangle_faces`),
//! not the face's corners; `triangulate_polygon` is deterministic, so each
//! face's corners are the candidate whose triangulation gives back its triangles.
// The readers could keep the polygons themselves (a `faces` field of `TriMesh`),
// which would make this module unnecessary.

use super::{triangulate_polygon, TriMesh};
use glam::DVec3;

/// Triangles and the polygons they came from, for a mesh made from polygons.
pub fn triangulate_faces(faces: &[Vec<u32>], positions: &[DVec3]) -> TriMesh {
    let mut mesh = TriMesh {
        positions: positions.to_vec(),
        ..TriMesh::default()
    };
    for (face, corners) in faces.iter().enumerate() {
        let before = mesh.triangles.len();
        triangulate_polygon(corners, positions, &mut mesh.triangles);
        mesh.triangle_faces.extend(std::iter::repeat_n(
            face as u32,
            mesh.triangles.len() - before,
        ));
    }
    mesh
}

/// The polygons of `mesh`, in file order, with their corners in file order.
pub fn polygons_of(mesh: &TriMesh) -> Vec<Vec<u32>> {
    if mesh.triangle_faces.len() != mesh.triangles.len() {
        return mesh.triangles.iter().map(|t| t.to_vec()).collect();
    }
    let mut faces = Vec::new();
    let mut start = 0;
    while start < mesh.triangles.len() {
        let face = mesh.triangle_faces[start];
        let end = start
            + mesh.triangle_faces[start..]
                .iter()
                .take_while(|&&f| f == face)
                .count();
        faces.push(polygon(&mesh.triangles[start..end], &mesh.positions));
        start = end;
    }
    faces
}

/// The corners of the polygon that `triangulate_polygon` cut into `triangles`.
fn polygon(triangles: &[[u32; 3]], positions: &[DVec3]) -> Vec<u32> {
    let fan = || {
        let mut corners = triangles[0].to_vec();
        corners.extend(triangles[1..].iter().map(|t| t[2]));
        corners
    };
    let candidates = match triangles {
        [only] => return only.to_vec(),
        // A quad cut along a-c gives [a, b, c], [a, c, d]; along b-d, [a, b, d], [b, c, d].
        [first, second] => vec![fan(), vec![first[0], first[1], second[1], second[2]]],
        _ => vec![fan()],
    };
    let mut cut = Vec::new();
    for corners in &candidates {
        cut.clear();
        triangulate_polygon(corners, positions, &mut cut);
        if cut == triangles {
            return corners.clone();
        }
    }
    candidates[0].clone()
}

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

/// The edges of the polygons the triangles were cut from, each once (smaller
/// vertex first, sorted): an edge inside one face, a diagonal that splits a
/// quad or a fan's spoke, is left out, since the artist never drew it. `None`
/// when the triangles carry no polygons: `triangle_faces` does not name one
/// face per triangle, or no face has more than one triangle (a mesh built from
/// triangles, whose faces say nothing the triangles do not).
pub fn polygon_edges(triangles: &[[u32; 3]], triangle_faces: &[u32]) -> Option<Vec<[u32; 2]>> {
    let has_polygons = triangle_faces.windows(2).any(|pair| pair[0] == pair[1]);
    if triangle_faces.len() != triangles.len() || !has_polygons {
        return None;
    }
    let mut sides: Vec<([u32; 2], u32)> = triangles
        .iter()
        .zip(triangle_faces)
        .flat_map(|(&[a, b, c], &face)| [[a, b], [b, c], [c, a]].map(|e| (e, face)))
        .map(|([u, v], face)| ([u.min(v), u.max(v)], face))
        .collect();
    sides.sort_unstable();
    let mut edges: Vec<[u32; 2]> = Vec::new();
    for run in sides.chunk_by(|a, b| a.0 == b.0) {
        let inside_one_face = run.len() == 2 && run[0].1 == run[1].1;
        if !inside_one_face {
            edges.push(run[0].0);
        }
    }
    Some(edges)
}

/// The polygons of `mesh`, in file order, with their corners in file order.
pub fn polygons_of(mesh: &TriMesh) -> Vec<Vec<u32>> {
    if mesh.triangle_faces.len() != mesh.triangles.len() {
        return mesh.triangles.iter().map(|t| t.to_vec()).collect();
    }
    face_runs(&mesh.triangle_faces)
        .map(|run| polygon(&mesh.triangles[run], &mesh.positions))
        .collect()
}

/// The runs of consecutive triangles with the same face in `triangle_faces`:
/// one range of triangle indices per polygon, in order.
pub(crate) fn face_runs(
    triangle_faces: &[u32],
) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
    let mut start = 0;
    std::iter::from_fn(move || {
        let face = *triangle_faces.get(start)?;
        let end = start
            + triangle_faces[start..]
                .iter()
                .take_while(|&&f| f == face)
                .count();
        let run = start..end;
        start = end;
        Some(run)
    })
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_of_quads_has_its_twelve_edges_and_no_diagonal_even_when_bent() {
        let mut positions: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new(f64::from(i & 1), f64::from((i >> 1) & 1), f64::from(i >> 2)))
            .collect();
        // One corner pulled out: its three quads are no longer planar.
        positions[7] += DVec3::splat(0.3);
        let quads: Vec<Vec<u32>> = crate::geometry::procedural::CUBE_QUADS
            .iter()
            .map(|q| q.to_vec())
            .collect();
        let mesh = triangulate_faces(&quads, &positions);
        assert_eq!(mesh.triangles.len(), 12);
        let edges = polygon_edges(&mesh.triangles, &mesh.triangle_faces).unwrap();
        // The cube's edges, from the quads themselves.
        let mut expected: Vec<[u32; 2]> = quads
            .iter()
            .flat_map(|q| (0..4).map(move |k| [q[k], q[(k + 1) % 4]]))
            .map(|[u, v]| [u.min(v), u.max(v)])
            .collect();
        expected.sort_unstable();
        expected.dedup();
        assert_eq!(expected.len(), 12);
        assert_eq!(edges, expected);
    }

    #[test]
    fn triangles_without_polygons_are_not_guessed() {
        assert_eq!(polygon_edges(&[[0, 1, 2]], &[]), None);
        assert_eq!(polygon_edges(&[[0, 1, 2], [0, 2, 3]], &[0, 1]), None);
        // A triangle beside a quad keeps the edge between them.
        assert_eq!(
            polygon_edges(&[[0, 1, 2], [0, 2, 3], [0, 3, 4]], &[0, 0, 1]),
            Some(vec![[0, 1], [0, 3], [0, 4], [1, 2], [2, 3], [3, 4]]),
        );
    }
}

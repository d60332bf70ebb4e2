//! Vertex normals of a triangle mesh, as exports write them: the area-weighted
//! sum of the incident triangles' normals (each triangle's cross product is twice
//! its area times its unit normal), normalised.

use glam::DVec3;

/// One unit normal per vertex of `positions`. Where the incident triangles
/// cancel (a sheet with faces on both sides) the first incident triangle's
/// normal is used, and a vertex in no triangle of positive area gets +z.
pub fn vertex_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let count = positions.len();
    let mut sums = vec![DVec3::ZERO; count];
    let mut magnitudes = vec![0.0f64; count];
    let mut first = vec![DVec3::ZERO; count];
    for &[a, b, c] in triangles {
        let corners = [a as usize, b as usize, c as usize];
        if corners.iter().any(|&i| i >= count) {
            continue;
        }
        let [pa, pb, pc] = corners.map(|i| positions[i]);
        let cross = (pb - pa).cross(pc - pa);
        if !cross.is_finite() || cross == DVec3::ZERO {
            continue;
        }
        for i in corners {
            sums[i] += cross;
            magnitudes[i] += cross.length();
            if first[i] == DVec3::ZERO {
                first[i] = cross;
            }
        }
    }
    sums.iter()
        .zip(&magnitudes)
        .zip(&first)
        .map(|((&sum, &magnitude), &first)| {
            if sum.length() > 1e-9 * magnitude {
                sum.normalize()
            } else {
                first.try_normalize().unwrap_or(DVec3::Z)
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn a_flat_grid_has_the_plane_normal_everywhere() {
        // A 3×3 grid of points in the plane z = x + y, two triangles per cell.
        let positions: Vec<DVec3> = (0..9)
            .map(|i| {
                let (x, y) = ((i % 3) as f64, (i / 3) as f64);
                DVec3::new(x, y, x + y)
            })
            .collect();
        let mut triangles = Vec::new();
        for cell in [0u32, 1, 3, 4] {
            triangles.push([cell, cell + 1, cell + 4]);
            triangles.push([cell, cell + 4, cell + 3]);
        }
        let plane = DVec3::new(-1.0, -1.0, 1.0).normalize();
        for normal in vertex_normals(&positions, &triangles) {
            assert!(close(normal, plane), "{normal}");
        }
    }

    #[test]
    fn a_regular_tetrahedron_corner_points_away_from_the_centre() {
        let positions = [
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(-1.0, -1.0, 1.0),
        ];
        // Outward-oriented faces.
        let triangles = [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]];
        let normals = vertex_normals(&positions, &triangles);
        for (p, n) in positions.iter().zip(normals) {
            assert!(close(n, p.normalize()), "{n} at {p}");
        }
    }

    #[test]
    fn degenerate_and_missing_triangles_give_no_nan() {
        let positions = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0, DVec3::Y];
        // A zero-area triangle, an index out of range, and a lone vertex (3).
        let normals = vertex_normals(&positions, &[[0, 1, 2], [0, 1, 9]]);
        assert!(normals.iter().all(|n| n.is_finite()));
        assert_eq!(normals[3], DVec3::Z);
    }

    #[test]
    fn a_sheet_with_both_sides_takes_its_first_face() {
        let positions = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let normals = vertex_normals(&positions, &[[0, 1, 2], [2, 1, 0]]);
        assert!(normals.iter().all(|&n| close(n, DVec3::Z)));
    }
}

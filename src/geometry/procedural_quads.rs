//! Procedural cages of quads, for tests and examples: a box whose top is
//! twisted (non-planar quads) and a comb of quads (non-convex).

use super::{triangulate_faces, Cage, CageError, CageReport};
use glam::{DQuat, DVec3};

/// A cage from polygons (each a quad or triangle, corners counter-clockwise
/// seen from outside), validated.
pub fn cage_from_polygons(
    positions: &[DVec3],
    polygons: &[Vec<u32>],
) -> Result<(Cage, CageReport), CageError> {
    Cage::new(triangulate_faces(polygons, positions))
}

/// A box `[−1, 1]² × [0, height]` of six quads whose top is turned by `angle`
/// radians about the z axis: its four side quads are then bent (not planar).
pub fn twisted_box(height: f64, angle: f64) -> Cage {
    let turn = DQuat::from_rotation_z(angle);
    let square = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    let mut positions: Vec<DVec3> = square.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
    positions.extend(square.iter().map(|&(x, y)| turn * DVec3::new(x, y, height)));
    let polygons = vec![
        vec![0, 3, 2, 1],
        vec![4, 5, 6, 7],
        vec![0, 1, 5, 4],
        vec![1, 2, 6, 5],
        vec![2, 3, 7, 6],
        vec![3, 0, 4, 7],
    ];
    expect_valid(cage_from_polygons(&positions, &polygons))
}

/// An extruded comb (see [`super::procedural::comb_outline`]) whose sides are
/// quads and whose caps are one quad per prong plus the spine's quads: a
/// non-convex cage of quads only, `depth` thick, with its far cap lifted at one
/// corner by `bend` so that some quads are not planar.
pub fn quad_comb(prongs: usize, width: f64, gap: f64, length: f64, depth: f64, bend: f64) -> Cage {
    // Two columns per prong (its sides); rows at y = 0, the spine's top and the tips.
    let columns: Vec<f64> = (0..prongs)
        .flat_map(|p| {
            let x0 = p as f64 * (width + gap);
            [x0, x0 + width]
        })
        .collect();
    let rows = [0.0, width, width + length];
    let mut positions: Vec<DVec3> = rows
        .iter()
        .flat_map(|&y| columns.iter().map(move |&x| DVec3::new(x, y, 0.0)))
        .collect();
    let at = |row: usize, column: usize| (row * columns.len() + column) as u32;
    let near = positions.len() as u32;
    let far = |i: u32| i + near;
    let mut far_positions: Vec<DVec3> = positions
        .iter()
        .map(|p| DVec3::new(p.x, p.y, depth))
        .collect();
    if let Some(last) = far_positions.last_mut() {
        last.z += bend;
    }
    positions.extend(far_positions);
    // Cap quads, counter-clockwise seen from +z: the spine, then one per prong.
    let mut caps: Vec<[u32; 4]> = (0..columns.len() - 1)
        .map(|k| [at(0, k), at(0, k + 1), at(1, k + 1), at(1, k)])
        .collect();
    caps.extend((0..prongs).map(|p| {
        [
            at(1, 2 * p),
            at(1, 2 * p + 1),
            at(2, 2 * p + 1),
            at(2, 2 * p),
        ]
    }));
    let mut polygons: Vec<Vec<u32>> = Vec::new();
    for [a, b, c, d] in caps {
        polygons.push(vec![d, c, b, a]);
        polygons.push(vec![far(a), far(b), far(c), far(d)]);
    }
    // The outline, counter-clockwise seen from +z: along the bottom, then over the
    // prongs from the right.
    let mut outline: Vec<u32> = (0..columns.len()).map(|k| at(0, k)).collect();
    for p in (0..prongs).rev() {
        outline.extend([
            at(1, 2 * p + 1),
            at(2, 2 * p + 1),
            at(2, 2 * p),
            at(1, 2 * p),
        ]);
    }
    outline.pop(); // at(1, 0) closes onto at(0, 0) below
    outline.push(at(1, 0));
    for k in 0..outline.len() {
        let (a, b) = (outline[k], outline[(k + 1) % outline.len()]);
        polygons.push(vec![a, b, far(b), far(a)]);
    }
    expect_valid(cage_from_polygons(&positions, &polygons))
}

fn expect_valid(result: Result<(Cage, CageReport), CageError>) -> Cage {
    match result {
        Ok((cage, _)) => cage,
        Err(error) => panic!("procedural quad cage is invalid: {error}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::quads::out_of_plane;

    #[test]
    fn a_twisted_box_keeps_six_quads_four_of_them_bent() {
        let cage = twisted_box(2.0, 0.6);
        assert_eq!(cage.quads().len(), 6);
        assert_eq!(cage.lone_triangles().count(), 0);
        let bent = (0..6)
            .filter(|&k| out_of_plane(&cage.quad(k)) > 1e-6)
            .count();
        assert_eq!(bent, 4);
        assert!(cage.signed_volume() > 0.0);
    }

    #[test]
    fn a_quad_comb_is_a_valid_cage_of_quads() {
        let cage = quad_comb(3, 1.0, 0.5, 3.0, 1.0, 0.3);
        assert!(cage.has_quads());
        assert_eq!(cage.lone_triangles().count(), 0);
        assert_eq!(cage.quads().len() * 2, cage.triangle_count());
    }
}

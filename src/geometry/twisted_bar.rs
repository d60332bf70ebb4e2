//! The gallery's shape-preservation experiment (docs/comparison.md): a round bar
//! in a box cage of stacked square rings, the cage twisted a quarter turn about
//! the bar's axis, and how round the bar's cross-sections stay.

use super::{Cage, TriMesh};
use glam::{DMat3, DVec3};
use std::f64::consts::{FRAC_PI_2, TAU};

/// Its name for `pmvc generate`.
pub const TWISTED_BAR: &str = "twisted-bar";

const LENGTH: f64 = 4.0;
const RADIUS: f64 = 0.5;
/// Half the side of the cage's square rings.
const CAGE_HALF_SIDE: f64 = 0.75;
/// How far the cage reaches beyond each end of the bar.
const CAGE_OVERHANG: f64 = 0.25;
const CAGE_RINGS: usize = 5;
const MESH_RINGS: usize = 81;
const SEGMENTS: usize = 32;

/// The bar (along z, centred on the origin), its cage, and the cage twisted.
pub struct TwistedBar {
    /// `MESH_RINGS` rings of `SEGMENTS` vertices, ring after ring, then the centres
    /// of the two end caps.
    pub mesh: TriMesh,
    pub cage: Cage,
    /// The cage's vertices with ring k turned by a quarter turn · k / (rings − 1).
    pub twisted: Vec<DVec3>,
}

/// Vertex `segment` of mesh ring `ring`.
fn ring_vertex(ring: usize, segment: usize) -> u32 {
    (ring * SEGMENTS + segment % SEGMENTS) as u32
}

pub fn twisted_bar() -> TwistedBar {
    let mut mesh = TriMesh::default();
    for ring in 0..MESH_RINGS {
        let z = -LENGTH / 2.0 + LENGTH * ring as f64 / (MESH_RINGS - 1) as f64;
        for segment in 0..SEGMENTS {
            let angle = TAU * segment as f64 / SEGMENTS as f64;
            mesh.positions
                .push(DVec3::new(RADIUS * angle.cos(), RADIUS * angle.sin(), z));
        }
    }
    for ring in 0..MESH_RINGS - 1 {
        for s in 0..SEGMENTS {
            let [a, b] = [ring_vertex(ring, s), ring_vertex(ring, s + 1)];
            let [c, d] = [ring_vertex(ring + 1, s + 1), ring_vertex(ring + 1, s)];
            mesh.triangles.extend([[a, b, c], [a, c, d]]);
        }
    }
    let centre = mesh.positions.len() as u32;
    mesh.positions.push(DVec3::new(0.0, 0.0, -LENGTH / 2.0));
    mesh.positions.push(DVec3::new(0.0, 0.0, LENGTH / 2.0));
    let last = MESH_RINGS - 1;
    for s in 0..SEGMENTS {
        mesh.triangles
            .push([centre, ring_vertex(0, s + 1), ring_vertex(0, s)]);
        mesh.triangles
            .push([centre + 1, ring_vertex(last, s), ring_vertex(last, s + 1)]);
    }

    mesh.triangle_faces = (0..mesh.triangles.len() as u32).collect();

    let corners = [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)];
    let reach = LENGTH / 2.0 + CAGE_OVERHANG;
    let mut cage_mesh = TriMesh::default();
    for ring in 0..CAGE_RINGS {
        let z = -reach + 2.0 * reach * ring as f64 / (CAGE_RINGS - 1) as f64;
        for (x, y) in corners {
            cage_mesh
                .positions
                .push(DVec3::new(x * CAGE_HALF_SIDE, y * CAGE_HALF_SIDE, z));
        }
    }
    let corner = |ring: usize, k: usize| (ring * 4 + k % 4) as u32;
    for ring in 0..CAGE_RINGS - 1 {
        for k in 0..4 {
            let [a, b] = [corner(ring, k), corner(ring, k + 1)];
            let [c, d] = [corner(ring + 1, k + 1), corner(ring + 1, k)];
            cage_mesh.triangles.extend([[a, b, c], [a, c, d]]);
        }
    }
    let top = CAGE_RINGS - 1;
    cage_mesh.triangles.extend([
        [corner(0, 0), corner(0, 2), corner(0, 1)],
        [corner(0, 0), corner(0, 3), corner(0, 2)],
        [corner(top, 0), corner(top, 1), corner(top, 2)],
        [corner(top, 0), corner(top, 2), corner(top, 3)],
    ]);
    cage_mesh.triangle_faces = (0..cage_mesh.triangles.len() as u32).collect();
    // Built outward; validation keeps it as it is.
    let (cage, _) = Cage::new(cage_mesh).unwrap_or_else(|error| {
        unreachable!("the twisted bar's cage is closed and manifold: {error}")
    });
    let twisted = cage
        .positions()
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let turn = FRAC_PI_2 * (i / 4) as f64 / (CAGE_RINGS - 1) as f64;
            DMat3::from_rotation_z(turn) * p
        })
        .collect();
    TwistedBar {
        mesh,
        cage,
        twisted,
    }
}

/// How the bar's cross-sections came out of a deformation, over the rings away
/// from the ends (the middle three fifths, where the cage alone decides).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrossSections {
    /// The largest (max − min) / mean of a ring's distances from its centroid:
    /// 0 for round rings.
    pub worst_out_of_round: f64,
    /// max / min of every ring edge's length ratio (deformed ÷ rest): 1 when the
    /// rings keep their shape and size along the bar.
    pub edge_ratio_spread: f64,
}

/// [`CrossSections`] of the bar deformed to `deformed` (its mesh's vertices).
pub fn cross_sections(deformed: &[DVec3], rest: &[DVec3]) -> CrossSections {
    let inner = MESH_RINGS / 5..MESH_RINGS - MESH_RINGS / 5;
    let mut worst_out_of_round = 0.0f64;
    let (mut lowest_ratio, mut highest_ratio) = (f64::INFINITY, 0.0f64);
    for ring in inner {
        let vertex = |s: usize| ring_vertex(ring, s) as usize;
        let centroid = (0..SEGMENTS).map(|s| deformed[vertex(s)]).sum::<DVec3>() / SEGMENTS as f64;
        let radii: Vec<f64> = (0..SEGMENTS)
            .map(|s| deformed[vertex(s)].distance(centroid))
            .collect();
        let mean = radii.iter().sum::<f64>() / SEGMENTS as f64;
        let (low, high) = radii
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(l, h), &r| (l.min(r), h.max(r)));
        worst_out_of_round = worst_out_of_round.max((high - low) / mean);
        for s in 0..SEGMENTS {
            let (a, b) = (vertex(s), vertex(s + 1));
            let ratio = deformed[a].distance(deformed[b]) / rest[a].distance(rest[b]);
            lowest_ratio = lowest_ratio.min(ratio);
            highest_ratio = highest_ratio.max(ratio);
        }
    }
    CrossSections {
        worst_out_of_round,
        edge_ratio_spread: highest_ratio / lowest_ratio,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rest_bar_is_round_and_a_rigid_turn_keeps_it_so() {
        let bar = twisted_bar();
        let rest = &bar.mesh.positions;
        let at_rest = cross_sections(rest, rest);
        assert!(at_rest.worst_out_of_round < 1e-12, "{at_rest:?}");
        assert!((at_rest.edge_ratio_spread - 1.0).abs() < 1e-12);
        let turned: Vec<DVec3> = rest
            .iter()
            .map(|&p| DMat3::from_rotation_z(0.3) * p)
            .collect();
        let turned = cross_sections(&turned, rest);
        assert!(
            turned.worst_out_of_round < 1e-12 && (turned.edge_ratio_spread - 1.0).abs() < 1e-12
        );
        // Squashing one axis is measured as out of round.
        let squashed: Vec<DVec3> = rest
            .iter()
            .map(|&p| DVec3::new(p.x, 0.8 * p.y, p.z))
            .collect();
        let squashed = cross_sections(&squashed, rest);
        assert!(squashed.worst_out_of_round > 0.15, "{squashed:?}");
        assert!(squashed.edge_ratio_spread > 1.15, "{squashed:?}");
        assert_eq!(bar.twisted.len(), bar.cage.vertex_count());
        let top = bar.cage.vertex_count() - 4;
        let quarter = DMat3::from_rotation_z(FRAC_PI_2) * bar.cage.positions()[top];
        assert!(bar.twisted[top].distance(quarter) < 1e-12);
    }
}

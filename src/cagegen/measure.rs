//! Measurements of a generated cage against its mesh, made independently of
//! how the cage was built.

use super::winding::TriangleTree;
use crate::geometry::{Cage, TriMesh};
use glam::DVec3;
use rayon::prelude::*;
use std::collections::HashMap;

pub(super) struct Enclosure {
    pub outside: usize,
    pub first_outside: Option<usize>,
    pub min_clearance: f64,
}

/// Winding number and distance of every mesh vertex against the cage.
pub(super) fn enclosure(cage: &Cage, mesh: &TriMesh) -> Enclosure {
    let tree = TriangleTree::new(cage.positions(), cage.triangles());
    let results: Vec<(bool, f64)> = mesh
        .positions
        .par_iter()
        .map(|&p| (tree.winding_number(p) > 0.5, tree.distance(p)))
        .collect();
    let first_outside = results.iter().position(|(inside, _)| !inside);
    Enclosure {
        outside: results.iter().filter(|(inside, _)| !inside).count(),
        first_outside,
        min_clearance: results
            .iter()
            .map(|(_, d)| *d)
            .fold(f64::INFINITY, f64::min),
    }
}

/// The mesh's enclosed volume when every edge has exactly two faces.
pub(super) fn closed_volume(mesh: &TriMesh) -> Option<f64> {
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (i, j) = (t[k], t[(k + 1) % 3]);
            *edges.entry((i.min(j), i.max(j))).or_default() += 1;
        }
    }
    if edges.values().any(|&n| n != 2) {
        return None;
    }
    // Summed about the mesh's centre (cage.rs), whatever the caller did first.
    let volume = crate::geometry::cage::signed_volume(&mesh.positions, &mesh.triangles);
    Some(volume.abs())
}

/// Connected parts of the cage.
pub(super) fn shell_count(cage: &Cage) -> usize {
    let mut parent: Vec<usize> = (0..cage.vertex_count()).collect();
    fn root(parent: &mut [usize], mut v: usize) -> usize {
        while parent[v] != v {
            parent[v] = parent[parent[v]];
            v = parent[v];
        }
        v
    }
    for t in cage.triangles() {
        for k in 1..3 {
            let (x, y) = (
                root(&mut parent, t[0] as usize),
                root(&mut parent, t[k] as usize),
            );
            parent[x] = y;
        }
    }
    let mut roots: Vec<usize> = cage
        .triangles()
        .iter()
        .map(|t| root(&mut parent, t[0] as usize))
        .collect();
    roots.sort_unstable();
    roots.dedup();
    roots.len()
}

pub(super) fn min_angle_degrees(cage: &Cage) -> f64 {
    (0..cage.triangle_count())
        .map(|t| super::guard::min_angle(cage.triangle(t)))
        .fold(f64::INFINITY, f64::min)
        .to_degrees()
}

/// All points within a billionth of the diagonal of one plane (or one line).
pub(super) fn is_flat(mesh: &TriMesh) -> bool {
    let tolerance = 1e-9 * mesh.diagonal();
    let Some(normal) = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            (b - a).cross(c - a)
        })
        .max_by(|x, y| x.length_squared().total_cmp(&y.length_squared()))
        .and_then(DVec3::try_normalize)
    else {
        return true;
    };
    let origin = mesh.positions[mesh.triangles[0][0] as usize];
    mesh.positions
        .iter()
        .all(|p| normal.dot(*p - origin).abs() <= tolerance)
}

/// Points on the mesh that the cage must keep inside: every vertex, and points
/// on each face at most `spacing` apart, so that a cage face kept `2 · spacing`
/// from all of them cannot pass through the surface between them. Their number
/// is [`super::plan::sample_count`], checked before this is called, and they
/// are allocated once at that size.
pub(super) fn surface_samples(mesh: &TriMesh, spacing: f64) -> Vec<DVec3> {
    let mut points = Vec::with_capacity(super::plan::sample_count(mesh, spacing) as usize);
    points.extend_from_slice(&mesh.positions);
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let n = super::plan::lattice_divisions([a, b, c], spacing) as usize;
        // A face no longer than the spacing is covered by its corners, which
        // are vertices already; larger ones get their interior lattice points.
        for i in 1..n {
            for j in 0..=n - i {
                points.push(a + (b - a) * (i as f64 / n as f64) + (c - a) * (j as f64 / n as f64));
            }
        }
        points.extend((1..n).map(|j| a + (c - a) * (j as f64 / n as f64)));
    }
    points
}

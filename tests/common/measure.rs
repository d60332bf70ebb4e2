//! Measurements of meshes and cages made independently of the library: the
//! winding number (van Oosterom–Strackee), point–triangle distances, volumes,
//! angles, connected components and surface samples.

use super::winding_number;
use glam::DVec3;
use pmvc::geometry::procedural::SplitMix64;
use pmvc::geometry::{Cage, TriMesh};
use std::collections::HashMap;

pub fn cage_winding(cage: &Cage, x: DVec3) -> f64 {
    winding_number(cage.positions(), cage.triangles(), x)
}

pub fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
    p.distance(a + (b - a) * t)
}

/// Distance from `p` to a triangle: to its plane when `p` projects inside it,
/// otherwise to the nearest of its edges.
pub fn triangle_distance(p: DVec3, [a, b, c]: [DVec3; 3]) -> f64 {
    let n = (b - a).cross(c - a);
    let projects_inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|&(u, v)| (v - u).cross(p - u).dot(n) >= 0.0);
    if projects_inside {
        ((p - a).dot(n) / n.length()).abs()
    } else {
        segment_distance(p, a, b)
            .min(segment_distance(p, b, c))
            .min(segment_distance(p, c, a))
    }
}

pub fn signed_volume(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            a.dot(b.cross(c))
        })
        .sum::<f64>()
        / 6.0
}

/// Smallest interior angle of any triangle, in degrees.
pub fn min_angle_degrees(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    let angle = |at: DVec3, u: DVec3, v: DVec3| (u - at).angle_between(v - at).to_degrees();
    triangles
        .iter()
        .flat_map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            [angle(a, b, c), angle(b, c, a), angle(c, a, b)]
        })
        .fold(f64::INFINITY, f64::min)
}

/// Connected components of the vertices used by `triangles` (union–find).
pub fn components(vertex_count: usize, triangles: &[[u32; 3]]) -> usize {
    let mut parent: Vec<usize> = (0..vertex_count).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for t in triangles {
        for k in 1..3 {
            let (a, b) = (
                root(&mut parent, t[0] as usize),
                root(&mut parent, t[k] as usize),
            );
            parent[a] = b;
        }
    }
    let mut used = vec![false; vertex_count];
    triangles
        .iter()
        .flatten()
        .for_each(|&i| used[i as usize] = true);
    (0..vertex_count)
        .filter(|&i| used[i] && root(&mut parent, i) == i)
        .count()
}

/// How many triangles use each directed edge.
pub fn directed_edges(triangles: &[[u32; 3]]) -> HashMap<(u32, u32), usize> {
    let mut directed = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    directed
}

/// Whether every edge of `mesh` is used by exactly two triangles, once each way.
pub fn is_closed(mesh: &TriMesh) -> bool {
    let directed = directed_edges(&mesh.triangles);
    directed
        .iter()
        .all(|(&(a, b), &uses)| uses == 1 && directed.get(&(b, a)) == Some(&1))
}

/// The mesh's vertices plus `per_triangle` seeded random points on every triangle
/// and about 4,000 more spread by area, so large triangles are sampled too.
pub fn surface_samples(mesh: &TriMesh, per_triangle: usize, seed: u64) -> Vec<DVec3> {
    let corners = |t: &[u32; 3]| t.map(|i| mesh.positions[i as usize]);
    let area = |[a, b, c]: [DVec3; 3]| 0.5 * (b - a).cross(c - a).length();
    let total_area: f64 = mesh.triangles.iter().map(|t| area(corners(t))).sum();
    let mut random = SplitMix64(seed);
    let mut samples = mesh.positions.clone();
    for t in &mesh.triangles {
        let [a, b, c] = corners(t);
        let extra = (4000.0 * area([a, b, c]) / total_area).ceil() as usize;
        for _ in 0..per_triangle + extra {
            let (mut u, mut v) = (random.unit(), random.unit());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            samples.push(a + (b - a) * u + (c - a) * v);
        }
    }
    samples
}

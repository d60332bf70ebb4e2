//! Quads where an artist would draw them: pairs of a generated cage's triangles
//! that make near-planar, well-shaped quads, each kept only where its bilinear
//! patch keeps every guarantee of the two triangles it replaces.
//!
//! A quad's patch is within `δ = |q0 − q1 + q2 − q3| / 4` of either split of it
//! (bilinear minus piecewise-linear interpolation is `±uv·twist`, largest at the
//! centre), so a pair is only made where no sample of the mesh's surface is
//! within the clearance plus δ of its triangles: the patch then keeps the
//! clearance, and no sample lies between it and the triangles. The cage is still
//! validated as a quad cage (folds, self-intersection of the patches), a quad
//! named by a failure is split again, and the result is measured on its patches.

use super::points::PointTree;
use super::winding::TriangleTree;
use crate::geometry::classify::closest_point_on_triangle;
use crate::geometry::quads::{bilinear_point, nearest_uv};
use crate::geometry::{classify_points, triangulate_faces, Cage, CageError, CageReport};
use crate::geometry::{PointClass, TriMesh};
use glam::DVec3;
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};

/// Largest angle between the normals of a quad's two triangles.
const MAX_BEND_DEGREES: f64 = 30.0;
/// A quad's corner angles stay within this much of a right angle.
const MAX_SKEW_DEGREES: f64 = 50.0;
/// Quads that a failed validation names are split again at most this often.
const MAX_RETRIES: usize = 8;

/// The mesh's surface samples, which keep the clearance, and the gap points,
/// which stay outside.
pub(super) type Points<'a> = (&'a PointTree, &'a PointTree);

/// A pair of triangles sharing an edge, as the quad they would make.
struct Candidate {
    triangles: [usize; 2],
    corners: [u32; 4],
    score: f64,
}

/// The cage's polygons with suitable pairs of `triangles` as quads, leaving out
/// the triangles in `kept_apart`. `clearance` is the generator's.
fn pair(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    points: Points,
    clearance: f64,
    kept_apart: &HashSet<usize>,
) -> Vec<Vec<u32>> {
    let mut by_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (t, triangle) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (triangle[k], triangle[(k + 1) % 3]);
            by_edge.entry((a.min(b), a.max(b))).or_default().push(t);
        }
    }
    let mut candidates: Vec<Candidate> = by_edge
        .into_values()
        .filter_map(|faces| match faces[..] {
            [first, second] if !kept_apart.contains(&first) && !kept_apart.contains(&second) => {
                candidate(positions, triangles, [first, second], points, clearance)
            }
            _ => None,
        })
        .collect();
    candidates.sort_by(|a, b| {
        a.score
            .total_cmp(&b.score)
            .then(a.triangles.cmp(&b.triangles))
    });
    let mut used = vec![false; triangles.len()];
    let mut polygons = Vec::with_capacity(triangles.len());
    for candidate in candidates {
        let [first, second] = candidate.triangles;
        if !used[first] && !used[second] {
            used[first] = true;
            used[second] = true;
            polygons.push(candidate.corners.to_vec());
        }
    }
    for (t, triangle) in triangles.iter().enumerate() {
        if !used[t] {
            polygons.push(triangle.to_vec());
        }
    }
    polygons
}

/// The quad of two triangles that share an edge, if it is flat and square enough
/// and its patch keeps the clearance.
fn candidate(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    pair: [usize; 2],
    (samples, gaps): Points,
    clearance: f64,
) -> Option<Candidate> {
    let [first, second] = pair.map(|t| triangles[t]);
    // `first` runs a → b → c; `second` runs b → a → d: the quad is a, d, b, c.
    let k = (0..3).find(|&k| !second.contains(&first[(k + 2) % 3]))?;
    let (a, b, c) = (first[k], first[(k + 1) % 3], first[(k + 2) % 3]);
    let d = *second.iter().find(|&&v| v != a && v != b)?;
    let oriented = (0..3).any(|j| second[j] == b && second[(j + 1) % 3] == a);
    if !oriented || d == c {
        return None;
    }
    let corners = [a, d, b, c];
    let q = corners.map(|i| positions[i as usize]);
    let normal = |[p, r, s]: [DVec3; 3]| (r - p).cross(s - p).normalize_or_zero();
    let bend = normal([q[0], q[2], q[3]])
        .angle_between(normal([q[2], q[0], q[1]]))
        .to_degrees();
    if bend.is_nan() || bend > MAX_BEND_DEGREES {
        return None;
    }
    let mean_normal = (q[2] - q[0]).cross(q[3] - q[1]);
    let mut skew = 0.0;
    for k in 0..4 {
        let (next, previous) = (q[(k + 1) % 4] - q[k], q[(k + 3) % 4] - q[k]);
        // Convex, seen along the mean normal, and near square at every corner.
        if next.cross(previous).dot(mean_normal) <= 0.0 {
            return None;
        }
        let off_square = (next.angle_between(previous).to_degrees() - 90.0).abs();
        if off_square.is_nan() || off_square > MAX_SKEW_DEGREES {
            return None;
        }
        skew += off_square;
    }
    // Along a valley (d above the plane of a b c) the patch lies outside the two
    // triangles: it only adds volume outside the cage, where no sample is, and
    // every sample keeps its distance (a path from it to the patch crosses the
    // old surface). Along a ridge it cuts in by up to δ.
    let valley = (q[1] - q[0]).dot((q[2] - q[0]).cross(q[3] - q[0])) > 0.0;
    let deviation = ((q[0] - q[1]) + (q[2] - q[3])).length() / 4.0;
    let faces = [[q[0], q[2], q[3]], [q[2], q[0], q[1]]];
    if !valley && samples.any_within(&faces, clearance + deviation) {
        return None;
    }
    // Across a valley the patch bulges out by up to δ: into a gap, unless no
    // gap point is that near.
    if valley && gaps.any_within(&faces, deviation) {
        return None;
    }
    Some(Candidate {
        triangles: pair,
        corners,
        score: bend + skew / 4.0,
    })
}

/// The generated triangles as a validated cage with quads where they fit. A
/// quad that a validation error names is split again and the pairing redone.
pub(super) fn quad_cage(
    positions: Vec<DVec3>,
    triangles: &[[u32; 3]],
    points: Points,
    clearance: f64,
) -> Result<(Cage, CageReport), CageError> {
    let mut kept_apart = HashSet::new();
    let mut last_error = None;
    for _ in 0..=MAX_RETRIES {
        let polygons = pair(&positions, triangles, points, clearance, &kept_apart);
        match Cage::new(triangulate_faces(&polygons, &positions)) {
            Ok(result) => return Ok(result),
            Err(error) => {
                let named: Vec<usize> = match error {
                    CageError::SelfIntersecting { first, second } => vec![first, second],
                    CageError::FoldedQuad { face, .. } | CageError::DegenerateQuad { face, .. } => {
                        vec![face]
                    }
                    _ => return Err(error),
                };
                let quads: Vec<&Vec<u32>> = named
                    .iter()
                    .filter_map(|&face| polygons.get(face))
                    .filter(|polygon| polygon.len() == 4)
                    .collect();
                if quads.is_empty() {
                    return Err(error);
                }
                // Keep the named quads' triangles apart from now on.
                for quad in quads {
                    for (t, triangle) in triangles.iter().enumerate() {
                        if triangle.iter().all(|v| quad.contains(v)) {
                            kept_apart.insert(t);
                        }
                    }
                }
                last_error = Some(error);
            }
        }
    }
    // Every quad named so far is split; the triangles alone passed before.
    let all: HashSet<usize> = (0..triangles.len()).collect();
    let polygons = pair(&positions, triangles, points, clearance, &all);
    Cage::new(triangulate_faces(&polygons, &positions)).map_err(|e| last_error.unwrap_or(e))
}

/// Mesh vertices outside a cage with quads, by its patches, and the smallest
/// distance from a mesh vertex to its surface (lone triangles and patches).
pub(super) fn enclosure_on_patches(cage: &Cage, mesh: &TriMesh) -> super::measure::Enclosure {
    let classes = classify_points(cage, &mesh.positions).classes;
    let outside: Vec<usize> = classes
        .iter()
        .enumerate()
        .filter(|(_, class)| !matches!(class, PointClass::Inside))
        .map(|(i, _)| i)
        .collect();
    // Each patch is within its δ of its triangles, so only vertices within
    // twice the largest δ of the nearest to the triangles can be nearest to
    // the patches: those are measured exactly.
    let deviation = (0..cage.quads().len())
        .map(|k| {
            let q = cage.quad(k);
            ((q[0] - q[1]) + (q[2] - q[3])).length() / 4.0
        })
        .fold(0.0, f64::max);
    let tree = TriangleTree::new(cage.positions(), cage.triangles());
    let to_triangles: Vec<f64> = mesh
        .positions
        .par_iter()
        .map(|&p| tree.distance(p))
        .collect();
    let nearest = to_triangles.iter().copied().fold(f64::INFINITY, f64::min);
    let min_clearance = mesh
        .positions
        .par_iter()
        .zip(&to_triangles)
        .filter(|(_, &d)| d <= nearest + 2.0 * deviation)
        .map(|(&p, &d)| surface_distance(cage, p, d + deviation))
        .reduce(|| f64::INFINITY, f64::min);
    super::measure::Enclosure {
        outside: outside.len(),
        first_outside: outside.first().copied(),
        min_clearance,
    }
}

/// Distance from `p` to the cage's lone triangles and patches, given that it
/// is at most `bound`.
fn surface_distance(cage: &Cage, p: DVec3, bound: f64) -> f64 {
    let mut best = cage
        .lone_triangles()
        .map(|t| {
            let [a, b, c] = cage.triangle(t);
            closest_point_on_triangle(p, a, b, c).0.distance(p)
        })
        .fold(bound, f64::min);
    for k in 0..cage.quads().len() {
        let q = cage.quad(k);
        let centre = (q[0] + q[1] + q[2] + q[3]) / 4.0;
        let radius = q.iter().map(|c| c.distance(centre)).fold(0.0, f64::max);
        if p.distance(centre) - radius >= best {
            continue;
        }
        // Near-planar convex quads: a Gauss–Newton descent from the centre and
        // from near each corner finds the nearest point.
        for start in [[0.5, 0.5], [0.1, 0.1], [0.9, 0.1], [0.9, 0.9], [0.1, 0.9]] {
            let [u, v] = nearest_uv(&q, p, start);
            best = best.min(bilinear_point(&q, u, v).distance(p));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles across a valley (d 0.2 above the plane of a b c): their
    /// patch stands up to δ = 0.05 above them, at the centre. A gap point
    /// under that bulge keeps them two triangles; one further off does not.
    #[test]
    fn a_valley_pair_whose_patch_would_cover_a_gap_point_stays_two_triangles() {
        let positions = vec![
            DVec3::ZERO,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 0.0, 0.2),
        ];
        let triangles = [[0, 1, 2], [1, 0, 3]];
        let pair_with = |gap_points: Vec<DVec3>| {
            let (samples, gaps) = (PointTree::new(Vec::new()), PointTree::new(gap_points));
            candidate(&positions, &triangles, [0, 1], (&samples, &gaps), 0.01).is_some()
        };
        assert!(pair_with(Vec::new()));
        assert!(pair_with(vec![DVec3::new(0.5, 0.5, 0.5)]));
        assert!(!pair_with(vec![DVec3::new(0.5, 0.5, 0.03)]));
    }
}

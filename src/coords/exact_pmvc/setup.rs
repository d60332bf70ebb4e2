//! The candidates at x: the faces it sees from their inner side, set up
//! for the scan of [`super::visibility`], nearest first.

use super::patch::{self, QuadView};
use super::polygon::EdgePlane;
use super::{Candidate, Cone, ExactPmvcFailure, ExactPmvcScratch, THIN};
use crate::geometry::{closest_point_on_triangle, Cage};
use glam::DVec3;

/// Directions to the cage vertices and the candidates at x, nearest first.
pub(super) fn set_up(
    x: DVec3,
    cage: &Cage,
    scratch: &mut ExactPmvcScratch,
) -> Result<(), ExactPmvcFailure> {
    scratch.relative.clear();
    scratch.directions.clear();
    scratch.distances.clear();
    for &position in cage.positions() {
        let p = position - x;
        let distance = p.length();
        if !(distance > 0.0 && distance.is_finite()) {
            // On a cage vertex: the surface policy's case.
            return Err(ExactPmvcFailure::NotEnclosed);
        }
        scratch.relative.push(p);
        scratch.distances.push(distance);
        scratch.directions.push(p / distance);
    }
    scratch.candidates.clear();
    scratch.cones.clear();
    scratch.quad_views.clear();
    for quad in cage.quads() {
        let corners = quad.corners.map(|v| scratch.relative[v as usize]);
        scratch.quad_views.push(patch::view(quad.corners, corners));
    }
    scratch.grid_points.clear();
    for (t, &vertices) in cage.triangles().iter().enumerate() {
        if cage.quad_of_triangle(t).is_some() {
            continue;
        }
        if let Some((candidate, cone)) = triangle_candidate(vertices, scratch) {
            scratch.candidates.push(candidate);
            scratch.cones.push(cone);
        }
    }
    for (q, quad) in cage.quads().iter().enumerate() {
        match scratch.quad_views[q] {
            QuadView::Inner => {
                let (candidate, cone) = quad_candidate(q as u32, quad.corners, scratch);
                scratch.candidates.push(candidate);
                scratch.cones.push(cone);
            }
            QuadView::Outer => {}
            QuadView::Folded => folded_quad(q as u32, quad.corners, scratch),
        }
    }
    // Both lists in the order of the candidates' distances.
    scratch.order.clear();
    scratch.order.extend(0..scratch.candidates.len() as u32);
    let candidates = &scratch.candidates;
    scratch.order.sort_by(|&a, &b| {
        candidates[a as usize]
            .nearest
            .total_cmp(&candidates[b as usize].nearest)
    });
    scratch.sorted.clear();
    scratch.sorted_cones.clear();
    for &k in &scratch.order {
        let candidate = scratch.candidates[k as usize];
        scratch.sorted.push(candidate);
        scratch.sorted_cones.push(Cone {
            nearest: candidate.nearest,
            ..scratch.cones[k as usize]
        });
    }
    std::mem::swap(&mut scratch.candidates, &mut scratch.sorted);
    std::mem::swap(&mut scratch.cones, &mut scratch.sorted_cones);
    Ok(())
}

/// Cells along each side of the grid of sub-patches a folded quad is cut
/// into ([`folded_quad`]).
pub(super) const FOLD_GRID: usize = 4;

/// A quad x sees folded, as a grid of [`FOLD_GRID`]² sub-patches (each the
/// bilinear patch of its corners, whose basis composed with the quad's is
/// the quad's basis): those x sees whole from inside are candidates, those
/// seen from outside are skipped, and those still folded are taken as two
/// triangles. The grid's points are extra vertices after the cage's, which
/// hand their weights on to the quad's corners by its bilinear basis
/// ([`ExactPmvcScratch::grid_points`]).
fn folded_quad(q: u32, corners: [u32; 4], scratch: &mut ExactPmvcScratch) {
    let n = FOLD_GRID;
    let q_relative = corners.map(|v| scratch.relative[v as usize]);
    let mut ids = [[0u32; FOLD_GRID + 1]; FOLD_GRID + 1];
    for (i, row) in ids.iter_mut().enumerate() {
        for (j, id) in row.iter_mut().enumerate() {
            *id = match (i, j) {
                (0, 0) => corners[0],
                (i, 0) if i == n => corners[1],
                (i, j) if i == n && j == n => corners[2],
                (0, j) if j == n => corners[3],
                _ => {
                    let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                    let p = crate::geometry::quads::bilinear_point(&q_relative, u, v);
                    let distance = p.length();
                    scratch.relative.push(p);
                    scratch.distances.push(distance);
                    scratch.directions.push(p / distance);
                    scratch.grid_points.push((q, u, v));
                    (scratch.relative.len() - 1) as u32
                }
            };
        }
    }
    for i in 0..n {
        for j in 0..n {
            let cell = [ids[i][j], ids[i + 1][j], ids[i + 1][j + 1], ids[i][j + 1]];
            let p = cell.map(|v| scratch.relative[v as usize]);
            // x on a grid point: the coverage check refuses the point.
            if p.iter().any(|p| p.length() == 0.0 || p.is_nan()) {
                continue;
            }
            match patch::view(cell, p) {
                QuadView::Inner => {
                    let (candidate, cone) = quad_candidate(q, cell, scratch);
                    scratch.candidates.push(candidate);
                    scratch.cones.push(cone);
                }
                QuadView::Outer => {}
                QuadView::Folded => {
                    for triangle in [[cell[0], cell[1], cell[2]], [cell[0], cell[2], cell[3]]] {
                        if let Some((candidate, cone)) = triangle_candidate(triangle, scratch) {
                            scratch.candidates.push(candidate);
                            scratch.cones.push(cone);
                        }
                    }
                }
            }
        }
    }
}

/// The triangle as a candidate at x, if x sees it from its inner side.
fn triangle_candidate(vertices: [u32; 3], scratch: &ExactPmvcScratch) -> Option<(Candidate, Cone)> {
    let u = &scratch.directions;
    let [i0, i1, i2] = vertices.map(|v| v as usize);
    let normals = [u[i1].cross(u[i2]), u[i2].cross(u[i0]), u[i0].cross(u[i1])];
    let det = u[i0].dot(normals[0]);
    // Seen from the outer side (never the first hit from inside), or
    // edge on (x in its plane: rays graze it, it neither holds nor blocks).
    if det <= 0.0 || det.is_nan() {
        return None;
    }
    let p = [i0, i1, i2].map(|i| scratch.relative[i]);
    let normal = (p[1] - p[0]).cross(p[2] - p[0]);
    let offset = normal.dot(p[0]);
    let distances = [i0, i1, i2].map(|i| scratch.distances[i]);
    let weight_normals = std::array::from_fn(|k| normals[k] / (distances[k] * det));
    let sides = [
        EdgePlane::new(vertices[0], vertices[1], u),
        EdgePlane::new(vertices[1], vertices[2], u),
        EdgePlane::new(vertices[2], vertices[0], u),
    ];
    let perimeter = (u[i0] - u[i1]).length() + (u[i1] - u[i2]).length() + (u[i2] - u[i0]).length();
    let candidate = Candidate {
        thin: det < THIN * perimeter * perimeter,
        // The fourth slot repeats the third: only the first `count` are read.
        vertices: [vertices[0], vertices[1], vertices[2], vertices[2]],
        count: 3,
        sides: [sides[0], sides[1], sides[2], sides[2]],
        normal,
        offset,
        far_offset: offset,
        weight_normals,
        directions: [u[i0], u[i1], u[i2], u[i2]],
        // Shrunk by far more than its rounding, to stay a lower bound.
        nearest: closest_point_on_triangle(DVec3::ZERO, p[0], p[1], p[2])
            .0
            .length()
            * (1.0 - 1e-12),
        farthest: distances[0].max(distances[1]).max(distances[2]),
        quad: None,
    };
    Some((candidate, cone_of(&[u[i0], u[i1], u[i2]])))
}

/// The patch of quad `q` as a candidate at x, which sees it from its inner
/// side with no fold ([`QuadView::Inner`]).
fn quad_candidate(q: u32, vertices: [u32; 4], scratch: &ExactPmvcScratch) -> (Candidate, Cone) {
    let u = &scratch.directions;
    let index = vertices.map(|v| v as usize);
    let p = index.map(|i| scratch.relative[i]);
    let directions = index.map(|i| u[i]);
    let normal = (p[2] - p[0]).cross(p[3] - p[1]);
    let along = p.map(|p| normal.dot(p));
    let candidate = Candidate {
        thin: false,
        vertices,
        count: 4,
        sides: std::array::from_fn(|k| EdgePlane::new(vertices[k], vertices[(k + 1) % 4], u)),
        normal,
        offset: along.iter().copied().fold(f64::INFINITY, f64::min),
        far_offset: along.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        weight_normals: [DVec3::ZERO; 3],
        directions,
        nearest: patch::nearest(p) * (1.0 - 1e-12),
        farthest: index
            .iter()
            .map(|&i| scratch.distances[i])
            .fold(0.0, f64::max),
        quad: Some(q),
    };
    (candidate, cone_of(&directions))
}

/// The bounding cone of a face's directions, as [`Cone`] reads it.
fn cone_of(directions: &[DVec3]) -> Cone {
    let (axis, cos_radius) = bounding_cone(directions);
    // Past a right angle the cone no longer bounds the arcs: take it all.
    let (cos_radius, sin_radius) = if cos_radius > 0.0 {
        (cos_radius, (1.0 - cos_radius * cos_radius).max(0.0).sqrt())
    } else {
        (-1.0, 0.0)
    };
    Cone {
        axis,
        cos_radius,
        sin_radius,
        nearest: 0.0,
    }
}

/// A cone around a face's directions: its unit axis and the cosine of its
/// half angle. The tightest of the cone around their mean and those around
/// the middle of a side or diagonal (the smallest for an obtuse or long thin
/// triangle).
fn bounding_cone(corners: &[DVec3]) -> (DVec3, f64) {
    let cos_radius = |axis: DVec3| corners.iter().map(|&c| axis.dot(c)).fold(1.0, f64::min);
    let mean = corners.iter().copied().sum::<DVec3>().normalize();
    let mut best = (mean, cos_radius(mean));
    let n = corners.len();
    let pairs = (0..n).map(|k| (k, (k + 1) % n));
    let diagonals = (n == 4).then_some([(0, 2), (1, 3)]).into_iter().flatten();
    for (i, j) in pairs.chain(diagonals) {
        let axis = (corners[i] + corners[j]).normalize();
        let cos = cos_radius(axis);
        if cos > best.1 {
            best = (axis, cos);
        }
    }
    best
}

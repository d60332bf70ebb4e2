//! Mean value coordinates for closed triangle cages in closed form (Ju, Schaefer,
//! Warren 2005, "Mean value coordinates for closed triangular meshes", Fig. 4),
//! defined both inside and outside the cage.
//!
//! Robustness: a point on a cage vertex, edge or face gets that element's
//! barycentric interpolation; a triangle coplanar with the point and not containing
//! it contributes nothing; all arithmetic is f64.

use crate::geometry::{closest_point_on_triangle, Cage};
use glam::DVec3;
use std::f64::consts::PI;

/// Reusable per-vertex buffers.
#[derive(Debug, Default)]
pub struct MvcScratch {
    distances: Vec<f64>,
    directions: Vec<DVec3>,
}

/// Below this (relative to the cage diagonal) a point is on a vertex, edge or face.
const ON_SURFACE: f64 = 1e-12;
/// `sin` of the angle below which a spherical triangle is treated as flat.
const FLAT: f64 = 1e-12;

/// MVC of `x`, written to `out` (one value per cage vertex).
pub fn mvc_weights(x: DVec3, cage: &Cage, out: &mut [f64], scratch: &mut MvcScratch) {
    out.fill(0.0);
    let tolerance = ON_SURFACE * cage.diagonal().max(f64::MIN_POSITIVE);
    scratch.distances.clear();
    scratch.directions.clear();
    for (j, &p) in cage.positions().iter().enumerate() {
        let offset = p - x;
        let distance = offset.length();
        if distance <= tolerance {
            out[j] = 1.0;
            return;
        }
        scratch.distances.push(distance);
        scratch.directions.push(offset / distance);
    }

    let mut total = 0.0;
    for (t, corners) in cage.triangles().iter().enumerate() {
        let index = corners.map(|i| i as usize);
        let d = index.map(|i| scratch.distances[i]);
        let u = index.map(|i| scratch.directions[i]);
        // θ_k: the arc opposite corner k on the unit sphere, via the half chord
        // sin(θ_k/2), which also gives sin θ_k and cos θ_k without more trigonometry.
        let half_chord: [f64; 3] =
            std::array::from_fn(|k| (0.5 * (u[(k + 1) % 3] - u[(k + 2) % 3]).length()).min(1.0));
        let theta = half_chord.map(|a| 2.0 * a.asin());
        let h = 0.5 * (theta[0] + theta[1] + theta[2]);
        if PI - h <= FLAT {
            // x lies inside this triangle: interpolate linearly on it.
            let [a, b, c] = cage.triangle(t);
            let (_, barycentric) = closest_point_on_triangle(x, a, b, c);
            out.fill(0.0);
            for k in 0..3 {
                out[index[k]] += barycentric[k];
            }
            return;
        }
        let sin_theta = half_chord.map(|a| 2.0 * a * (1.0 - a * a).max(0.0).sqrt());
        let cos_theta = half_chord.map(|a| 1.0 - 2.0 * a * a);
        let (sin_h, cos_h) = h.sin_cos();
        let c: [f64; 3] = std::array::from_fn(|k| {
            // sin(h − θ_k), expanded.
            let sin_h_minus_theta = sin_h * cos_theta[k] - cos_h * sin_theta[k];
            2.0 * sin_h * sin_h_minus_theta / (sin_theta[(k + 1) % 3] * sin_theta[(k + 2) % 3])
                - 1.0
        });
        let orientation = u[0].dot(u[1].cross(u[2])).signum();
        let s = c.map(|ck| orientation * (1.0 - ck * ck).max(0.0).sqrt());
        if s.iter().any(|sk| sk.abs() <= FLAT) {
            // x is in the triangle's plane, outside it: no contribution.
            continue;
        }
        for k in 0..3 {
            let (next, previous) = ((k + 1) % 3, (k + 2) % 3);
            let w = (theta[k] - c[next] * theta[previous] - c[previous] * theta[next])
                / (d[k] * sin_theta[next] * s[previous]);
            out[index[k]] += w;
            total += w;
        }
    }
    if total != 0.0 && total.is_finite() {
        let inverse = 1.0 / total;
        for value in out.iter_mut() {
            *value *= inverse;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::procedural;

    #[test]
    fn vertex_gets_its_own_coordinate() {
        let cage = procedural::cube_cage(1.0);
        let mut out = vec![0.0; cage.vertex_count()];
        mvc_weights(
            cage.positions()[3],
            &cage,
            &mut out,
            &mut MvcScratch::default(),
        );
        for (j, &w) in out.iter().enumerate() {
            assert_eq!(w, if j == 3 { 1.0 } else { 0.0 });
        }
    }
}

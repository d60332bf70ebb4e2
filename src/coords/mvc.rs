//! Mean value coordinates for closed triangle cages in closed form (Ju, Schaefer,
//! Warren 2005, "Mean value coordinates for closed triangular meshes", Fig. 4),
//! defined both inside and outside the cage.
//!
//! Robustness: a point on a cage vertex, edge or face gets that element's
//! barycentric interpolation; a triangle coplanar with the point and not containing
//! it contributes nothing; all arithmetic is f64.
//!
//! Far field: outside the cage the closed form's total weight is a sum of front-
//! and back-face terms that cancel to about (size/distance)³, so its linear
//! precision decays with the cube of the distance: measured on a comb cage, 1e-11
//! of the distance at one cage diagonal and 2e-9 at four; on a cube 3e-4 at 10⁴
//! diagonals, nothing left at 10⁵, and all-zero rows from 10¹⁷.
//! Beyond [`FAR_FIELD_DIAGONALS`] from the cage's vertex centroid, a point gets
//! the closed form at the point where its ray from the centroid crosses that
//! sphere, plus the cage's least-squares affine extension of the remaining
//! offset. That keeps, exactly and at every distance, what MVC promise outside:
//! the weights sum to one, reproduce the point (linear precision), so that an
//! affine motion of the cage moves the point by the same map, and vary
//! continuously (across the sphere too).

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

/// Distance from the cage's vertex centroid, in cage diagonals, beyond which
/// [`mvc_weights`] extends the closed form affinely instead of evaluating it
/// (see the module doc): up to there the closed form keeps linear precision to
/// a few 1e-9 of the distance.
pub const FAR_FIELD_DIAGONALS: f64 = 4.0;

/// MVC of `x`, written to `out` (one value per cage vertex); far from the cage,
/// their affine extension (see the module doc).
pub fn mvc_weights(x: DVec3, cage: &Cage, out: &mut [f64], scratch: &mut MvcScratch) {
    let positions = cage.positions();
    let centroid = positions.iter().sum::<DVec3>() / positions.len().max(1) as f64;
    let radius = FAR_FIELD_DIAGONALS * cage.diagonal();
    let offset = x - centroid;
    let distance = offset.length();
    if distance.is_nan() || distance <= radius {
        closed_form(x, cage, out, scratch);
        return;
    }
    // The anchor is where the ray from the centroid leaves the sphere; what is
    // left of the offset is carried by the affine extension.
    let anchor = centroid + offset * (radius / distance);
    let remaining = offset * (1.0 - radius / distance);
    closed_form(anchor, cage, out, scratch);
    add_affine_extension(cage, centroid, remaining, out);
}

/// Add to `out` the weights `μᵢ = (vᵢ − c)ᵀ M⁻¹ r`, with `M = Σ (vᵢ − c)(vᵢ − c)ᵀ`:
/// they sum to zero and reproduce the offset `r` (`Σ μᵢ vᵢ = r`), and applied to
/// cage displacements they give the least-squares affine fit of the motion.
fn add_affine_extension(cage: &Cage, centroid: DVec3, remaining: DVec3, out: &mut [f64]) {
    let mut spread = glam::DMat3::ZERO;
    for &v in cage.positions() {
        let e = v - centroid;
        spread += glam::DMat3::from_cols(e * e.x, e * e.y, e * e.z);
    }
    // A validated cage encloses a volume, so its vertices span 3D and the spread
    // is invertible.
    let direction = spread.inverse() * remaining;
    for (value, &v) in out.iter_mut().zip(cage.positions()) {
        *value += (v - centroid).dot(direction);
    }
}

/// Ju, Schaefer and Warren's closed form at `x`.
fn closed_form(x: DVec3, cage: &Cage, out: &mut [f64], scratch: &mut MvcScratch) {
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

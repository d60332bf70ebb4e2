//! Mean value coordinates for closed triangle cages in closed form (Ju, Schaefer,
//! Warren 2005, "Mean value coordinates for closed triangular meshes", Fig. 4),
//! defined both inside and outside the cage. A cage's quads are bilinear
//! patches, with QMVC terms ([`super::qmvc`], Thiery, Memari, Boubekeur 2018)
//! beside its lone triangles' terms: the same integral with the bilinear basis.
//! A cage of triangles only takes the triangle path exactly as it always did.
//!
//! Robustness: a point on a cage vertex, edge, face or patch gets that element's
//! barycentric or bilinear interpolation; a triangle or flat quad coplanar with
//! the point and not containing it contributes nothing; all arithmetic is f64.
//!
//! Far field: outside the cage the closed form's total weight is a sum of front-
//! and back-face terms that cancel to about (size/distance)³, so its linear
//! precision decays with the cube of the distance: measured on a comb cage, 1e-11
//! of the distance at one cage diagonal and 2e-9 at four; on a cube 3e-4 at 10⁴
//! diagonals, nothing left at 10⁵, and all-zero rows from 10¹⁷. With quads it
//! holds better (their three closed-form equations use the edges only): 2e-14
//! of the distance at four diagonals on a comb of quads.
//! Beyond [`FAR_FIELD_DIAGONALS`] from the cage's vertex centroid, a point gets
//! the closed form at the point where its ray from the centroid crosses that
//! sphere, plus the cage's least-squares affine extension of the remaining
//! offset. That keeps, exactly and at every distance, what MVC promise outside:
//! the weights sum to one, reproduce the point (linear precision), so that an
//! affine motion of the cage moves the point by the same map, and vary
//! continuously (across the sphere too). It needs only that the closed form
//! has those properties at the sphere, which QMVC have as MVC do.

use super::qmvc::{self, QuadTerm};
use crate::geometry::{closest_point_on_triangle, Cage};
use glam::DVec3;
use std::f64::consts::PI;

/// Reusable per-vertex buffers.
#[derive(Debug, Default)]
pub struct MvcScratch {
    distances: Vec<f64>,
    directions: Vec<DVec3>,
}

/// Below this (relative to the cage diagonal) a point is on a vertex, edge, face
/// or patch.
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

/// Ju, Schaefer and Warren's closed form at `x`, with QMVC terms for quads.
fn closed_form(x: DVec3, cage: &Cage, out: &mut [f64], scratch: &mut MvcScratch) {
    closed_form_with(x, cage, out, scratch, |x, q, tolerance| {
        qmvc::quadrature::integrate(x, q, tolerance, &qmvc::RULE)
    });
}

/// [`closed_form`] with the quads' numerical term from `integrate(x, quad,
/// tolerance)`, for tests that compare quadratures.
pub(crate) fn closed_form_with(
    x: DVec3,
    cage: &Cage,
    out: &mut [f64],
    scratch: &mut MvcScratch,
    integrate: impl Fn(DVec3, &[DVec3; 4], f64) -> qmvc::Integral,
) {
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
    // Triangles that are faces of their own (all of them in a cage of triangles);
    // the others are halves of quads, which are patches here.
    for t in (0..cage.triangle_count()).filter(|&t| cage.quad_of_triangle(t).is_none()) {
        let index = cage.triangles()[t].map(|i| i as usize);
        match triangle_term(index, scratch) {
            TriangleTerm::Inside => return on_triangle(x, cage, t, index, out),
            TriangleTerm::Coplanar => continue,
            TriangleTerm::Weights(w) => {
                for k in 0..3 {
                    out[index[k]] += w[k];
                    total += w[k];
                }
            }
        }
    }
    for (k, quad) in cage.quads().iter().enumerate() {
        let index = quad.corners.map(|i| i as usize);
        let q = cage.quad(k);
        let term = qmvc::quad_term(
            x,
            &q,
            index.map(|i| scratch.distances[i]),
            index.map(|i| scratch.directions[i]),
            integrate(x, &q, tolerance),
        );
        match term {
            QuadTerm::OnPatch(basis) => {
                out.fill(0.0);
                for (&i, b) in index.iter().zip(basis) {
                    out[i] += b;
                }
                return;
            }
            QuadTerm::Coplanar => continue,
            QuadTerm::Weights(w) => {
                // Ju et al.'s triangle weights are twice the integral (their
                // pseudocode drops m's factor ½); the quads' match them.
                for k in 0..4 {
                    out[index[k]] += 2.0 * w[k];
                    total += 2.0 * w[k];
                }
            }
        }
    }
    if total != 0.0 && total.is_finite() {
        let inverse = 1.0 / total;
        for value in out.iter_mut() {
            *value *= inverse;
        }
    }
}

/// What one triangle adds to the closed form.
enum TriangleTerm {
    /// The point lies inside the triangle.
    Inside,
    /// The point is in the triangle's plane, outside it: no contribution.
    Coplanar,
    Weights([f64; 3]),
}

/// Ju, Schaefer and Warren's weights of one triangle's corners, from the
/// distances and directions in `scratch`.
fn triangle_term(index: [usize; 3], scratch: &MvcScratch) -> TriangleTerm {
    let d = index.map(|i| scratch.distances[i]);
    let u = index.map(|i| scratch.directions[i]);
    // θ_k: the arc opposite corner k on the unit sphere, via the half chord
    // sin(θ_k/2), which also gives sin θ_k and cos θ_k without more trigonometry.
    let half_chord: [f64; 3] =
        std::array::from_fn(|k| (0.5 * (u[(k + 1) % 3] - u[(k + 2) % 3]).length()).min(1.0));
    let theta = half_chord.map(|a| 2.0 * a.asin());
    let h = 0.5 * (theta[0] + theta[1] + theta[2]);
    if PI - h <= FLAT {
        return TriangleTerm::Inside;
    }
    let sin_theta = half_chord.map(|a| 2.0 * a * (1.0 - a * a).max(0.0).sqrt());
    let cos_theta = half_chord.map(|a| 1.0 - 2.0 * a * a);
    let (sin_h, cos_h) = h.sin_cos();
    let c: [f64; 3] = std::array::from_fn(|k| {
        // sin(h − θ_k), expanded.
        let sin_h_minus_theta = sin_h * cos_theta[k] - cos_h * sin_theta[k];
        2.0 * sin_h * sin_h_minus_theta / (sin_theta[(k + 1) % 3] * sin_theta[(k + 2) % 3]) - 1.0
    });
    let orientation = u[0].dot(u[1].cross(u[2])).signum();
    let s = c.map(|ck| orientation * (1.0 - ck * ck).max(0.0).sqrt());
    if s.iter().any(|sk| sk.abs() <= FLAT) {
        return TriangleTerm::Coplanar;
    }
    TriangleTerm::Weights(std::array::from_fn(|k| {
        let (next, previous) = ((k + 1) % 3, (k + 2) % 3);
        (theta[k] - c[next] * theta[previous] - c[previous] * theta[next])
            / (d[k] * sin_theta[next] * s[previous])
    }))
}

/// `x` inside triangle `t`: interpolate linearly on it.
fn on_triangle(x: DVec3, cage: &Cage, t: usize, index: [usize; 3], out: &mut [f64]) {
    let [a, b, c] = cage.triangle(t);
    let (_, barycentric) = closest_point_on_triangle(x, a, b, c);
    out.fill(0.0);
    for k in 0..3 {
        out[index[k]] += barycentric[k];
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

    /// Ju et al.'s weights are twice `∫ βᵢ (p − x)·n / |p − x|⁴ dA`, the measure
    /// the quads' terms are integrals of: hence the quads' factor 2.
    #[test]
    fn triangle_weights_are_twice_the_integral() {
        let tri = [
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(-0.5, -0.9, 0.1),
            DVec3::new(-0.4, 0.8, -0.2),
        ];
        for x in [DVec3::new(0.1, -0.3, 1.1), DVec3::new(0.4, 0.2, -0.7)] {
            let mut scratch = MvcScratch::default();
            for p in tri {
                scratch.distances.push((p - x).length());
                scratch.directions.push((p - x).normalize());
            }
            let TriangleTerm::Weights(w) = triangle_term([0, 1, 2], &scratch) else {
                panic!("a triangle off its plane has weights");
            };
            // The triangle as the patch whose last side collapses onto its first corner.
            let quad = [tri[0], tri[1], tri[2], tri[0]];
            let integral = crate::coords::qmvc::reference::face_integral(x, &quad, 32, 10);
            let expected = [integral[0] + integral[3], integral[1], integral[2]];
            for k in 0..3 {
                assert!(
                    (w[k] - 2.0 * expected[k]).abs() < 1e-12 * w[k].abs(),
                    "{w:?} {expected:?}"
                );
            }
        }
    }
}

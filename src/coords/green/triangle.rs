//! The boundary integrals of one cage triangle in closed form.
//!
//! With G(ξ, η) = −1/(4π|ξ − η|) and h = n·(ξ − η) the height of the triangle's
//! plane above η (positive when η is on the inner side of an outward triangle):
//! - the solid angle Ω = h ∫ 1/r³ dξ (Van Oosterom and Strackee);
//! - Lₑ = ∫ₑ 1/r ds along each edge;
//! - ψ = −∫ G dξ = (Σₑ dₑ Lₑ − h Ω) / 4π, with dₑ the signed in-plane distance from
//!   η's foot to edge e;
//! - φₖ = ∫ Γₖ ∂G/∂n dξ = (Γₖ(p) Ω − h ∇Γₖ · Σₑ mₑ Lₑ) / 4π, with Γₖ corner k's
//!   linear hat function, p η's foot and mₑ the outward in-plane edge normals.
//!
//! Both come from the in-plane divergence theorem (docs/green.md derives them).
//! Unlike the paper's per-corner division by `N·v`, nothing here divides by h, so
//! points on or near the triangle's plane lose no accuracy.

use crate::geometry::closest_offset_on_triangle;
use glam::DVec3;
use std::f64::consts::PI;

/// What one triangle adds to a point's coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct TriangleIntegrals {
    /// Signed solid angle the triangle subtends (positive seen from its inner side).
    pub solid_angle: f64,
    /// φ contribution of each corner, in the triangle's corner order.
    pub phi: [f64; 3],
    pub psi: f64,
}

/// One cage triangle's geometry, computed once per bind.
#[derive(Clone, Copy, Debug)]
pub(super) struct TriangleFrame {
    pub corners: [DVec3; 3],
    /// Unit outward normal.
    pub normal: DVec3,
    pub doubled_area: f64,
    /// `edges[e]` runs from corner e to corner e + 1; it is opposite corner e + 2.
    edges: [DVec3; 3],
    lengths: [f64; 3],
    /// Outward in-plane unit normal of each edge.
    edge_normals: [DVec3; 3],
}

impl TriangleFrame {
    pub fn new(corners: [DVec3; 3]) -> Self {
        let edges: [DVec3; 3] = std::array::from_fn(|e| corners[(e + 1) % 3] - corners[e]);
        let area_vector = edges[0].cross(corners[2] - corners[0]);
        let doubled_area = area_vector.length();
        let normal = area_vector.normalize_or_zero();
        let lengths = edges.map(DVec3::length);
        let edge_normals = edges.map(|edge| edge.cross(normal).normalize_or_zero());
        Self {
            corners,
            normal,
            doubled_area,
            edges,
            lengths,
            edge_normals,
        }
    }

    /// Signed distance from the triangle's plane to `x`, positive on the outer side.
    pub fn height_of(&self, x: DVec3) -> f64 {
        self.normal.dot(x - self.corners[0])
    }

    /// The affine frame of the triangle and its normal: `(λ, t)` with
    /// `x = Σ λₖ cornerₖ + t n` and `Σ λₖ = 1`, the λ not clamped to the triangle.
    pub fn affine_frame(&self, x: DVec3) -> ([f64; 3], f64) {
        let height = self.height_of(x);
        // Corners relative to x's foot, from differences with x: the foot itself
        // would be rounded to the coordinates' spacing far from the origin.
        let barycentric = std::array::from_fn(|k| {
            let opposite = (k + 1) % 3;
            let from_foot = (self.corners[opposite] - x) + height * self.normal;
            self.edge_normals[opposite].dot(from_foot) * self.lengths[opposite] / self.doubled_area
        });
        (barycentric, height)
    }

    /// If `x` is within `tolerance` of the triangle, the angle the triangle spans
    /// around the closest point: 2π inside it, π on an edge, the corner's angle at a
    /// corner (the weights of the angle-weighted normal).
    pub fn angle_at(&self, x: DVec3, tolerance: f64) -> Option<f64> {
        if self.height_of(x).abs() > tolerance {
            return None;
        }
        let [a, b, c] = self.corners;
        let (offset, barycentric) = closest_offset_on_triangle(x, a, b, c);
        if offset.length() > tolerance {
            return None;
        }
        // Distance from the closest point to the edge opposite each corner.
        let near_edge: [bool; 3] = std::array::from_fn(|k| {
            let opposite = (k + 1) % 3;
            barycentric[k] * self.doubled_area / self.lengths[opposite] <= tolerance
        });
        Some(match near_edge.iter().filter(|&&near| near).count() {
            0 => 2.0 * PI,
            1 => PI,
            _ => {
                // At the corner both of whose edges are near: the one whose
                // opposite edge is not.
                let corner = (0..3).find(|&k| !near_edge[k]).unwrap_or(0);
                let (to_next, to_previous) = (
                    self.corners[(corner + 1) % 3] - self.corners[corner],
                    self.corners[(corner + 2) % 3] - self.corners[corner],
                );
                to_next.angle_between(to_previous)
            }
        })
    }

    /// The triangle's integrals seen from `x`.
    pub fn integrals(&self, x: DVec3) -> TriangleIntegrals {
        let relative = self.corners.map(|corner| corner - x);
        let distances = relative.map(DVec3::length);
        // The plane's height above x (positive on the inner side), averaged over the
        // three corners so that one corner's rounding does not decide the side.
        // `+ 0.0` turns −0 into +0: a point exactly on the triangle gets the limit
        // from the inner side, Ω = 2π.
        let inner_height = (self.normal.dot(relative[0])
            + self.normal.dot(relative[1])
            + self.normal.dot(relative[2]))
            / 3.0
            + 0.0;
        let [a, b, c] = relative;
        let [ra, rb, rc] = distances;
        let denominator = ra * rb * rc + a.dot(b) * rc + b.dot(c) * ra + c.dot(a) * rb;
        let solid_angle = 2.0 * (inner_height * self.doubled_area).atan2(denominator);

        let mut foot_distances = [0.0; 3];
        let mut psi_sum = 0.0;
        let mut weighted_normals = DVec3::ZERO;
        for e in 0..3 {
            let next = (e + 1) % 3;
            foot_distances[e] = self.edge_normals[e].dot(relative[e]);
            let log = edge_log_integral(
                relative[e],
                relative[next],
                distances[e],
                distances[next],
                self.edges[e],
                self.lengths[e],
            );
            psi_sum += foot_distances[e] * log;
            weighted_normals += self.edge_normals[e] * log;
        }
        let quarter_over_pi = 0.25 / PI;
        let psi = (psi_sum - inner_height * solid_angle) * quarter_over_pi;
        let phi = std::array::from_fn(|k| {
            let opposite = (k + 1) % 3;
            self.lengths[opposite] / self.doubled_area
                * (foot_distances[opposite] * solid_angle
                    + inner_height * self.edge_normals[opposite].dot(weighted_normals))
                * quarter_over_pi
        });
        TriangleIntegrals {
            solid_angle,
            phi,
            psi,
        }
    }
}

/// ∫ 1/r ds along the segment from `a` to `b` (given relative to the point, with
/// their lengths `ra`, `rb`), as ln((ra + rb + ℓ) / (ra + rb − ℓ)).
///
/// `ra + rb − ℓ` cancels when the point is near the segment; there it is rewritten
/// as `2|a × e|² / ((ra rb − a·b)(ra + rb + ℓ))`, which has no cancellation. On the
/// segment itself the integral is infinite; it is capped (every use multiplies it by
/// a distance that is then zero), so the result stays finite.
fn edge_log_integral(a: DVec3, b: DVec3, ra: f64, rb: f64, edge: DVec3, length: f64) -> f64 {
    let sum = ra + rb;
    let cosine_term = a.dot(b);
    let gap = if cosine_term >= 0.0 {
        // The segment is seen under at most 90°: ra + rb − ℓ ≥ 0.29 (ra + rb).
        sum - length
    } else {
        2.0 * a.cross(edge).length_squared() / ((ra * rb - cosine_term) * (sum + length))
    };
    (sum + length).ln() - gap.max(f64::MIN_POSITIVE).ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> TriangleFrame {
        TriangleFrame::new([
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.5, 1.5, 0.0),
        ])
    }

    #[test]
    fn edge_integral_matches_the_direct_logarithm() {
        let (a, b) = (DVec3::new(-1.0, 0.3, 0.2), DVec3::new(2.0, 0.3, 0.2));
        // ∫ ds / sqrt(s² + ρ²) from s = −1 to 2 with ρ² = 0.13.
        let rho = 0.13f64.sqrt();
        let direct = (2.0 / rho).asinh() - (-1.0 / rho).asinh();
        let closed = edge_log_integral(a, b, a.length(), b.length(), b - a, 3.0);
        assert!((direct - closed).abs() < 1e-13, "{direct} {closed}");
    }

    #[test]
    fn point_on_the_triangle_gets_the_inner_limit() {
        let frame = frame();
        let x = DVec3::new(0.7, 0.4, 0.0);
        let on = frame.integrals(x);
        let below = frame.integrals(x - 1e-9 * DVec3::Z);
        assert_eq!(on.solid_angle, 2.0 * PI);
        for k in 0..3 {
            assert!((on.phi[k] - below.phi[k]).abs() < 1e-7, "{on:?} {below:?}");
        }
        assert!((on.psi - below.psi).abs() < 1e-7);
        // The inner limit of the double layer on the triangle: half the hat function.
        let (barycentric, _) = frame.affine_frame(x);
        for (phi, hat) in on.phi.iter().zip(barycentric) {
            assert!((phi - 0.5 * hat).abs() < 1e-12);
        }
    }

    #[test]
    fn points_on_edges_and_corners_stay_finite() {
        let frame = frame();
        for x in [
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(3.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 1e-300),
        ] {
            let integrals = frame.integrals(x);
            assert!(integrals.psi.is_finite() && integrals.phi.iter().all(|v| v.is_finite()));
        }
    }
}

//! Quads as bilinear patches `P(u, v)` in exact PMVC: which quads are
//! candidates at x, where a ray meets one, and the adaptive quadrature of
//! `∫_R ψₖ(u(σ), v(σ)) / |P(u, v) − x| dσ` over a visible piece R.
//!
//! `det[P − x, Pᵤ, Pᵥ]` is bilinear in (u, v) (see
//! [`crate::coords::pmvc::patch::PatchSetup::corner_sides`]), so its four
//! corner values bound its sign over the patch. All four positive: x sees the
//! whole patch from its inner side with no fold, the map from (u, v) to
//! directions is one to one, and its image is the spherical quadrilateral of
//! the corners, convex (each corner value is the determinant of three
//! consecutive corners' directions). All four non-positive: x sees it from
//! outside (or edge on) and it is skipped as a triangle would be. Mixed: x sees
//! a fold of the patch (a silhouette inside it); that quad is then taken, at
//! this point only, as the cage's two triangles of it (its shorter split),
//! and counted ([`super::ExactPmvcStats::folded`]).

use super::polygon::{mean_vector, Corner};
use crate::coords::pmvc::frustum::FACE_FRAMES;
use crate::coords::pmvc::patch::{FacePatch, PatchSetup};
use crate::geometry::closest_point_on_triangle;
use glam::DVec3;

/// How x sees a quad.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum QuadView {
    /// From its inner side, with no fold: a candidate of four sides.
    Inner,
    /// From its outer side, or edge on: skipped.
    Outer,
    /// A fold of the patch: its two triangles stand in for it at this point.
    Folded,
}

/// How x (the origin) sees the patch of `corners` (relative to x).
pub(super) fn view(vertices: [u32; 4], corners: [DVec3; 4]) -> QuadView {
    let sides = PatchSetup::new(vertices, corners).corner_sides();
    if sides.iter().all(|&d| d > 0.0) {
        QuadView::Inner
    } else if sides.iter().all(|&d| d <= 0.0) {
        QuadView::Outer
    } else {
        QuadView::Folded
    }
}

/// A lower bound on the distance from x (the origin) to the patch: the
/// distance to the tetrahedron of its corners, which holds it (0 when x is
/// inside it).
pub(super) fn nearest(corners: [DVec3; 4]) -> f64 {
    const FACES: [[usize; 3]; 4] = [[0, 1, 2], [0, 2, 3], [0, 1, 3], [1, 2, 3]];
    let [a, b, c, d] = corners;
    let volume = (b - a).cross(c - a).dot(d - a);
    // x is inside when it is on the side of each face that the fourth corner is.
    let inside = volume != 0.0
        && FACES.iter().enumerate().all(|(k, &[i, j, l])| {
            let opposite = corners[3 - k];
            let (p, q, r) = (corners[i], corners[j], corners[l]);
            let normal = (q - p).cross(r - p);
            normal.dot(-p) * normal.dot(opposite - p) >= 0.0
        });
    if inside {
        return 0.0;
    }
    FACES
        .iter()
        .map(|&[i, j, l]| {
            closest_point_on_triangle(DVec3::ZERO, corners[i], corners[j], corners[l])
                .0
                .length()
        })
        .fold(f64::INFINITY, f64::min)
}

/// One patch at x, its cube-face solves built as rays need them.
#[derive(Debug)]
pub(super) struct Patch {
    setup: PatchSetup,
    faces: [Option<FacePatch>; 6],
}

/// How far outside [0, 1] a node's u and v may round and still count as on
/// the patch (nodes are inside visible pieces, so inside the patch's image).
const SLACK: f64 = 1e-9;

impl Patch {
    pub(super) fn new(vertices: [u32; 4], corners: [DVec3; 4]) -> Self {
        Self {
            setup: PatchSetup::new(vertices, corners),
            faces: [None; 6],
        }
    }

    /// Where the ray from x along `d` (any length) first meets the patch:
    /// `1/|y − x|` and the bilinear basis of the corners at the hit, or
    /// `None` when it misses.
    pub(super) fn hit(&mut self, d: DVec3) -> Option<(f64, [f64; 4])> {
        let a = d.abs();
        let axis = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let face = 2 * axis + usize::from(d[axis] < 0.0);
        let frame = &FACE_FRAMES[face];
        let setup = &self.setup;
        let solve = self.faces[face].get_or_insert_with(|| setup.on_face(frame, 0, 0));
        let local = frame.local(d);
        let (s, r) = (local.x / local.z, local.y / local.z);
        let [inverse_t, u, below, above] = solve.hit_with_slack(s, r, SLACK)?;
        let inverse_distance = inverse_t / (1.0 + s * s + r * r).sqrt();
        let v = above / (below + above);
        if !(inverse_distance > 0.0 && inverse_distance.is_finite() && v.is_finite()) {
            return None;
        }
        let basis = crate::geometry::quads::bilinear_basis(u, v);
        Some((inverse_distance, basis))
    }
}

/// What one piece's quadrature did.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct QuadratureCount {
    /// Rays cast (two rules per spherical triangle integrated).
    pub(super) nodes: usize,
    /// Rays that missed the patch (rounding at its edge): they add nothing.
    pub(super) missed: usize,
    /// Triangles accepted at [`DEEPEST`] above their tolerance.
    pub(super) unresolved: usize,
}

/// Splits deeper than this stop, and the finer rule's value is kept.
const DEEPEST: u32 = 10;

/// `∫_R ψₖ / |y − x| dσ` over the convex spherical polygon `piece` of the
/// patch's image, for its four corners: each triangle of a fan is
/// integrated by two Gauss–Legendre rules (6² and 8² nodes on the square
/// collapsed onto it), and split in four until the two differ by at most
/// `tolerance_per_steradian` times its solid angle (summed over the four
/// corners), the finer one kept. Returns the weights and the solid angle.
pub(super) fn integrate_piece(
    piece: &[Corner],
    patch: &mut Patch,
    tolerance_per_steradian: f64,
    count: &mut QuadratureCount,
) -> ([f64; 4], f64) {
    let (_, solid_angle) = mean_vector(piece);
    let first = piece[0].direction;
    let mut sum = [0.0; 4];
    for k in 1..piece.len() - 1 {
        let (b, c) = (piece[k].direction, piece[k + 1].direction);
        let omega = triangle_solid_angle(first, b, c);
        let tolerance = tolerance_per_steradian * omega.abs();
        let part = adapt(first, b, c, patch, tolerance, 0, count);
        for (s, p) in sum.iter_mut().zip(part) {
            *s += p;
        }
    }
    (sum, solid_angle)
}

/// Van Oosterom and Strackee's solid angle of the spherical triangle.
fn triangle_solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let triple = a.dot(b.cross(c));
    let cosines = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
    2.0 * triple.atan2(cosines)
}

fn adapt(
    a: DVec3,
    b: DVec3,
    c: DVec3,
    patch: &mut Patch,
    tolerance: f64,
    depth: u32,
    count: &mut QuadratureCount,
) -> [f64; 4] {
    let coarse = rule(a, b, c, patch, &GAUSS_6, count);
    let fine = rule(a, b, c, patch, &super::polygon::GAUSS, count);
    let error: f64 = coarse.iter().zip(&fine).map(|(c, f)| (c - f).abs()).sum();
    if error <= tolerance {
        return fine;
    }
    if depth >= DEEPEST {
        count.unresolved += 1;
        return fine;
    }
    let [ab, bc, ca] = [a + b, b + c, c + a].map(|m| m.normalize());
    let mut sum = [0.0; 4];
    let quarter = 0.25 * tolerance;
    for (p, q, r) in [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)] {
        let part = adapt(p, q, r, patch, quarter, depth + 1, count);
        for (s, p) in sum.iter_mut().zip(part) {
            *s += p;
        }
    }
    sum
}

/// 6-point Gauss–Legendre on [0, 1]: nodes and weights.
const GAUSS_6: [(f64, f64); 6] = [
    (0.033_765_242_898_423_99, 0.085_662_246_189_585_17),
    (0.169_395_306_766_867_74, 0.180_380_786_524_069_3),
    (0.380_690_406_958_401_55, 0.233_956_967_286_345_5),
    (0.619_309_593_041_598_5, 0.233_956_967_286_345_5),
    (0.830_604_693_233_132_3, 0.180_380_786_524_069_3),
    (0.966_234_757_101_576, 0.085_662_246_189_585_17),
];

/// The tensor rule `nodes` on the spherical triangle (a, b, c): the flat
/// triangle `P(s, t) = a + s(b − a) + st(c − b)` projects onto it with
/// `dσ = s·det[a, b, c] / |P|³ ds dt`.
fn rule(
    a: DVec3,
    b: DVec3,
    c: DVec3,
    patch: &mut Patch,
    nodes: &[(f64, f64)],
    count: &mut QuadratureCount,
) -> [f64; 4] {
    let det = a.dot(b.cross(c));
    let mut sum = [0.0; 4];
    for &(s, ws) in nodes {
        for &(t, wt) in nodes {
            let p = a + s * (b - a) + (s * t) * (c - b);
            count.nodes += 1;
            let Some((inverse_distance, basis)) = patch.hit(p) else {
                count.missed += 1;
                continue;
            };
            let length = p.length();
            let weight = ws * wt * s * det * inverse_distance / (length * length * length);
            for (sum, psi) in sum.iter_mut().zip(basis) {
                *sum += weight * psi;
            }
        }
    }
    sum
}

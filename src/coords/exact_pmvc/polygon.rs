//! Convex spherical polygons around a point x, as seen from x: their corners are
//! unit directions, their sides arcs of great circles, and every great circle is
//! the plane through x and one cage edge ([`EdgePlane`]). Clipping one by such a
//! plane is Sutherland–Hodgman on the directions, valid because every polygon
//! here lies in the cone of one cage triangle seen from its inner side, hence in
//! an open hemisphere.
//!
//! Exactness where it matters: a corner remembers what it lies on (a cage vertex,
//! or the two edge planes that cut it), and its side of a plane it lies on is 0,
//! not the rounding of a dot product. Two triangles that share an edge or a
//! vertex therefore touch without a sliver of overlap or of gap, and pieces cut
//! along one plane share it exactly (both triangles at an edge compute its
//! plane from the same two directions, and the two orders give exactly
//! opposite normals). A side within the rounding of the plane's normal is 0
//! as well: collinear cage edges give one plane from two pairs of corners.

use glam::DVec3;

/// The plane through x and the directed cage edge `from → to`, with unit normal
/// `û_from × û_to` normalised: the side kept by a clip is `normal·d ≥ 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct EdgePlane {
    pub normal: DVec3,
    /// Below this a direction's side is the rounding of the normal: 0.
    pub tolerance: f64,
    pub from: u32,
    pub to: u32,
}

impl EdgePlane {
    /// The plane of edge `from → to`, from the unit directions of the cage
    /// vertices. Zero normal when the two directions are parallel.
    pub fn new(from: u32, to: u32, directions: &[DVec3]) -> Self {
        let cross = directions[from as usize].cross(directions[to as usize]);
        let length = cross.length();
        // Each component of the cross product is off by a few ulps: so is the
        // normal, relative to its length. Collinear cage edges (common on flat
        // faces) give one plane twice, from different corners.
        let tolerance = SIDE_ROUNDING * (1.0 + 1.0 / length);
        Self {
            normal: cross / length,
            tolerance,
            from,
            to,
        }
    }

    /// The same plane with the other side kept: bit for bit the plane of the
    /// edge taken the other way round.
    pub fn flipped(self) -> Self {
        Self {
            normal: -self.normal,
            tolerance: self.tolerance,
            from: self.to,
            to: self.from,
        }
    }

    /// The undirected edge, as one number.
    pub fn key(&self) -> u64 {
        let (a, b) = (self.from.min(self.to), self.from.max(self.to));
        (u64::from(a) << 32) | u64::from(b)
    }
}

/// What a corner lies on exactly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Label {
    /// The direction of this cage vertex: on the plane of every edge at it.
    Vertex(u32),
    /// The crossing of the planes of these two edges ([`EdgePlane::key`]).
    Crossing(u64, u64),
}

/// A corner of a polygon and the plane of the side that leaves it.
#[derive(Clone, Copy, Debug)]
pub(super) struct Corner {
    pub direction: DVec3,
    pub label: Label,
    pub side: EdgePlane,
}

/// `direction`'s side of `plane`: exactly 0 when its label puts it on the plane.
#[inline]
pub(super) fn side_of(direction: DVec3, label: Label, plane: &EdgePlane) -> f64 {
    let on = match label {
        Label::Vertex(v) => v == plane.from || v == plane.to,
        Label::Crossing(a, b) => {
            let key = plane.key();
            a == key || b == key
        }
    };
    let side = plane.normal.dot(direction);
    if on || side.abs() <= plane.tolerance {
        0.0
    } else {
        side
    }
}

/// Rounding of a side test, relative, before the normal's own.
const SIDE_ROUNDING: f64 = 8.0 * f64::EPSILON;

/// The cage vertex at both ends of two edges, if they share exactly one.
fn shared_vertex(a: &EdgePlane, b: &EdgePlane) -> Option<u32> {
    let (p, q) = ((a.from, a.to), (b.from, b.to));
    match (p.0 == q.0 || p.0 == q.1, p.1 == q.0 || p.1 == q.1) {
        (true, false) => Some(p.0),
        (false, true) => Some(p.1),
        _ => None,
    }
}

/// Appends to `out` the part of `polygon` on the kept side of `plane`, given
/// `sides[k]`, the side of corner k ([`side_of`]). Returns whether it has an
/// area (three corners or more); otherwise `out` is left as it was.
pub(super) fn clip(
    polygon: &[Corner],
    sides: &[f64],
    plane: &EdgePlane,
    directions: &[DVec3],
    out: &mut Vec<Corner>,
) -> bool {
    let start = out.len();
    let n = polygon.len();
    for k in 0..n {
        let (a, b) = (&polygon[k], &polygon[(k + 1) % n]);
        let (sa, sb) = (sides[k], sides[(k + 1) % n]);
        if sa >= 0.0 {
            if sb >= 0.0 {
                out.push(*a);
            } else if sa == 0.0 {
                // The side leaves the kept half at a: a starts the cut.
                out.push(Corner { side: *plane, ..*a });
            } else {
                out.push(*a);
                out.push(crossing(a, b, sa, sb, plane, directions));
            }
        } else if sb > 0.0 {
            let mut entry = crossing(a, b, sa, sb, plane, directions);
            entry.side = a.side;
            out.push(entry);
        }
    }
    if out.len() - start < 3 {
        out.truncate(start);
        return false;
    }
    true
}

/// Where the side from `a` to `b` (on opposite sides of `plane`, strictly)
/// crosses it, as a corner whose side continues along `plane`.
fn crossing(
    a: &Corner,
    b: &Corner,
    sa: f64,
    sb: f64,
    plane: &EdgePlane,
    directions: &[DVec3],
) -> Corner {
    let direction = (a.direction * sb.abs() + b.direction * sa.abs()).normalize();
    // Two edge planes through one cage vertex cross at its direction.
    if let Some(v) = shared_vertex(&a.side, plane) {
        let exact = directions[v as usize];
        if exact.dot(direction) > 0.0 {
            return Corner {
                direction: exact,
                label: Label::Vertex(v),
                side: *plane,
            };
        }
    }
    Corner {
        direction,
        label: Label::Crossing(a.side.key(), plane.key()),
        side: *plane,
    }
}

/// `∫ σ dσ` over the polygon (its mean vector: ½ Σ θₑ nₑ over its sides, θₑ the
/// arc, nₑ the unit normal pointing in, of the great circle through the side's
/// two corners: the sum of the same over a fan of spherical triangles, whose
/// diagonals cancel, so that a sliver whose corners lie on one circle in any
/// order integrates to about 0) and its solid angle (summed over a fan
/// of spherical triangles by Van Oosterom and Strackee's formula, which stays
/// near 0 for a sliver whose corners nearly coincide, where the sum of its
/// turns would not).
pub(super) fn mean_vector(polygon: &[Corner]) -> (DVec3, f64) {
    let n = polygon.len();
    let mut mean = DVec3::ZERO;
    let mut solid_angle = 0.0;
    let first = polygon[0].direction;
    for k in 0..n {
        let (a, b) = (polygon[k].direction, polygon[(k + 1) % n].direction);
        let normal = a.cross(b);
        mean += normal.length().atan2(a.dot(b)) * normal.normalize_or_zero();
        if k > 0 && k + 1 < n {
            let triple = first.dot(a.cross(b));
            let cosines = 1.0 + first.dot(a) + a.dot(b) + b.dot(first);
            solid_angle += 2.0 * triple.atan2(cosines);
        }
    }
    (0.5 * mean, solid_angle)
}

/// `∫ σ dσ` over the polygon by quadrature: Gauss–Legendre on each triangle of
/// a fan, split until every arc is short. Every term is a positive weight
/// times a direction, so a thin polygon (nearly on one great circle) gets its
/// small mean vector to rounding of its own size, where the closed form's sum
/// of long arcs loses all but the rounding of the arcs.
pub(super) fn mean_vector_by_quadrature(polygon: &[Corner]) -> DVec3 {
    mean_vector_by_quadrature_with(polygon, LONGEST_CHORD)
}

/// [`mean_vector_by_quadrature`] splitting down to chords of `longest_chord`.
pub(super) fn mean_vector_by_quadrature_with(polygon: &[Corner], longest_chord: f64) -> DVec3 {
    let first = polygon[0].direction;
    let mut sum = DVec3::ZERO;
    for k in 1..polygon.len() - 1 {
        let (b, c) = (polygon[k].direction, polygon[k + 1].direction);
        sum += triangle_quadrature(first, b, c, longest_chord, 0);
    }
    sum
}

/// Longest chord between corners of a triangle integrated without splitting:
/// at 0.6 the rule is off by about 1e-13 of the triangle's mean vector, at
/// 0.25 by rounding. Pieces of thin triangles have tiny weights, so that
/// this costs far less than rounding of the total.
const LONGEST_CHORD: f64 = 0.6;

/// Splits deeper than this stop splitting (a corner pair nearly antipodal,
/// which no polygon here has).
const DEEPEST_SPLIT: u32 = 12;

/// 8-point Gauss–Legendre on [0, 1]: nodes and weights.
pub(super) const GAUSS: [(f64, f64); 8] = [
    (0.019_855_071_751_231_856, 0.050_614_268_145_188_09),
    (0.101_666_761_293_186_58, 0.111_190_517_226_687_23),
    (0.237_233_795_041_835_5, 0.156_853_322_938_943_7),
    (0.408_282_678_752_175_1, 0.181_341_891_689_181),
    (0.591_717_321_247_825, 0.181_341_891_689_181),
    (0.762_766_204_958_164_5, 0.156_853_322_938_943_7),
    (0.898_333_238_706_813_5, 0.111_190_517_226_687_23),
    (0.980_144_928_248_768_2, 0.050_614_268_145_188_09),
];

/// `∫ σ dσ` over the spherical triangle (a, b, c), signed by its orientation.
/// The flat triangle `P(u, v) = a + u(b − a) + uv(c − b)` projects onto it
/// with `dσ = u·det[a, b, c] / |P|³ du dv`.
fn triangle_quadrature(a: DVec3, b: DVec3, c: DVec3, longest_chord: f64, depth: u32) -> DVec3 {
    let longest = (a - b)
        .length_squared()
        .max((b - c).length_squared())
        .max((c - a).length_squared());
    if longest > longest_chord * longest_chord && depth < DEEPEST_SPLIT {
        let [ab, bc, ca] = [a + b, b + c, c + a].map(|m| m.normalize());
        let split = |a, b, c| triangle_quadrature(a, b, c, longest_chord, depth + 1);
        return split(a, ab, ca) + split(ab, b, bc) + split(ca, bc, c) + split(ab, bc, ca);
    }
    let det = a.dot(b.cross(c));
    let mut sum = DVec3::ZERO;
    for &(u, wu) in &GAUSS {
        let mut row = DVec3::ZERO;
        for &(v, wv) in &GAUSS {
            let p = a + u * (b - a) + (u * v) * (c - b);
            let inverse = 1.0 / p.length_squared();
            // σ / |P|³ = P / |P|⁴.
            row += wv * p * (inverse * inverse);
        }
        sum += (wu * u) * row;
    }
    det * sum
}

//! A triangle's blocks at a point near it, in polar coordinates about the
//! point's foot on the triangle's plane, with the radial integrals in closed form.
//!
//! With ζ = n·(y − x) (the plane's height above x, positive on the inner side of
//! an outward face), y − x = ρω + ζn with ω = cos θ e₁ + sin θ e₂, and a corner's
//! hat function Γ = a + ρ (g·ω) (a its value at the foot, g its in-plane
//! gradient), every kernel term is a matrix in ω, n times a radial integral
//! J(k, m) = ∫₀^R ρᵏ (ρ² + ζ²)^(−m/2) dρ, where R(θ) reaches the triangle's edge.
//! The triangle is the signed sum of the three triangles (foot, corner, next
//! corner), so each integral is a sum over edges of ∫ J(R(θ)) dθ.
//!
//! J = P(R) − P(0) is split: the upper-limit part P(R) is integrated along each
//! edge numerically (adaptive Gauss–Kronrod in u, with R = |d| cosh u and d the
//! foot's distance to the edge's line, which spreads the features near the edge
//! over O(1) in u); the lower-limit part P(0) depends on ζ only and multiplies an
//! angular moment ∫ ωω…ω dθ that is integrated in closed form. Those moments sum
//! to zero over the three edges when the foot is outside the triangle, and to
//! those of the full circle when it is inside, and are set to those exact values:
//! so a point in the plane of a face but off it gets no jump (solid angle 0),
//! and a point just inside a face gets exactly the inner limit (half the hat).

use super::quadrature::integrate_interval;
use super::triangle::{outer, Material, TriangleBlocks, TriangleFrame, TOLERANCE};
use glam::{DMat3, DVec2, DVec3};
use std::f64::consts::PI;

/// The four matrix integrals of a triangle, each a sum over its edges:
/// the single layer (divided by the longest edge), the double layer against the
/// constant 1, and against ω·e₁ and ω·e₂ times ρ.
#[derive(Clone, Copy, Debug, Default)]
struct Moments {
    single: DMat3,
    constant: DMat3,
    linear: [DMat3; 2],
}

impl Moments {
    fn to_array(self) -> [f64; 36] {
        let mut out = [0.0; 36];
        for (k, m) in [self.single, self.constant, self.linear[0], self.linear[1]]
            .iter()
            .enumerate()
        {
            out[9 * k..9 * (k + 1)].copy_from_slice(&m.to_cols_array());
        }
        out
    }

    fn from_array(values: &[f64; 36]) -> Self {
        let block = |k: usize| DMat3::from_cols_slice(&values[9 * k..9 * (k + 1)]);
        Self {
            single: block(0),
            constant: block(1),
            linear: [block(2), block(3)],
        }
    }
}

/// The closed-form angular moments of the apex part, ∫ over θ of 1, ω, ωωᵀ and
/// ω⊗ω⊗ω, in the triangle's 2D frame.
#[derive(Clone, Copy, Debug, Default)]
struct AngularMoments {
    zeroth: f64,
    first: [f64; 2],
    second: [[f64; 2]; 2],
    third: [[[f64; 2]; 2]; 2],
}

impl AngularMoments {
    /// ∫ from the direction `p` to the direction `q` (unit vectors), the short way.
    fn of_edge(p: DVec2, q: DVec2) -> Self {
        let angle = p.perp_dot(q).atan2(p.dot(q));
        // Antiderivatives in cos θ = v.x, sin θ = v.y.
        let sin_cos = |v: DVec2| v.x * v.y;
        let cubic = |v: DVec2| {
            let (c, s) = (v.x, v.y);
            [
                s - s * s * s / 3.0,  // ∫ cos³
                -c * c * c / 3.0,     // ∫ cos² sin
                s * s * s / 3.0,      // ∫ cos sin²
                -c + c * c * c / 3.0, // ∫ sin³
            ]
        };
        let (cq, cp) = (cubic(q), cubic(p));
        let by_sines = |k: usize| cq[k] - cp[k];
        let half_sin2 = 0.5 * (sin_cos(q) - sin_cos(p));
        let mixed = 0.5 * (q.y * q.y - p.y * p.y);
        let mut third = [[[0.0; 2]; 2]; 2];
        for (a, plane) in third.iter_mut().enumerate() {
            for (b, row) in plane.iter_mut().enumerate() {
                for (c, value) in row.iter_mut().enumerate() {
                    *value = by_sines(a + b + c);
                }
            }
        }
        Self {
            zeroth: angle,
            first: [q.y - p.y, p.x - q.x],
            second: [
                [0.5 * angle + half_sin2, mixed],
                [mixed, 0.5 * angle - half_sin2],
            ],
            third,
        }
    }

    fn add(&mut self, other: &Self) {
        self.zeroth += other.zeroth;
        for a in 0..2 {
            self.first[a] += other.first[a];
            for b in 0..2 {
                self.second[a][b] += other.second[a][b];
                for c in 0..2 {
                    self.third[a][b][c] += other.third[a][b][c];
                }
            }
        }
    }

    /// The moments of the full circle.
    fn circle() -> Self {
        Self {
            zeroth: 2.0 * PI,
            second: [[PI, 0.0], [0.0, PI]],
            ..Self::default()
        }
    }
}

/// The radial parts P(R) of every kernel term at one (R, ζ), named by J's
/// indices and the power of ζ multiplying them.
struct Radial {
    p11: f64,
    z_p13: f64,
    zz_p13: f64,
    p23: f64,
    z_p23: f64,
    p33: f64,
    z_p35: f64,
    zz_p35: f64,
    zz_p25: f64,
    zzz_p25: f64,
    zzz_p15: f64,
    z_p45: f64,
}

impl Radial {
    fn new(big_r: f64, zeta: f64) -> Self {
        let r = big_r.hypot(zeta);
        let (inverse, z2) = (1.0 / r, zeta * zeta);
        let cube = inverse * inverse * inverse;
        let log = (big_r + r).ln() - big_r * inverse;
        let r3_over_3 = big_r * big_r * big_r * cube / 3.0;
        Self {
            p11: r,
            z_p13: -zeta * inverse,
            zz_p13: -z2 * inverse,
            p23: log,
            z_p23: zeta * log,
            p33: r + z2 * inverse,
            z_p35: -zeta * inverse + zeta * z2 * cube / 3.0,
            zz_p35: -z2 * inverse + z2 * z2 * cube / 3.0,
            zz_p25: r3_over_3,
            zzz_p25: zeta * r3_over_3,
            zzz_p15: -zeta * z2 * cube / 3.0,
            z_p45: zeta * (log - r3_over_3),
        }
    }
}

/// The blocks of `frame` at the point its corners are `relative` to.
pub(super) fn blocks(
    frame: &TriangleFrame,
    relative: [DVec3; 3],
    material: &Material,
) -> TriangleBlocks {
    let (n, e1, e2) = (frame.normal, frame.tangent, frame.bitangent);
    // `+ 0.0` makes −0 into +0: a point exactly in the plane takes the inner side.
    let zeta = relative.iter().map(|r| n.dot(*r)).sum::<f64>() / 3.0 + 0.0;
    let corners = relative.map(|r| DVec2::new(r.dot(e1), r.dot(e2)));
    let doubled_area = (corners[1] - corners[0]).perp_dot(corners[2] - corners[0]);
    let lift = |v: [f64; 2]| e1 * v[0] + e2 * v[1];
    let inverse_length = 1.0 / frame.longest_edge;

    let mut integrals = [0.0; 36];
    let mut moments = AngularMoments::default();
    let mut all_edges = true;
    let mut inside = true;
    for k in 0..3 {
        let (p, q) = (corners[k], corners[(k + 1) % 3]);
        let edge = q - p;
        let length = edge.length();
        let along = edge / length;
        let across = DVec2::new(along.y, -along.x);
        let distance = p.dot(across);
        // The foot on this edge's line: the (foot, p, q) triangle has no area.
        if distance.abs() <= 4.0 * f64::EPSILON * p.length().max(q.length()) {
            all_edges = false;
            continue;
        }
        inside &= distance > 0.0;
        moments.add(&AngularMoments::of_edge(p.normalize(), q.normalize()));
        let edge_frame = EdgeFrame {
            distance,
            along,
            across,
            zeta,
            n,
            e1,
            e2,
            inverse_length,
        };
        edge_frame.integrate(p.dot(along), q.dot(along), material, &mut integrals);
    }
    if all_edges {
        moments = if inside {
            AngularMoments::circle()
        } else {
            AngularMoments::default()
        };
    }
    let mut total = Moments::from_array(&integrals);
    add_apex(
        &mut total,
        &moments,
        zeta,
        n,
        &lift,
        inverse_length,
        material,
    );

    let vertex = std::array::from_fn(|k| {
        let (next, after) = (corners[(k + 1) % 3], corners[(k + 2) % 3]);
        let at_foot = next.perp_dot(after) / doubled_area;
        let opposite = after - next;
        let gradient = DVec2::new(-opposite.y, opposite.x) / doubled_area;
        (total.constant * at_foot + total.linear[0] * gradient.x + total.linear[1] * gradient.y)
            * material.vertex_factor
    });
    TriangleBlocks {
        vertex,
        face: total.single * (frame.longest_edge * material.face_factor),
    }
}

/// The P(0) parts: −P(0) times the angular moments, for each term of
/// [`EdgeFrame::integrand`] (the ln|ζ| ones only where ζ ≠ 0; their moments
/// vanish unless the foot is on an edge of the triangle).
fn add_apex(
    total: &mut Moments,
    moments: &AngularMoments,
    zeta: f64,
    n: DVec3,
    lift: &impl Fn([f64; 2]) -> DVec3,
    inverse_length: f64,
    material: &Material,
) {
    let sign = zeta.signum();
    let height = zeta.abs();
    let z_log = if zeta == 0.0 { 0.0 } else { zeta * height.ln() };
    let log = if zeta == 0.0 { 0.0 } else { height.ln() };
    let identity = DMat3::IDENTITY;
    let nn = outer(n, n);
    let first = lift(moments.first);
    let second = lift2(&moments.second, lift);
    let symmetric = |v: DVec3| outer(v, n) + outer(n, v);
    let antisymmetric = |v: DVec3| outer(v, n) - outer(n, v);
    let (one_minus_2nu, a0) = (material.one_minus_2nu, moments.zeroth);

    total.single += (identity * (-material.three_minus_4nu * height * a0)
        - second * (2.0 * height)
        - symmetric(first) * z_log
        + nn * (height * a0))
        * inverse_length;
    total.constant += (identity * (one_minus_2nu * a0) + second * 2.0 + nn * a0) * sign
        + antisymmetric(first) * (one_minus_2nu * log);
    for c in 0..2 {
        let first_c = moments.first[c];
        let second_c = lift(moments.second[c]);
        let third_c = lift2(&moments.third[c], lift);
        total.linear[c] += identity * (-one_minus_2nu * z_log * first_c) - third_c * (3.0 * z_log)
            + symmetric(second_c) * (2.0 * height)
            + antisymmetric(second_c) * (2.0 * one_minus_2nu * height);
    }
}

/// Σ m[a][b] e_a e_bᵀ.
fn lift2(m: &[[f64; 2]; 2], lift: &impl Fn([f64; 2]) -> DVec3) -> DMat3 {
    let rows = [lift(m[0]), lift(m[1])];
    let e = [lift([1.0, 0.0]), lift([0.0, 1.0])];
    outer(e[0], rows[0]) + outer(e[1], rows[1])
}

/// One edge of the signed decomposition, in the u parameter.
struct EdgeFrame {
    /// Signed distance from the foot to the edge's line (positive when the foot
    /// is on the triangle's side).
    distance: f64,
    along: DVec2,
    across: DVec2,
    zeta: f64,
    n: DVec3,
    e1: DVec3,
    e2: DVec3,
    inverse_length: f64,
}

impl EdgeFrame {
    /// Adds ∫ P(R(θ)) dθ over the edge from arc position `start` to `end`
    /// (measured along the edge from the foot of the perpendicular).
    fn integrate(&self, start: f64, end: f64, material: &Material, sum: &mut [f64; 36]) {
        let height = self.distance.abs();
        let (u0, u1) = ((start / height).asinh(), (end / height).asinh());
        let pieces = (u1 - u0).abs().ceil().max(1.0) as usize;
        let mut f = |u: f64| self.integrand(u, material).to_array();
        for piece in 0..pieces {
            let a = u0 + (u1 - u0) * piece as f64 / pieces as f64;
            let b = u0 + (u1 - u0) * (piece + 1) as f64 / pieces as f64;
            integrate_interval(&mut f, a, b, TOLERANCE / pieces as f64, sum);
        }
    }

    /// The P(R) parts of every kernel term at u, times dθ/du.
    fn integrand(&self, u: f64, material: &Material) -> Moments {
        let (cosh, tanh) = (u.cosh(), u.tanh());
        let sign = self.distance.signum();
        let direction = self.across * (sign / cosh) + self.along * tanh;
        let omega = self.e1 * direction.x + self.e2 * direction.y;
        let radial = Radial::new(self.distance.abs() * cosh, self.zeta);
        let n = self.n;
        let (identity, nn, ww) = (DMat3::IDENTITY, outer(n, n), outer(omega, omega));
        let symmetric = outer(omega, n) + outer(n, omega);
        let antisymmetric = outer(omega, n) - outer(n, omega);
        let one_minus_2nu = material.one_minus_2nu;
        let single = identity * (material.three_minus_4nu * radial.p11)
            + ww * radial.p33
            + symmetric * radial.z_p23
            + nn * radial.zz_p13;
        let constant = identity * (one_minus_2nu * radial.z_p13)
            + ww * (3.0 * radial.z_p35)
            + symmetric * (3.0 * radial.zz_p25)
            + nn * (3.0 * radial.zzz_p15)
            - antisymmetric * (one_minus_2nu * radial.p23);
        let linear = identity * (one_minus_2nu * radial.z_p23)
            + ww * (3.0 * radial.z_p45)
            + symmetric * (3.0 * radial.zz_p35)
            + nn * (3.0 * radial.zzz_p25)
            - antisymmetric * (one_minus_2nu * radial.p33);
        let weight = sign / cosh;
        Moments {
            single: single * (weight * self.inverse_length),
            constant: constant * weight,
            linear: [
                linear * (weight * direction.x),
                linear * (weight * direction.y),
            ],
        }
    }
}

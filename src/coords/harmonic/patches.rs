//! The cage's surface as the harmonic solve sees it: its lone triangles, with
//! the hat functions as boundary data, and its quads as bilinear patches, with
//! the bilinear basis. A cage without quads is its triangles, as before quads.
//!
//! A grid line is an axis-aligned ray; it meets a patch `P(u, v)` where the
//! patch's projection along the axis covers the line's point, a quadratic in
//! `v` with up to two roots. Each root is a crossing of the surface, so counting
//! them gives the right parity even where a bent patch folds over itself in
//! projection (two roots) or grazes the line (none or two).

use crate::geometry::quads::{bilinear_basis, bilinear_point};
use crate::geometry::{closest_offset_on_triangle, Cage};
use glam::{DVec2, DVec3};

/// The boundary data at a cage point: up to four cage vertices and the value of
/// each one's function there. On a triangle the fourth value is zero.
/// `gradients` are the functions' surface gradients there, in the units of the
/// points the face was given in, where known (crossings of grid lines; zero at
/// closest points, where nothing reads them).
#[derive(Clone, Copy, Debug)]
pub(in crate::coords) struct BoundaryValue {
    pub corners: [u32; 4],
    pub values: [f64; 4],
    pub gradients: [DVec3; 4],
}

impl BoundaryValue {
    pub fn triangle([a, b, c]: [u32; 3], [wa, wb, wc]: [f64; 3]) -> BoundaryValue {
        BoundaryValue {
            corners: [a, b, c, c],
            values: [wa, wb, wc, 0.0],
            gradients: [DVec3::ZERO; 4],
        }
    }

    pub fn quad(corners: [u32; 4], u: f64, v: f64) -> BoundaryValue {
        BoundaryValue {
            corners,
            values: bilinear_basis(u, v),
            gradients: [DVec3::ZERO; 4],
        }
    }

    /// With the hat functions' gradients on the triangle `q` (constant on it):
    /// `∇φₖ = n̂ × eₖ / 2A`, eₖ the edge opposite corner k.
    pub fn with_triangle_gradients(mut self, q: [DVec3; 3]) -> BoundaryValue {
        let normal = (q[1] - q[0]).cross(q[2] - q[0]);
        let twice_area = normal.length();
        if twice_area > 0.0 {
            let unit = normal / twice_area;
            for k in 0..3 {
                let edge = q[(k + 2) % 3] - q[(k + 1) % 3];
                self.gradients[k] = unit.cross(edge) / twice_area;
            }
        }
        self
    }

    /// With the bilinear basis functions' surface gradients on the patch `q`
    /// at `(u, v)`: `[P_u P_v] G⁻¹ (∂φ/∂u, ∂φ/∂v)`, G the metric.
    pub fn with_patch_gradients(mut self, q: &[DVec3; 4], u: f64, v: f64) -> BoundaryValue {
        let along_u = (1.0 - v) * (q[1] - q[0]) + v * (q[2] - q[3]);
        let along_v = (1.0 - u) * (q[3] - q[0]) + u * (q[2] - q[1]);
        let (guu, guv, gvv) = (
            along_u.dot(along_u),
            along_u.dot(along_v),
            along_v.dot(along_v),
        );
        let det = guu * gvv - guv * guv;
        if det <= 0.0 {
            return self;
        }
        let partials = [
            (-(1.0 - v), -(1.0 - u)),
            (1.0 - v, -u),
            (v, u),
            (-v, 1.0 - u),
        ];
        for (gradient, (du, dv)) in self.gradients.iter_mut().zip(partials) {
            let a = (gvv * du - guv * dv) / det;
            let b = (guu * dv - guv * du) / det;
            *gradient = a * along_u + b * along_v;
        }
        self
    }
}

fn cross(a: DVec2, b: DVec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Where the line through `(point.x, point.y)` on axes `(axis+1, axis+2) % 3`,
/// along `axis`, crosses the patch `q` (in grid units): up to two `(s, u, v)`,
/// `s` the place along the line. Roots on the patch's border count, as the
/// triangles' do.
pub(super) fn patch_line_crossings(
    q: &[DVec3; 4],
    axis: usize,
    point: DVec2,
) -> [Option<[f64; 3]>; 2] {
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    let flat = |p: DVec3| DVec2::new(p[b], p[c]);
    let e = flat(q[1]) - flat(q[0]);
    let f = flat(q[3]) - flat(q[0]);
    let g = flat(q[0]) - flat(q[1]) + flat(q[2]) - flat(q[3]);
    let h = point - flat(q[0]);
    // The normal's component along the axis is affine in (u, v): zero at these
    // three terms means the patch runs along the axis and no line crosses it.
    let (ef, eg, gf) = (cross(e, f), cross(e, g), cross(g, f));
    let mut out = [None; 2];
    if ef == 0.0 && eg == 0.0 && gf == 0.0 {
        return out;
    }
    // u (e + v g) = h − v f, crossed with e + v g: k2 v² + k1 v + k0 = 0.
    let (k2, k1, k0) = (gf, ef + cross(h, g), cross(h, e));
    let mut roots = [f64::NAN; 2];
    if k2 == 0.0 {
        if k1 != 0.0 {
            roots[0] = -k0 / k1;
        }
    } else {
        let discriminant = k1 * k1 - 4.0 * k0 * k2;
        if discriminant < 0.0 {
            return out;
        }
        // The stable pair of roots: no cancellation between k1 and the root.
        let half = -0.5 * (k1 + discriminant.sqrt().copysign(k1));
        if half == 0.0 {
            // A double root at v = 0: the line grazes the patch.
            return out;
        }
        roots = [half / k2, k0 / half];
    }
    for (slot, v) in out.iter_mut().zip(roots) {
        if !v.is_finite() {
            continue;
        }
        let along_u = e + v * g;
        let rest = h - v * f;
        let u = if along_u.x.abs() >= along_u.y.abs() {
            rest.x / along_u.x
        } else {
            rest.y / along_u.y
        };
        if !u.is_finite() {
            continue;
        }
        let (u, v) = polish(e, f, g, h, u, v);
        if (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v) {
            *slot = Some([bilinear_point(q, u, v)[axis], u, v]);
        }
    }
    out
}

/// One Newton step on `u e + v f + uv g = h`, kept only if it shrinks the
/// residual: the crossing then lies on the line to rounding, which keeps linear
/// functions exact.
fn polish(e: DVec2, f: DVec2, g: DVec2, h: DVec2, u: f64, v: f64) -> (f64, f64) {
    let residual = |u: f64, v: f64| u * e + v * f + u * v * g - h;
    let r = residual(u, v);
    let (du, dv) = (e + v * g, f + u * g);
    let det = cross(du, dv);
    if det == 0.0 {
        return (u, v);
    }
    let (u1, v1) = (u - cross(r, dv) / det, v - cross(du, r) / det);
    if residual(u1, v1).length_squared() < r.length_squared() {
        (u1, v1)
    } else {
        (u, v)
    }
}

/// Grid steps per side of the start search on a patch: its points map onto
/// themselves when the corners are rotated, so the search does not depend on
/// which corner comes first.
const START_STEPS: usize = 4;
const CLOSEST_ITERATIONS: usize = 40;

/// The point of patch `q` closest to `x`: `(squared distance, u, v)`. From the
/// nearest of a small grid of the patch, Newton steps clamped to the square,
/// each kept only if it brings the point closer, else exact minimisation along
/// u and then v (the patch is a line along either).
pub(super) fn closest_on_patch(q: &[DVec3; 4], x: DVec3) -> (f64, f64, f64) {
    let distance = |u: f64, v: f64| bilinear_point(q, u, v).distance_squared(x);
    let mut best = (f64::INFINITY, 0.0, 0.0);
    for j in 0..=START_STEPS {
        for i in 0..=START_STEPS {
            let (u, v) = (i as f64 / START_STEPS as f64, j as f64 / START_STEPS as f64);
            let d = distance(u, v);
            if d < best.0 {
                best = (d, u, v);
            }
        }
    }
    let (mut d, mut u, mut v) = best;
    let twist = q[0] - q[1] + q[2] - q[3];
    for _ in 0..CLOSEST_ITERATIONS {
        let r = bilinear_point(q, u, v) - x;
        let pu = (1.0 - v) * (q[1] - q[0]) + v * (q[2] - q[3]);
        let pv = (1.0 - u) * (q[3] - q[0]) + u * (q[2] - q[1]);
        let (gu, gv) = (r.dot(pu), r.dot(pv));
        let (huu, huv, hvv) = (pu.dot(pu), pu.dot(pv) + r.dot(twist), pv.dot(pv));
        let det = huu * hvv - huv * huv;
        let mut next = None;
        if det > 0.0 && huu > 0.0 {
            let nu = (u - (hvv * gu - huv * gv) / det).clamp(0.0, 1.0);
            let nv = (v - (huu * gv - huv * gu) / det).clamp(0.0, 1.0);
            let nd = distance(nu, nv);
            if nd < d {
                next = Some((nd, nu, nv));
            }
        }
        let (nd, nu, nv) = next.unwrap_or_else(|| {
            let nu = along(q, u, v, true, x);
            let nv = along(q, nu, v, false, x);
            (distance(nu, nv), nu, nv)
        });
        let moved = (nu - u).abs().max((nv - v).abs());
        if nd <= d {
            (d, u, v) = (nd, nu, nv);
        }
        if moved <= 1e-14 || nd > d {
            break;
        }
    }
    (d, u, v)
}

/// The parameter along u (or v) that brings `P` closest to `x`, the other held.
fn along(q: &[DVec3; 4], u: f64, v: f64, along_u: bool, x: DVec3) -> f64 {
    let (start, end) = if along_u {
        (bilinear_point(q, 0.0, v), bilinear_point(q, 1.0, v))
    } else {
        (bilinear_point(q, u, 0.0), bilinear_point(q, u, 1.0))
    };
    let direction = end - start;
    let length = direction.length_squared();
    if length == 0.0 {
        return if along_u { u } else { v };
    }
    ((x - start).dot(direction) / length).clamp(0.0, 1.0)
}

/// The boundary data at the cage point nearest to `x`.
pub(super) fn closest_boundary_value(cage: &Cage, x: DVec3) -> BoundaryValue {
    let mut best = (f64::INFINITY, 0, [1.0, 0.0, 0.0]);
    for t in cage.lone_triangles() {
        let [a, b, c] = cage.triangle(t);
        let (offset, barycentric) = closest_offset_on_triangle(x, a, b, c);
        let distance = offset.length_squared();
        if distance < best.0 {
            best = (distance, t as u32, barycentric.to_array());
        }
    }
    let mut value = BoundaryValue::triangle(cage.triangles()[best.1 as usize], best.2);
    let mut nearest = best.0;
    for (k, quad) in cage.quads().iter().enumerate() {
        let q = cage.quad(k);
        // The patch lies in its corners' box: no nearer than the box.
        let lo = q[1..].iter().fold(q[0], |m, &p| m.min(p));
        let hi = q[1..].iter().fold(q[0], |m, &p| m.max(p));
        if (x.clamp(lo, hi) - x).length_squared() >= nearest {
            continue;
        }
        let (distance, u, v) = closest_on_patch(&q, x);
        if distance < nearest {
            nearest = distance;
            value = BoundaryValue::quad(quad.corners, u, v);
        }
    }
    value
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::procedural_quads::twisted_box;

    #[test]
    fn crossings_lie_on_the_line_and_the_patch() {
        let cage = twisted_box(2.0, 0.6);
        let mut found = 0;
        for k in 0..cage.quads().len() {
            let q = cage.quad(k).map(|p| p * 7.3);
            for axis in 0..3 {
                for j in 0..40 {
                    let point =
                        DVec2::new(-8.0 + 0.41 * j as f64, -7.0 + 0.37 * (j * 7 % 40) as f64);
                    for [s, u, v] in patch_line_crossings(&q, axis, point).into_iter().flatten() {
                        let p = bilinear_point(&q, u, v);
                        let on_line = DVec3::from_array({
                            let mut a = [0.0; 3];
                            a[axis] = s;
                            a[(axis + 1) % 3] = point.x;
                            a[(axis + 2) % 3] = point.y;
                            a
                        });
                        assert!(p.distance(on_line) < 1e-12, "{p} vs {on_line}");
                        found += 1;
                    }
                }
            }
        }
        assert!(found > 20, "{found} crossings");
    }

    #[test]
    fn the_closest_point_on_a_patch_is_a_minimum() {
        let cage = twisted_box(2.0, 0.6);
        let q = cage.quad(2);
        for x in [
            DVec3::new(0.1, -1.6, 0.9),
            DVec3::new(2.0, -2.0, 3.0),
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(-0.4, -0.8, 0.3),
        ] {
            let (d, u, v) = closest_on_patch(&q, x);
            // No point of a fine grid of the patch is nearer.
            let n = 200;
            for j in 0..=n {
                for i in 0..=n {
                    let p = bilinear_point(&q, i as f64 / n as f64, j as f64 / n as f64);
                    assert!(p.distance_squared(x) >= d - 1e-12, "{x}: ({u}, {v})");
                }
            }
        }
    }
}

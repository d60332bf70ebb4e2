//! The boundary integrals of one bilinear quad (QGC: Thiery and Boubekeur,
//! "Green Coordinates for Triquad Cages in 3D", SIGGRAPH Asia 2022).
//!
//! On the patch `P(u, v) = Σ Bₖ(u, v) qₖ` the area vector `N = ∂P/∂u × ∂P/∂v`
//! is bilinear too: `N(u, v) = Σ Bₖ(u, v) Nₖ`, with `Nₖ` the cross product of
//! the two edges at corner k (so a corner's split triangle has area vector `Nₖ`).
//! Green's third identity for `f(ξ) = ξ` then gives a point η, per quad,
//! - `φₖ = ∫∫ Bₖ (P − η)·N / (4π |P − η|³) du dv` (the double layer), and
//! - `ψₖ = ∫∫ Bₖ / (4π |P − η|) du dv` (the single layer), multiplying `Nₖ`.
//!
//! Both are integrated by tensor Gauss–Legendre on an adaptive quadtree
//! ([`QUADTREE`]). Two of their combinations are then known in closed form,
//! because their integrands are divergence-free fields whose flux depends on
//! the quad's boundary only: the same as through its two split triangles
//! (today's closed form), up to 4π when η lies between the patch and them:
//! - `Σ φₖ = Ω / 4π`, the solid angle;
//! - `Σ φₖ (qₖ − η) + Σ ψₖ Nₖ = M`, the integral of `f(ξ) − f(η)`.
//!
//! The quadrature's eight values are projected (least change) onto these four
//! equations, so that the cage's rest pose and similarities are reproduced to
//! rounding, as for triangles, while the split of each sum among the corners is
//! the quadrature's, accurate to [`Quadtree`]'s tolerance (tested).

use super::triangle::TriangleFrame;
use crate::coords::qmvc::quadrature::{gauss_legendre, order_for};
use crate::geometry::quads::bilinear_basis;
use glam::{DMat4, DVec3, DVec4};
use std::f64::consts::PI;

/// Refinement and order of the quadtree: a cell is split while its bounding
/// radius exceeds `eta` times its centre's distance from η; a leaf gets the
/// fewest Gauss–Legendre nodes per side (2 to 8) whose error model is below `tau`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadtree {
    pub eta: f64,
    pub tau: f64,
}

/// The rule QGC bind with: each φₖ and ψₖ within about 1e-10 (relative to the
/// quad's solid angle and size) of converged, see the tests.
pub const QUADTREE: Quadtree = Quadtree {
    eta: 0.4,
    tau: 1e-14,
};

/// Cells smaller than 2⁻⁵⁰ of the patch are integrated as they are.
const MAX_DEPTH: u32 = 50;

/// What one quad adds to a point's coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct QuadIntegrals {
    /// Signed solid angle of the patch (positive seen from its inner side).
    pub solid_angle: f64,
    /// φ of each corner, in the quad's corner order.
    pub phi: [f64; 4],
    /// ψ of each corner's normal `Nₖ`.
    pub psi: [f64; 4],
}

/// One cage quad's geometry, computed once per bind.
#[derive(Clone, Copy, Debug)]
pub(super) struct QuadFrame {
    pub corners: [DVec3; 4],
    /// `Nₖ`: the area vector at each corner.
    pub corner_normals: [DVec3; 4],
    /// The quad's two triangles in the cage (outward, as the patch).
    pub(super) halves: [TriangleFrame; 2],
    /// `P − q0 = u e + v f + uv k` and `N = n + u nu + v nv`.
    e: DVec3,
    f: DVec3,
    k: DVec3,
    n: DVec3,
    nu: DVec3,
    nv: DVec3,
    /// Mean corner, and a length: the size of the quad.
    centre: DVec3,
    size: f64,
}

impl QuadFrame {
    pub fn new(corners: [DVec3; 4], halves: [[DVec3; 3]; 2]) -> Self {
        let [q0, q1, q2, q3] = corners;
        let (e, f, k) = (q1 - q0, q3 - q0, q0 - q1 + q2 - q3);
        let size = (q2 - q0).length().max((q3 - q1).length());
        Self {
            corners,
            corner_normals: corner_normals(&corners),
            halves: halves.map(TriangleFrame::new),
            e,
            f,
            k,
            n: e.cross(f),
            nu: e.cross(k),
            nv: k.cross(f),
            centre: 0.25 * (q0 + q1 + q2 + q3),
            size,
        }
    }

    /// `P(u, v) − x`, from the corners' differences with x.
    #[inline]
    pub fn offset(&self, x: DVec3, u: f64, v: f64) -> DVec3 {
        (self.corners[0] - x) + u * self.e + v * (self.f + u * self.k)
    }

    /// The mean corner.
    pub fn centre(&self) -> DVec3 {
        self.centre
    }

    /// `∂P/∂u × ∂P/∂v` at (u, v).
    #[inline]
    pub fn normal_at(&self, u: f64, v: f64) -> DVec3 {
        self.n + u * self.nu + v * self.nv
    }

    /// `∂P/∂u` and `∂P/∂v` at (u, v).
    #[inline]
    pub fn tangents(&self, u: f64, v: f64) -> (DVec3, DVec3) {
        (self.e + v * self.k, self.f + u * self.k)
    }

    /// The integrals seen from `x` (not on the patch): the quadrature projected
    /// onto the closed-form sums of the module doc.
    pub fn integrals(&self, x: DVec3, rule: &Quadtree) -> QuadIntegrals {
        let raw = self.quadrature(x, rule);
        self.project(x, raw)
    }

    /// The integrals by quadrature alone, before the projection.
    pub fn quadrature(&self, x: DVec3, rule: &Quadtree) -> QuadIntegrals {
        let mut tree = Tree {
            frame: self,
            x,
            rule,
            sums: [0.0; 8],
        };
        tree.cell(0.0, 0.0, 1.0, 0);
        let [p0, p1, p2, p3, s0, s1, s2, s3] = tree.sums.map(|s| s * (0.25 / PI));
        let phi = [p0, p1, p2, p3];
        QuadIntegrals {
            solid_angle: 4.0 * PI * phi.iter().sum::<f64>(),
            phi,
            psi: [s0, s1, s2, s3],
        }
    }

    /// The least change (in φ and ψ·size) that makes `raw` satisfy the four
    /// closed-form equations; `raw` as it is where they are singular.
    fn project(&self, x: DVec3, raw: QuadIntegrals) -> QuadIntegrals {
        let (halves_angle, moment) = self.halves_closed_form(x);
        // The patch and the split differ by a whole sphere where x lies between.
        let turns = ((raw.solid_angle - halves_angle) / (4.0 * PI)).round();
        let solid_angle = halves_angle + 4.0 * PI * turns;
        let winding = solid_angle / (4.0 * PI);
        // Rows relative to the centre (well conditioned far from the quad),
        // everything over the quad's size.
        let s = self.size;
        let rows: [[f64; 8]; 4] = std::array::from_fn(|row| {
            std::array::from_fn(|col| match (row, col) {
                (0, 0..=3) => 1.0,
                (0, _) => 0.0,
                (r, 0..=3) => (self.corners[col] - self.centre)[r - 1] / s,
                (r, _) => self.corner_normals[col - 4][r - 1] / (s * s),
            })
        });
        let target_moment = (moment - (self.centre - x) * winding) / s;
        let target = [winding, target_moment.x, target_moment.y, target_moment.z];
        let z: [f64; 8] = std::array::from_fn(|i| {
            if i < 4 {
                raw.phi[i]
            } else {
                raw.psi[i - 4] * s
            }
        });
        let residual = DVec4::from_array(std::array::from_fn(|r| {
            target[r] - (0..8).map(|c| rows[r][c] * z[c]).sum::<f64>()
        }));
        let gram = DMat4::from_cols_array_2d(&std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..8).map(|c| rows[i][c] * rows[j][c]).sum::<f64>())
        }));
        let det = gram.determinant();
        if det.is_nan() || det.abs() <= 1e-12 {
            return QuadIntegrals { solid_angle, ..raw };
        }
        let lambda = gram.inverse() * residual;
        let corrected: [f64; 8] =
            std::array::from_fn(|c| z[c] + (0..4).map(|r| rows[r][c] * lambda[r]).sum::<f64>());
        QuadIntegrals {
            solid_angle,
            phi: std::array::from_fn(|i| corrected[i]),
            psi: std::array::from_fn(|i| corrected[i + 4] / s),
        }
    }

    /// The split triangles' solid angle and `Σ φ (v − x) + ψ n`, in closed form.
    fn halves_closed_form(&self, x: DVec3) -> (f64, DVec3) {
        let mut angle = 0.0;
        let mut moment = DVec3::ZERO;
        for half in &self.halves {
            let integrals = half.integrals(x);
            angle += integrals.solid_angle;
            for (corner, phi) in half.corners.iter().zip(integrals.phi) {
                moment += phi * (*corner - x);
            }
            moment += integrals.psi * half.normal;
        }
        (angle, moment)
    }
}

/// `Nₖ` of the patch `q`: `(q_{k+1} − qₖ) × (q_{k−1} − qₖ)`, the area vector of
/// the triangle of the corner and its two neighbours.
pub fn corner_normals(q: &[DVec3; 4]) -> [DVec3; 4] {
    std::array::from_fn(|k| (q[(k + 1) % 4] - q[k]).cross(q[(k + 3) % 4] - q[k]))
}

struct Tree<'a> {
    frame: &'a QuadFrame,
    x: DVec3,
    rule: &'a Quadtree,
    /// φ₀..φ₃ then ψ₀..ψ₃, times 4π.
    sums: [f64; 8],
}

impl Tree<'_> {
    fn cell(&mut self, u: f64, v: f64, size: f64, depth: u32) {
        let half = 0.5 * size;
        let (cu, cv) = (u + half, v + half);
        let centre = self.frame.offset(self.x, cu, cv);
        let distance = centre.length();
        let radius = [(u, v), (u + size, v), (u + size, v + size), (u, v + size)]
            .into_iter()
            .map(|(u, v)| self.frame.offset(self.x, u, v).distance_squared(centre))
            .fold(0.0, f64::max)
            .sqrt();
        if radius > self.rule.eta * distance && depth < MAX_DEPTH {
            for (du, dv) in [(0.0, 0.0), (half, 0.0), (half, half), (0.0, half)] {
                self.cell(u + du, v + dv, half, depth + 1);
            }
            return;
        }
        let order = order_for(distance / radius.max(f64::MIN_POSITIVE), self.rule.tau);
        self.leaf(cu, cv, half, order);
    }

    fn leaf(&mut self, cu: f64, cv: f64, half: f64, order: usize) {
        let (nodes, weights) = gauss_legendre(order);
        let area = half * half;
        for (&s, &ws) in nodes.iter().zip(weights) {
            let u = cu + half * s;
            for (&t, &wt) in nodes.iter().zip(weights) {
                let v = cv + half * t;
                let offset = self.frame.offset(self.x, u, v);
                let r = offset.length();
                if r == 0.0 {
                    continue;
                }
                let w = area * ws * wt / r;
                let double_layer = w * offset.dot(self.frame.normal_at(u, v)) / (r * r);
                for (i, b) in bilinear_basis(u, v).into_iter().enumerate() {
                    self.sums[i] += b * double_layer;
                    self.sums[i + 4] += b * w;
                }
            }
        }
    }
}

/// Gauss–Legendre nodes per side for the corner scales: the integrands are
/// smooth (square roots of polynomials).
const SCALE_ORDER: usize = 8;

/// Each corner's scale `σₖ` from the rest quad `q` to the deformed `q1`:
/// `∫ Bₖ s |N| / ∫ Bₖ |N'|`, with `s` the pointwise stretch of Green
/// coordinates (the triangle's stretch factor at each point of the patch).
/// `σₖ Nₖ'` then replaces `Nₖ`: it is `k R Nₖ` under a similarity of scale k
/// and rotation R (both integrands scale alike at every point), and on a flat
/// parallelogram it is the triangle's `s n' |N|`. A corner whose deformed
/// integral vanishes (the patch collapsed) gets 0.
pub fn corner_scales(q: &[DVec3; 4], q1: &[DVec3; 4]) -> [f64; 4] {
    let rest = QuadFrame::new(*q, [[q[0], q[1], q[2]]; 2]);
    let posed = QuadFrame::new(*q1, [[q1[0], q1[1], q1[2]]; 2]);
    let (nodes, weights) = gauss_legendre(SCALE_ORDER);
    let (mut stretched, mut deformed) = ([0.0; 4], [0.0; 4]);
    for (&s, &ws) in nodes.iter().zip(weights) {
        let u = 0.5 + 0.5 * s;
        for (&t, &wt) in nodes.iter().zip(weights) {
            let v = 0.5 + 0.5 * t;
            let (a, b) = rest.tangents(u, v);
            let (a1, b1) = posed.tangents(u, v);
            let squared = 0.5
                * (a1.length_squared() * b.length_squared()
                    + a.length_squared() * b1.length_squared()
                    - 2.0 * a1.dot(b1) * a.dot(b));
            let stretch_area = squared.max(0.0).sqrt();
            let deformed_area = a1.cross(b1).length();
            for (i, basis) in bilinear_basis(u, v).into_iter().enumerate() {
                stretched[i] += ws * wt * basis * stretch_area;
                deformed[i] += ws * wt * basis * deformed_area;
            }
        }
    }
    std::array::from_fn(|i| {
        if deformed[i] > 0.0 {
            stretched[i] / deformed[i]
        } else {
            0.0
        }
    })
}

#[cfg(test)]
#[path = "quad_tests.rs"]
mod tests;

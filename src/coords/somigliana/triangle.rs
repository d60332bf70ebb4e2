//! One cage triangle's blocks seen from a point: the frame computed once per
//! bind, the choice between the near-field scheme ([`super::near`]) and direct
//! quadrature far away, and the far-field integrand.

use super::near;
use super::quadrature::integrate_triangle;
use crate::geometry::closest_offset_on_triangle;
use glam::{DMat3, DVec3};
use std::f64::consts::PI;

/// Farther than this many longest edges from a triangle, its kernels are smooth
/// enough for direct quadrature; nearer, the polar scheme (whose edge terms
/// cancel more the farther the point) is used.
const FAR_FIELD_EDGES: f64 = 2.0;

/// Absolute tolerance of every integral, on quantities scaled to be of order one
/// (the single layer is divided by the longest edge).
pub(super) const TOLERANCE: f64 = 1e-13;

/// The material constants the kernels need, from the Poisson ratio ν (μ = 1:
/// the shear modulus cancels between the Kelvin kernel and the traction).
#[derive(Clone, Copy, Debug)]
pub(super) struct Material {
    /// 1 − 2ν.
    pub one_minus_2nu: f64,
    /// 3 − 4ν.
    pub three_minus_4nu: f64,
    /// 1 / (8π(1 − ν)): the traction kernel's factor.
    pub vertex_factor: f64,
    /// (1 + ν) / (8π(1 − ν)(1 − 2ν)): the Kelvin kernel's 1/(16π(1 − ν)) times
    /// the traction 2(1 + ν)/(1 − 2ν) of a unit dilation.
    pub face_factor: f64,
}

impl Material {
    pub fn new(poisson_ratio: f64) -> Self {
        let nu = poisson_ratio;
        Self {
            one_minus_2nu: 1.0 - 2.0 * nu,
            three_minus_4nu: 3.0 - 4.0 * nu,
            vertex_factor: 1.0 / (8.0 * PI * (1.0 - nu)),
            face_factor: (1.0 + nu) / (8.0 * PI * (1.0 - nu) * (1.0 - 2.0 * nu)),
        }
    }
}

/// What one triangle adds at a point: a block per corner (in corner order) and
/// its face block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct TriangleBlocks {
    pub vertex: [DMat3; 3],
    pub face: DMat3,
}

/// One cage triangle's rest geometry.
#[derive(Clone, Copy, Debug)]
pub(super) struct TriangleFrame {
    pub corners: [DVec3; 3],
    /// Unit outward normal n, and the in-plane unit vectors e₁ (along the first
    /// edge) and e₂ = n × e₁.
    pub normal: DVec3,
    pub tangent: DVec3,
    pub bitangent: DVec3,
    pub longest_edge: f64,
}

impl TriangleFrame {
    pub fn new(corners: [DVec3; 3]) -> Self {
        let [a, b, c] = corners;
        let normal = (b - a).cross(c - a).normalize_or_zero();
        let tangent = (b - a).normalize_or_zero();
        let longest_edge = (b - a).length().max((c - b).length()).max((a - c).length());
        Self {
            corners,
            normal,
            tangent,
            bitangent: normal.cross(tangent),
            longest_edge,
        }
    }

    /// The triangle's blocks at `x`, from its corners relative to `x`.
    pub fn blocks(&self, x: DVec3, material: &Material) -> TriangleBlocks {
        let relative = self.corners.map(|corner| corner - x);
        let (offset, _) =
            closest_offset_on_triangle(DVec3::ZERO, relative[0], relative[1], relative[2]);
        if offset.length() > FAR_FIELD_EDGES * self.longest_edge {
            self.far_field(relative, material)
        } else {
            near::blocks(self, relative, material)
        }
    }

    /// Direct quadrature of the kernels on the triangle (adaptive collapsed Gauss).
    pub(super) fn far_field(&self, relative: [DVec3; 3], material: &Material) -> TriangleBlocks {
        let [a, b, c] = relative;
        let (ab, ac) = (b - a, c - a);
        let doubled_area = ab.cross(ac).length();
        let n = self.normal;
        let inverse_length = 1.0 / self.longest_edge;
        let mut integrand = |xi: f64, eta: f64| {
            let r = a + xi * ab + eta * ac;
            let values = kernels_at(r, n, material);
            let single = values.single * inverse_length;
            let hats = [1.0 - xi - eta, xi, eta];
            let mut out = [0.0; 36];
            out[..9].copy_from_slice(&single.to_cols_array());
            for (k, hat) in hats.iter().enumerate() {
                out[9 * (k + 1)..9 * (k + 2)]
                    .copy_from_slice(&(values.double * *hat).to_cols_array());
            }
            out
        };
        let mut sum = [0.0; 36];
        integrate_triangle(
            &mut integrand,
            TOLERANCE / doubled_area.max(1e-300),
            &mut sum,
        );
        let block = |k: usize| DMat3::from_cols_slice(&sum[9 * k..9 * (k + 1)]) * doubled_area;
        TriangleBlocks {
            vertex: [1, 2, 3].map(|k| block(k) * material.vertex_factor),
            face: block(0) * (self.longest_edge * material.face_factor),
        }
    }
}

/// The two kernels at `r = y − x` (without their constant factors) for a surface
/// with unit normal `n` at y.
#[derive(Clone, Copy, Debug)]
pub(super) struct Kernels {
    /// (3 − 4ν) I / r + r rᵀ / r³: the Kelvin kernel times 16πμ(1 − ν).
    pub single: DMat3,
    /// [(1 − 2ν) I + 3 r̂ r̂ᵀ] (r̂·n)/r² − (1 − 2ν)(r̂ nᵀ − n r̂ᵀ)/r²: minus the
    /// traction kernel times 8π(1 − ν).
    pub double: DMat3,
}

pub(super) fn kernels_at(r: DVec3, n: DVec3, material: &Material) -> Kernels {
    let length = r.length();
    let inverse = 1.0 / length;
    let unit = r * inverse;
    let rr = outer(unit, unit);
    let single = (DMat3::IDENTITY * material.three_minus_4nu + rr) * inverse;
    let inverse_squared = inverse * inverse;
    let normal_part = (DMat3::IDENTITY * material.one_minus_2nu + rr * 3.0) * unit.dot(n);
    let twist = (outer(unit, n) - outer(n, unit)) * material.one_minus_2nu;
    Kernels {
        single,
        double: (normal_part - twist) * inverse_squared,
    }
}

/// a bᵀ.
pub(super) fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

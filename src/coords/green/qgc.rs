//! QGC: Green coordinates of a cage with bilinear quads (Thiery and Boubekeur
//! 2022). A point gets one φ per cage vertex, one ψ per triangle that is a face
//! of its own ([`Cage::lone_triangles`] order), then four ψ per quad (one per
//! corner normal `Nₖ`, [`Cage::quads`] order), and a deformed cage moves it to
//! `Σ φᵢ vᵢ' + Σ ψⱼ sⱼ nⱼ' + Σ ψ_qk σ_qk N_qk'` ([`face_vectors`]).
//!
//! A cage without quads gets today's Green coordinates ([`GreenCage`]), exactly.
//! The policies follow Green's: a point on the surface is evaluated pushed
//! inward with the push given back through the touching faces' ψ; a point
//! outside is continued through the nearest face, which for a quad adds the
//! jump of the double layer (φₖ += Bₖ at the foot on the patch, extended beyond
//! its square) and `h` along the normal there (ψₖ += h Bₖ / |N|): exact at rest
//! and continuous across the patch.

use super::quad::{corner_normals, corner_scales, QuadFrame, QUADTREE};
use super::triangle::TriangleFrame;
use super::{stretch_factors, GreenCage, GreenError, SURFACE_PUSH, SURFACE_TOLERANCE};
use crate::geometry::quads::{bilinear_basis, nearest_uv};
use crate::geometry::{closest_offset_on_triangle, Cage};
use glam::DVec3;
use std::f64::consts::PI;

/// Green coordinates of a cage, with its quads as bilinear patches.
#[derive(Clone, Debug)]
pub struct QgcCage(Inner);

#[derive(Clone, Debug)]
enum Inner {
    Triangles(GreenCage),
    Quads(QuadCage),
}

#[derive(Clone, Debug)]
struct QuadCage {
    vertex_count: usize,
    lone: Vec<([u32; 3], TriangleFrame)>,
    quads: Vec<PreparedQuad>,
    surface_tolerance: f64,
    surface_push: f64,
}

#[derive(Clone, Debug)]
struct PreparedQuad {
    corners: [u32; 4],
    frame: QuadFrame,
    /// Each half's corners as indices into the quad's corners.
    half_corners: [[usize; 3]; 2],
    /// The corner whose `Nₖ` is each half's area vector.
    half_middle: [usize; 2],
    /// Every point of the patch is this close to the mean corner.
    radius: f64,
}

/// A face a point is continued through or pushed off.
#[derive(Clone, Copy, Debug)]
enum Face {
    Triangle(usize),
    /// Quad index and (u, v) of the foot, possibly outside the square.
    Quad(usize, f64, f64),
}

/// What one ψ column of Green coordinates multiplies: a triangle's normal, or
/// (QGC) one corner normal of a quad.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaceColumn {
    /// Index into [`Cage::triangles`].
    Triangle(usize),
    /// Index into [`Cage::quads`], and the corner (0 to 3) in its order.
    QuadCorner { quad: usize, corner: usize },
}

impl std::fmt::Display for FaceColumn {
    /// "triangle 5" or "quad 2, corner 1" (0-based, as the files and views count).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            FaceColumn::Triangle(triangle) => write!(f, "triangle {triangle}"),
            FaceColumn::QuadCorner { quad, corner } => write!(f, "quad {quad}, corner {corner}"),
        }
    }
}

/// What ψ column `k` (counted from the first after the vertex columns) of
/// Green coordinates bound on `cage` multiplies; `None` past the last.
pub fn face_column(cage: &Cage, k: usize) -> Option<FaceColumn> {
    if !cage.has_quads() {
        return (k < cage.triangle_count()).then_some(FaceColumn::Triangle(k));
    }
    let lone = cage.lone_triangles().count();
    if k < lone {
        return cage.lone_triangles().nth(k).map(FaceColumn::Triangle);
    }
    let corner = k - lone;
    (corner < 4 * cage.quads().len()).then_some(FaceColumn::QuadCorner {
        quad: corner / 4,
        corner: corner % 4,
    })
}

/// ψ columns of `cage` for Green coordinates: one per triangle on a cage of
/// triangles; one per lone triangle and four per quad on a cage with quads.
pub fn face_columns(cage: &Cage) -> usize {
    if cage.has_quads() {
        cage.lone_triangles().count() + 4 * cage.quads().len()
    } else {
        cage.triangle_count()
    }
}

impl QgcCage {
    pub fn new(cage: &Cage) -> Self {
        if !cage.has_quads() {
            return Self(Inner::Triangles(GreenCage::new(cage)));
        }
        let diagonal = cage.diagonal();
        let lone = cage
            .lone_triangles()
            .map(|t| (cage.triangles()[t], TriangleFrame::new(cage.triangle(t))))
            .collect();
        let quads = cage
            .quads()
            .iter()
            .enumerate()
            .map(|(k, quad)| {
                let q = cage.quad(k);
                let halves = quad.triangles.map(|t| cage.triangles()[t as usize]);
                let half_corners = halves.map(|half| {
                    half.map(|v| quad.corners.iter().position(|&c| c == v).unwrap_or(0))
                });
                let half_middle =
                    half_corners.map(|h| ((0..4).find(|i| !h.contains(i)).unwrap_or(0) + 2) % 4);
                let frame =
                    QuadFrame::new(q, halves.map(|h| h.map(|v| cage.positions()[v as usize])));
                let centre = 0.25 * (q[0] + q[1] + q[2] + q[3]);
                let radius = q.iter().map(|p| p.distance(centre)).fold(0.0, f64::max);
                PreparedQuad {
                    corners: quad.corners,
                    frame,
                    half_corners,
                    half_middle,
                    radius,
                }
            })
            .collect();
        Self(Inner::Quads(QuadCage {
            vertex_count: cage.vertex_count(),
            lone,
            quads,
            surface_tolerance: SURFACE_TOLERANCE * diagonal,
            surface_push: SURFACE_PUSH * diagonal,
        }))
    }

    pub fn vertex_count(&self) -> usize {
        match &self.0 {
            Inner::Triangles(green) => green.vertex_count(),
            Inner::Quads(cage) => cage.vertex_count,
        }
    }

    /// ψ columns: [`face_columns`] of the cage.
    pub fn face_columns(&self) -> usize {
        match &self.0 {
            Inner::Triangles(green) => green.triangle_count(),
            Inner::Quads(cage) => cage.lone.len() + 4 * cage.quads.len(),
        }
    }

    /// The coordinates of `x`: `phi_out` one per cage vertex, `psi_out`
    /// [`face_columns`] values.
    pub fn coordinates(
        &self,
        x: DVec3,
        phi_out: &mut [f64],
        psi_out: &mut [f64],
    ) -> Result<(), GreenError> {
        let cage = match &self.0 {
            Inner::Triangles(green) => return green.coordinates(x, phi_out, psi_out),
            Inner::Quads(cage) => cage,
        };
        if phi_out.len() != cage.vertex_count {
            return Err(GreenError::PhiLength {
                expected: cage.vertex_count,
                actual: phi_out.len(),
            });
        }
        if psi_out.len() != self.face_columns() {
            return Err(GreenError::FaceColumns {
                expected: self.face_columns(),
                actual: psi_out.len(),
            });
        }
        if !x.is_finite() {
            return Err(GreenError::NonFinitePoint { index: 0 });
        }
        let Some((direction, shares)) = cage.surface_push_at(x) else {
            if cage.closed_form(x, phi_out, psi_out) < 0.5 {
                cage.continue_outside(x, phi_out, psi_out);
            }
            return Ok(());
        };
        let pushed = x + cage.surface_push * direction;
        if cage.closed_form(pushed, phi_out, psi_out) < 0.5 {
            cage.continue_outside(pushed, phi_out, psi_out);
        }
        // x = pushed + push · Σ share · n, each n in its face's ψ columns.
        for (face, share) in shares {
            cage.add_along_normal(face, cage.surface_push * share, psi_out);
        }
        Ok(())
    }
}

impl QuadCage {
    /// Every face's integrals at `x` into the outputs; the winding number.
    fn closed_form(&self, x: DVec3, phi_out: &mut [f64], psi_out: &mut [f64]) -> f64 {
        phi_out.fill(0.0);
        let mut solid_angle = 0.0;
        let (lone_psi, quad_psi) = psi_out.split_at_mut(self.lone.len());
        for ((corners, frame), psi) in self.lone.iter().zip(lone_psi) {
            let integrals = frame.integrals(x);
            for (&corner, value) in corners.iter().zip(integrals.phi) {
                phi_out[corner as usize] += value;
            }
            *psi = integrals.psi;
            solid_angle += integrals.solid_angle;
        }
        for (quad, psi) in self.quads.iter().zip(quad_psi.chunks_mut(4)) {
            let integrals = quad.frame.integrals(x, &QUADTREE);
            for (&corner, value) in quad.corners.iter().zip(integrals.phi) {
                phi_out[corner as usize] += value;
            }
            psi.copy_from_slice(&integrals.psi);
            solid_angle += integrals.solid_angle;
        }
        solid_angle / (4.0 * PI)
    }

    /// ψ of `face` changed so that the row moves by `amount` along its unit
    /// normal (at the foot, for a quad).
    fn add_along_normal(&self, face: Face, amount: f64, psi_out: &mut [f64]) {
        match face {
            Face::Triangle(t) => psi_out[t] += amount,
            Face::Quad(j, u, v) => {
                let length = self.quads[j].frame.normal_at(u, v).length();
                if length > 0.0 {
                    let base = self.lone.len() + 4 * j;
                    for (k, b) in bilinear_basis(u, v).into_iter().enumerate() {
                        psi_out[base + k] += amount * b / length;
                    }
                }
            }
        }
    }

    /// The patch point nearest `x` (u, v in the square) and its distance.
    fn nearest_on_quad(&self, j: usize, x: DVec3) -> (f64, f64, f64) {
        let frame = &self.quads[j].frame;
        let start = (0..9)
            .map(|i| [0.5 * (i % 3) as f64, 0.5 * (i / 3) as f64])
            .min_by(|a, b| {
                let da = frame.offset(x, a[0], a[1]).length_squared();
                let db = frame.offset(x, b[0], b[1]).length_squared();
                da.total_cmp(&db)
            })
            .unwrap_or([0.5, 0.5]);
        let [u, v] = nearest_uv(&frame.corners, x, start);
        (u, v, frame.offset(x, u, v).length())
    }

    /// Inward direction and the touching faces' shares, for a point on the
    /// surface (as [`GreenCage`]'s, with a quad's normal at the nearest point).
    fn surface_push_at(&self, x: DVec3) -> Option<(DVec3, Vec<(Face, f64)>)> {
        let tolerance = self.surface_tolerance;
        let mut touches: Vec<(Face, f64, DVec3)> = Vec::new();
        for (t, (_, frame)) in self.lone.iter().enumerate() {
            if let Some(angle) = frame.angle_at(x, tolerance) {
                touches.push((Face::Triangle(t), angle, frame.normal));
            }
        }
        for (j, quad) in self.quads.iter().enumerate() {
            if x.distance(quad.frame.centre()) > quad.radius + tolerance {
                continue;
            }
            let (u, v, distance) = self.nearest_on_quad(j, x);
            if distance > tolerance {
                continue;
            }
            let q = &quad.frame.corners;
            let near: [bool; 4] = std::array::from_fn(|e| {
                let (a, b) = (q[e], q[(e + 1) % 4]);
                closest_offset_on_triangle(x, a, b, b).0.length() <= tolerance
            });
            let angle = match near.iter().filter(|&&n| n).count() {
                0 => 2.0 * PI,
                1 => PI,
                _ => {
                    let corner = (0..4).find(|&c| near[c] && near[(c + 3) % 4]).unwrap_or(0);
                    (q[(corner + 1) % 4] - q[corner]).angle_between(q[(corner + 3) % 4] - q[corner])
                }
            };
            let normal = quad.frame.normal_at(u, v).normalize_or_zero();
            touches.push((Face::Quad(j, u, v), angle, normal));
        }
        if touches.is_empty() {
            return None;
        }
        let weighted: DVec3 = touches.iter().map(|(_, a, n)| *a * *n).sum();
        let length = weighted.length();
        if length <= 1e-3 {
            // Two sheets meet at x with opposite normals: push off one.
            let (face, _, normal) = touches[0];
            return Some((-normal, vec![(face, 1.0)]));
        }
        let shares = touches
            .into_iter()
            .map(|(f, a, _)| (f, a / length))
            .collect();
        Some((-weighted / length, shares))
    }

    /// The foot of `x` on quad j's patch extended beyond its square:
    /// `(u, v, h)` with `x = P(u, v) + h N/|N|`, from Gauss–Newton steps started
    /// at the nearest point; `None` where they do not settle.
    fn extended_foot(&self, j: usize, x: DVec3) -> Option<(f64, f64, f64)> {
        let frame = &self.quads[j].frame;
        let (mut u, mut v, _) = self.nearest_on_quad(j, x);
        for _ in 0..40 {
            let residual = frame.offset(x, u, v);
            let (a, b) = frame.tangents(u, v);
            let (aa, ab, bb) = (a.dot(a), a.dot(b), b.dot(b));
            let det = aa * bb - ab * ab;
            // Not positive, or NaN: the tangents are parallel there.
            if det.is_nan() || det <= 0.0 {
                return None;
            }
            let (ra, rb) = (a.dot(residual), b.dot(residual));
            let (du, dv) = ((bb * ra - ab * rb) / det, (aa * rb - ab * ra) / det);
            u -= du;
            v -= dv;
            if !(u.abs() <= 4.0 && v.abs() <= 4.0) {
                return None;
            }
            if du.abs().max(dv.abs()) < 1e-15 {
                break;
            }
        }
        let residual = -frame.offset(x, u, v);
        let (a, b) = frame.tangents(u, v);
        let normal = a.cross(b);
        let length = normal.length();
        let slack = 1e-9 * residual.length();
        let settled = a.dot(residual).abs() <= slack * a.length()
            && b.dot(residual).abs() <= slack * b.length();
        (settled && length > 0.0).then(|| (u, v, residual.dot(normal) / length))
    }

    /// Green's exterior extension through the nearest face: the face whose
    /// outer normal prism holds x at the least height, else the nearest one.
    fn continue_outside(&self, x: DVec3, phi_out: &mut [f64], psi_out: &mut [f64]) {
        let mut best: Option<(Face, f64)> = None;
        let mut consider = |face: Face, height: f64| {
            if best.is_none_or(|(_, h)| height < h) {
                best = Some((face, height));
            }
        };
        for (t, (_, frame)) in self.lone.iter().enumerate() {
            let (barycentric, height) = frame.affine_frame(x);
            if height >= 0.0 && barycentric.iter().all(|&b| b >= 0.0) {
                consider(Face::Triangle(t), height);
            }
        }
        for j in 0..self.quads.len() {
            if let Some((u, v, h)) = self.extended_foot(j, x) {
                if h >= 0.0 && (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v) {
                    consider(Face::Quad(j, u, v), h);
                }
            }
        }
        let face = match best {
            Some((face, _)) => face,
            None => match self.nearest_face(x) {
                Some(face) => face,
                None => return,
            },
        };
        match face {
            Face::Triangle(t) => {
                let (corners, frame) = &self.lone[t];
                let (barycentric, height) = frame.affine_frame(x);
                for (&corner, value) in corners.iter().zip(barycentric) {
                    phi_out[corner as usize] += value;
                }
                psi_out[t] += height;
            }
            Face::Quad(j, ..) => self.continue_through_quad(j, x, phi_out, psi_out),
        }
    }

    /// The nearest face, and of the faces sharing the nearest edge or corner
    /// the one with the smallest hat values at x (as [`GreenCage`]'s).
    fn nearest_face(&self, x: DVec3) -> Option<Face> {
        let mut faces: Vec<(Face, f64)> = Vec::new();
        for (t, (_, frame)) in self.lone.iter().enumerate() {
            let [a, b, c] = frame.corners;
            let distance = closest_offset_on_triangle(x, a, b, c).0.length();
            faces.push((Face::Triangle(t), distance));
        }
        for j in 0..self.quads.len() {
            let (u, v, distance) = self.nearest_on_quad(j, x);
            faces.push((Face::Quad(j, u, v), distance));
        }
        let nearest = faces.iter().map(|f| f.1).fold(f64::INFINITY, f64::min);
        let tie = nearest + self.surface_tolerance;
        let largest_hat = |face: Face| match face {
            Face::Triangle(t) => {
                let (barycentric, _) = self.lone[t].1.affine_frame(x);
                barycentric.iter().fold(0.0f64, |m, b| m.max(b.abs()))
            }
            Face::Quad(j, ..) => match self.extended_foot(j, x) {
                Some((u, v, _)) => bilinear_basis(u, v)
                    .iter()
                    .fold(0.0f64, |m, b| m.max(b.abs())),
                None => f64::INFINITY,
            },
        };
        faces
            .into_iter()
            .filter(|f| f.1 <= tie)
            .map(|(face, _)| (face, largest_hat(face)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(face, _)| face)
    }

    /// The extension through quad j: at the foot on the extended patch, or
    /// where that does not settle, through its nearer half (a triangle whose
    /// area vector is one of the `Nₖ`).
    fn continue_through_quad(&self, j: usize, x: DVec3, phi_out: &mut [f64], psi_out: &mut [f64]) {
        let quad = &self.quads[j];
        if let Some((u, v, h)) = self.extended_foot(j, x) {
            for (&corner, b) in quad.corners.iter().zip(bilinear_basis(u, v)) {
                phi_out[corner as usize] += b;
            }
            self.add_along_normal(Face::Quad(j, u, v), h, psi_out);
            return;
        }
        let distance = |h: usize| {
            let [a, b, c] = quad.frame.halves[h].corners;
            closest_offset_on_triangle(x, a, b, c).0.length()
        };
        let h = usize::from(distance(1) < distance(0));
        let half = &quad.frame.halves[h];
        let (barycentric, height) = half.affine_frame(x);
        for (&k, value) in quad.half_corners[h].iter().zip(barycentric) {
            phi_out[quad.corners[k] as usize] += value;
        }
        let middle = quad.half_middle[h];
        let length = quad.frame.corner_normals[middle].length();
        if length > 0.0 {
            psi_out[self.lone.len() + 4 * j + middle] += height / length;
        }
    }
}

/// QGC of one point `x` with respect to `cage` ([`QgcCage::coordinates`]).
pub fn qgc_coordinates(
    x: DVec3,
    cage: &Cage,
    phi_out: &mut [f64],
    psi_out: &mut [f64],
) -> Result<(), GreenError> {
    QgcCage::new(cage).coordinates(x, phi_out, psi_out)
}

/// The vector each ψ column multiplies at rest: each lone triangle's unit
/// outward normal, then each quad's four `Nₖ` (on a cage of triangles, every
/// triangle's normal).
pub fn rest_face_vectors(rest: &Cage) -> Vec<DVec3> {
    let normal = |t: usize| {
        let [a, b, c] = rest.triangle(t);
        (b - a).cross(c - a).normalize_or_zero()
    };
    if !rest.has_quads() {
        return (0..rest.triangle_count()).map(normal).collect();
    }
    let mut vectors: Vec<DVec3> = rest.lone_triangles().map(normal).collect();
    for k in 0..rest.quads().len() {
        vectors.extend(corner_normals(&rest.quad(k)));
    }
    vectors
}

/// The vector each ψ column multiplies in the pose `deformed_positions`: each
/// lone triangle's `s n'` ([`super::face_vectors`]), then each quad's
/// `σₖ Nₖ'` (see [`super::quad::corner_scales`]).
pub fn face_vectors(rest: &Cage, deformed_positions: &[DVec3]) -> Result<Vec<DVec3>, GreenError> {
    if !rest.has_quads() {
        return super::face_vectors(rest, deformed_positions);
    }
    let stretch = stretch_factors(rest, deformed_positions)?;
    let mut vectors: Vec<DVec3> = rest
        .lone_triangles()
        .map(|t| {
            let [a, b, c] = rest.triangles()[t].map(|i| deformed_positions[i as usize]);
            stretch[t] * (b - a).cross(c - a).normalize_or_zero()
        })
        .collect();
    for (k, quad) in rest.quads().iter().enumerate() {
        let posed = quad.corners.map(|i| deformed_positions[i as usize]);
        let scales = corner_scales(&rest.quad(k), &posed);
        let normals = corner_normals(&posed);
        vectors.extend((0..4).map(|c| scales[c] * normals[c]));
    }
    Ok(vectors)
}

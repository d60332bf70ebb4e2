//! Green coordinates (Lipman, Levin, Cohen-Or, "Green Coordinates", SIGGRAPH 2008)
//! for closed, outward-oriented triangle cages, in closed form and f64.
//!
//! A point η gets one φᵢ per cage vertex and one ψⱼ per cage triangle (in
//! [`Cage::triangles`] order), and a deformed cage moves it to
//! `η' = Σ φᵢ vᵢ' + Σ ψⱼ sⱼ nⱼ'`, with nⱼ' the deformed triangle's unit normal and
//! sⱼ its stretch factor ([`stretch_factors`]). The result is invariant under
//! similarity transforms of the cage and reproduces the rest pose exactly.
//!
//! Policy for points that are not strictly inside (docs/green.md has the details):
//! - within [`SURFACE_TOLERANCE`] of the surface, the coordinates are those of a
//!   point pushed [`SURFACE_PUSH`] inward, with the push given back through the
//!   touching triangles' ψ, so the rest pose is still reproduced exactly;
//! - outside, the coordinates are continued analytically through the nearest cage
//!   triangle (the paper's exterior extension): continuous across that triangle,
//!   exact at rest, and discontinuous only where the nearest triangle changes.

mod qgc;
mod quad;
mod triangle;

#[cfg(test)]
mod paper;

use super::{BindProgress, Cancelled, Weights};
use crate::geometry::{closest_offset_on_triangle, Cage};
use glam::DVec3;
pub use qgc::{face_column, face_columns, qgc_coordinates, rest_face_vectors, FaceColumn, QgcCage};
pub use quad::{corner_normals, corner_scales, Quadtree, QUADTREE};
use rayon::prelude::*;
use std::f64::consts::PI;
use triangle::TriangleFrame;

/// QGC's vectors per ψ column in a pose: [`qgc::face_vectors`].
pub fn qgc_face_vectors(
    rest: &Cage,
    deformed_positions: &[DVec3],
) -> Result<Vec<DVec3>, GreenError> {
    qgc::face_vectors(rest, deformed_positions)
}

/// Points closer than this fraction of the cage diagonal are on the surface (the
/// tolerance point classification uses).
pub const SURFACE_TOLERANCE: f64 = 1e-9;
/// How far inward (as a fraction of the cage diagonal) a point on the surface is
/// evaluated: far enough from every edge that the closed form is well conditioned.
pub const SURFACE_PUSH: f64 = 1e-6;

/// Rows bound per parallel task (as in the other CPU binds).
const ROWS_PER_TASK: usize = 32;

/// What can go wrong computing or applying Green coordinates.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GreenError {
    #[error("φ needs one value per cage vertex ({expected}), the buffer holds {actual}")]
    PhiLength { expected: usize, actual: usize },
    #[error("ψ needs one value per cage triangle ({expected}), the buffer holds {actual}")]
    PsiLength { expected: usize, actual: usize },
    #[error("ψ needs one value per lone cage triangle and four per quad ({expected}), the buffer holds {actual}")]
    FaceColumns { expected: usize, actual: usize },
    #[error("point {index} is not finite")]
    NonFinitePoint { index: usize },
    #[error("the cage has {expected} vertices but {actual} deformed positions were given")]
    PositionCount { expected: usize, actual: usize },
    #[error("the cage has {expected} triangles but {actual} face vectors were given")]
    FaceVectorCount { expected: usize, actual: usize },
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
}

/// A cage prepared for many evaluations: each triangle's frame computed once.
#[derive(Clone, Debug)]
pub struct GreenCage {
    frames: Vec<TriangleFrame>,
    triangles: Vec<[u32; 3]>,
    vertex_count: usize,
    surface_tolerance: f64,
    surface_push: f64,
}

impl GreenCage {
    pub fn new(cage: &Cage) -> Self {
        let diagonal = cage.diagonal();
        Self {
            frames: (0..cage.triangle_count())
                .map(|t| TriangleFrame::new(cage.triangle(t)))
                .collect(),
            triangles: cage.triangles().to_vec(),
            vertex_count: cage.vertex_count(),
            surface_tolerance: SURFACE_TOLERANCE * diagonal,
            surface_push: SURFACE_PUSH * diagonal,
        }
    }

    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    pub fn triangle_count(&self) -> usize {
        self.frames.len()
    }

    /// Green coordinates of `x`: `phi_out` one per cage vertex, `psi_out` one per
    /// cage triangle, following the policy of the module doc.
    pub fn coordinates(
        &self,
        x: DVec3,
        phi_out: &mut [f64],
        psi_out: &mut [f64],
    ) -> Result<(), GreenError> {
        self.check_lengths(phi_out.len(), psi_out.len())?;
        if !x.is_finite() {
            return Err(GreenError::NonFinitePoint { index: 0 });
        }
        let mut shares = Vec::new();
        let Some(direction) = self.surface_push_at(x, &mut shares) else {
            let winding = self.closed_form(x, phi_out, psi_out);
            if winding < 0.5 {
                self.continue_outside(x, phi_out, psi_out);
            }
            return Ok(());
        };
        let pushed = x + self.surface_push * direction;
        if self.closed_form(pushed, phi_out, psi_out) < 0.5 {
            // A sliver of the cage thinner than the push: still exact at rest.
            self.continue_outside(pushed, phi_out, psi_out);
        }
        // x = pushed − push · direction = pushed + push · Σ shareⱼ nⱼ.
        for (t, share) in shares {
            psi_out[t] += self.surface_push * share;
        }
        Ok(())
    }

    fn check_lengths(&self, phi: usize, psi: usize) -> Result<(), GreenError> {
        if phi != self.vertex_count {
            return Err(GreenError::PhiLength {
                expected: self.vertex_count,
                actual: phi,
            });
        }
        if psi != self.frames.len() {
            return Err(GreenError::PsiLength {
                expected: self.frames.len(),
                actual: psi,
            });
        }
        Ok(())
    }

    /// The boundary integrals at `x`, written to the outputs; returns the
    /// generalised winding number (Σ φᵢ, 1 inside and 0 outside).
    fn closed_form(&self, x: DVec3, phi_out: &mut [f64], psi_out: &mut [f64]) -> f64 {
        phi_out.fill(0.0);
        let mut solid_angle = 0.0;
        for ((frame, corners), psi) in self.frames.iter().zip(&self.triangles).zip(psi_out) {
            let integrals = frame.integrals(x);
            for (&corner, value) in corners.iter().zip(integrals.phi) {
                phi_out[corner as usize] += value;
            }
            *psi = integrals.psi;
            solid_angle += integrals.solid_angle;
        }
        solid_angle / (4.0 * PI)
    }

    /// For a point on the surface: the inward direction to evaluate along, and each
    /// touching triangle's share of the push, `(triangle, share)` with
    /// `Σ share · nⱼ = −direction`. The direction is the angle-weighted normal
    /// (Bærentzen and Aanæs), which points into the cage at faces, edges and
    /// vertices alike. `None` off the surface.
    fn surface_push_at(&self, x: DVec3, shares: &mut Vec<(usize, f64)>) -> Option<DVec3> {
        shares.clear();
        let mut weighted_normal = DVec3::ZERO;
        for (t, frame) in self.frames.iter().enumerate() {
            if let Some(angle) = frame.angle_at(x, self.surface_tolerance) {
                shares.push((t, angle));
                weighted_normal += angle * frame.normal;
            }
        }
        let length = weighted_normal.length();
        if shares.is_empty() {
            return None;
        }
        if length <= 1e-3 {
            // Two sheets of the cage meet at x with opposite normals: push off one.
            shares.truncate(1);
            shares[0].1 = 1.0;
            return Some(-self.frames[shares[0].0].normal);
        }
        for (_, share) in shares.iter_mut() {
            *share /= length;
        }
        Some(-weighted_normal / length)
    }

    /// The paper's exterior extension: crossing triangle j outward, φ of its corners
    /// jumps by the hat functions at x and ψⱼ's normal derivative by one; adding
    /// both back continues the inside coordinates analytically through j.
    ///
    /// j is the nearest triangle whose outer prism holds x (so the added hat values
    /// lie in [0, 1]). Where no prism does (beyond an edge or a corner), j is the
    /// nearest triangle, and of the triangles sharing that nearest edge or corner
    /// the one with the smallest hat values at x (a sliver's would be large and lose
    /// precision in f32 weights).
    fn continue_outside(&self, x: DVec3, phi_out: &mut [f64], psi_out: &mut [f64]) {
        let in_prism = (self.frames.iter().enumerate())
            .filter_map(|(t, frame)| {
                let (barycentric, height) = frame.affine_frame(x);
                (height >= 0.0 && barycentric.iter().all(|&b| b >= 0.0)).then_some((t, height))
            })
            .min_by(|(_, h0), (_, h1)| h0.total_cmp(h1));
        let chosen = in_prism.map(|(t, _)| t).or_else(|| {
            let distances: Vec<f64> = self
                .frames
                .iter()
                .map(|frame| {
                    let [a, b, c] = frame.corners;
                    closest_offset_on_triangle(x, a, b, c).0.length()
                })
                .collect();
            let nearest = distances.iter().copied().fold(f64::INFINITY, f64::min);
            let tie = nearest + self.surface_tolerance;
            let largest_hat = |t: usize| {
                let (barycentric, _) = self.frames[t].affine_frame(x);
                barycentric.iter().fold(0.0f64, |m, b| m.max(b.abs()))
            };
            (0..self.frames.len())
                .filter(|&t| distances[t] <= tie)
                .map(|t| (t, largest_hat(t)))
                .min_by(|(_, m0), (_, m1)| m0.total_cmp(m1))
                .map(|(t, _)| t)
        });
        let Some(t) = chosen else {
            return;
        };
        let (barycentric, height) = self.frames[t].affine_frame(x);
        for (&corner, value) in self.triangles[t].iter().zip(barycentric) {
            phi_out[corner as usize] += value;
        }
        psi_out[t] += height;
    }
}

/// Green coordinates of one point `x` with respect to `cage`: `phi_out` gets one
/// value per cage vertex, `psi_out` one per cage triangle. For many points, build a
/// [`GreenCage`] once or use [`bind_green`].
pub fn green_coordinates(
    x: DVec3,
    cage: &Cage,
    phi_out: &mut [f64],
    psi_out: &mut [f64],
) -> Result<(), GreenError> {
    GreenCage::new(cage).coordinates(x, phi_out, psi_out)
}

/// Green coordinates of many points, as two dense row-major f32 matrices.
#[derive(Clone, Debug, PartialEq)]
pub struct GreenWeights {
    /// Points × cage vertices.
    pub phi: Weights,
    /// Points × cage triangles.
    pub psi: Weights,
}

/// Bind `points` to `cage` on the CPU, in parallel over points, advancing
/// `progress` and stopping early when it is cancelled.
pub fn bind_green(
    points: &[DVec3],
    cage: &Cage,
    progress: &BindProgress,
) -> Result<GreenWeights, GreenError> {
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(GreenError::NonFinitePoint { index });
    }
    let prepared = GreenCage::new(cage);
    let (vertices, triangles) = (prepared.vertex_count(), prepared.triangle_count());
    let mut weights = GreenWeights {
        phi: Weights::zeros(points.len(), vertices),
        psi: Weights::zeros(points.len(), triangles),
    };
    if vertices == 0 || triangles == 0 {
        return Ok(weights);
    }
    weights
        .phi
        .values
        .par_chunks_mut(vertices * ROWS_PER_TASK)
        .zip(weights.psi.values.par_chunks_mut(triangles * ROWS_PER_TASK))
        .zip(points.par_chunks(ROWS_PER_TASK))
        .try_for_each_init(
            || (vec![0.0f64; vertices], vec![0.0f64; triangles]),
            |(phi, psi), ((phi_block, psi_block), block_points)| {
                if progress.is_cancelled() {
                    return Err(GreenError::Cancelled(Cancelled));
                }
                let rows = phi_block
                    .chunks_mut(vertices)
                    .zip(psi_block.chunks_mut(triangles));
                for ((phi_row, psi_row), &x) in rows.zip(block_points) {
                    prepared.coordinates(x, phi, psi)?;
                    narrow_into(phi, phi_row);
                    narrow_into(psi, psi_row);
                }
                progress.advance(block_points.len());
                Ok(())
            },
        )?;
    Ok(weights)
}

fn narrow_into(values: &[f64], out: &mut [f32]) {
    for (out, &value) in out.iter_mut().zip(values) {
        *out = value as f32;
    }
}

/// The paper's stretch factor of every triangle from `rest` to `deformed_positions`:
/// `sqrt(|u'|²|v|² − 2(u'·v')(u·v) + |v'|²|u|²) / (sqrt(8) · area)`, with u, v the
/// rest edge vectors from the first corner, u', v' the deformed ones and `area` the
/// rest area. 1 at rest, k under a uniform scale by k.
pub fn stretch_factors(rest: &Cage, deformed_positions: &[DVec3]) -> Result<Vec<f64>, GreenError> {
    check_position_count(rest, deformed_positions)?;
    Ok(rest
        .triangles()
        .iter()
        .map(|&corners| {
            let [a, b, c] = corners.map(|i| rest.positions()[i as usize]);
            let [a1, b1, c1] = corners.map(|i| deformed_positions[i as usize]);
            let (u, v) = (b - a, c - a);
            let (u1, v1) = (b1 - a1, c1 - a1);
            let area = 0.5 * u.cross(v).length();
            let squared = u1.length_squared() * v.length_squared() - 2.0 * u1.dot(v1) * u.dot(v)
                + v1.length_squared() * u.length_squared();
            if area > 0.0 {
                squared.max(0.0).sqrt() / (8f64.sqrt() * area)
            } else {
                1.0
            }
        })
        .collect())
}

/// `sⱼ nⱼ'` for every triangle: the deformed unit normal times the stretch factor,
/// the vector each ψⱼ multiplies.
pub fn face_vectors(rest: &Cage, deformed_positions: &[DVec3]) -> Result<Vec<DVec3>, GreenError> {
    let stretch = stretch_factors(rest, deformed_positions)?;
    Ok(rest
        .triangles()
        .iter()
        .zip(stretch)
        .map(|(&corners, stretch)| {
            let [a, b, c] = corners.map(|i| deformed_positions[i as usize]);
            stretch * (b - a).cross(c - a).normalize_or_zero()
        })
        .collect())
}

fn check_position_count(cage: &Cage, positions: &[DVec3]) -> Result<(), GreenError> {
    if positions.len() == cage.vertex_count() {
        Ok(())
    } else {
        Err(GreenError::PositionCount {
            expected: cage.vertex_count(),
            actual: positions.len(),
        })
    }
}

/// One point's deformed position `Σ φᵢ vᵢ' + Σ ψⱼ fⱼ` from its f64 coordinates, the
/// deformed cage positions and the [`face_vectors`] `fⱼ`.
pub fn apply_coordinates(
    phi: &[f64],
    psi: &[f64],
    positions: &[DVec3],
    face_vectors: &[DVec3],
) -> Result<DVec3, GreenError> {
    check_columns(phi.len(), psi.len(), positions, face_vectors)?;
    let from_vertices: DVec3 = phi.iter().zip(positions).map(|(&w, &p)| w * p).sum();
    let from_faces: DVec3 = psi.iter().zip(face_vectors).map(|(&w, &f)| w * f).sum();
    Ok(from_vertices + from_faces)
}

fn check_columns(
    vertices: usize,
    triangles: usize,
    positions: &[DVec3],
    face_vectors: &[DVec3],
) -> Result<(), GreenError> {
    if positions.len() != vertices {
        return Err(GreenError::PositionCount {
            expected: vertices,
            actual: positions.len(),
        });
    }
    if face_vectors.len() != triangles {
        return Err(GreenError::FaceVectorCount {
            expected: triangles,
            actual: face_vectors.len(),
        });
    }
    Ok(())
}

impl GreenWeights {
    /// Every bound point moved by the cage deformed from `rest` to
    /// `deformed_positions`, accumulated in f64.
    pub fn deform(
        &self,
        rest: &Cage,
        deformed_positions: &[DVec3],
    ) -> Result<Vec<DVec3>, GreenError> {
        let faces = face_vectors(rest, deformed_positions)?;
        self.deform_with_face_vectors(deformed_positions, &faces)
    }

    /// Every bound point moved to `Σ φᵢ vᵢ' + Σ ψⱼ fⱼ`, given the deformed cage
    /// positions and the [`face_vectors`] `fⱼ`.
    pub fn deform_with_face_vectors(
        &self,
        positions: &[DVec3],
        face_vectors: &[DVec3],
    ) -> Result<Vec<DVec3>, GreenError> {
        check_columns(self.phi.cols, self.psi.cols, positions, face_vectors)?;
        let from_vertices = self.phi.apply(positions);
        let from_faces = self.psi.apply(face_vectors);
        Ok(from_vertices
            .into_iter()
            .zip(from_faces)
            .map(|(v, f)| v + f)
            .collect())
    }
}

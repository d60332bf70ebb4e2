//! Somigliana coordinates (Chen, de Goes, Desbrun, "Somigliana Coordinates: an
//! elasticity-derived approach for cage deformation", SIGGRAPH 2023), the CPU
//! core: 3×3 blocks per point and cage vertex or triangle, in f64, and the
//! paper's global deformation; as the family [`super::Method::Somigliana`], each
//! block expanded into 9 scalar columns (`columns.rs`).
//!
//! # Formulation
//!
//! The Somigliana identity of linear elasticity (shear modulus μ, Poisson ratio
//! ν) gives the displacement inside a body from its boundary values u and
//! tractions t:
//!
//! `u(x) = ∫ K(x, y) t(y) dA − ∫ T(x, y) u(y) dA`, with, for r = y − x,
//! - the Kelvin solution `K = [(3 − 4ν) I + r̂ r̂ᵀ] / (16πμ(1 − ν)|r|)`;
//! - its traction kernel `T = −{[(1 − 2ν) I + 3 r̂ r̂ᵀ](r̂·n) − (1 − 2ν)(r̂ nᵀ − n r̂ᵀ)}
//!   / (8π(1 − ν)|r|²)`, n the outward normal at y.
//!
//! On a closed outward triangle cage ([`Cage::triangles`]: quads enter as their
//! two triangles), u is taken piecewise linear (hat functions Γᵥ of the cage
//! vertices) and t constant per triangle. A point x then gets
//! - a vertex block `Bᵥ(x) = −∫ T(x, y) Γᵥ(y) dA` per cage vertex, and
//! - a face block `F_f(x) = c(ν) μ ∫_f K(x, y) dA` per cage triangle, with
//!   `c(ν) = 2(1 + ν)/(1 − 2ν)` folded in: c μ is the traction per unit normal of
//!   a unit dilation (stress (2μ + 3λ) I), so μ cancels and the face vector of
//!   the rest pose is the plain unit normal.
//!
//! Every affine field u = A x + b is reproduced when face f is given its own
//! traction σ(A) n_f / (c μ); at rest, `x = Σ Bᵥ vᵥ + Σ F_f n_f`, and `Σ Bᵥ = I`
//! inside the cage (0 outside).
//!
//! The deformation is the paper's global variant: the similarity `v' ≈ s R v + t`
//! that best fits the deformed cage (Umeyama, least squares over the vertices,
//! see [`fit_similarity`]) gives every triangle the traction of the dilation
//! s about the rotated frame (the paper's 2μ(h + ν(2s + h)/(1 − 2ν)) R n_f with
//! h = s, which is c μ s R n_f), and
//!
//! `x' = R (Σ Bᵥ Rᵀ vᵥ' + s Σ F_f n_f)`, n_f the rest unit normals,
//!
//! i.e. the blocks act in the rest frame on the unrotated cage (evaluated about
//! the deformed cage's centroid c' as `c' + R (Σ Bᵥ Rᵀ (vᵥ' − c') + …)`, equal
//! inside where Σ Bᵥ = I, and exact far from the origin); the result is
//! invariant under similarities of the cage (a similarity is followed exactly).
//! With the bulging term γ (`bulging.rs`), each triangle's traction is its own
//! t_f instead of s (`s Σ F_f n_f` becomes `Σ t_f F_f n_f`), projected onto zero
//! net force; a similarity sweeps nothing, so it is still followed exactly.
//! The local/global blend (`blend.rs`, a second deformation setting) turns
//! each vertex and triangle with its own blended frame and normalises each
//! point by `(Σ Rᵥ Bᵥ Rᵥᵀ)⁻¹`, which is no weighted sum of per-column vectors:
//! its columns carry matrices too ([`crate::coords::ColumnMoves`]). Left out:
//! the solid-angle measure of bulging.
//!
//! # Evaluation
//!
//! Per triangle, near a point (within two of its longest edges) in polar
//! coordinates about the point's foot with the radial integrals in closed form
//! and adaptive Gauss–Kronrod along the edges (`near.rs`); farther, adaptive
//! collapsed Gauss quadrature of the kernels. Both work on the corners relative
//! to the point, to an absolute tolerance of about 1e-13 on quantities of order
//! one per triangle. A point exactly in the plane of a face it is not on gets no
//! contribution from that face's jump (solid angle 0, not 2π), so the blocks are
//! continuous there. Points are meant to be strictly inside: on a face the inner
//! limit is taken, close to a cage edge digits are lost (the tests' point 1e-6
//! from a re-entrant edge keeps Σ Bᵥ = I to 2e-12), and outside
//! the blocks are the identity's exterior value (Σ Bᵥ = 0), with no exterior
//! extension.

mod blend;
mod bulging;
mod columns;
mod fit;
mod near;
mod quadrature;
mod triangle;

#[cfg(test)]
mod reference;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_blend;
#[cfg(test)]
mod tests_bulging;
#[cfg(test)]
mod tests_family;
#[cfg(test)]
mod tests_schemes;

use crate::geometry::Cage;
pub use blend::{blended_pose, deform_blended, BlendedPose, MAX_BLEND};
pub use columns::{
    column_count, column_displacements, column_moves, identity_blocks, rest_columns,
    SomiglianaCage, BLOCK_COLUMNS,
};
pub use fit::SimilarityFit;
use glam::{DMat3, DVec3};
use rayon::prelude::*;
use triangle::{Material, TriangleFrame};

/// The Poisson ratio used when none is given.
pub const DEFAULT_POISSON_RATIO: f64 = 0.0;
/// The open range of Poisson ratios accepted: at −1 the face term vanishes, at ½
/// it diverges (incompressible material).
pub const POISSON_RATIO_RANGE: (f64, f64) = (-1.0, 0.5);

/// The family's Poisson ratio setting ν, to a thousandth: −0.999 (auxetic) to
/// 0.499 (at −1 the face term vanishes, at ½ it diverges), held as thousandths
/// above a zero of 1000.
pub const POISSON_RATIO_SETTING: super::ParameterSpec = super::ParameterSpec {
    key: super::Parameter::PoissonRatio,
    label: "Poisson ratio",
    flag: "--poisson-ratio",
    choices: &[500, 1000, 1250, 1300, 1400, 1450],
    default: POISSON_RATIO_ZERO + (DEFAULT_POISSON_RATIO * 1000.0) as u32,
    min: POISSON_RATIO_ZERO - 999,
    max: POISSON_RATIO_ZERO + 499,
    named: &[],
    format: |value| {
        format!(
            "ν {}",
            super::family::signed_decimal(value.into(), POISSON_RATIO_ZERO, 1000)
        )
    },
    scale: 1000,
    zero: POISSON_RATIO_ZERO,
};

/// The held value of ν = 0 in [`POISSON_RATIO_SETTING`].
const POISSON_RATIO_ZERO: u32 = 1000;

/// The largest bulging γ accepted: the normal stretch grows as exp(γ² V_f / V),
/// and past 10 a triangle that sweeps a few percent of the cage's volume
/// already pushes tens of times harder than the rest.
pub const MAX_BULGING: f64 = 10.0;

/// The bulging γ of the deformation (`bulging.rs`), to a hundredth: 0 (none,
/// the default) to [`MAX_BULGING`]. Read when the weights deform a pose, not
/// when they are bound: changing it binds nothing again.
pub const BULGING_SETTING: super::ParameterSpec = super::ParameterSpec {
    key: super::Parameter::Bulging,
    label: "Bulging γ",
    flag: "--bulging",
    choices: &[0, 100, 200, 400, 800],
    default: 0,
    min: 0,
    max: (MAX_BULGING * 100.0) as u32,
    named: &[],
    format: |value| format!("γ {}", super::family::decimal(value.into(), 100)),
    scale: 100,
    zero: 0,
};

/// The local/global blend of the deformation (`blend.rs`), to a hundredth: 0
/// (the global variant, the default) to 1 (the local variant: each triangle
/// and vertex turns and stretches with its own frame). Read when the weights
/// deform a pose, as bulging is.
pub const LOCAL_BLEND_SETTING: super::ParameterSpec = super::ParameterSpec {
    key: super::Parameter::LocalBlend,
    label: "Local blend",
    flag: "--local-blend",
    choices: &[0, 25, 50, 75, 100],
    default: 0,
    min: 0,
    max: (blend::MAX_BLEND * 100.0) as u32,
    named: &[],
    format: |value| format!("local blend {}", super::family::decimal(value.into(), 100)),
    scale: 100,
    zero: 0,
};

/// Check that `bulging` is usable: finite, 0 to [`MAX_BULGING`].
pub fn validate_bulging(bulging: f64) -> Result<f64, SomiglianaError> {
    if (0.0..=MAX_BULGING).contains(&bulging) {
        Ok(bulging)
    } else {
        Err(SomiglianaError::Bulging { value: bulging })
    }
}

/// What can go wrong computing or applying Somigliana blocks.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SomiglianaError {
    #[error("the Poisson ratio must lie strictly between −1 and 0.5, got {value}")]
    PoissonRatio { value: f64 },
    #[error("the bulging γ must be 0 to {MAX_BULGING}, got {value}")]
    Bulging { value: f64 },
    #[error("the blend must be 0 (global) to 1 (local), got {value}")]
    Blend { value: f64 },
    #[error("point {index} is not finite")]
    NonFinitePoint { index: usize },
    #[error("deformed cage vertex {index} is not finite")]
    NonFinitePosition { index: usize },
    #[error("the cage has {expected} vertices but {actual} deformed positions were given")]
    PositionCount { expected: usize, actual: usize },
    #[error("the blocks were computed for a cage of {expected_vertices} vertices and {expected_triangles} triangles, not {actual_vertices} and {actual_triangles}")]
    CageMismatch {
        expected_vertices: usize,
        expected_triangles: usize,
        actual_vertices: usize,
        actual_triangles: usize,
    },
}

/// Check that `poisson_ratio` is usable: finite and strictly inside
/// [`POISSON_RATIO_RANGE`].
pub fn validate_poisson_ratio(poisson_ratio: f64) -> Result<f64, SomiglianaError> {
    let (low, high) = POISSON_RATIO_RANGE;
    if poisson_ratio.is_finite() && poisson_ratio > low && poisson_ratio < high {
        Ok(poisson_ratio)
    } else {
        Err(SomiglianaError::PoissonRatio {
            value: poisson_ratio,
        })
    }
}

/// The blocks of many points: point-major, `vertex_count` vertex blocks and
/// `triangle_count` face blocks per point. Rows of a block are the output's
/// components, columns the input's.
#[derive(Clone, Debug, PartialEq)]
pub struct SomiglianaBlocks {
    poisson_ratio: f64,
    point_count: usize,
    vertex_count: usize,
    triangle_count: usize,
    vertex: Vec<DMat3>,
    face: Vec<DMat3>,
}

impl SomiglianaBlocks {
    pub fn poisson_ratio(&self) -> f64 {
        self.poisson_ratio
    }

    pub fn point_count(&self) -> usize {
        self.point_count
    }

    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// Point `point`'s blocks for every cage vertex, in vertex order.
    pub fn vertex_blocks(&self, point: usize) -> &[DMat3] {
        &self.vertex[point * self.vertex_count..(point + 1) * self.vertex_count]
    }

    /// Point `point`'s blocks for every cage triangle, in [`Cage::triangles`] order.
    pub fn face_blocks(&self, point: usize) -> &[DMat3] {
        &self.face[point * self.triangle_count..(point + 1) * self.triangle_count]
    }
}

/// Rows per parallel task: fewer than the other binds' 32, as a row here costs
/// adaptive quadrature over every triangle.
const ROWS_PER_TASK: usize = 8;

/// The Somigliana blocks of `points` with respect to `cage`, in parallel over
/// points.
pub fn somigliana_blocks(
    points: &[DVec3],
    cage: &Cage,
    poisson_ratio: f64,
) -> Result<SomiglianaBlocks, SomiglianaError> {
    let poisson_ratio = validate_poisson_ratio(poisson_ratio)?;
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(SomiglianaError::NonFinitePoint { index });
    }
    let material = Material::new(poisson_ratio);
    let frames: Vec<TriangleFrame> = (0..cage.triangle_count())
        .map(|t| TriangleFrame::new(cage.triangle(t)))
        .collect();
    let (vertex_count, triangle_count) = (cage.vertex_count(), cage.triangle_count());
    let mut vertex = vec![DMat3::ZERO; points.len() * vertex_count];
    let mut face = vec![DMat3::ZERO; points.len() * triangle_count];
    if vertex_count > 0 && triangle_count > 0 {
        vertex
            .par_chunks_mut(vertex_count * ROWS_PER_TASK)
            .zip(face.par_chunks_mut(triangle_count * ROWS_PER_TASK))
            .zip(points.par_chunks(ROWS_PER_TASK))
            .for_each(|((vertex_rows, face_rows), block_points)| {
                let rows = vertex_rows
                    .chunks_mut(vertex_count)
                    .zip(face_rows.chunks_mut(triangle_count));
                for ((vertex_row, face_row), &x) in rows.zip(block_points) {
                    for ((frame, corners), face_block) in
                        frames.iter().zip(cage.triangles()).zip(face_row.iter_mut())
                    {
                        let blocks = frame.blocks(x, &material);
                        for (&corner, block) in corners.iter().zip(blocks.vertex) {
                            vertex_row[corner as usize] += block;
                        }
                        *face_block = blocks.face;
                    }
                }
            });
    }
    Ok(SomiglianaBlocks {
        poisson_ratio,
        point_count: points.len(),
        vertex_count,
        triangle_count,
        vertex,
        face,
    })
}

/// The similarity `deformed ≈ s R rest + t` of the global variant: least squares
/// over the cage vertices, equally weighted (Umeyama), a proper rotation.
pub fn fit_similarity(
    rest: &Cage,
    deformed_positions: &[DVec3],
) -> Result<SimilarityFit, SomiglianaError> {
    check_positions(rest, deformed_positions)?;
    Ok(fit::fit_similarity(rest.positions(), deformed_positions))
}

fn check_positions(rest: &Cage, positions: &[DVec3]) -> Result<(), SomiglianaError> {
    if positions.len() != rest.vertex_count() {
        return Err(SomiglianaError::PositionCount {
            expected: rest.vertex_count(),
            actual: positions.len(),
        });
    }
    match positions.iter().position(|p| !p.is_finite()) {
        Some(index) => Err(SomiglianaError::NonFinitePosition { index }),
        None => Ok(()),
    }
}

/// Every point of `blocks` moved by the cage deformed from `rest` to
/// `deformed_positions`, by the global variant of the module doc with bulging
/// γ `bulging` (0: none; see [`BULGING_SETTING`]).
pub fn deform(
    blocks: &SomiglianaBlocks,
    rest: &Cage,
    deformed_positions: &[DVec3],
    bulging: f64,
) -> Result<Vec<DVec3>, SomiglianaError> {
    if rest.vertex_count() != blocks.vertex_count || rest.triangle_count() != blocks.triangle_count
    {
        return Err(SomiglianaError::CageMismatch {
            expected_vertices: blocks.vertex_count,
            expected_triangles: blocks.triangle_count,
            actual_vertices: rest.vertex_count(),
            actual_triangles: rest.triangle_count(),
        });
    }
    let fit = fit_similarity(rest, deformed_positions)?;
    // About the deformed centroid (Σ Bᵥ = I inside), so that a cage far from the
    // origin loses no digits to the blocks' rounding.
    let centre = deformed_positions.iter().sum::<DVec3>() / deformed_positions.len().max(1) as f64;
    let unrotated: Vec<DVec3> = deformed_positions
        .iter()
        .map(|&p| fit.rotation.transpose() * (p - centre))
        .collect();
    // Each triangle's traction, per unit of the face block's constant.
    let tractions = bulging::face_tractions(
        rest,
        deformed_positions,
        &fit,
        blocks.poisson_ratio,
        validate_bulging(bulging)?,
    );
    let face_vectors: Vec<DVec3> = (0..rest.triangle_count())
        .zip(tractions)
        .map(|(t, traction)| traction * rest.unit_normal(t))
        .collect();
    Ok((0..blocks.point_count)
        .into_par_iter()
        .map(|point| {
            let from_vertices: DVec3 = (blocks.vertex_blocks(point).iter())
                .zip(&unrotated)
                .map(|(block, &p)| *block * p)
                .sum();
            let from_faces: DVec3 = (blocks.face_blocks(point).iter())
                .zip(&face_vectors)
                .map(|(block, &f)| *block * f)
                .sum();
            centre + fit.rotation * (from_vertices + from_faces)
        })
        .collect())
}

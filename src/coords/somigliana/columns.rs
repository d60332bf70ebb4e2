//! Somigliana coordinates as a weights matrix: each 3×3 block expanded into 9
//! scalar columns, 9 per cage vertex then 9 per cage triangle, entry (a, b) of
//! a block at offset `3a + b`. Column (v, a, b) multiplies the vector
//! `(Rᵀ (vᵥ' − c'))_b R e_a + c'_b e_a` (c' the pose's vertex centroid) and
//! column (f, a, b) the vector `t_f (n_f)_b R e_a`, with s R the similarity
//! fitted to the pose and t_f the triangle's traction (s without bulging,
//! `bulging.rs`), so that `Σ wₖ cₖ'` is the global deformation of
//! [`super::deform`] about c' (inside, where Σ Bᵥ = I).

use super::triangle::{Material, TriangleFrame};
use super::{blend, bulging, check_positions, fit, validate_poisson_ratio, SomiglianaError};
use crate::coords::ColumnMoves;
use crate::geometry::Cage;
use glam::{DMat3, DVec3};

/// Scalar columns per block.
pub const BLOCK_COLUMNS: usize = 9;

/// How far from the identity Σ Bᵥ may be before a point counts as not inside
/// (numerically on the surface or outside): the blocks there are the exterior
/// value or lose digits.
const INSIDE_TOLERANCE: f64 = 1e-3;

/// Weights columns of a cage: 9 per vertex and per triangle.
pub fn column_count(cage: &Cage) -> usize {
    BLOCK_COLUMNS * (cage.vertex_count() + cage.triangle_count())
}

/// A cage prepared for rows of blocks at one Poisson ratio.
#[derive(Clone, Debug)]
pub struct SomiglianaCage {
    material: Material,
    frames: Vec<TriangleFrame>,
    triangles: Vec<[u32; 3]>,
    vertex_count: usize,
}

impl SomiglianaCage {
    pub fn new(cage: &Cage, poisson_ratio: f64) -> Result<Self, SomiglianaError> {
        let material = Material::new(validate_poisson_ratio(poisson_ratio)?);
        Ok(Self {
            material,
            frames: (0..cage.triangle_count())
                .map(|t| TriangleFrame::new(cage.triangle(t)))
                .collect(),
            triangles: cage.triangles().to_vec(),
            vertex_count: cage.vertex_count(),
        })
    }

    /// The blocks of `x` into `out` ([`column_count`] values). False, with
    /// `out` unspecified, where Σ Bᵥ is not the identity: `x` is not inside.
    pub fn row(&self, x: DVec3, out: &mut [f64]) -> bool {
        out.fill(0.0);
        let (vertices, faces) = out.split_at_mut(BLOCK_COLUMNS * self.vertex_count);
        let mut total = DMat3::ZERO;
        for ((frame, corners), face) in self
            .frames
            .iter()
            .zip(&self.triangles)
            .zip(faces.chunks_mut(BLOCK_COLUMNS))
        {
            let blocks = frame.blocks(x, &self.material);
            for (&corner, block) in corners.iter().zip(blocks.vertex) {
                let start = BLOCK_COLUMNS * corner as usize;
                add_block(&mut vertices[start..start + BLOCK_COLUMNS], block);
                total += block;
            }
            add_block(face, blocks.face);
        }
        let error = (total - DMat3::IDENTITY).to_cols_array();
        x.is_finite() && error.iter().all(|e| e.abs() <= INSIDE_TOLERANCE)
    }
}

/// `out[3a + b] += block[a][b]` (row a, column b).
fn add_block(out: &mut [f64], block: DMat3) {
    for a in 0..3 {
        for b in 0..3 {
            out[3 * a + b] += block.col(b)[a];
        }
    }
}

/// The row of scalar weights λ as blocks λᵥ I (no face term): `Σ λᵥ vᵥ'`, the
/// deformation of the family λ comes from, whatever the pose's rotation.
pub fn identity_blocks(lambda: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for (block, &weight) in out.chunks_mut(BLOCK_COLUMNS).zip(lambda) {
        for a in 0..3 {
            block[4 * a] = weight;
        }
    }
}

/// Every column's vector for rotation `rotation` and the faces' tractions, less
/// `(vᵥ − c)_b e_a` for a vertex's (less nothing for a face's), where
/// `centred[v]` is `Rᵀ (vᵥ' − c')` and `shift` is `c' − c`. Centred, so a cage
/// far from the origin loses no digits to the weights' f32 rounding.
fn global_columns(
    rest: &Cage,
    rotation: DMat3,
    tractions: &[f64],
    centred: &[DVec3],
    shift: DVec3,
) -> Vec<DVec3> {
    let mut columns = Vec::with_capacity(column_count(rest));
    let centre = centroid(rest.positions());
    for (&centred, &position) in centred.iter().zip(rest.positions()) {
        let before = position - centre;
        for a in 0..3 {
            for b in 0..3 {
                let axis = DVec3::AXES[a];
                columns.push(centred[b] * rotation.col(a) + (shift[b] - before[b]) * axis);
            }
        }
    }
    for (t, &traction) in tractions.iter().enumerate() {
        let normal = rest.unit_normal(t);
        for a in 0..3 {
            for b in 0..3 {
                columns.push(traction * normal[b] * rotation.col(a));
            }
        }
    }
    columns
}

fn centroid(points: &[DVec3]) -> DVec3 {
    points.iter().sum::<DVec3>() / points.len().max(1) as f64
}

/// Each column's vector at rest: `(vᵥ)_b e_a`, then `(n_f)_b e_a`.
pub fn rest_columns(rest: &Cage) -> Vec<DVec3> {
    let mut columns = Vec::with_capacity(column_count(rest));
    for &position in rest.positions() {
        for a in 0..3 {
            for b in 0..3 {
                columns.push(position[b] * DVec3::AXES[a]);
            }
        }
    }
    let unit = vec![1.0; rest.triangle_count()];
    let faces = global_columns(rest, DMat3::IDENTITY, &unit, &[], DVec3::ZERO);
    columns.extend(faces);
    columns
}

/// Each column's vector in `pose` less its rest vector (the displacement
/// form), for weights bound at `poisson_ratio` and deformed with bulging γ
/// `bulging` (0: none). A pose of the wrong length or not finite moves nothing.
pub fn column_displacements(
    rest: &Cage,
    pose: &[DVec3],
    poisson_ratio: f64,
    bulging: f64,
) -> Vec<DVec3> {
    if check_positions(rest, pose).is_err() {
        return vec![DVec3::ZERO; column_count(rest)];
    }
    let similarity = fit::fit_similarity(rest.positions(), pose);
    let (rotation, centre) = (similarity.rotation, centroid(pose));
    let centred: Vec<DVec3> = pose
        .iter()
        .map(|&p| rotation.transpose() * (p - centre))
        .collect();
    let shift = centre - centroid(rest.positions());
    let tractions = bulging::face_tractions(rest, pose, &similarity, poisson_ratio, bulging);
    let mut moves = global_columns(rest, rotation, &tractions, &centred, shift);
    // The faces' vectors less their rest vectors.
    let vertex_columns = BLOCK_COLUMNS * rest.vertex_count();
    let rested = rest_columns(rest);
    for (moved, rested) in moves[vertex_columns..]
        .iter_mut()
        .zip(&rested[vertex_columns..])
    {
        *moved -= *rested;
    }
    moves
}

/// How each column moves in `pose` with the local blend `local_blend` (0: the
/// global variant, linear: [`column_displacements`]; past 0 the normalised
/// form of [`ColumnMoves`], about the rest cage's centroid o), for weights bound
/// at `poisson_ratio` and deformed with bulging γ `bulging`. With Rᵥ, R_f and
/// t_f the blended rotations and tractions (`blend.rs`), column (v, a, b) has
/// the matrix `(Rᵥ e_a)(Rᵥ e_b)ᵀ − e_a e_bᵀ` and the vector `(Rᵥ e_a)(Rᵥ e_b)·(vᵥ'
/// − o) − (vᵥ − o)_b e_a`, column (f, a, b) no matrix and the vector `t_f (n_f)_b
/// R_f e_a − (n_f)_b e_a`; their blend is `x' = o + A⁻¹ (Σ Rᵥ Bᵥ Rᵥᵀ (vᵥ' − o) + Σ
/// t_f R_f F_f n_f)` with `A = Σ Rᵥ Bᵥ Rᵥᵀ` ([`super::deform_blended`]).
pub fn column_moves(
    rest: &Cage,
    pose: &[DVec3],
    poisson_ratio: f64,
    bulging: f64,
    local_blend: f64,
) -> ColumnMoves {
    if local_blend <= 0.0 || !local_blend.is_finite() || check_positions(rest, pose).is_err() {
        return ColumnMoves::linear(column_displacements(rest, pose, poisson_ratio, bulging));
    }
    let blend = local_blend.min(blend::MAX_BLEND);
    let posed = blend::blended_pose(rest, pose, poisson_ratio, bulging, blend);
    let origin = centroid(rest.positions());
    let outer = |u: DVec3, w: DVec3| DMat3::from_cols(u * w.x, u * w.y, u * w.z);
    let count = column_count(rest);
    let (mut vectors, mut matrices) = (Vec::with_capacity(count), Vec::with_capacity(count));
    let vertices = (rest.positions().iter().zip(pose)).zip(&posed.vertex_rotations);
    for ((&before, &after), rotation) in vertices {
        for a in 0..3 {
            for b in 0..3 {
                let (turned_a, turned_b) = (rotation.col(a), rotation.col(b));
                let (axis_a, axis_b) = (DVec3::AXES[a], DVec3::AXES[b]);
                matrices.push(outer(turned_a, turned_b) - outer(axis_a, axis_b));
                vectors
                    .push(turned_a * turned_b.dot(after - origin) - axis_a * (before - origin)[b]);
            }
        }
    }
    for (t, (&traction, rotation)) in posed
        .tractions
        .iter()
        .zip(&posed.face_rotations)
        .enumerate()
    {
        let normal = rest.unit_normal(t);
        for a in 0..3 {
            for b in 0..3 {
                matrices.push(DMat3::ZERO);
                vectors.push(normal[b] * (traction * rotation.col(a) - DVec3::AXES[a]));
            }
        }
    }
    ColumnMoves::normalised(origin, vectors, matrices)
}

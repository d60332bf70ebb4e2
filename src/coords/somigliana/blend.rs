//! The paper's local/global blend: rotations and stretches per cage triangle
//! and vertex, blended by `blend` between the fitted similarity's (0, the
//! global variant) and each triangle's own (1, the local variant).
//!
//! - Triangle f's own rotation `r_f` takes its rest frame (first edge, the
//!   normal cross it, the normal) to its posed frame; its blended rotation is
//!   `R_f = R exp(b log(Rᵀ r_f))`, the rotation vector scaled by the blend
//!   (along the geodesic from R).
//! - Vertex v's rotation averages its triangles' rotation vectors, weighted by
//!   rest area: `Rᵥ = R exp(Σ A_f log(Rᵀ R_f) / Σ A_f)`.
//!
//! The authors' code blends and averages Cayley parameters `(I − M)(I +
//! M)⁻¹` instead: the same at 0 and 1 and to second order in the angle, but
//! unbounded towards a half turn, so that one triangle folded over by a pose
//! (a finger tip corner pulled past its neighbour) sent whole fingers of the
//! comb off by hundreds of cage sizes; rotation vectors stay within π.
//! - Triangle f's stretch along the surface is `b σ̄_f + (1 − b) s`, σ̄_f the mean
//!   singular value of its tangent map unrotated by R_f (`½ √(‖T‖² + 2 A'/A)`,
//!   the area ratio for det T); along the normal, as
//!   the bulging term says (`bulging.rs`), and its traction pushes along
//!   `R_f n_f`, projected onto zero net force.
//! - The point is `x' = c' + A⁻¹ (Σ Rᵥ Bᵥ Rᵥᵀ (vᵥ' − c') + Σ t_f R_f F_f n_f)`
//!   with `A = Σ Rᵥ Bᵥ Rᵥᵀ`, which is I when every Rᵥ is R.
//!
//! A depends on the point, so this is no weighted sum of per-column vectors:
//! `columns::column_moves` writes it in the normalised form of
//! [`crate::coords::ColumnMoves`], which every consumer applies.

use super::bulging::{swept_volume, without_net_force_along};
use super::{check_positions, fit, validate_bulging, SomiglianaBlocks, SomiglianaError};
use crate::geometry::Cage;
use glam::{DMat2, DMat3, DQuat, DVec2, DVec3};
use rayon::prelude::*;

/// The largest blend: 1, the local variant.
pub const MAX_BLEND: f64 = 1.0;

/// What the blended deformation needs of a pose.
#[derive(Clone, Debug)]
pub struct BlendedPose {
    pub vertex_rotations: Vec<DMat3>,
    pub face_rotations: Vec<DMat3>,
    /// Each triangle's traction per unit of the face blocks' constant.
    pub tractions: Vec<f64>,
    /// The posed cage's vertex centroid.
    pub centre: DVec3,
}

/// A rotation's rotation vector (axis times angle, the angle 0 to π): the
/// logarithm, bounded where the authors' Cayley map `(I − R)(I + R)⁻¹` grows
/// without bound towards a half turn, so that one folded triangle cannot
/// swamp its vertices' averages.
fn rotation_vector(rotation: DMat3) -> DVec3 {
    let quat = DQuat::from_mat3(&rotation).normalize();
    let quat = if quat.w < 0.0 { -quat } else { quat };
    let sine = quat.xyz().length();
    if sine < 1e-300 {
        return DVec3::ZERO;
    }
    quat.xyz() * (2.0 * sine.atan2(quat.w) / sine)
}

/// The rotation of a rotation vector: the exponential.
fn rotation_of(vector: DVec3) -> DMat3 {
    DMat3::from_quat(DQuat::from_scaled_axis(vector))
}

/// A triangle's frame: its first edge, the normal cross it, the normal.
fn frame(a: DVec3, b: DVec3, c: DVec3) -> DMat3 {
    let edge = (b - a).normalize_or_zero();
    let normal = (b - a).cross(c - a).normalize_or_zero();
    DMat3::from_cols(edge, normal.cross(edge), normal)
}

/// The 2×2 coordinates of a triangle's two edges in the first two axes of `frame`.
fn tangent_edges(frame: DMat3, a: DVec3, b: DVec3, c: DVec3) -> DMat2 {
    let local = |e: DVec3| DVec2::new(frame.col(0).dot(e), frame.col(1).dot(e));
    DMat2::from_cols(local(b - a), local(c - a))
}

/// The rotations, stretches and tractions of `pose` at blend `blend` (0 to 1)
/// and bulging `bulging`, for weights bound at `poisson_ratio`. `pose` has one
/// finite position per cage vertex (the caller checks).
pub fn blended_pose(
    rest: &Cage,
    pose: &[DVec3],
    poisson_ratio: f64,
    bulging: f64,
    blend: f64,
) -> BlendedPose {
    let fit = fit::fit_similarity(rest.positions(), pose);
    let (rotation, scale) = (fit.rotation, fit.scale);
    let count = rest.vertex_count().max(1) as f64;
    let rest_centre = rest.positions().iter().sum::<DVec3>() / count;
    let centre = pose.iter().sum::<DVec3>() / count;
    let fitted = |v: usize| centre + scale * (rotation * (rest.positions()[v] - rest_centre));
    let volume = rest.signed_volume().abs();
    let triangles = rest.triangles();
    let mut face_rotations = Vec::with_capacity(triangles.len());
    let mut tractions = Vec::with_capacity(triangles.len());
    let mut areas = Vec::with_capacity(triangles.len());
    for &[i, j, k] in triangles {
        let (i, j, k) = (i as usize, j as usize, k as usize);
        let [a, b, c] = [i, j, k].map(|v| rest.positions()[v]);
        let [pa, pb, pc] = [i, j, k].map(|v| pose[v]);
        let rest_frame = frame(a, b, c);
        let own = frame(pa, pb, pc) * rest_frame.transpose();
        let face_rotation = if blend == 0.0 {
            rotation
        } else {
            rotation * rotation_of(rotation_vector(rotation.transpose() * own) * blend)
        };
        // The tangent map with the triangle's rotation taken out.
        let unrotated = |p: DVec3| face_rotation.transpose() * p;
        let posed_edges = tangent_edges(rest_frame, unrotated(pa), unrotated(pb), unrotated(pc));
        let tangent = posed_edges * tangent_edges(rest_frame, a, b, c).inverse();
        // ½ √(‖T‖² + 2 det T) is the mean of T's singular values; the area ratio
        // stands for det T, as in the authors' code, so a triangle tilted out of
        // its blended plane is not shrunk by the projection.
        let squares = tangent.x_axis.length_squared() + tangent.y_axis.length_squared();
        let area_ratio = (pb - pa).cross(pc - pa).length() / (b - a).cross(c - a).length();
        let mean_singular = 0.5 * (squares + 2.0 * area_ratio).max(0.0).sqrt();
        let stretch = blend * mean_singular + (1.0 - blend) * scale;
        let normal_stretch = if bulging == 0.0 || volume <= 0.0 {
            stretch
        } else {
            let swept = swept_volume([pa, pb, pc], [fitted(i), fitted(j), fitted(k)]);
            stretch * (bulging * bulging * swept / volume).exp()
        };
        tractions.push(
            (normal_stretch * (1.0 - poisson_ratio) + 2.0 * poisson_ratio * stretch)
                / (1.0 + poisson_ratio),
        );
        face_rotations.push(face_rotation);
        areas.push((b - a).cross(c - a).length() / 2.0);
    }
    // Pushed along each triangle's own rotated normal: project onto zero net
    // force along those.
    let directions: Vec<DVec3> = (0..triangles.len())
        .map(|t| face_rotations[t] * rest.unit_normal(t))
        .collect();
    if bulging != 0.0 || blend != 0.0 {
        without_net_force_along(&areas, &directions, &mut tractions);
    }
    let mut parameters = vec![DVec3::ZERO; rest.vertex_count()];
    let mut weights = vec![0.0; rest.vertex_count()];
    for ((corners, face_rotation), &area) in triangles.iter().zip(&face_rotations).zip(&areas) {
        let parameter = rotation_vector(rotation.transpose() * *face_rotation);
        for &v in corners {
            parameters[v as usize] += parameter * area;
            weights[v as usize] += area;
        }
    }
    let vertex_rotations = parameters
        .iter()
        .zip(&weights)
        .map(|(&sum, &weight)| match blend == 0.0 || weight <= 0.0 {
            true => rotation,
            false => rotation * rotation_of(sum / weight),
        })
        .collect();
    BlendedPose {
        vertex_rotations,
        face_rotations,
        tractions,
        centre,
    }
}

/// Every point of `blocks` moved by the cage posed as `deformed_positions`,
/// with the blend `blend` (0: the global variant of [`super::deform`], 1: the
/// local one) and bulging γ `bulging`.
pub fn deform_blended(
    blocks: &SomiglianaBlocks,
    rest: &Cage,
    deformed_positions: &[DVec3],
    bulging: f64,
    blend: f64,
) -> Result<Vec<DVec3>, SomiglianaError> {
    check_positions(rest, deformed_positions)?;
    let bulging = validate_bulging(bulging)?;
    if !(0.0..=MAX_BLEND).contains(&blend) {
        return Err(SomiglianaError::Blend { value: blend });
    }
    if rest.vertex_count() != blocks.vertex_count()
        || rest.triangle_count() != blocks.triangle_count()
    {
        return Err(SomiglianaError::CageMismatch {
            expected_vertices: blocks.vertex_count(),
            expected_triangles: blocks.triangle_count(),
            actual_vertices: rest.vertex_count(),
            actual_triangles: rest.triangle_count(),
        });
    }
    let posed = blended_pose(
        rest,
        deformed_positions,
        blocks.poisson_ratio(),
        bulging,
        blend,
    );
    let centred: Vec<DVec3> = deformed_positions
        .iter()
        .map(|&p| p - posed.centre)
        .collect();
    let face_vectors: Vec<DVec3> = (0..rest.triangle_count())
        .map(|t| posed.tractions[t] * rest.unit_normal(t))
        .collect();
    Ok((0..blocks.point_count())
        .into_par_iter()
        .map(|point| {
            let mut matrix = DMat3::ZERO;
            let mut sum = DVec3::ZERO;
            let vertices = blocks
                .vertex_blocks(point)
                .iter()
                .zip(&posed.vertex_rotations);
            for ((block, rotation), &p) in vertices.zip(&centred) {
                let turned = *rotation * *block * rotation.transpose();
                matrix += turned;
                sum += turned * p;
            }
            let faces = blocks.face_blocks(point).iter().zip(&posed.face_rotations);
            for ((block, rotation), &f) in faces.zip(&face_vectors) {
                sum += *rotation * (*block * f);
            }
            posed.centre + matrix.inverse() * sum
        })
        .collect())
}

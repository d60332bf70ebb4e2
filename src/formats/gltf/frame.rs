//! The frame a glTF export's positions are written in: the source node's
//! transform kept on the node, so that an import lands where the original
//! was, and a point near the mesh as a further translation where the mesh is
//! far from its node's origin, so that the f32 positions keep their precision.

use super::super::MeshFile;
use crate::geometry::bounds_of;
use glam::{DMat3, DMat4, DQuat, DVec3, Vec3};

/// The node's transform as glTF writes it (f32 TRS), and the map from the
/// positions given (the world's) to those written.
pub(super) struct Frame {
    pub translation: Vec3,
    /// x, y, z, w.
    pub rotation: [f32; 4],
    pub scale: Vec3,
    /// Written from given: `inverse_linear · (p − world_translation)`.
    inverse_linear: DMat3,
    world_translation: DVec3,
    /// The node's transform mirrors: triangles are written in the source's
    /// winding, and normals flipped with it.
    pub mirrored: bool,
}

impl Frame {
    /// The frame for `base` (world positions) read through `file`'s node.
    /// A node transform that is not translation, rotation and scale (a shear,
    /// which glTF's animated nodes cannot hold) or not invertible is baked
    /// into the positions instead, as it is for a mesh from no glTF.
    pub(super) fn of(file: &MeshFile, base: &[DVec3]) -> Frame {
        let (scale, rotation, translation) = file.node_transform.and_then(trs_of).unwrap_or((
            DVec3::ONE,
            DQuat::IDENTITY,
            DVec3::ZERO,
        ));
        let node = f32_trs(scale, rotation, translation);
        let node_matrix = node.matrix();
        let local: Vec<DVec3> = base
            .iter()
            .map(|&p| node.inverse_linear * (p - node.world_translation))
            .collect();
        // A point near the mesh in the node's frame, moved to where the node puts it.
        let origin = origin_of(&local);
        let translation = node_matrix.transform_point3(origin);
        f32_trs(scale, rotation, translation)
    }

    /// Where `p` (given) is written.
    pub(super) fn point(&self, p: DVec3) -> DVec3 {
        self.inverse_linear * (p - self.world_translation)
    }

    /// A difference of two given positions, as written.
    pub(super) fn vector(&self, v: DVec3) -> DVec3 {
        self.inverse_linear * v
    }

    fn quat(&self) -> DQuat {
        quat_of(self.rotation)
    }

    /// The transform a reader builds from the node's numbers.
    fn matrix(&self) -> DMat4 {
        DMat4::from_scale_rotation_translation(
            self.scale.as_dvec3(),
            self.quat(),
            self.translation.as_dvec3(),
        )
    }
}

/// A quaternion as the reader takes it: normalized in f64.
fn quat_of(rotation: [f32; 4]) -> DQuat {
    let q = DQuat::from_array(rotation.map(f64::from));
    let length = q.length();
    if length.is_normal() {
        q / length
    } else {
        DQuat::IDENTITY
    }
}

/// The frame of the node with these values, rounded to f32 as written.
fn f32_trs(scale: DVec3, rotation: DQuat, translation: DVec3) -> Frame {
    let scale32 = scale.as_vec3();
    let rotation32 = rotation.as_quat().to_array();
    let translation32 = translation.as_vec3();
    let linear = DMat3::from_quat(quat_of(rotation32)) * DMat3::from_diagonal(scale32.as_dvec3());
    Frame {
        translation: translation32,
        rotation: rotation32,
        scale: scale32,
        inverse_linear: linear.inverse(),
        world_translation: translation32.as_dvec3(),
        mirrored: linear.determinant() < 0.0,
    }
}

/// `matrix` as scale, rotation and translation, when it is one (within
/// rounding) and can be inverted.
fn trs_of(matrix: DMat4) -> Option<(DVec3, DQuat, DVec3)> {
    if !matrix.is_finite() {
        return None;
    }
    let (scale, rotation, translation) = matrix.to_scale_rotation_translation();
    let smallest = scale.abs().min_element();
    if !(smallest.is_normal() && rotation.is_finite()) {
        return None;
    }
    let again = DMat4::from_scale_rotation_translation(scale, rotation, translation);
    let size = matrix
        .to_cols_array()
        .iter()
        .fold(1.0f64, |m, v| m.max(v.abs()));
    let worst = (again - matrix)
        .to_cols_array()
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    (worst <= 1e-9 * size).then_some((scale, rotation, translation))
}

/// The point the positions are written relative to: their bounding-box
/// centre rounded to a multiple of the power of two at or above its diagonal,
/// then to f32, so 0 for a mesh around the origin.
fn origin_of(positions: &[DVec3]) -> DVec3 {
    let (low, high) = bounds_of(positions);
    let diagonal = (high - low).length();
    let step = diagonal.max(f64::MIN_POSITIVE).log2().ceil().exp2();
    let rounded = ((low + high) * 0.5 / step).round() * step;
    rounded.as_vec3().as_dvec3()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shear_is_no_node_transform_and_a_mirror_is_one() {
        let shear = DMat4::from_cols_array(&[
            1.0, 0.0, 0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        ]);
        assert!(trs_of(shear).is_none());
        let mirror = DMat4::from_scale(DVec3::new(-1.0, 2.0, 1.0));
        let (scale, _, _) = trs_of(mirror).unwrap();
        assert!((scale.x * scale.y * scale.z + 2.0).abs() < 1e-12);
        let frame = f32_trs(scale, DQuat::IDENTITY, DVec3::ZERO);
        assert!(frame.mirrored);
    }
}

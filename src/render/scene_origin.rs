//! Where the viewport's f32 coordinates are measured from. The GPU draws in
//! f32, whose spacing is 0.0625 at 1e6: a unit sphere uploaded at (1e6, 1e6, 1e6)
//! would lose its shape. So every position the viewport uploads, and the cameras
//! and projections that picking uses, are relative to a scene origin chosen per
//! document near its rest cage, kept in f64 on the CPU (no GPU here).

use glam::{DVec3, Vec3};

/// The translation from scene coordinates (what the GPU and the cameras hold, in
/// f32) to world coordinates (the document's, in f64): `world = scene + world_from_scene`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SceneOrigin {
    pub world_from_scene: DVec3,
}

impl SceneOrigin {
    /// The origin of a scene whose rest cage has `rest_cage` as its positions: the
    /// cage's bounding-box centre, rounded to a multiple of the power of two at or
    /// above its diagonal. Every cage position is then within about a diagonal of
    /// the origin, where f32 keeps about 2⁻²⁴ of the diagonal; and a scene that
    /// already lies around the world origin keeps origin 0, so it is drawn with
    /// exactly the arithmetic it always was.
    pub fn of_cage(rest_cage: &[DVec3]) -> Self {
        if rest_cage.is_empty() {
            return Self::default();
        }
        let (lo, hi) = crate::geometry::bounds_of(rest_cage);
        let centre = (lo + hi) / 2.0;
        let diagonal = (hi - lo).length();
        if !centre.is_finite() || !diagonal.is_finite() {
            return Self::default();
        }
        let step = diagonal.max(f64::MIN_POSITIVE).log2().ceil().exp2();
        Self {
            world_from_scene: (centre / step).round() * step,
        }
    }

    /// A world position in scene coordinates: the difference is taken in f64,
    /// and only then rounded.
    pub fn to_scene(self, world: DVec3) -> Vec3 {
        (world - self.world_from_scene).as_vec3()
    }

    /// A scene position in world coordinates.
    pub fn to_world(self, scene: Vec3) -> DVec3 {
        scene.as_dvec3() + self.world_from_scene
    }

    /// World points in scene coordinates, as the shaders' `vec4<f32>` with `w`.
    pub fn points_to_scene(self, world: &[DVec3], w: f32) -> Vec<[f32; 4]> {
        world
            .iter()
            .map(|&p| self.to_scene(p).extend(w).to_array())
            .collect()
    }

    /// A point in the scene coordinates of `from`, in this origin's: the same
    /// place in the world.
    pub fn rebased_point(self, from: SceneOrigin, scene: Vec3) -> Vec3 {
        self.to_scene(from.to_world(scene))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube_at(centre: DVec3, half: f64) -> Vec<DVec3> {
        (0..8)
            .map(|k| {
                let corner = DVec3::new(
                    if k & 1 == 0 { -half } else { half },
                    if k & 2 == 0 { -half } else { half },
                    if k & 4 == 0 { -half } else { half },
                );
                centre + corner
            })
            .collect()
    }

    #[test]
    fn a_cage_around_the_world_origin_keeps_origin_zero() {
        let origin = SceneOrigin::of_cage(&cube_at(DVec3::new(0.3, -0.2, 0.1), 1.0));
        assert_eq!(origin.world_from_scene, DVec3::ZERO);
    }

    #[test]
    fn a_far_cage_is_drawn_about_a_point_within_a_diagonal() {
        for offset in [1e3, 1e6, 1e7, -6.4e6, 1e12] {
            let centre = DVec3::new(offset, 0.5 * offset, -offset) + DVec3::splat(0.37);
            let cage = cube_at(centre, 1.2);
            let origin = SceneOrigin::of_cage(&cage);
            let diagonal = 2.4 * 3f64.sqrt();
            assert!(
                (origin.world_from_scene - centre).length() <= diagonal,
                "{offset}: {origin:?}"
            );
            // Relative to the origin, f32 keeps the cube's shape.
            for p in &cage {
                let back = origin.to_world(origin.to_scene(*p));
                assert!(
                    (back - *p).length() < 1e-6 * diagonal,
                    "{offset}: {back} {p}"
                );
            }
        }
    }

    #[test]
    fn rebasing_keeps_the_world_point() {
        let from = SceneOrigin {
            world_from_scene: DVec3::new(1e6, 0.0, 0.0),
        };
        let to = SceneOrigin {
            world_from_scene: DVec3::new(1e6 + 8.0, 0.0, 0.0),
        };
        assert_eq!(
            to.rebased_point(from, Vec3::new(1.0, 2.0, 3.0)),
            Vec3::new(-7.0, 2.0, 3.0)
        );
    }
}

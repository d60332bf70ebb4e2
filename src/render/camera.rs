//! An orbit camera (Blender conventions: orbit around a target, pan moves the
//! target in the view plane, zoom moves towards the cursor) and the projections
//! the editor needs for picking and dragging. Cameras live in scene coordinates
//! (relative to the document's [`SceneOrigin`]), as the positions the GPU draws.

use super::scene_origin::SceneOrigin;
use glam::{DVec3, Mat4, Vec2, Vec3, Vec4Swizzles};

/// Vertical field of view.
const FOV_Y: f32 = 40.0 * std::f32::consts::PI / 180.0;

/// The vertical field of view for a viewport of `aspect` (width / height): `FOV_Y`
/// spans the shorter side, so narrow views (side by side) still show the scene.
fn fov_y(aspect: f32) -> f32 {
    if aspect >= 1.0 {
        FOV_Y
    } else {
        2.0 * ((FOV_Y / 2.0).tan() / aspect).atan()
    }
}

/// How far above or below the xz plane a camera may look from.
const PITCH_LIMIT_DEGREES: f32 = 89.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    /// In scene coordinates, except in session files, which hold world ones.
    pub target: Vec3,
    pub distance: f32,
    /// Rotation about the world y axis, radians.
    pub yaw: f32,
    /// Elevation above the xz plane, radians, kept inside ±89°.
    pub pitch: f32,
    /// Parallel projection (Blender's numpad 5): the view at the target's
    /// depth keeps its size, so switching does not jump.
    pub orthographic: bool,
}

impl Default for OrbitCamera {
    fn default() -> Self {
        Self {
            target: Vec3::ZERO,
            distance: 5.0,
            yaw: 0.35,
            pitch: 0.3,
            orthographic: false,
        }
    }
}

impl OrbitCamera {
    /// Unit vector from the target towards the eye.
    fn backward(&self) -> Vec3 {
        let (sin_yaw, cos_yaw) = self.yaw.sin_cos();
        let (sin_pitch, cos_pitch) = self.pitch.sin_cos();
        Vec3::new(cos_pitch * sin_yaw, sin_pitch, cos_pitch * cos_yaw)
    }

    pub fn eye(&self) -> Vec3 {
        self.target + self.backward() * self.distance
    }

    /// Camera right and up vectors (world and scene axes are the same).
    pub fn right_up(&self) -> (Vec3, Vec3) {
        let forward = -self.backward();
        let right = forward.cross(Vec3::Y).normalize_or(Vec3::X);
        (right, right.cross(forward))
    }

    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        let near = (self.distance * 0.01).max(1e-4);
        let far = self.distance * 100.0 + 10.0;
        let aspect = aspect.max(1e-3);
        let view = glam::camera::rh::view::look_at_mat4(self.eye(), self.target, Vec3::Y);
        if self.orthographic {
            // What the perspective shows at the target's depth; depth reaches
            // as far behind the eye as in front, since nothing divides by it.
            let half_height = self.distance * (fov_y(aspect) / 2.0).tan();
            let half_width = half_height * aspect;
            // wgpu's clip space is DirectX's: z in [0, 1], y up.
            return glam::camera::rh::proj::directx::orthographic(
                -half_width,
                half_width,
                -half_height,
                half_height,
                -far,
                far,
            ) * view;
        }
        glam::camera::rh::proj::directx::perspective(fov_y(aspect), aspect, near, far) * view
    }

    /// World units per pixel at `depth` along the view direction, in a viewport
    /// whose shorter side is `short_side_px` (the field of view spans that side).
    pub fn units_per_pixel(&self, depth: f32, short_side_px: f32) -> f32 {
        // A parallel view has one scale at every depth: the target's.
        let depth = if self.orthographic {
            self.distance
        } else {
            depth
        };
        2.0 * depth.max(1e-4) * (FOV_Y / 2.0).tan() / short_side_px.max(1.0)
    }

    /// Depth of `point` along the view direction.
    pub fn depth_of(&self, point: Vec3) -> f32 {
        (point - self.eye()).dot(-self.backward())
    }

    /// Rotate by a mouse motion of `delta` pixels.
    pub fn orbit(&mut self, delta: Vec2) {
        self.look_from(self.yaw - delta.x * 0.008, self.pitch + delta.y * 0.008);
    }

    /// Look from `yaw` and `pitch` (radians), the pitch kept inside ±89° so
    /// that the view's up stays defined; the target and distance stay.
    pub fn look_from(&mut self, yaw: f32, pitch: f32) {
        let limit = PITCH_LIMIT_DEGREES.to_radians();
        self.yaw = yaw;
        self.pitch = pitch.clamp(-limit, limit);
    }

    /// Move the target with the mouse by `delta` pixels in a viewport whose shorter
    /// side is `short_side_px`.
    pub fn pan(&mut self, delta: Vec2, short_side_px: f32) {
        let (right, up) = self.right_up();
        let scale = self.units_per_pixel(self.distance, short_side_px);
        self.target += (-right * delta.x + up * delta.y) * scale;
    }

    /// Zoom by `factor` (< 1 moves in) keeping the point under `cursor_ndc` fixed on
    /// the plane through the target.
    pub fn zoom_towards(&mut self, factor: f32, cursor_ndc: Vec2, aspect: f32) {
        let (right, up) = self.right_up();
        let half_height = self.distance * (fov_y(aspect.max(1e-3)) / 2.0).tan();
        let under_cursor = self.target
            + right * cursor_ndc.x * half_height * aspect
            + up * cursor_ndc.y * half_height;
        self.target += (under_cursor - self.target) * (1.0 - factor);
        self.distance = (self.distance * factor).max(1e-3);
    }

    /// Look at a sphere so that it fills the view's shorter side.
    pub fn frame(&mut self, centre: Vec3, radius: f32) {
        self.target = centre;
        self.distance = radius.max(1e-3) / (FOV_Y / 2.0).sin() * 1.1;
    }
}

/// A projection from scene space to a viewport rectangle in points.
#[derive(Clone, Copy, Debug)]
pub struct ScreenProjection {
    /// From scene coordinates to clip space.
    pub view_projection: Mat4,
    /// Viewport origin and size, in egui points.
    pub origin: Vec2,
    pub size: Vec2,
    /// Where the scene coordinates are measured from.
    pub scene_origin: SceneOrigin,
}

impl ScreenProjection {
    /// Screen position of the world position `point`, or `None` behind the
    /// camera; taken relative to the scene origin in f64 first.
    pub fn project_world(&self, point: DVec3) -> Option<Vec2> {
        self.project(self.scene_origin.to_scene(point))
    }

    /// Screen position of `point` in scene coordinates, or `None` behind the camera.
    pub fn project(&self, point: Vec3) -> Option<Vec2> {
        let clip = self.view_projection * point.extend(1.0);
        if clip.w <= 1e-6 {
            return None;
        }
        let ndc = clip.xy() / clip.w;
        Some(self.origin + Vec2::new((ndc.x + 1.0) / 2.0, (1.0 - ndc.y) / 2.0) * self.size)
    }

    /// Normalised device coordinates of a screen position.
    pub fn to_ndc(&self, screen: Vec2) -> Vec2 {
        let unit = (screen - self.origin) / self.size.max(Vec2::ONE);
        Vec2::new(unit.x * 2.0 - 1.0, 1.0 - unit.y * 2.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn target_projects_to_the_viewport_centre() {
        let camera = OrbitCamera::default();
        let projection = ScreenProjection {
            view_projection: camera.view_projection(2.0),
            origin: Vec2::new(10.0, 20.0),
            size: Vec2::new(200.0, 100.0),
            scene_origin: SceneOrigin::default(),
        };
        let centre = projection.project(camera.target).unwrap();
        assert!((centre - Vec2::new(110.0, 70.0)).length() < 1e-3);
    }

    #[test]
    fn the_parallel_view_shows_the_targets_plane_as_the_perspective_does_and_ignores_depth() {
        let perspective = OrbitCamera::default();
        let parallel = OrbitCamera {
            orthographic: true,
            ..perspective
        };
        let screen = |camera: &OrbitCamera, point: Vec3| {
            ScreenProjection {
                view_projection: camera.view_projection(1.5),
                origin: Vec2::ZERO,
                size: Vec2::new(300.0, 200.0),
                scene_origin: SceneOrigin::default(),
            }
            .project(point)
            .unwrap()
        };
        let (right, up) = perspective.right_up();
        // On the plane through the target, both agree.
        let on_plane = perspective.target + right * 0.7 + up * 0.4;
        let gap = (screen(&perspective, on_plane) - screen(&parallel, on_plane)).length();
        assert!(gap < 1e-2, "{gap}");
        // Moved along the view direction, a point stays put only in parallel.
        let towards = -perspective.backward() * 1.5;
        let moved_parallel = screen(&parallel, on_plane + towards) - screen(&parallel, on_plane);
        let moved_perspective =
            screen(&perspective, on_plane + towards) - screen(&perspective, on_plane);
        assert!(moved_parallel.length() < 1e-3, "{moved_parallel}");
        assert!(moved_perspective.length() > 10.0, "{moved_perspective}");
    }

    #[test]
    fn zoom_keeps_the_target_when_the_cursor_is_centred() {
        let mut camera = OrbitCamera::default();
        camera.zoom_towards(0.5, Vec2::ZERO, 1.0);
        assert_eq!(camera.target, Vec3::ZERO);
        assert!((camera.distance - 2.5).abs() < 1e-6);
    }
}

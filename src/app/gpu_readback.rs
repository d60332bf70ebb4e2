//! The GPU's results read back, for tests and checks: what the shaders draw,
//! in world coordinates (the GPU works relative to the scene origin).

use super::editor::EditorApp;
use crate::coords::Method;
use crate::render::{ReadBack, RenderError, SceneOrigin, Shading, ViewportRenderer};
use glam::{DVec3, Vec3};

impl EditorApp {
    /// Deformed mesh positions of the active method as the vertex shader computes
    /// them, read back from the GPU, in world coordinates rounded to f32.
    pub fn read_back_deformed(&self) -> Option<Result<Vec<Vec3>, RenderError>> {
        let shading = Shading {
            method: self.active_method(),
            ..Default::default()
        };
        self.read_back(&shading)
            .map(|result| result.map(|read_back| read_back.positions))
    }

    /// Smooth shading's vertex normals of `method`'s deformation as the GPU last
    /// computed them; `None` before a smooth-shaded view of it was drawn.
    pub fn read_back_normals(&self, method: Method) -> Option<Vec<Vec3>> {
        self.with_renderer(|renderer, device, queue| {
            renderer.read_back_normals(device, queue, method)
        })
        .flatten()
        .and_then(Result::ok)
    }

    /// `method`'s deformed positions as the vertex shader draws them, in world
    /// coordinates rounded to f32.
    pub fn read_back_drawn(&self, method: Method) -> Option<Result<Vec<Vec3>, RenderError>> {
        let world = self.read_back_drawn_world(method)?;
        Some(world.map(|points| points.iter().map(|p| p.as_vec3()).collect()))
    }

    /// `method`'s deformed positions as the vertex shader draws them, in world
    /// coordinates: the scene coordinates the GPU drew plus the scene origin, in f64.
    pub fn read_back_drawn_world(&self, method: Method) -> Option<Result<Vec<DVec3>, RenderError>> {
        self.with_renderer(|renderer, device, queue| {
            let drawn = renderer.read_back_drawn(device, queue, method)?;
            Ok(in_world(renderer, &drawn))
        })
    }

    /// The scene origin of the document shown: what the GPU's positions and the
    /// cameras are relative to.
    pub fn scene_origin(&self) -> SceneOrigin {
        self.viewport.origin()
    }

    /// Why smooth shading cannot be shown for this scene on this GPU, if it
    /// cannot (the mesh is then lit per face).
    pub fn smooth_shading_refusal(&self) -> Option<String> {
        self.with_renderer(|renderer, device, _| renderer.smooth_shading_refusal(device))
            .flatten()
    }

    /// The weights columns of `method` drawn from vertex attributes; `None`
    /// when the viewport reads them all from storage.
    pub fn attribute_columns(&self, method: Method) -> Option<u32> {
        self.with_renderer(|renderer, _, _| renderer.attribute_columns(method))
            .flatten()
    }

    /// Positions (in world coordinates rounded to f32), colouring values and
    /// colours as the shaders compute them.
    pub fn read_back(&self, shading: &Shading) -> Option<Result<ReadBack, RenderError>> {
        self.with_renderer(|renderer, device, queue| {
            let mut read = renderer.read_back(device, queue, shading)?;
            read.positions = in_world(renderer, &read.positions)
                .iter()
                .map(|p| p.as_vec3())
                .collect();
            Ok(read)
        })
    }
}

/// Positions read back from `renderer` (scene coordinates) in world coordinates.
fn in_world(renderer: &ViewportRenderer, scene: &[Vec3]) -> Vec<DVec3> {
    let origin = renderer.scene_origin().unwrap_or_default();
    scene.iter().map(|&p| origin.to_world(p)).collect()
}

//! The GPU copy follows the model: what changed in the document since the last
//! frame (`Changes`) is uploaded, and nothing else writes to the viewport's
//! buffers — the scene, the pose, the handle states, each method's weights and
//! the mesh's outside flags alike. And what the GPU drew, read back in world
//! coordinates (the GPU works relative to the scene origin), for tests and checks.

use super::EditorApp;
use crate::coords::{Method, WeightsId};
use crate::render::{ReadBack, RenderError, SceneOrigin, SceneUpload, Shading, ViewportRenderer};
use glam::{DVec3, Vec3};
use std::collections::BTreeSet;
use std::sync::Arc;

impl EditorApp {
    /// Apply what changed in the document to the GPU copy and the caches.
    pub fn sync_gpu(&mut self) {
        let changes = self.model.take_changes();
        if changes.scene {
            let origin = self.document_origin();
            self.views.viewport.set_origin(origin);
            let mesh = Arc::clone(self.model.document().mesh());
            let cage = Arc::clone(self.model.document().cage());
            self.with_renderer(|renderer, device, _| {
                renderer.upload_scene(
                    device,
                    &SceneUpload {
                        rest_positions: &mesh.positions,
                        triangles: &mesh.triangles,
                        cage: &cage,
                        origin,
                    },
                )
            });
        }
        if !changes.weights.is_empty() {
            self.upload_weights(&changes.weights);
        }
        // After the weights: every bound family's displacements follow the pose.
        if changes.scene || changes.pose {
            let pose = self.model.document().pose().to_vec();
            let deform = self.model.document().deform_values();
            self.with_renderer(|renderer, _, queue| renderer.set_cage_pose(queue, &pose, &deform));
        }
        if changes.scene || changes.pose || !changes.weights.is_empty() {
            self.views.readouts.invalidate(&changes);
        }
        let hover_changed = self.views.viewport.take_hover_changed();
        let tools = &self.panels.pose_tools.tools;
        if changes.scene || changes.selection || hover_changed || tools.soft_selection {
            let states = self.views.handle_states(self.model.document(), tools);
            self.with_renderer(|renderer, _, queue| renderer.set_handle_states(queue, &states));
        }
    }

    /// Upload the weights of `methods` and the outside flags beside them; a
    /// bind's copy already on the device is used where there is one.
    fn upload_weights(&mut self, methods: &BTreeSet<WeightsId>) {
        let resident = self
            .gpu
            .as_mut()
            .and_then(|gpu| gpu.resident_weights.take());
        let document = self.model.document();
        let rest = &document.mesh().positions;
        let outside = document.outside();
        let sets: Vec<_> = methods
            .iter()
            .filter_map(|&id| {
                document
                    .bound_id(id)
                    .map(|set| (id, Arc::clone(&set.weights), set.options))
            })
            .collect();
        let uploaded = self.with_renderer(|renderer, device, queue| {
            renderer.set_outside(queue, rest, outside);
            sets.iter().try_for_each(|(method, weights, options)| {
                let on_device = resident
                    .as_ref()
                    .filter(|(bound, _)| Arc::ptr_eq(bound, weights))
                    .map(|(_, buffer)| buffer);
                renderer.set_weights(device, *method, Some(weights), *options, on_device)
            })
        });
        if let Some(Err(error)) = uploaded {
            self.error(error.to_string());
        }
    }

    /// What the viewport draws this document relative to: positions on the GPU,
    /// cameras and projections are taken from there ([`SceneOrigin::of_cage`]).
    pub(super) fn document_origin(&self) -> SceneOrigin {
        SceneOrigin::of_cage(self.model.document().cage().positions())
    }

    // ---- read back -------------------------------------------------------------

    /// Deformed mesh positions of the active method as the vertex shader computes
    /// them, read back from the GPU, in world coordinates rounded to f32.
    pub fn read_back_deformed(&self) -> Option<Result<Vec<Vec3>, RenderError>> {
        let shading = Shading {
            method: self.binding.active_method(),
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
        self.views.viewport.origin()
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

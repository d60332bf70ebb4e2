//! The GPU copy follows the model: what changed in the document since the last
//! frame (`Changes`) is uploaded, and nothing else writes to the viewport's
//! buffers — the scene, the pose, the handle states, each method's weights and
//! the mesh's outside flags alike.

use super::editor::EditorApp;
use crate::coords::Method;
use crate::render::{SceneOrigin, SceneUpload};
use std::collections::BTreeSet;
use std::sync::Arc;

impl EditorApp {
    /// Apply what changed in the document to the GPU copy and the caches.
    pub fn sync_gpu(&mut self) {
        let changes = self.model.take_changes();
        if changes.scene {
            let origin = self.document_origin();
            self.viewport.set_origin(origin);
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
            self.with_renderer(|renderer, _, queue| renderer.set_cage_pose(queue, &pose));
        }
        if changes.scene || changes.pose || !changes.weights.is_empty() {
            self.readouts.invalidate(&changes);
        }
        let hover_changed = self.viewport.take_hover_changed();
        if changes.scene || changes.selection || hover_changed || self.pose_tools.soft_selection {
            let states = self.handle_states();
            self.with_renderer(|renderer, _, queue| renderer.set_handle_states(queue, &states));
        }
    }

    /// Upload the weights of `methods` and the outside flags beside them; a
    /// bind's copy already on the device is used where there is one.
    fn upload_weights(&mut self, methods: &BTreeSet<Method>) {
        let resident = self
            .gpu
            .as_mut()
            .and_then(|gpu| gpu.resident_weights.take());
        let document = self.model.document();
        let rest = &document.mesh().positions;
        let outside = document.outside();
        let sets: Vec<_> = methods
            .iter()
            .filter_map(|&m| document.bound(m).map(|set| (m, Arc::clone(&set.weights))))
            .collect();
        let uploaded = self.with_renderer(|renderer, device, queue| {
            renderer.set_outside(queue, rest, outside);
            sets.iter().try_for_each(|(method, weights)| {
                let on_device = resident
                    .as_ref()
                    .filter(|(bound, _)| Arc::ptr_eq(bound, weights))
                    .map(|(_, buffer)| buffer);
                renderer.set_weights(device, *method, Some(weights), on_device)
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
}

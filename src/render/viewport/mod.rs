//! The 3D viewport inside egui: the orchestrator of the renderers. It owns the
//! scene's GPU state ([`super::scene_gpu`]), one offscreen target per view
//! ([`super::composite`]); the paint callback ([`super::callback`]) asks it to
//! draw the mesh and cage there and to composite the image into egui's pass.
//!
//! Up to [`MAX_VIEWS`] views are drawn in one frame (families side by side, and
//! their difference). Each has its own slot of the frame uniform (a dynamic
//! offset) and its own offscreen target. The weights of every family bound so far
//! stay resident, so switching the family shown is only a different bind group.

use super::cage::CageRenderer;
use super::colormap::Scale;
use super::composite::{Compositor, OffscreenTarget};
use super::drawn::DrawnPositions;
use super::mesh::{MeshPipelineKey, MeshRenderer};
use super::normals::NormalsPass;
use super::readback::Readback;
use super::scene_gpu::{
    buffer_with, scene_layout, uniform_displacements_buffer, FrameUniform, SceneGpu, WeightSlot,
    FRAME_SLOT_BYTES, STORAGE_BUFFERS_PER_STAGE,
};
use super::scene_origin::SceneOrigin;
pub use super::shading::{Colouring, FrameParams, Shading};
use super::weight_attributes::AttributeBlend;
use super::weight_chunks::{ChunkLimits, ChunksTooLarge};

mod readbacks;
use crate::coords::{BindOptions, Method, Parameter, Weights, WeightsId};
use crate::geometry::Cage;
use glam::{DVec3, Vec3};

/// Multisampling smooths the one-pixel cage lines and the mesh silhouette. It
/// costs about 16 ms a frame on lavapipe, so software adapters default to 1.
pub const MSAA_SAMPLES: u32 = 4;
/// Views drawn in one frame.
pub const MAX_VIEWS: usize = 4;
/// The frame-uniform slot of readbacks, after the views'.
const READBACK_SLOT: usize = MAX_VIEWS;
const BACKGROUND: wgpu::Color = wgpu::Color {
    r: 0.13,
    g: 0.14,
    b: 0.16,
    a: 1.0,
};

/// A failure to put the scene on the GPU.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error(transparent)]
    WeightsTooLarge(#[from] ChunksTooLarge),
    #[error("reading the deformed positions back from the GPU failed")]
    ReadBack,
    #[error("no scene is on the GPU")]
    NoScene,
    #[error(
        "the graphics adapter '{adapter}' cannot draw the viewport: {missing}; install a Vulkan, Metal or DirectX 12 driver (on Linux without a GPU: Mesa's lavapipe, package mesa-vulkan-drivers)"
    )]
    UnsupportedAdapter { adapter: String, missing: String },
}

/// Whether the viewport can draw on `adapter` with `device`: its vertex shader
/// reads storage buffers, which WebGL-class adapters (wgpu's GL backend, for one)
/// do not offer. Readback's compute pass is not required: only tests use it.
pub fn check_adapter(adapter: &wgpu::Adapter, device: &wgpu::Device) -> Result<(), RenderError> {
    let flags = adapter.get_downlevel_capabilities().flags;
    let storage_buffers = device.limits().max_storage_buffers_per_shader_stage;
    let missing = if !flags.contains(wgpu::DownlevelFlags::VERTEX_STORAGE) {
        "no storage buffers in vertex shaders".to_owned()
    } else if storage_buffers < STORAGE_BUFFERS_PER_STAGE {
        format!(
            "{storage_buffers} storage buffers per shader stage, and it needs {STORAGE_BUFFERS_PER_STAGE}"
        )
    } else {
        return Ok(());
    };
    let info = adapter.get_info();
    Err(RenderError::UnsupportedAdapter {
        adapter: format!("{} ({:?})", info.name, info.backend),
        missing,
    })
}

/// What the viewport draws, uploaded when the scene changes.
pub struct SceneUpload<'a> {
    /// The mesh at rest, in world coordinates.
    pub rest_positions: &'a [DVec3],
    pub triangles: &'a [[u32; 3]],
    /// The rest cage; weights columns follow its vertices (and faces).
    pub cage: &'a Cage,
    /// What every position is uploaded relative to; the cameras that draw the
    /// scene must be relative to it too.
    pub origin: SceneOrigin,
}

/// All GPU state of the viewport; lives in egui_wgpu's callback resources.
pub struct ViewportRenderer {
    scene_layout: wgpu::BindGroupLayout,
    /// One [`FRAME_SLOT_BYTES`] slot per view, then the readback slot.
    frame: wgpu::Buffer,
    mesh: MeshRenderer,
    cage: CageRenderer,
    compositor: Compositor,
    /// Made on the first readback.
    readback: Option<Readback>,
    /// Made on the first readback of the drawn positions.
    drawn: Option<DrawnPositions>,
    /// Made when smooth shading first needs normals.
    normals: Option<NormalsPass>,
    targets: [Option<OffscreenTarget>; MAX_VIEWS],
    scene: Option<SceneGpu>,
    chunk_limits: ChunkLimits,
    sample_count: u32,
}

impl ViewportRenderer {
    /// `target_format` is the format of egui's render pass.
    /// `sample_count` is 1 or [`MSAA_SAMPLES`].
    pub fn new(
        device: &wgpu::Device,
        target_format: wgpu::TextureFormat,
        sample_count: u32,
    ) -> Self {
        let chunk_limits = ChunkLimits::of(&device.limits());
        let scene_layout = scene_layout(device, chunk_limits.slots);
        let frame = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame"),
            size: FRAME_SLOT_BYTES * (MAX_VIEWS as u64 + 1),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            mesh: MeshRenderer::new(device, &scene_layout, chunk_limits.slots, sample_count),
            cage: CageRenderer::new(device, &scene_layout, sample_count),
            compositor: Compositor::new(device, target_format),
            readback: None,
            drawn: None,
            normals: None,
            sample_count,
            scene_layout,
            frame,
            targets: Default::default(),
            scene: None,
            chunk_limits,
        }
    }

    pub fn sample_count(&self) -> u32 {
        self.sample_count
    }

    /// Switch multisampling (1 or [`MSAA_SAMPLES`]); rebuilds the pipelines.
    pub fn set_sample_count(&mut self, device: &wgpu::Device, sample_count: u32) {
        if sample_count == self.sample_count {
            return;
        }
        self.sample_count = sample_count;
        self.mesh = MeshRenderer::new(
            device,
            &self.scene_layout,
            self.chunk_limits.slots,
            sample_count,
        );
        self.cage = CageRenderer::new(device, &self.scene_layout, sample_count);
        self.targets = Default::default();
    }

    /// Replace the scene. Weights start unbound: the mesh shows at rest.
    pub fn upload_scene(&mut self, device: &wgpu::Device, scene: &SceneUpload<'_>) {
        let cage_rest: Vec<Vec3> = (scene.cage.positions().iter())
            .map(|&p| scene.origin.to_scene(p))
            .collect();
        // The artist's polygons where the cage has them (quads' diagonals are
        // never drawn); for a cage of triangles, the edges between triangles
        // that are not coplanar.
        let cage = scene.cage;
        let edges = crate::geometry::polygon_edges(cage.triangles(), cage.triangle_faces())
            .unwrap_or_else(|| super::cage::feature_edges(&cage_rest, cage.triangles()));
        self.scene = Some(SceneGpu::new(
            device,
            scene.rest_positions,
            scene.triangles,
            scene.cage,
            &edges,
            scene.origin,
            self.chunk_limits,
        ));
    }

    /// What the scene on the GPU is drawn relative to: the positions read back
    /// are in its coordinates. `None` before a scene is uploaded.
    pub fn scene_origin(&self) -> Option<SceneOrigin> {
        self.scene.as_ref().map(|scene| scene.origin)
    }

    /// Bind one family's weights (or unbind them with `None`, showing the mesh at
    /// rest in views of that family). A `resident` buffer already holding them on
    /// this device is used as it is when they fit in one chunk; otherwise they are
    /// uploaded in chunks ([`super::weight_chunks`]). Fails, leaving the weights
    /// unbound, when the matrix exceeds what the GPU can bind.
    pub fn set_weights(
        &mut self,
        device: &wgpu::Device,
        id: WeightsId,
        weights: Option<&Weights>,
        options: BindOptions,
        resident: Option<&wgpu::Buffer>,
    ) -> Result<(), RenderError> {
        let Some(scene) = self.scene.as_mut() else {
            return Err(RenderError::NoScene);
        };
        let Some(weights) = weights.filter(|weights| !weights.values.is_empty()) else {
            scene.set_slot(id, None);
            return Ok(());
        };
        let split = match self.chunk_limits.split(weights.rows, weights.cols) {
            Ok(split) => split,
            Err(too_large) => {
                scene.set_slot(id, None);
                return Err(too_large.into());
            }
        };
        // Readable as vertex attributes too (render::weight_attributes).
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::VERTEX;
        let chunks = match resident {
            Some(buffer) if split.chunks == 1 => vec![buffer.clone()],
            _ => split
                .chunks_of(weights)
                .map(|values| buffer_with(device, "weights", values, usage))
                .collect(),
        };
        let matrices = options.moves_may_carry_matrices();
        let attributes = AttributeBlend::new(
            &device.limits(),
            weights.cols as u32,
            chunks.len(),
            matrices,
        )
        .filter(|_| chunks[0].usage().contains(wgpu::BufferUsages::VERTEX));
        // The columns' vectors, then room for their matrices where the family's
        // may carry them, then for the vertex normals.
        let moves = scene.displacements_of(&options);
        let matrix_columns = moves.matrix_columns();
        let uniform_displacements = uniform_displacements_buffer(device, &moves.vectors);
        let mut displacements = moves.vectors;
        if options.moves_may_carry_matrices() {
            displacements.extend(&moves.matrices);
            displacements.resize(4 * weights.cols, [0.0; 4]);
        }
        let normals_first = displacements.len() as u32;
        displacements.resize(displacements.len() + scene.vertex_count as usize, [0.0; 4]);
        let displacements = buffer_with(
            device,
            "column displacements and vertex normals",
            &displacements,
            wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        );
        scene.set_slot(
            id,
            Some(WeightSlot {
                chunks,
                split,
                displacements,
                matrix_columns,
                normals_first,
                uniform_displacements,
                columns: weights.cols as u32,
                options,
                attributes,
                normals_pose: None,
            }),
        );
        Ok(())
    }

    /// Mark the mesh vertices outside the cage (drawn red when highlighted);
    /// `rest_positions` in world coordinates, as uploaded with the scene.
    pub fn set_outside(&mut self, queue: &wgpu::Queue, rest_positions: &[DVec3], outside: &[u32]) {
        let Some(scene) = &self.scene else { return };
        let mut rest = scene.origin.points_to_scene(rest_positions, 0.0);
        for &i in outside {
            if let Some(vertex) = rest.get_mut(i as usize) {
                vertex[3] = 1.0;
            }
        }
        if rest.len() as u32 == scene.vertex_count {
            queue.write_buffer(&scene.rest, 0, bytemuck::cast_slice(&rest));
        }
    }

    /// Upload the posed cage and every bound family's column displacements with
    /// the deformation settings `deform` (Somigliana's bulging; those not listed
    /// at their defaults); called only when the pose or those settings change.
    pub fn set_cage_pose(
        &mut self,
        queue: &wgpu::Queue,
        pose: &[DVec3],
        deform: &[(Parameter, u32)],
    ) {
        let Some(scene) = self.scene.as_mut() else {
            return;
        };
        if pose.len() as u32 != scene.cage_vertex_count {
            return;
        }
        scene.pose = pose.to_vec();
        scene.deform = deform.to_vec();
        scene.pose_revision += 1;
        let scene_pose = scene.origin.points_to_scene(pose, 1.0);
        queue.write_buffer(&scene.cage, 0, bytemuck::cast_slice(&scene_pose));
        let mut matrix_columns = Vec::new();
        for slot in scene.slots.values().chain(scene.twin_slots.values()) {
            let moves = scene.displacements_of(&slot.options);
            SceneGpu::write_moves(queue, slot, &moves);
            matrix_columns.push(moves.matrix_columns());
        }
        let slots = scene
            .slots
            .values_mut()
            .chain(scene.twin_slots.values_mut());
        for (slot, columns) in slots.zip(matrix_columns) {
            slot.matrix_columns = columns;
        }
    }

    /// Per handle: 0 idle, 1 selected, 2 hovered.
    pub fn set_handle_states(&mut self, queue: &wgpu::Queue, states: &[u32]) {
        let Some(scene) = &self.scene else { return };
        if states.len() as u32 == scene.cage_vertex_count && !states.is_empty() {
            queue.write_buffer(&scene.handle_state, 0, bytemuck::cast_slice(states));
        }
    }

    /// Whether `method`'s weights are on the GPU.
    pub fn has_weights(&self, method: Method) -> bool {
        self.scene
            .as_ref()
            .is_some_and(|scene| scene.slots.contains_key(&method))
    }

    fn frame_uniform(&self, params: &FrameParams) -> FrameUniform {
        let shading = &params.shading;
        let slot_of = |id: Option<WeightsId>| {
            let slot = self.scene.as_ref().zip(id);
            slot.and_then(|(scene, id)| scene.slot(id))
        };
        let shown = slot_of(Some(WeightsId::of(shading.method)));
        let against = slot_of(shading.against);
        let columns = shown.map_or(0, |slot| slot.columns);
        let rows_per_chunk = |slot: Option<&WeightSlot>| slot.map_or(1, |s| s.split.rows_per_chunk);
        let cage_vertices = self
            .scene
            .as_ref()
            .map_or(0, |scene| scene.cage_vertex_count);
        let layout = shading.method.spec().columns;
        let [colouring, colouring_column] = shading.colouring.code(layout, cage_vertices, columns);
        FrameUniform {
            view_projection: params.view_projection.to_cols_array_2d(),
            eye: params.eye.to_array(),
            handle_radius_px: params.handle_radius_px,
            viewport_size_px: params.size_px.map(|size| size as f32),
            colour_limit: shading.colour_limit,
            cage_size: shading.cage_size,
            columns,
            weights_bound: u32::from(columns > 0),
            highlight_outside: u32::from(params.highlight_outside),
            vertex_count: self.scene.as_ref().map_or(0, |scene| scene.vertex_count),
            colouring,
            colouring_column,
            log_scale: u32::from(shading.scale == Scale::LogMagnitude),
            other_columns: against.map_or(0, |slot| slot.columns),
            rows_per_chunk: rows_per_chunk(shown),
            other_rows_per_chunk: rows_per_chunk(against),
            // The pool holds the shown family's chunks first (SceneGpu::bind_group).
            other_first_chunk: shown.map_or(0, |slot| slot.chunks.len() as u32),
            smooth_shading: u32::from(params.smooth_shading),
            vertex_columns: cage_vertices * layout.columns_per_element() as u32,
            probe_width: super::scene_gpu::PROBE_WIDTH,
            vertex_column_stride: layout.columns_per_element() as u32,
            matrix_columns: shown.map_or(0, |slot| slot.matrix_columns),
            other_matrix_columns: against.map_or(0, |slot| slot.matrix_columns),
            normals_first: shown.map_or(0, |slot| slot.normals_first),
            _padding: [0; 2],
        }
    }

    fn write_frame_slot(&self, queue: &wgpu::Queue, slot: usize, uniform: &FrameUniform) {
        queue.write_buffer(
            &self.frame,
            slot as u64 * FRAME_SLOT_BYTES,
            bytemuck::bytes_of(uniform),
        );
    }

    /// Draw view `params.view` into its offscreen target.
    pub(super) fn draw_view(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        params: &FrameParams,
    ) {
        let view = params.view.min(MAX_VIEWS - 1);
        let size = [params.size_px[0].max(1), params.size_px[1].max(1)];
        if self.targets[view].as_ref().is_none_or(|t| t.size != size) {
            self.targets[view] = Some(self.compositor.target(device, size, self.sample_count));
        }
        let uniform = self.frame_uniform(params);
        self.write_frame_slot(queue, view, &uniform);
        let bind_group = self.scene.as_mut().map(|scene| {
            scene
                .bind_group(
                    device,
                    &self.scene_layout,
                    &self.frame,
                    params.shading.method,
                    params.shading.against,
                )
                .clone()
        });
        if params.smooth_shading {
            if let Some(bind_group) = &bind_group {
                let offset = (view as u64 * FRAME_SLOT_BYTES) as u32;
                self.update_normals(device, encoder, params.shading.method, bind_group, offset);
            }
        }
        let key = MeshPipelineKey {
            attributes: self.scene.as_ref().and_then(|scene| {
                let slot = scene.slots.get(&params.shading.method)?;
                slot.attributes
            }),
            coloured: params.shading.colouring != Colouring::Shaded,
        };
        self.mesh.prepare(device, key);
        let Some(target) = &self.targets[view] else {
            return;
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("viewport"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target.multisampled.as_ref().unwrap_or(&target.resolved),
                depth_slice: None,
                resolve_target: target.multisampled.as_ref().map(|_| &target.resolved),
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(BACKGROUND),
                    // With MSAA only the resolved image is needed; without, the
                    // attachment is that image.
                    store: if target.multisampled.is_some() {
                        wgpu::StoreOp::Discard
                    } else {
                        wgpu::StoreOp::Store
                    },
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &target.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if let (Some(scene), Some(bind_group)) = (&self.scene, bind_group) {
            let offset = (view as u64 * FRAME_SLOT_BYTES) as u32;
            let weights = scene.slots.get(&params.shading.method);
            let weights = weights.and_then(WeightSlot::attribute_weights);
            let buffer = weights.map(|(_, buffer)| buffer);
            self.mesh
                .draw(&mut pass, scene, &bind_group, offset, key, buffer);
            if params.wireframe {
                self.mesh
                    .draw_wireframe(&mut pass, scene, &bind_group, offset, key, buffer);
            }
            if params.show_cage {
                self.cage.draw(&mut pass, scene, &bind_group, offset);
            }
        }
    }

    /// Recompute `method`'s vertex normals if the pose changed since they were.
    fn update_normals(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        method: Method,
        bind_group: &wgpu::BindGroup,
        frame_offset: u32,
    ) {
        let Some(scene) = &self.scene else { return };
        let Some(slot) = scene.slots.get(&method) else {
            return;
        };
        // Without normals the shader lights each face with its own.
        let too_large = super::normals::largest_binding(scene)
            > device.limits().max_storage_buffer_binding_size;
        if slot.normals_pose == Some(scene.pose_revision) || too_large {
            return;
        }
        let slots = self.chunk_limits.slots;
        // Where the weights are read as attributes, the positions are drawn with
        // them: one vertex fetch per vertex, where the compute pass would load
        // every weight from storage.
        let positions_drawn = slot.attribute_weights().is_some_and(|weights| {
            let drawn = (self.drawn)
                .get_or_insert_with(|| DrawnPositions::new(device, &self.scene_layout, slots));
            drawn.encode(
                device,
                encoder,
                scene,
                bind_group,
                frame_offset,
                Some(weights),
                &scene.deformed_scratch,
            )
        });
        let pass = (self.normals)
            .get_or_insert_with(|| NormalsPass::new(device, &self.scene_layout, slots));
        pass.encode(
            device,
            encoder,
            scene,
            bind_group,
            frame_offset,
            &slot.displacements,
            positions_drawn,
        );
        let revision = scene.pose_revision;
        if let Some(slot) = self.scene.as_mut().and_then(|s| s.slots.get_mut(&method)) {
            slot.normals_pose = Some(revision);
        }
    }

    /// Why this device cannot compute smooth shading's normals for the scene,
    /// if it cannot: the mesh needs a larger storage binding than it offers.
    pub fn smooth_shading_refusal(&self, device: &wgpu::Device) -> Option<String> {
        let needed = super::normals::largest_binding(self.scene.as_ref()?);
        let limit = device.limits().max_storage_buffer_binding_size;
        (needed > limit).then(|| {
            format!(
                "this mesh's normals need {:.2} MiB in one storage buffer and this GPU binds at \
                 most {:.2} MiB, so each face is lit with its own normal",
                needed as f64 / 1048576.0,
                limit as f64 / 1048576.0
            )
        })
    }

    /// Composite view `view`'s image into egui's pass.
    pub(super) fn composite(&self, pass: &mut wgpu::RenderPass<'static>, view: usize) {
        let Some(target) = &self.targets[view.min(MAX_VIEWS - 1)] else {
            return;
        };
        pass.set_pipeline(&self.compositor.pipeline);
        pass.set_bind_group(0, &target.composite_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

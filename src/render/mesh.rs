//! The deformed mesh: a render pipeline whose vertex shader deforms each vertex from
//! the weights and the column displacements. Paired with `shaders/render_mesh.wgsl`
//! (whose compute entry point [`super::readback`] uses).

use super::colormap::LOG_DECADES;
use super::scene_gpu::{SceneGpu, DEPTH_FORMAT, OFFSCREEN_FORMAT};
use super::weight_chunks::{self, MAX_CHUNK_SLOTS};
use crate::gpu::shader_source::compose;

const SHADER: &str = include_str!("../../shaders/render_mesh.wgsl");

/// The shader's `override` constants, from their CPU twins.
pub(super) const CONSTANTS: &[(&str, f64)] = &[("LOG_DECADES", LOG_DECADES as f64)];

/// `render_mesh.wgsl` with its imports resolved and the largest pool of weight
/// chunks.
pub fn shader_source() -> String {
    shader_source_with_chunks(MAX_CHUNK_SLOTS)
}

/// `render_mesh.wgsl` with its imports resolved and `chunk_slots` weight chunks.
pub fn shader_source_with_chunks(chunk_slots: u32) -> String {
    // The shared files are compiled in, so only a broken build can fail here.
    let mut source = compose("render_mesh.wgsl", SHADER).unwrap_or_else(|error| panic!("{error}"));
    source.push_str(&weight_chunks::wgsl(chunk_slots));
    source
}

pub(super) fn shader_module(device: &wgpu::Device, chunk_slots: u32) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("render_mesh.wgsl"),
        source: wgpu::ShaderSource::Wgsl(shader_source_with_chunks(chunk_slots).into()),
    })
}

pub struct MeshRenderer {
    pipeline: wgpu::RenderPipeline,
    /// The mesh's edges over it (View > Wireframe).
    wire_pipeline: wgpu::RenderPipeline,
}

impl MeshRenderer {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        chunk_slots: u32,
        sample_count: u32,
    ) -> Self {
        let module = shader_module(device, chunk_slots);
        let constants = wgpu::PipelineCompilationOptions {
            constants: CONSTANTS,
            ..Default::default()
        };
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("mesh"),
            bind_group_layouts: &[Some(scene_layout)],
            immediate_size: 0,
        });
        let pipeline_for = |label, entries: [&str; 2], topology, depth_write, depth_compare| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(entries[0]),
                    compilation_options: constants.clone(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState {
                    topology,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(depth_write),
                    depth_compare: Some(depth_compare),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState {
                    count: sample_count,
                    ..Default::default()
                },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(entries[1]),
                    compilation_options: constants.clone(),
                    targets: &[Some(OFFSCREEN_FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        Self {
            pipeline: pipeline_for(
                "mesh",
                ["vs_mesh", "fs_mesh"],
                wgpu::PrimitiveTopology::TriangleList,
                true,
                wgpu::CompareFunction::Less,
            ),
            wire_pipeline: pipeline_for(
                "mesh wireframe",
                ["vs_wire", "fs_wire"],
                wgpu::PrimitiveTopology::LineList,
                false,
                wgpu::CompareFunction::LessEqual,
            ),
        }
    }

    /// Draw with `bind_group` (which picks the method's weights), whose frame
    /// uniform is at `frame_offset`.
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        scene: &SceneGpu,
        bind_group: &wgpu::BindGroup,
        frame_offset: u32,
    ) {
        if scene.index_count == 0 {
            return;
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[frame_offset]);
        pass.set_index_buffer(scene.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..scene.index_count, 0, 0..1);
    }

    /// The mesh's edges, after [`Self::draw`] in the same pass.
    pub fn draw_wireframe(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        scene: &SceneGpu,
        bind_group: &wgpu::BindGroup,
        frame_offset: u32,
    ) {
        if scene.mesh_edge_index_count == 0 {
            return;
        }
        pass.set_pipeline(&self.wire_pipeline);
        pass.set_bind_group(0, bind_group, &[frame_offset]);
        pass.set_index_buffer(scene.mesh_edges.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..scene.mesh_edge_index_count, 0, 0..1);
    }
}

//! The deformed mesh: a render pipeline whose vertex shader deforms each vertex from
//! the weights and the column displacements, with the first weights columns read
//! as vertex attributes where the device allows ([`super::weight_attributes`]).
//! Paired with `shaders/render_mesh.wgsl` (whose compute entry point
//! [`super::readback`] uses, and whose probe entry points [`super::drawn`] does).

use super::colormap::LOG_DECADES;
use super::scene_gpu::{SceneGpu, DEPTH_FORMAT, OFFSCREEN_FORMAT};
use super::weight_attributes::AttributeBlend;
use super::weight_chunks::{self, MAX_CHUNK_SLOTS};
use crate::gpu::shader_source::compose;
use std::collections::HashMap;

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
    shader_source_for(chunk_slots, None)
}

/// The same, with the entry points that read `attributes`' weights columns as
/// vertex attributes.
pub fn shader_source_for(chunk_slots: u32, attributes: Option<&AttributeBlend>) -> String {
    // The shared files are compiled in, so only a broken build can fail here.
    let mut source = compose("render_mesh.wgsl", SHADER).unwrap_or_else(|error| panic!("{error}"));
    source.push_str(&weight_chunks::wgsl(chunk_slots));
    if let Some(attributes) = attributes {
        source.push_str(&attributes.wgsl());
    }
    source
}

pub(super) fn shader_module(device: &wgpu::Device, chunk_slots: u32) -> wgpu::ShaderModule {
    shader_module_for(device, chunk_slots, None)
}

pub(super) fn shader_module_for(
    device: &wgpu::Device,
    chunk_slots: u32,
    attributes: Option<&AttributeBlend>,
) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("render_mesh.wgsl"),
        source: wgpu::ShaderSource::Wgsl(shader_source_for(chunk_slots, attributes).into()),
    })
}

/// A vertex shader entry point: `name`, or its `_attributes` twin.
pub(super) fn vertex_entry(name: &str, attributes: Option<&AttributeBlend>) -> String {
    match attributes {
        Some(_) => format!("{name}_attributes"),
        None => name.to_owned(),
    }
}

/// The surface and the wireframe, for one way of reading the weights.
struct MeshPipelines {
    surface: wgpu::RenderPipeline,
    wire: wgpu::RenderPipeline,
}

/// Which pipelines draw a view: how the weights are read (`None`: from storage
/// alone), and whether the mesh is coloured by a value or only shaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MeshPipelineKey {
    pub attributes: Option<AttributeBlend>,
    pub coloured: bool,
}

pub struct MeshRenderer {
    layout: wgpu::PipelineLayout,
    chunk_slots: u32,
    sample_count: u32,
    /// Made on first use: a view switches between few of them.
    pipelines: HashMap<MeshPipelineKey, MeshPipelines>,
}

impl MeshRenderer {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        chunk_slots: u32,
        sample_count: u32,
    ) -> Self {
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("mesh"),
            bind_group_layouts: &[Some(scene_layout)],
            immediate_size: 0,
        });
        Self {
            layout,
            chunk_slots,
            sample_count,
            pipelines: HashMap::new(),
        }
    }

    /// Make the pipelines of `key`, once; [`Self::draw`] draws nothing without.
    pub fn prepare(&mut self, device: &wgpu::Device, key: MeshPipelineKey) {
        if !self.pipelines.contains_key(&key) {
            let made = pipelines(
                device,
                &self.layout,
                self.chunk_slots,
                self.sample_count,
                key,
            );
            self.pipelines.insert(key, made);
        }
    }

    /// Draw with `bind_group` (which picks the method's weights), whose frame
    /// uniform is at `frame_offset`, with the pipelines of `key` (prepared with
    /// [`Self::prepare`]); `weights` holds the vertex attributes `key` reads.
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        scene: &SceneGpu,
        bind_group: &wgpu::BindGroup,
        frame_offset: u32,
        key: MeshPipelineKey,
        weights: Option<&wgpu::Buffer>,
    ) {
        let Some(pipelines) = self.pipelines.get(&key) else {
            return;
        };
        draw_indexed(
            pass,
            &pipelines.surface,
            bind_group,
            frame_offset,
            weights,
            &scene.indices,
            scene.index_count,
        );
    }

    /// The mesh's edges, after [`Self::draw`] in the same pass.
    pub fn draw_wireframe(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        scene: &SceneGpu,
        bind_group: &wgpu::BindGroup,
        frame_offset: u32,
        key: MeshPipelineKey,
        weights: Option<&wgpu::Buffer>,
    ) {
        let Some(pipelines) = self.pipelines.get(&key) else {
            return;
        };
        draw_indexed(
            pass,
            &pipelines.wire,
            bind_group,
            frame_offset,
            weights,
            &scene.mesh_edges,
            scene.mesh_edge_index_count,
        );
    }
}

fn draw_indexed(
    pass: &mut wgpu::RenderPass<'_>,
    pipeline: &wgpu::RenderPipeline,
    bind_group: &wgpu::BindGroup,
    frame_offset: u32,
    weights: Option<&wgpu::Buffer>,
    indices: &wgpu::Buffer,
    count: u32,
) {
    if count == 0 {
        return;
    }
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, bind_group, &[frame_offset]);
    if let Some(buffer) = weights {
        pass.set_vertex_buffer(0, buffer.slice(..));
    }
    pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
    pass.draw_indexed(0..count, 0, 0..1);
}

/// The surface and wireframe pipelines of `key`.
fn pipelines(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    chunk_slots: u32,
    sample_count: u32,
    key: MeshPipelineKey,
) -> MeshPipelines {
    let attributes = key.attributes.as_ref();
    let module = shader_module_for(device, chunk_slots, attributes);
    let values = [
        CONSTANTS[0],
        ("COLOURED", f64::from(u8::from(key.coloured))),
    ];
    let constants = wgpu::PipelineCompilationOptions {
        constants: &values,
        ..Default::default()
    };
    let vertex_attributes = attributes.map(AttributeBlend::vertex_attributes);
    let buffers: Vec<Option<wgpu::VertexBufferLayout>> = attributes
        .zip(vertex_attributes.as_deref())
        .map(|(blend, list)| Some(blend.buffer_layout(list)))
        .into_iter()
        .collect();
    let pipeline_for = |label, entries: [&str; 2], topology, depth_write, depth_compare| {
        let vertex_entry = vertex_entry(entries[0], attributes);
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(&vertex_entry),
                compilation_options: constants.clone(),
                buffers: &buffers,
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
    MeshPipelines {
        surface: pipeline_for(
            "mesh",
            ["vs_mesh", "fs_mesh"],
            wgpu::PrimitiveTopology::TriangleList,
            true,
            wgpu::CompareFunction::Less,
        ),
        wire: pipeline_for(
            "mesh wireframe",
            ["vs_wire", "fs_wire"],
            wgpu::PrimitiveTopology::LineList,
            false,
            wgpu::CompareFunction::LessEqual,
        ),
    }
}

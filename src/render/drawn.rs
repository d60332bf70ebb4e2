//! What the vertex shader draws, read back. [`super::readback`] runs the mesh
//! shader's functions in a compute pass, which cannot read vertex attributes, so
//! it does not see the blend the viewport draws with where the weights are read
//! as attributes ([`super::weight_attributes`]). Here the mesh's vertices are
//! drawn as points with the viewport's own vertex fetch: vertex i lands on texel
//! (i mod [`PROBE_WIDTH`], i / [`PROBE_WIDTH`]) of a float image and writes its
//! deformed position there (`vs_probe`, `vs_probe_attributes` and `fs_probe` in
//! `shaders/render_mesh.wgsl`). Tests compare it with the CPU's deformation, and
//! smooth shading takes its positions from here where the weights are read as
//! attributes ([`super::normals`]): one vertex fetch per vertex instead of a
//! compute pass loading every weight from storage.

use super::mesh::{shader_module_for, vertex_entry, CONSTANTS};
use super::readback::map_vec4s;
use super::scene_gpu::{padded_bytes, SceneGpu, PROBE_WIDTH};
use super::weight_attributes::{AttributeBlend, AttributeWeights};
use glam::Vec3;
use std::collections::HashMap;

const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
const ROW_BYTES: u32 = PROBE_WIDTH * 16;

pub struct DrawnPositions {
    layout: wgpu::PipelineLayout,
    chunk_slots: u32,
    /// Per way of reading the weights (`None`: storage alone), made on first use.
    pipelines: HashMap<Option<AttributeBlend>, wgpu::RenderPipeline>,
    /// The image the points are drawn into, kept while the mesh keeps its size.
    image: Option<wgpu::Texture>,
}

impl DrawnPositions {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        chunk_slots: u32,
    ) -> Self {
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("drawn positions"),
            bind_group_layouts: &[Some(scene_layout)],
            immediate_size: 0,
        });
        Self {
            layout,
            chunk_slots,
            pipelines: HashMap::new(),
            image: None,
        }
    }

    /// Make the pipeline for `attributes`, once.
    fn prepare_pipeline(&mut self, device: &wgpu::Device, attributes: Option<AttributeBlend>) {
        self.pipelines.entry(attributes).or_insert_with(|| {
            let module = shader_module_for(device, self.chunk_slots, attributes.as_ref());
            let vertex_attributes = attributes.map(|blend| blend.vertex_attributes());
            let buffers: Vec<Option<wgpu::VertexBufferLayout>> = attributes
                .zip(vertex_attributes.as_deref())
                .map(|(blend, list)| Some(blend.buffer_layout(list)))
                .into_iter()
                .collect();
            let constants = wgpu::PipelineCompilationOptions {
                constants: CONSTANTS,
                ..Default::default()
            };
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("drawn positions"),
                layout: Some(&self.layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(&vertex_entry("vs_probe", attributes.as_ref())),
                    compilation_options: constants.clone(),
                    buffers: &buffers,
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::PointList,
                    ..Default::default()
                },
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_probe"),
                    compilation_options: constants,
                    targets: &[Some(FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        });
    }

    /// Draw every mesh vertex as the viewport does (with `weights` as vertex
    /// attributes where given) and read back the deformed positions. Blocks
    /// until the GPU is done. The frame uniform at `frame_offset` must name the
    /// family. Fails when the read-back fails or when the image would be taller
    /// than the device allows (more than 8 million vertices on most).
    pub fn run(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &SceneGpu,
        bind_group: &wgpu::BindGroup,
        frame_offset: u32,
        weights: Option<AttributeWeights<'_>>,
    ) -> Result<Vec<Vec3>, wgpu::BufferAsyncError> {
        let vertices = scene.vertex_count as usize;
        if vertices == 0 {
            return Ok(Vec::new());
        }
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("drawn positions staging"),
            size: padded_bytes(scene.vertex_count),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        let encoded = self.encode(
            device,
            &mut encoder,
            scene,
            bind_group,
            frame_offset,
            weights,
            &staging,
        );
        if !encoded {
            return Err(wgpu::BufferAsyncError);
        }
        queue.submit([encoder.finish()]);
        let texels = map_vec4s(device, &staging)?;
        Ok(texels[..vertices]
            .iter()
            .map(|texel| Vec3::new(texel[0], texel[1], texel[2]))
            .collect())
    }

    /// Encode drawing every mesh vertex's deformed position and copying the
    /// positions to `output` (vertex i at `vec4` i; at least [`padded_bytes`]
    /// long, with `COPY_DST`). False, with nothing encoded, when there are no
    /// vertices or the image would be taller than the device allows.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        bind_group: &wgpu::BindGroup,
        frame_offset: u32,
        weights: Option<AttributeWeights<'_>>,
        output: &wgpu::Buffer,
    ) -> bool {
        let vertices = scene.vertex_count;
        let height = vertices.div_ceil(PROBE_WIDTH);
        if vertices == 0 || height > device.limits().max_texture_dimension_2d {
            return false;
        }
        let size = wgpu::Extent3d {
            width: PROBE_WIDTH,
            height,
            depth_or_array_layers: 1,
        };
        if self
            .image
            .as_ref()
            .is_none_or(|image| image.height() != height)
        {
            self.image = Some(device.create_texture(&wgpu::TextureDescriptor {
                label: Some("drawn positions"),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            }));
        }
        self.prepare_pipeline(device, weights.map(|(blend, _)| blend));
        let (Some(image), Some(pipeline)) = (
            self.image.as_ref(),
            self.pipelines.get(&weights.map(|(blend, _)| blend)),
        ) else {
            return false;
        };
        let view = image.create_view(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("drawn positions"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, bind_group, &[frame_offset]);
            if let Some((_, buffer)) = weights {
                pass.set_vertex_buffer(0, buffer.slice(..));
            }
            pass.draw(0..vertices, 0..1);
        }
        encoder.copy_texture_to_buffer(
            image.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: output,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(ROW_BYTES),
                    rows_per_image: Some(height),
                },
            },
            size,
        );
        true
    }
}

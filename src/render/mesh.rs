//! The deformed mesh: a render pipeline whose vertex shader deforms each vertex from
//! the weights and the deformed cage, and a compute pipeline doing the same sums
//! into a buffer for readback. Paired with `shaders/render_mesh.wgsl`.

use super::viewport::{ReadBack, SceneGpu, DEPTH_FORMAT, OFFSCREEN_FORMAT};
use glam::Vec3;

const SHADER: &str = include_str!("../../shaders/render_mesh.wgsl");

pub struct MeshRenderer {
    pipeline: wgpu::RenderPipeline,
    deform_pipeline: wgpu::ComputePipeline,
    output_layout: wgpu::BindGroupLayout,
}

impl MeshRenderer {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        sample_count: u32,
    ) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("render_mesh.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("mesh"),
            bind_group_layouts: &[Some(scene_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("mesh"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_mesh"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: wgpu::MultisampleState {
                count: sample_count,
                ..Default::default()
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_mesh"),
                compilation_options: Default::default(),
                targets: &[Some(OFFSCREEN_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let output_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("deformed output"),
            entries: &[output_entry(0), output_entry(1)],
        });
        let compute_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("deform readback"),
            bind_group_layouts: &[Some(scene_layout), Some(&output_layout)],
            immediate_size: 0,
        });
        let deform_pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("deform readback"),
            layout: Some(&compute_layout),
            module: &module,
            entry_point: Some("cs_deform"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self {
            pipeline,
            deform_pipeline,
            output_layout,
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

    /// Run the vertex shader's deformation and colouring for every mesh vertex and
    /// read them back. Blocks until the GPU is done. The frame uniform at
    /// `frame_offset` must describe the shading wanted.
    pub fn read_back(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &SceneGpu,
        bind_group: &wgpu::BindGroup,
        frame_offset: u32,
    ) -> Result<ReadBack, wgpu::BufferAsyncError> {
        let count = scene.vertex_count as u64;
        let size = (count * 16).max(16);
        let storage = |label| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        };
        let (output, colours) = (storage("deformed positions"), storage("vertex colours"));
        // Positions, then colours.
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback staging"),
            size: 2 * size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let output_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("readback output"),
            layout: &self.output_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: output.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: colours.as_entire_binding(),
                },
            ],
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.deform_pipeline);
            pass.set_bind_group(0, bind_group, &[frame_offset]);
            pass.set_bind_group(1, &output_group, &[]);
            pass.dispatch_workgroups((scene.vertex_count).div_ceil(64).max(1), 1, 1);
        }
        encoder.copy_buffer_to_buffer(&output, 0, &staging, 0, size);
        encoder.copy_buffer_to_buffer(&colours, 0, &staging, size, size);
        queue.submit([encoder.finish()]);
        let (sender, receiver) = std::sync::mpsc::channel();
        staging.map_async(wgpu::MapMode::Read, .., move |result| {
            let _ = sender.send(result);
        });
        let _ = device.poll(wgpu::PollType::wait_indefinitely());
        receiver.recv().unwrap_or(Err(wgpu::BufferAsyncError))?;
        let read_back = {
            let view = staging
                .get_mapped_range(..)
                .map_err(|_| wgpu::BufferAsyncError)?;
            let floats: &[[f32; 4]] = bytemuck::cast_slice(&view);
            let (deformed, colours) = floats.split_at(floats.len() / 2);
            let vertices = scene.vertex_count as usize;
            ReadBack {
                positions: deformed[..vertices]
                    .iter()
                    .map(|p| Vec3::new(p[0], p[1], p[2]))
                    .collect(),
                values: deformed[..vertices].iter().map(|p| p[3]).collect(),
                colours: colours[..vertices]
                    .iter()
                    .map(|c| [c[0], c[1], c[2]])
                    .collect(),
            }
        };
        staging.unmap();
        Ok(read_back)
    }
}

fn output_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: false },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

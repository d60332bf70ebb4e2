//! Reading back what the mesh shader computes: the same deformation and colouring
//! in a compute pass, into buffers. Tests and checks use it; drawing does not, so
//! its pipeline is only made on the first readback, and an adapter that cannot run
//! it can still draw.

use super::mesh::{shader_module, CONSTANTS};
use super::scene_gpu::{ReadBack, SceneGpu};
use glam::Vec3;

pub struct Readback {
    pipeline: wgpu::ComputePipeline,
    output_layout: wgpu::BindGroupLayout,
}

impl Readback {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        chunk_slots: u32,
    ) -> Self {
        let output_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("deformed output"),
            entries: &[output_entry(0)],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("deform readback"),
            bind_group_layouts: &[Some(scene_layout), Some(&output_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("deform readback"),
            layout: Some(&layout),
            module: &shader_module(device, chunk_slots),
            entry_point: Some("cs_deform"),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: CONSTANTS,
                ..Default::default()
            },
            cache: None,
        });
        Self {
            pipeline,
            output_layout,
        }
    }

    /// Run the vertex shader's deformation and colouring for every mesh vertex and
    /// read them back. Blocks until the GPU is done. The frame uniform at
    /// `frame_offset` must describe the shading wanted.
    pub fn run(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &SceneGpu,
        bind_group: &wgpu::BindGroup,
        frame_offset: u32,
    ) -> Result<ReadBack, wgpu::BufferAsyncError> {
        let count = scene.vertex_count as u64;
        let size = (count * 16).max(16);
        // Positions, then colours.
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("deformed positions and colours"),
            size: 2 * size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback staging"),
            size: 2 * size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let output_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("readback output"),
            layout: &self.output_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: output.as_entire_binding(),
            }],
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, bind_group, &[frame_offset]);
            pass.set_bind_group(1, &output_group, &[]);
            pass.dispatch_workgroups((scene.vertex_count).div_ceil(64).max(1), 1, 1);
        }
        encoder.copy_buffer_to_buffer(&output, 0, &staging, 0, 2 * size);
        queue.submit([encoder.finish()]);
        let floats = map_vec4s(device, &staging)?;
        let vertices = scene.vertex_count as usize;
        let (deformed, colours) = floats.split_at(vertices.max(1).min(floats.len()));
        let read_back = ReadBack {
            positions: deformed[..vertices]
                .iter()
                .map(|p| Vec3::new(p[0], p[1], p[2]))
                .collect(),
            values: deformed[..vertices].iter().map(|p| p[3]).collect(),
            colours: colours[..vertices]
                .iter()
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
        };
        Ok(read_back)
    }
}

/// Map `staging` (filled by commands already submitted), wait for the GPU, and
/// copy it out as `vec4<f32>`s.
pub(super) fn map_vec4s(
    device: &wgpu::Device,
    staging: &wgpu::Buffer,
) -> Result<Vec<[f32; 4]>, wgpu::BufferAsyncError> {
    Ok(bytemuck::pod_collect_to_vec::<u8, [f32; 4]>(&map_bytes(
        device, staging,
    )?))
}

/// Map `staging` (filled by commands already submitted), wait for the GPU, and
/// copy out its bytes.
pub fn map_bytes(
    device: &wgpu::Device,
    staging: &wgpu::Buffer,
) -> Result<Vec<u8>, wgpu::BufferAsyncError> {
    let (sender, receiver) = std::sync::mpsc::channel();
    staging.map_async(wgpu::MapMode::Read, .., move |result| {
        let _ = sender.send(result);
    });
    let _ = device.poll(wgpu::PollType::wait_indefinitely());
    receiver.recv().unwrap_or(Err(wgpu::BufferAsyncError))?;
    let bytes = staging
        .get_mapped_range(..)
        .map_err(|_| wgpu::BufferAsyncError)?
        .to_vec();
    staging.unmap();
    Ok(bytes)
}

/// A compute-only writable buffer: writable storage in other stages needs features
/// not every adapter has.
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

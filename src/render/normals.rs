//! Smooth shading's vertex normals on the GPU, recomputed per pose change (never
//! per frame): the vertex shader's deformed positions are drawn into a float image
//! ([`super::drawn`]) where the weights are read as vertex attributes, or else a
//! compute pass computes them (`cs_positions` in `shaders/render_mesh.wgsl`); a
//! second pass sums each vertex's incident triangles
//! (`shaders/render_normals.wgsl`) through an adjacency built once per mesh.
//! CPU twin: [`crate::geometry::vertex_normals`].

use super::mesh::{shader_module, CONSTANTS};
use super::scene_gpu::{buffer_with, SceneGpu};
use glam::Vec3;

const SHADER: &str = include_str!("../../shaders/render_normals.wgsl");

/// `render_normals.wgsl` (it imports nothing).
pub fn shader_source() -> String {
    SHADER.to_owned()
}

/// Each vertex's triangles: `offsets[v]..offsets[v + 1]` index `corners`, which
/// hold the other two corners of each triangle in winding order, so that every
/// corner's cross product has the triangle's orientation.
pub struct Adjacency {
    pub offsets: Vec<u32>,
    pub corners: Vec<[u32; 2]>,
}

impl Adjacency {
    pub fn of(vertex_count: usize, triangles: &[[u32; 3]]) -> Self {
        let valid = |t: &&[u32; 3]| t.iter().all(|&i| (i as usize) < vertex_count);
        let mut offsets = vec![0u32; vertex_count + 1];
        for triangle in triangles.iter().filter(valid) {
            for &v in triangle {
                offsets[v as usize + 1] += 1;
            }
        }
        for v in 0..vertex_count {
            offsets[v + 1] += offsets[v];
        }
        let mut next = offsets.clone();
        let mut corners = vec![[0u32; 2]; offsets[vertex_count] as usize];
        for &[a, b, c] in triangles.iter().filter(valid) {
            for (v, others) in [(a, [b, c]), (b, [c, a]), (c, [a, b])] {
                corners[next[v as usize] as usize] = others;
                next[v as usize] += 1;
            }
        }
        Self { offsets, corners }
    }
}

/// The pipelines, made on first use.
pub struct NormalsPass {
    positions: wgpu::ComputePipeline,
    positions_layout: wgpu::BindGroupLayout,
    normals: wgpu::ComputePipeline,
    normals_layout: wgpu::BindGroupLayout,
}

fn compute_storage(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl NormalsPass {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        chunk_slots: u32,
    ) -> Self {
        let positions_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("deformed positions"),
            entries: &[compute_storage(0, false)],
        });
        let positions = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("deformed positions"),
            layout: Some(
                &device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("deformed positions"),
                    bind_group_layouts: &[Some(scene_layout), Some(&positions_layout)],
                    immediate_size: 0,
                }),
            ),
            module: &shader_module(device, chunk_slots),
            entry_point: Some("cs_positions"),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: CONSTANTS,
                ..Default::default()
            },
            cache: None,
        });
        let normals_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("vertex normals"),
            entries: &[
                compute_storage(0, true),
                compute_storage(1, true),
                compute_storage(2, true),
                compute_storage(3, false),
            ],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("render_normals.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let normals = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("vertex normals"),
            layout: Some(
                &device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some("vertex normals"),
                    bind_group_layouts: &[Some(&normals_layout)],
                    immediate_size: 0,
                }),
            ),
            module: &module,
            entry_point: Some("cs_normals"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self {
            positions,
            positions_layout,
            normals,
            normals_layout,
        }
    }

    /// Recompute the vertex normals of the family `bind_group` shows (its frame
    /// uniform at `frame_offset`) into the end of its `displacements` buffer,
    /// after the columns' vectors and matrices, into `encoder`. With `positions_drawn` the deformed
    /// positions are already in the scene's scratch buffer ([`super::drawn`]);
    /// otherwise the first pass computes them.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        scene: &SceneGpu,
        bind_group: &wgpu::BindGroup,
        frame_offset: u32,
        displacements: &wgpu::Buffer,
        positions_drawn: bool,
    ) {
        let groups = scene.vertex_count.div_ceil(64).max(1);
        let positions_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("deformed positions"),
            layout: &self.positions_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: scene.deformed_scratch.as_entire_binding(),
            }],
        });
        let buffers = [
            &scene.deformed_scratch,
            &scene.adjacency_offsets,
            &scene.adjacency_corners,
            displacements,
        ];
        let normals_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("vertex normals"),
            layout: &self.normals_layout,
            entries: &buffers
                .iter()
                .enumerate()
                .map(|(binding, buffer)| wgpu::BindGroupEntry {
                    binding: binding as u32,
                    resource: buffer.as_entire_binding(),
                })
                .collect::<Vec<_>>(),
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("vertex normals"),
            timestamp_writes: None,
        });
        if !positions_drawn {
            pass.set_pipeline(&self.positions);
            pass.set_bind_group(0, bind_group, &[frame_offset]);
            pass.set_bind_group(1, &positions_group, &[]);
            pass.dispatch_workgroups(groups, 1, 1);
        }
        pass.set_pipeline(&self.normals);
        pass.set_bind_group(0, &normals_group, &[]);
        pass.dispatch_workgroups(groups, 1, 1);
    }
}

/// The largest storage binding the normals passes add to drawing's: the corners
/// of the triangles around each vertex, as a rule (24 bytes per triangle, so
/// about 2.8 million vertices fill lavapipe's 128 MiB).
pub fn largest_binding(scene: &SceneGpu) -> u64 {
    [
        &scene.adjacency_offsets,
        &scene.adjacency_corners,
        &scene.deformed_scratch,
    ]
    .iter()
    .map(|buffer| buffer.size())
    .max()
    .unwrap_or(0)
}

/// The adjacency's GPU buffers: offsets, then corners.
pub fn adjacency_buffers(device: &wgpu::Device, adjacency: &Adjacency) -> [wgpu::Buffer; 2] {
    let storage = wgpu::BufferUsages::STORAGE;
    [
        buffer_with(
            device,
            "normal adjacency offsets",
            &adjacency.offsets,
            storage,
        ),
        buffer_with(
            device,
            "normal adjacency corners",
            &adjacency.corners,
            storage,
        ),
    ]
}

/// `method`'s normals as last computed; `None` before the first time.
pub fn read_back(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    scene: &SceneGpu,
    method: crate::coords::Method,
) -> Option<Result<Vec<Vec3>, wgpu::BufferAsyncError>> {
    let slot = scene.slots.get(&method)?;
    slot.normals_pose?;
    let offset = u64::from(slot.normals_first) * 16;
    Some(read_normals(
        device,
        queue,
        &slot.displacements,
        offset,
        scene.vertex_count as usize,
    ))
}

/// Read the normals (one `vec4` per vertex from byte `offset` of `buffer`) back
/// to the CPU; blocks until done.
pub fn read_normals(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    offset: u64,
    vertex_count: usize,
) -> Result<Vec<Vec3>, wgpu::BufferAsyncError> {
    let size = (vertex_count as u64 * 16).max(16);
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("normals staging"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(buffer, offset, &staging, 0, size);
    queue.submit([encoder.finish()]);
    let floats = super::readback::map_vec4s(device, &staging)?;
    let normals = floats
        .iter()
        .take(vertex_count)
        .map(|n| Vec3::new(n[0], n[1], n[2]))
        .collect();
    Ok(normals)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_vertex_lists_its_triangles_with_the_winding_kept() {
        let adjacency = Adjacency::of(4, &[[0, 1, 2], [2, 1, 3], [0, 1, 9]]);
        assert_eq!(adjacency.offsets, vec![0, 1, 3, 5, 6]);
        assert_eq!(adjacency.corners[0], [1, 2]);
        // Vertex 1: (2, 0) from the first triangle, (3, 2) from the second.
        assert_eq!(&adjacency.corners[1..3], &[[2, 0], [3, 2]]);
        assert_eq!(&adjacency.corners[3..5], &[[0, 1], [1, 3]]);
        assert_eq!(adjacency.corners[5], [2, 1]);
    }
}

//! The cage overlay: wire edges and vertex handles, each drawn dimmed where the
//! mesh hides it and bright where visible. Paired with `shaders/render_cage.wgsl`.

use super::scene_gpu::{SceneGpu, DEPTH_FORMAT, OFFSCREEN_FORMAT};
use crate::gpu::shader_source::compose;
use glam::Vec3;

const SHADER: &str = include_str!("../../shaders/render_cage.wgsl");

/// `render_cage.wgsl` with its imports resolved.
pub fn shader_source() -> String {
    // The shared files are compiled in, so only a broken build can fail here.
    compose("render_cage.wgsl", SHADER).unwrap_or_else(|error| panic!("{error}"))
}

pub struct CageRenderer {
    hidden_edges: wgpu::RenderPipeline,
    visible_edges: wgpu::RenderPipeline,
    hidden_handles: wgpu::RenderPipeline,
    visible_handles: wgpu::RenderPipeline,
}

impl CageRenderer {
    pub fn new(
        device: &wgpu::Device,
        scene_layout: &wgpu::BindGroupLayout,
        sample_count: u32,
    ) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("render_cage.wgsl"),
            source: wgpu::ShaderSource::Wgsl(shader_source().into()),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("cage"),
            bind_group_layouts: &[Some(scene_layout)],
            immediate_size: 0,
        });
        let pipeline = |vertex: &str, topology, hidden: bool| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(vertex),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vertex),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState {
                    topology,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    // The overlay never hides itself, only the mesh hides it.
                    depth_write_enabled: Some(false),
                    depth_compare: Some(if hidden {
                        wgpu::CompareFunction::Greater
                    } else {
                        wgpu::CompareFunction::LessEqual
                    }),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState {
                    count: sample_count,
                    ..Default::default()
                },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(if hidden { "fs_hidden" } else { "fs_visible" }),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: OFFSCREEN_FORMAT,
                        blend: Some(wgpu::BlendState::ALPHA_BLENDING),
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        use wgpu::PrimitiveTopology::{LineList, TriangleList};
        Self {
            hidden_edges: pipeline("vs_edge", LineList, true),
            visible_edges: pipeline("vs_edge", LineList, false),
            hidden_handles: pipeline("vs_handle", TriangleList, true),
            visible_handles: pipeline("vs_handle", TriangleList, false),
        }
    }

    /// Draw with `bind_group`, whose frame uniform is at `frame_offset`.
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        scene: &SceneGpu,
        bind_group: &wgpu::BindGroup,
        frame_offset: u32,
    ) {
        if scene.cage_vertex_count == 0 {
            return;
        }
        pass.set_bind_group(0, bind_group, &[frame_offset]);
        pass.set_index_buffer(scene.cage_edges.slice(..), wgpu::IndexFormat::Uint32);
        for pipeline in [&self.hidden_edges, &self.visible_edges] {
            pass.set_pipeline(pipeline);
            pass.draw_indexed(0..scene.cage_edge_index_count, 0, 0..1);
        }
        for pipeline in [&self.hidden_handles, &self.visible_handles] {
            pass.set_pipeline(pipeline);
            pass.draw(0..6, 0..scene.cage_vertex_count);
        }
    }
}

/// Cage edges worth drawing: those between faces that are not coplanar. The
/// diagonals that split flat quads and ear-clipped caps only clutter the view.
pub(super) fn feature_edges(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let normal = |[a, b, c]: [u32; 3]| {
        let p = |i: u32| positions.get(i as usize).copied().unwrap_or(Vec3::ZERO);
        (p(b) - p(a)).cross(p(c) - p(a)).normalize_or_zero()
    };
    let mut faces_of_edge: std::collections::BTreeMap<[u32; 2], Vec<Vec3>> = Default::default();
    for &triangle in triangles {
        let [a, b, c] = triangle;
        for [u, v] in [[a, b], [b, c], [c, a]] {
            faces_of_edge
                .entry([u.min(v), u.max(v)])
                .or_default()
                .push(normal(triangle));
        }
    }
    faces_of_edge
        .into_iter()
        .filter(|(_, normals)| match normals.as_slice() {
            [n, m] => n.dot(*m) < 0.9995,
            _ => true,
        })
        .map(|(edge, _)| edge)
        .collect()
}

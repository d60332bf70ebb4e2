//! The 3D viewport inside egui: GPU buffers of the scene, an offscreen colour and
//! depth target (egui's own pass has no depth buffer), and the paint callback that
//! draws the mesh and cage there and composites the image into egui's pass.
//! Paired with `shaders/render_composite.wgsl`.
//!
//! Up to [`MAX_VIEWS`] views are drawn in one frame (MVC and PMVC side by side, and
//! their difference). Each has its own slot of the frame uniform (a dynamic
//! offset) and its own offscreen target; the weights of both methods stay
//! resident, so switching the method shown is only a different bind group.

use super::cage::CageRenderer;
use super::colormap::Scale;
use super::mesh::MeshRenderer;
use crate::coords::{Method, Weights};
use eframe::egui_wgpu::{self, wgpu::util::DeviceExt};
use glam::{Mat4, Vec3};

pub const OFFSCREEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Multisampling smooths the one-pixel cage lines and the mesh silhouette. It
/// costs about 16 ms a frame on lavapipe, so software adapters default to 1.
pub const MSAA_SAMPLES: u32 = 4;
const COMPOSITE_SHADER: &str = include_str!("../../shaders/render_composite.wgsl");
/// Views drawn in one frame.
pub const MAX_VIEWS: usize = 3;
/// Frame uniform slots: one per view and one for readbacks, each at an offset that
/// every adapter accepts for dynamic uniform offsets.
const FRAME_SLOT_BYTES: u64 = 256;
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
    #[error(
        "the weights matrix needs {needed_mib:.1} MiB, but this GPU allows at most {limit_mib:.1} MiB in one storage buffer; use a smaller mesh or cage"
    )]
    WeightsTooLarge { needed_mib: f64, limit_mib: f64 },
    #[error("reading the deformed positions back from the GPU failed")]
    ReadBack,
    #[error("no scene is on the GPU")]
    NoScene,
    #[error(
        "the graphics adapter '{adapter}' cannot draw the viewport: {missing}; install a Vulkan, Metal or DirectX 12 driver (on Linux without a GPU: Mesa's lavapipe, package mesa-vulkan-drivers)"
    )]
    UnsupportedAdapter { adapter: String, missing: String },
}

/// Storage buffers one shader stage needs: the scene group's five (read by every
/// stage) and the two outputs of the readback's compute pass.
pub const STORAGE_BUFFERS_PER_STAGE: u32 = 7;

/// Whether the viewport's shaders can run on `adapter` with `device`: they read
/// storage buffers in the vertex stage and deform in a compute pass, which
/// WebGL-class adapters (wgpu's GL backend, for one) do not offer.
pub fn check_adapter(adapter: &wgpu::Adapter, device: &wgpu::Device) -> Result<(), RenderError> {
    let flags = adapter.get_downlevel_capabilities().flags;
    let storage_buffers = device.limits().max_storage_buffers_per_shader_stage;
    let missing = if !flags.contains(wgpu::DownlevelFlags::COMPUTE_SHADERS) {
        "no compute shaders".to_owned()
    } else if !flags.contains(wgpu::DownlevelFlags::VERTEX_STORAGE) {
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

/// What the mesh is coloured by.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Colouring {
    /// Plain shading.
    #[default]
    Shaded,
    /// λᵢ of one cage vertex i.
    CageVertexWeight(u32),
    /// minⱼ λⱼ per mesh vertex: where the coordinates go negative.
    MostNegativeWeight,
    /// |p′ − p′_other| between the two methods' deformations, over the cage size.
    MethodDistance,
}

impl Colouring {
    fn code(self) -> [u32; 2] {
        match self {
            Colouring::Shaded => [0, 0],
            Colouring::CageVertexWeight(vertex) => [1, vertex],
            Colouring::MostNegativeWeight => [2, 0],
            Colouring::MethodDistance => [3, 0],
        }
    }
}

/// How one view colours the mesh, and with which method's weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shading {
    /// The weights the mesh is deformed (and coloured) with.
    pub method: Method,
    pub colouring: Colouring,
    pub scale: Scale,
    /// Magnitude at which the colour map saturates.
    pub colour_limit: f32,
    /// Distances of [`Colouring::MethodDistance`] are divided by this.
    pub cage_size: f32,
}

impl Default for Shading {
    fn default() -> Self {
        Self {
            method: Method::Pmvc,
            colouring: Colouring::Shaded,
            scale: Scale::Linear,
            colour_limit: 1.0,
            cage_size: 1.0,
        }
    }
}

/// What a readback returns per mesh vertex, exactly as the shaders compute it.
#[derive(Clone, Debug, Default)]
pub struct ReadBack {
    pub positions: Vec<Vec3>,
    /// The colouring value (0 when shaded).
    pub values: Vec<f32>,
    /// The unshaded colour of each value.
    pub colours: Vec<[f32; 3]>,
}

fn method_slot(method: Method) -> usize {
    match method {
        Method::Mvc => 0,
        Method::Pmvc => 1,
    }
}

/// The uniform shared by all viewport shaders (`struct Frame` in the WGSL).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
struct FrameUniform {
    view_projection: [[f32; 4]; 4],
    eye: [f32; 4],
    viewport: [f32; 4],
    counts: [u32; 4],
    colouring: [u32; 4],
    colour_scale: [f32; 4],
}

/// Per-frame camera settings, carried by the paint callback.
#[derive(Clone, Copy, Debug)]
pub struct FrameParams {
    /// Which view this is, below [`MAX_VIEWS`].
    pub view: usize,
    pub shading: Shading,
    pub view_projection: Mat4,
    pub eye: Vec3,
    /// Viewport size in physical pixels.
    pub size_px: [u32; 2],
    pub handle_radius_px: f32,
    pub highlight_outside: bool,
}

/// What the viewport draws, uploaded when the scene changes.
pub struct SceneUpload<'a> {
    pub rest_positions: &'a [Vec3],
    pub triangles: &'a [[u32; 3]],
    pub cage_rest: &'a [Vec3],
    pub cage_triangles: &'a [[u32; 3]],
}

/// The scene's GPU buffers and their bind group.
pub struct SceneGpu {
    /// Per method shown ([`method_slot`]): that method's weights at binding 1,
    /// the other's at binding 5.
    bind_groups: [wgpu::BindGroup; 2],
    pub indices: wgpu::Buffer,
    pub index_count: u32,
    pub vertex_count: u32,
    pub cage_edges: wgpu::Buffer,
    pub cage_edge_index_count: u32,
    pub cage_vertex_count: u32,
    rest: wgpu::Buffer,
    /// Per method ([`method_slot`]).
    weights: [Option<wgpu::Buffer>; 2],
    placeholder: wgpu::Buffer,
    cage: wgpu::Buffer,
    handle_state: wgpu::Buffer,
}

struct OffscreenTarget {
    size: [u32; 2],
    /// `None` without multisampling: then the pass draws straight into `resolved`.
    multisampled: Option<wgpu::TextureView>,
    depth: wgpu::TextureView,
    resolved: wgpu::TextureView,
    composite_group: wgpu::BindGroup,
}

/// All GPU state of the viewport; lives in egui_wgpu's callback resources.
pub struct ViewportRenderer {
    scene_layout: wgpu::BindGroupLayout,
    /// One [`FRAME_SLOT_BYTES`] slot per view, then the readback slot.
    frame: wgpu::Buffer,
    mesh: MeshRenderer,
    cage: CageRenderer,
    composite: wgpu::RenderPipeline,
    composite_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    targets: [Option<OffscreenTarget>; MAX_VIEWS],
    scene: Option<SceneGpu>,
    max_storage_binding: u64,
    sample_count: u32,
}

fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX
            | wgpu::ShaderStages::FRAGMENT
            | wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl ViewportRenderer {
    /// `target_format` is the format of egui's render pass.
    /// `sample_count` is 1 or [`MSAA_SAMPLES`].
    pub fn new(
        device: &wgpu::Device,
        target_format: wgpu::TextureFormat,
        sample_count: u32,
    ) -> Self {
        let scene_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::VERTEX
                        | wgpu::ShaderStages::FRAGMENT
                        | wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: true,
                        min_binding_size: wgpu::BufferSize::new(
                            std::mem::size_of::<FrameUniform>() as u64,
                        ),
                    },
                    count: None,
                },
                storage_entry(1, true),
                storage_entry(2, true),
                storage_entry(3, true),
                storage_entry(4, true),
                storage_entry(5, true),
            ],
        });
        let frame = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame"),
            size: FRAME_SLOT_BYTES * (MAX_VIEWS as u64 + 1),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let composite_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("composite"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("render_composite.wgsl"),
            source: wgpu::ShaderSource::Wgsl(COMPOSITE_SHADER.into()),
        });
        let composite_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("composite"),
                bind_group_layouts: &[Some(&composite_layout)],
                immediate_size: 0,
            });
        let composite = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("composite"),
            layout: Some(&composite_pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_fullscreen"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_composite"),
                compilation_options: Default::default(),
                targets: &[Some(target_format.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("composite"),
            ..Default::default()
        });
        let limits = device.limits();
        Self {
            mesh: MeshRenderer::new(device, &scene_layout, sample_count),
            cage: CageRenderer::new(device, &scene_layout, sample_count),
            sample_count,
            scene_layout,
            frame,
            composite,
            composite_layout,
            sampler,
            targets: Default::default(),
            scene: None,
            max_storage_binding: limits
                .max_storage_buffer_binding_size
                .min(limits.max_buffer_size),
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
        self.mesh = MeshRenderer::new(device, &self.scene_layout, sample_count);
        self.cage = CageRenderer::new(device, &self.scene_layout, sample_count);
        self.targets = Default::default();
    }

    /// Replace the scene. Weights start unbound: the mesh shows at rest.
    pub fn upload_scene(&mut self, device: &wgpu::Device, scene: &SceneUpload<'_>) {
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let rest: Vec<[f32; 4]> = scene
            .rest_positions
            .iter()
            .map(|p| [p.x, p.y, p.z, 0.0])
            .collect();
        let rest = buffer_with(device, "rest positions", &rest, storage);
        let indices: Vec<u32> = scene.triangles.iter().flatten().copied().collect();
        let index_buffer = buffer_with(device, "mesh indices", &indices, wgpu::BufferUsages::INDEX);
        let edges = feature_edges(scene.cage_rest, scene.cage_triangles);
        let cage_positions: Vec<[f32; 4]> = scene
            .cage_rest
            .iter()
            .map(|p| [p.x, p.y, p.z, 1.0])
            .collect();
        let cage = buffer_with(device, "cage pose", &cage_positions, storage);
        let states = vec![0u32; scene.cage_rest.len().max(1)];
        let handle_state = buffer_with(device, "handle states", &states, storage);
        let placeholder = buffer_with(device, "no weights", &[0f32; 4], storage);
        let cage_edges = buffer_with(device, "cage edges", &edges, wgpu::BufferUsages::INDEX);
        let bind_group =
            || self.scene_bind_group(device, [&placeholder; 2], &rest, &cage, &handle_state);
        self.scene = Some(SceneGpu {
            bind_groups: [bind_group(), bind_group()],
            indices: index_buffer,
            index_count: indices.len() as u32,
            vertex_count: scene.rest_positions.len() as u32,
            cage_edges,
            cage_edge_index_count: edges.len() as u32 * 2,
            cage_vertex_count: scene.cage_rest.len() as u32,
            rest,
            weights: [None, None],
            placeholder,
            cage,
            handle_state,
        });
    }

    fn scene_bind_group(
        &self,
        device: &wgpu::Device,
        [shown_weights, other_weights]: [&wgpu::Buffer; 2],
        rest: &wgpu::Buffer,
        cage: &wgpu::Buffer,
        handle_state: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            }
        }
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene"),
            layout: &self.scene_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &self.frame,
                        offset: 0,
                        size: wgpu::BufferSize::new(std::mem::size_of::<FrameUniform>() as u64),
                    }),
                },
                entry(1, shown_weights),
                entry(2, rest),
                entry(3, cage),
                entry(4, handle_state),
                entry(5, other_weights),
            ],
        })
    }

    /// Bind one method's weights (or unbind them with `None`, showing the mesh at
    /// rest in views of that method). A `resident` buffer already holding them on
    /// this device is used as it is; otherwise they are uploaded. Fails, leaving
    /// the weights unbound, when the matrix exceeds the GPU's limit.
    pub fn set_weights(
        &mut self,
        device: &wgpu::Device,
        method: Method,
        weights: Option<&Weights>,
        resident: Option<&wgpu::Buffer>,
    ) -> Result<(), RenderError> {
        let limit = self.max_storage_binding;
        let Some(mut scene) = self.scene.take() else {
            return Err(RenderError::NoScene);
        };
        let mut result = Ok(());
        scene.weights[method_slot(method)] = match weights {
            Some(weights) if (weights.values.len() as u64) * 4 > limit => {
                result = Err(RenderError::WeightsTooLarge {
                    needed_mib: weights.values.len() as f64 * 4.0 / 1048576.0,
                    limit_mib: limit as f64 / 1048576.0,
                });
                None
            }
            Some(weights) if !weights.values.is_empty() => Some(match resident {
                Some(buffer) => buffer.clone(),
                None => buffer_with(
                    device,
                    "weights",
                    &weights.values,
                    wgpu::BufferUsages::STORAGE,
                ),
            }),
            _ => None,
        };
        let buffer = |slot: usize| scene.weights[slot].as_ref().unwrap_or(&scene.placeholder);
        let group = |shown: usize| {
            self.scene_bind_group(
                device,
                [buffer(shown), buffer(1 - shown)],
                &scene.rest,
                &scene.cage,
                &scene.handle_state,
            )
        };
        let bind_groups = [group(0), group(1)];
        scene.bind_groups = bind_groups;
        self.scene = Some(scene);
        result
    }

    /// Mark the mesh vertices outside the cage (drawn red when highlighted).
    pub fn set_outside(&mut self, queue: &wgpu::Queue, rest_positions: &[Vec3], outside: &[u32]) {
        let Some(scene) = &self.scene else { return };
        let mut rest: Vec<[f32; 4]> = rest_positions
            .iter()
            .map(|p| [p.x, p.y, p.z, 0.0])
            .collect();
        for &i in outside {
            if let Some(vertex) = rest.get_mut(i as usize) {
                vertex[3] = 1.0;
            }
        }
        if rest.len() as u32 == scene.vertex_count {
            queue.write_buffer(&scene.rest, 0, bytemuck::cast_slice(&rest));
        }
    }

    /// Upload the deformed cage; called only when the pose changes.
    pub fn set_cage_pose(&mut self, queue: &wgpu::Queue, pose: &[Vec3]) {
        let Some(scene) = &self.scene else { return };
        if pose.len() as u32 != scene.cage_vertex_count {
            return;
        }
        let positions: Vec<[f32; 4]> = pose.iter().map(|p| [p.x, p.y, p.z, 1.0]).collect();
        queue.write_buffer(&scene.cage, 0, bytemuck::cast_slice(&positions));
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
            .is_some_and(|scene| scene.weights[method_slot(method)].is_some())
    }

    fn frame_uniform(&self, params: &FrameParams) -> FrameUniform {
        let shading = &params.shading;
        let slot = method_slot(shading.method);
        let (columns, weights_bound, other_bound, vertices) = match &self.scene {
            Some(scene) => (
                scene.cage_vertex_count,
                scene.weights[slot].is_some() as u32,
                scene.weights[1 - slot].is_some() as u32,
                scene.vertex_count,
            ),
            None => (0, 0, 0, 0),
        };
        let [colouring, cage_vertex] = shading.colouring.code();
        FrameUniform {
            view_projection: params.view_projection.to_cols_array_2d(),
            eye: params.eye.extend(1.0).to_array(),
            viewport: [
                params.size_px[0] as f32,
                params.size_px[1] as f32,
                params.handle_radius_px,
                0.0,
            ],
            counts: [
                columns,
                weights_bound,
                params.highlight_outside as u32,
                vertices,
            ],
            colouring: [
                colouring,
                cage_vertex,
                (shading.scale == Scale::LogMagnitude) as u32,
                other_bound,
            ],
            colour_scale: [shading.colour_limit, shading.cage_size, 0.0, 0.0],
        }
    }

    fn write_frame_slot(&self, queue: &wgpu::Queue, slot: usize, uniform: &FrameUniform) {
        queue.write_buffer(
            &self.frame,
            slot as u64 * FRAME_SLOT_BYTES,
            bytemuck::bytes_of(uniform),
        );
    }

    /// The deformed mesh positions, colouring values and colours exactly as the
    /// shaders compute them for `shading`.
    pub fn read_back(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        shading: &Shading,
    ) -> Result<ReadBack, RenderError> {
        let params = FrameParams {
            view: READBACK_SLOT,
            shading: *shading,
            view_projection: Mat4::IDENTITY,
            eye: Vec3::ZERO,
            size_px: [1, 1],
            handle_radius_px: 0.0,
            highlight_outside: false,
        };
        let uniform = self.frame_uniform(&params);
        self.write_frame_slot(queue, READBACK_SLOT, &uniform);
        let Some(scene) = &self.scene else {
            return Err(RenderError::NoScene);
        };
        let bind_group = &scene.bind_groups[method_slot(shading.method)];
        let offset = (READBACK_SLOT as u64 * FRAME_SLOT_BYTES) as u32;
        self.mesh
            .read_back(device, queue, scene, bind_group, offset)
            .map_err(|_| RenderError::ReadBack)
    }

    fn ensure_target(&mut self, device: &wgpu::Device, view: usize, size: [u32; 2]) {
        let samples = self.sample_count;
        if self.targets[view].as_ref().is_some_and(|t| t.size == size) {
            return;
        }
        let extent = wgpu::Extent3d {
            width: size[0],
            height: size[1],
            depth_or_array_layers: 1,
        };
        let texture = |label, format, samples, usage| {
            device
                .create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: extent,
                    mip_level_count: 1,
                    sample_count: samples,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage,
                    view_formats: &[],
                })
                .create_view(&Default::default())
        };
        let attachment = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let resolved = texture(
            "viewport image",
            OFFSCREEN_FORMAT,
            1,
            attachment | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let composite_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("composite"),
            layout: &self.composite_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&resolved),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
            ],
        });
        self.targets[view] = Some(OffscreenTarget {
            size,
            multisampled: (samples > 1)
                .then(|| texture("viewport msaa", OFFSCREEN_FORMAT, samples, attachment)),
            depth: texture("viewport depth", DEPTH_FORMAT, samples, attachment),
            composite_group,
            resolved,
        });
    }
}

/// Cage edges worth drawing: those between faces that are not coplanar. The
/// diagonals that split flat quads and ear-clipped caps only clutter the view.
fn feature_edges(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
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

fn buffer_with<T: bytemuck::Pod>(
    device: &wgpu::Device,
    label: &str,
    contents: &[T],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    // wgpu rejects empty buffers; an empty slice gets one zeroed element's worth.
    let bytes: &[u8] = bytemuck::cast_slice(contents);
    let padding = [0u8; 16];
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: if bytes.is_empty() { &padding } else { bytes },
        usage,
    })
}

/// The paint callback for one frame of the viewport.
pub struct ViewportCallback {
    pub params: FrameParams,
}

impl egui_wgpu::CallbackTrait for ViewportCallback {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen_descriptor: &egui_wgpu::ScreenDescriptor,
        encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        let Some(renderer) = resources.get_mut::<ViewportRenderer>() else {
            return Vec::new();
        };
        let view = self.params.view.min(MAX_VIEWS - 1);
        let size = [self.params.size_px[0].max(1), self.params.size_px[1].max(1)];
        renderer.ensure_target(device, view, size);
        let uniform = renderer.frame_uniform(&self.params);
        renderer.write_frame_slot(queue, view, &uniform);
        let Some(target) = &renderer.targets[view] else {
            return Vec::new();
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
        if let Some(scene) = &renderer.scene {
            let bind_group = &scene.bind_groups[method_slot(self.params.shading.method)];
            let offset = (view as u64 * FRAME_SLOT_BYTES) as u32;
            renderer.mesh.draw(&mut pass, scene, bind_group, offset);
            renderer.cage.draw(&mut pass, scene, bind_group, offset);
        }
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        let Some(renderer) = resources.get::<ViewportRenderer>() else {
            return;
        };
        let Some(target) = &renderer.targets[self.params.view.min(MAX_VIEWS - 1)] else {
            return;
        };
        pass.set_pipeline(&renderer.composite);
        pass.set_bind_group(0, &target.composite_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

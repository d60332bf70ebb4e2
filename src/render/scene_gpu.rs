//! What every viewport renderer shares: target formats, the frame uniform, and the
//! scene's GPU buffers with their bind-group layout. A leaf: it imports nothing else
//! from `render`, and the renderers ([`super::mesh`], [`super::cage`]) depend on it,
//! never on the orchestrator ([`super::viewport`]), as re_renderer's renderers
//! depend on its global bindings.

use super::draw_order::{draw_order, unique_edges};
use super::scene_origin::SceneOrigin;
use super::weight_attributes::{AttributeBlend, AttributeWeights};
use super::weight_chunks::{
    ChunkLimits, ChunkSplit, FIRST_CHUNK_BINDING, OTHER_STORAGE_BUFFERS, UNIFORM_COLUMNS,
};
use crate::coords::{BindOptions, Method, Parameter, WeightsId};
use crate::geometry::Cage;
use eframe::egui_wgpu::wgpu::util::DeviceExt;
use glam::DVec3;
use std::collections::{BTreeMap, HashMap};

pub const OFFSCREEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Bytes per frame-uniform slot: an offset every adapter accepts for dynamic
/// uniform offsets.
pub const FRAME_SLOT_BYTES: u64 = 256;

/// The uniform of every viewport shader: `struct Frame` in
/// `shaders/shared/frame.wgsl` (layouts compared by `tests/gpu/shader_layouts.rs`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameUniform {
    pub view_projection: [[f32; 4]; 4],
    pub eye: [f32; 3],
    pub handle_radius_px: f32,
    pub viewport_size_px: [f32; 2],
    pub colour_limit: f32,
    pub cage_size: f32,
    pub columns: u32,
    pub weights_bound: u32,
    pub highlight_outside: u32,
    pub vertex_count: u32,
    pub colouring: u32,
    pub colouring_column: u32,
    pub log_scale: u32,
    pub other_columns: u32,
    /// Weights rows in each chunk buffer of the family shown
    /// ([`super::weight_chunks`]).
    pub rows_per_chunk: u32,
    /// The same for the compared family.
    pub other_rows_per_chunk: u32,
    /// The pool slot of the compared family's first chunk.
    pub other_first_chunk: u32,
    /// 1 for smooth shading (per-vertex normals), 0 for faceted.
    pub smooth_shading: u32,
    /// The weights columns of the cage vertices (the negativity view's minimum
    /// runs over these; Green coordinates' triangle columns follow them).
    pub vertex_columns: u32,
    /// Texels per row of the image [`super::drawn`] reads the drawn positions from.
    pub probe_width: u32,
    /// Columns per cage vertex ([`ColumnLayout::columns_per_element`]): the
    /// negativity view's minimum takes every such column from the first.
    ///
    /// [`ColumnLayout::columns_per_element`]: crate::coords::family::ColumnLayout::columns_per_element
    pub vertex_column_stride: u32,
    /// Columns whose matrices the shown family's blend solves with (a
    /// normalised [`crate::coords::ColumnMoves`]); 0 for a linear move.
    pub matrix_columns: u32,
    /// The same for the compared family.
    pub other_matrix_columns: u32,
    /// Where the shown family's vertex normals start in its displacements
    /// ([`WeightSlot::normals_first`]).
    pub normals_first: u32,
    /// Rounds the size up to WGSL's 16-byte struct alignment.
    pub _padding: [u32; 2],
}

/// Texels per row of the image [`super::drawn`] draws the deformed positions
/// into: 1,024 `vec4<f32>`s are 16 KiB, a multiple of the 256-byte row alignment
/// of texture copies, so the rows read back contiguous.
pub const PROBE_WIDTH: u32 = 1024;

/// Bytes of the drawn positions of `vertex_count` vertices: whole image rows.
pub fn padded_bytes(vertex_count: u32) -> u64 {
    u64::from(vertex_count.div_ceil(PROBE_WIDTH).max(1)) * u64::from(PROBE_WIDTH) * 16
}

/// Scene bindings: 0 frame, 1 rest positions, 2 column displacements of the family
/// shown (followed by its vertex normals), 3 cage pose, 4 handle states, 5 column
/// displacements of the compared family; 6 and 7 the first [`UNIFORM_COLUMNS`]
/// column displacements of both families again, as uniforms; from
/// [`FIRST_CHUNK_BINDING`] the pool of weight chunks.
const SCENE_STORAGE_BINDINGS: [u32; OTHER_STORAGE_BUFFERS as usize] = [1, 2, 3, 4, 5];
const UNIFORM_DISPLACEMENT_BINDINGS: [u32; 2] = [6, 7];
/// Bytes of each uniform copy of the column displacements.
pub const UNIFORM_DISPLACEMENT_BYTES: u64 = UNIFORM_COLUMNS as u64 * 16;

/// Storage buffers the drawing shaders read in one stage, with the smallest pool
/// of weight chunks (one per family).
pub const STORAGE_BUFFERS_PER_STAGE: u32 = OTHER_STORAGE_BUFFERS + 2;

/// The layout of the scene bind group (group 0 of every viewport shader), with
/// `chunk_slots` weight chunks.
pub fn scene_layout(device: &wgpu::Device, chunk_slots: u32) -> wgpu::BindGroupLayout {
    let mut entries = vec![wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::VERTEX
            | wgpu::ShaderStages::FRAGMENT
            | wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: true,
            min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<FrameUniform>() as u64),
        },
        count: None,
    }];
    entries.extend(SCENE_STORAGE_BINDINGS.map(|binding| storage_entry(binding, true)));
    entries.extend(
        UNIFORM_DISPLACEMENT_BINDINGS.map(|binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: wgpu::BufferSize::new(UNIFORM_DISPLACEMENT_BYTES),
            },
            count: None,
        }),
    );
    entries.extend(
        (FIRST_CHUNK_BINDING..FIRST_CHUNK_BINDING + chunk_slots)
            .map(|binding| storage_entry(binding, true)),
    );
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("scene"),
        entries: &entries,
    })
}

/// A storage buffer binding visible to every stage.
pub fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
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

/// A buffer holding `contents`; wgpu rejects empty buffers, so an empty slice gets
/// one zeroed element's worth.
pub fn buffer_with<T: bytemuck::Pod>(
    device: &wgpu::Device,
    label: &str,
    contents: &[T],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    let bytes: &[u8] = bytemuck::cast_slice(contents);
    let padding = [0u8; 16];
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: if bytes.is_empty() { &padding } else { bytes },
        usage,
    })
}

/// A family's column moves as the shader reads them
/// ([`crate::coords::ColumnMoves`], about the scene origin).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShaderMoves {
    /// One per column: its vector (its displacement when linear).
    pub vectors: Vec<[f32; 4]>,
    /// Three per column, the columns of its matrix, up to the last column
    /// whose matrix is not zero; empty when linear.
    pub matrices: Vec<[f32; 4]>,
}

impl ShaderMoves {
    /// Columns carrying matrices.
    pub fn matrix_columns(&self) -> u32 {
        (self.matrices.len() / 3) as u32
    }
}

/// One family's weights on the GPU, in chunks of whole rows, and how far each of
/// its columns' vectors moved in the current pose (`Method::column_displacements`).
pub struct WeightSlot {
    pub chunks: Vec<wgpu::Buffer>,
    pub split: ChunkSplit,
    /// One `vec4` per column, then for a family whose columns may carry
    /// matrices room for three `vec4`s per column (the columns of each
    /// column's matrix, for a normalised move), then (smooth shading) one
    /// normal per mesh vertex, last as `shaders/render_normals.wgsl` writes
    /// them: one buffer, so that drawing needs no storage binding more than
    /// devices with the default 8 per stage have.
    pub displacements: wgpu::Buffer,
    /// Where the vertex normals start in `displacements`, in `vec4`s.
    pub normals_first: u32,
    /// Columns whose matrices the current pose's moves carry (0: linear).
    pub matrix_columns: u32,
    /// The first [`UNIFORM_COLUMNS`] displacements again, where the blend reads
    /// them ([`UNIFORM_DISPLACEMENT_BYTES`], zero past the columns).
    pub uniform_displacements: wgpu::Buffer,
    pub columns: u32,
    /// How the weights were bound (their family, parameters and the cage's
    /// quads: Green's columns differ with them as patches, QGC, or split).
    pub options: BindOptions,
    /// How the rows' first columns are read as vertex attributes from the one
    /// chunk; `None`: from storage alone.
    pub attributes: Option<AttributeBlend>,
    /// The pose revision the normals were computed for; `None` before the first.
    pub normals_pose: Option<u64>,
}

impl WeightSlot {
    /// The weights as vertex attributes, where they are read so.
    pub fn attribute_weights(&self) -> Option<AttributeWeights<'_>> {
        Some((self.attributes?, self.chunks.first()?))
    }
}

/// The scene's GPU buffers: one mesh and cage, and the weights of every family
/// bound so far.
pub struct SceneGpu {
    pub indices: wgpu::Buffer,
    pub index_count: u32,
    /// Bumped by every pose upload, so normals know when they are stale.
    pub pose_revision: u64,
    /// Smooth shading: each vertex's triangles ([`super::normals::Adjacency`]),
    /// and room for one family's deformed positions.
    pub adjacency_offsets: wgpu::Buffer,
    pub adjacency_corners: wgpu::Buffer,
    pub deformed_scratch: wgpu::Buffer,
    /// Each mesh edge once, as line-list indices, for the wireframe overlay.
    pub mesh_edges: wgpu::Buffer,
    pub mesh_edge_index_count: u32,
    pub vertex_count: u32,
    pub cage_edges: wgpu::Buffer,
    pub cage_edge_index_count: u32,
    pub cage_vertex_count: u32,
    /// Where every position uploaded is measured from (scene coordinates).
    pub origin: SceneOrigin,
    /// xyz: rest position (scene coordinates); w: 1 for a vertex outside the cage.
    pub rest: wgpu::Buffer,
    /// The posed cage (scene coordinates), for drawing its edges and handles.
    pub cage: wgpu::Buffer,
    pub handle_state: wgpu::Buffer,
    /// Bound where a view's family has no weights yet.
    pub placeholder: wgpu::Buffer,
    /// The same for the uniform copy of the displacements.
    pub uniform_placeholder: wgpu::Buffer,
    pub slots: BTreeMap<Method, WeightSlot>,
    /// Each family's triangulated twin, where one is bound (the difference view's
    /// quads-split comparison).
    pub twin_slots: BTreeMap<Method, WeightSlot>,
    /// The rest cage and the current pose, in f64: displacements are taken in f64
    /// and only then rounded.
    pub rest_cage: Cage,
    pub pose: Vec<DVec3>,
    /// The deformation settings the displacements are computed with, where
    /// not at their defaults (Somigliana's bulging).
    pub deform: Vec<(Parameter, u32)>,
    /// How weights are split on this device.
    pub chunk_limits: ChunkLimits,
    /// Per (family shown, family compared): its bind group, made on first use.
    bind_groups: HashMap<(Method, Option<WeightsId>), wgpu::BindGroup>,
}

impl SceneGpu {
    /// `rest_positions` are the mesh's in world coordinates, uploaded relative
    /// to `origin`.
    pub fn new(
        device: &wgpu::Device,
        rest_positions: &[DVec3],
        triangles: &[[u32; 3]],
        rest_cage: &Cage,
        cage_edges: &[[u32; 2]],
        origin: SceneOrigin,
        chunk_limits: ChunkLimits,
    ) -> Self {
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let rest = origin.points_to_scene(rest_positions, 0.0);
        let indices = draw_order(triangles, rest_positions.len());
        let edges = unique_edges(triangles);
        let adjacency = super::normals::Adjacency::of(rest_positions.len(), triangles);
        let [adjacency_offsets, adjacency_corners] =
            super::normals::adjacency_buffers(device, &adjacency);
        // Whole rows of the image `render::drawn` copies the positions from.
        let deformed_scratch = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("deformed positions"),
            size: padded_bytes(rest_positions.len() as u32),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let pose = rest_cage.positions().to_vec();
        let states = vec![0u32; pose.len().max(1)];
        Self {
            indices: buffer_with(device, "mesh indices", &indices, wgpu::BufferUsages::INDEX),
            index_count: indices.len() as u32,
            pose_revision: 0,
            adjacency_offsets,
            adjacency_corners,
            deformed_scratch,
            mesh_edges: buffer_with(device, "mesh edges", &edges, wgpu::BufferUsages::INDEX),
            mesh_edge_index_count: edges.len() as u32 * 2,
            vertex_count: rest_positions.len() as u32,
            cage_edges: buffer_with(device, "cage edges", cage_edges, wgpu::BufferUsages::INDEX),
            cage_edge_index_count: cage_edges.len() as u32 * 2,
            cage_vertex_count: pose.len() as u32,
            origin,
            rest: buffer_with(device, "rest positions", &rest, storage),
            cage: buffer_with(
                device,
                "cage pose",
                &origin.points_to_scene(&pose, 1.0),
                storage,
            ),
            handle_state: buffer_with(device, "handle states", &states, storage),
            placeholder: buffer_with(device, "no weights", &[0f32; 4], storage),
            uniform_placeholder: uniform_displacements_buffer(device, &[]),
            slots: BTreeMap::new(),
            twin_slots: BTreeMap::new(),
            rest_cage: rest_cage.clone(),
            pose,
            deform: Vec::new(),
            chunk_limits,
            bind_groups: HashMap::new(),
        }
    }

    /// Write `displacements` (a family's columns, as [`Self::displacements_of`]
    /// gives them) to that family's uniform copy.
    pub fn write_uniform_displacements(
        queue: &wgpu::Queue,
        slot: &WeightSlot,
        displacements: &[[f32; 4]],
    ) {
        let head = &displacements[..displacements.len().min(UNIFORM_COLUMNS as usize)];
        queue.write_buffer(&slot.uniform_displacements, 0, bytemuck::cast_slice(head));
    }

    /// The column moves of weights bound with `bound` for the current pose
    /// and deformation settings, as the shader reads them: about the scene
    /// origin, as the rest positions are.
    pub fn displacements_of(&self, bound: &BindOptions) -> ShaderMoves {
        let mut options = *bound;
        for &(parameter, value) in &self.deform {
            options.set(parameter, value);
        }
        let moves =
            (options.column_moves(&self.rest_cage, &self.pose)).about(self.origin.world_from_scene);
        // Up to the last column that carries a matrix (`ColumnMoves::matrices`),
        // where the vertex shader's matrix blend stops.
        let matrices = moves.matrices().iter().flat_map(|m| {
            [m.x_axis, m.y_axis, m.z_axis].map(|c| [c.x as f32, c.y as f32, c.z as f32, 0.0])
        });
        ShaderMoves {
            vectors: points_f32(moves.vectors(), 0.0),
            matrices: matrices.collect(),
        }
    }

    /// Write `moves` (as [`Self::displacements_of`] gives them) to `slot`'s
    /// buffers: the vectors first, the matrices after them.
    pub fn write_moves(queue: &wgpu::Queue, slot: &WeightSlot, moves: &ShaderMoves) {
        queue.write_buffer(&slot.displacements, 0, bytemuck::cast_slice(&moves.vectors));
        if !moves.matrices.is_empty() {
            let offset = u64::from(slot.columns) * 16;
            let bytes = bytemuck::cast_slice(&moves.matrices);
            queue.write_buffer(&slot.displacements, offset, bytes);
        }
        Self::write_uniform_displacements(queue, slot, &moves.vectors);
    }

    /// The slot of weights `id`, if bound.
    pub fn slot(&self, id: WeightsId) -> Option<&WeightSlot> {
        match id.twin {
            None => self.slots.get(&id.method),
            Some(_) => self.twin_slots.get(&id.method),
        }
    }

    /// Install or remove the weights `id`; bind groups that used the old ones go.
    pub fn set_slot(&mut self, id: WeightsId, slot: Option<WeightSlot>) {
        let slots = match id.twin {
            None => &mut self.slots,
            Some(_) => &mut self.twin_slots,
        };
        match slot {
            Some(slot) => slots.insert(id.method, slot),
            None => slots.remove(&id.method),
        };
        let primary = id.twin.is_none();
        self.bind_groups.retain(|(shown, against), _| {
            !(primary && *shown == id.method) && against.is_none_or(|a| a.method != id.method)
        });
    }

    /// The bind group showing `shown` (and `against` for the difference view).
    pub fn bind_group(
        &mut self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        frame: &wgpu::Buffer,
        shown: Method,
        against: Option<WeightsId>,
    ) -> &wgpu::BindGroup {
        if !self.bind_groups.contains_key(&(shown, against)) {
            let group = self.make_bind_group(device, layout, frame, shown, against);
            self.bind_groups.insert((shown, against), group);
        }
        &self.bind_groups[&(shown, against)]
    }

    fn make_bind_group(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        frame: &wgpu::Buffer,
        shown: Method,
        against: Option<WeightsId>,
    ) -> wgpu::BindGroup {
        let slot = |id: Option<WeightsId>| id.and_then(|id| self.slot(id));
        let shown = WeightsId::of(shown);
        let moves = |method| slot(method).map_or(&self.placeholder, |s| &s.displacements);
        let uniform_moves =
            |method| slot(method).map_or(&self.uniform_placeholder, |s| &s.uniform_displacements);
        let buffers = [
            &self.rest,
            moves(Some(shown)),
            &self.cage,
            &self.handle_state,
            moves(against),
        ];
        // The pool: the shown family's chunks, then the compared family's.
        let chunks = [shown]
            .into_iter()
            .chain(against)
            .flat_map(|id| self.slot(id).into_iter().flat_map(|slot| &slot.chunks));
        let pool = chunks
            .chain(std::iter::repeat(&self.placeholder))
            .take(self.chunk_limits.slots as usize);
        let mut entries = vec![wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: frame,
                offset: 0,
                size: wgpu::BufferSize::new(std::mem::size_of::<FrameUniform>() as u64),
            }),
        }];
        entries.extend(
            SCENE_STORAGE_BINDINGS
                .iter()
                .copied()
                .zip(buffers)
                .chain(
                    UNIFORM_DISPLACEMENT_BINDINGS
                        .into_iter()
                        .zip([uniform_moves(Some(shown)), uniform_moves(against)]),
                )
                .chain((FIRST_CHUNK_BINDING..).zip(pool))
                .map(|(binding, buffer)| wgpu::BindGroupEntry {
                    binding,
                    resource: buffer.as_entire_binding(),
                }),
        );
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene"),
            layout,
            entries: &entries,
        })
    }
}

/// A uniform copy of the first [`UNIFORM_COLUMNS`] of `displacements`, zero past
/// them.
pub fn uniform_displacements_buffer(
    device: &wgpu::Device,
    displacements: &[[f32; 4]],
) -> wgpu::Buffer {
    let mut head = vec![[0f32; 4]; UNIFORM_COLUMNS as usize];
    let count = displacements.len().min(head.len());
    head[..count].copy_from_slice(&displacements[..count]);
    buffer_with(
        device,
        "column displacements (uniform copy)",
        &head,
        wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
    )
}

/// Vectors (displacements, not positions) as the shaders' `vec4<f32>`, with `w`
/// as given.
pub fn points_f32(points: &[DVec3], w: f32) -> Vec<[f32; 4]> {
    points
        .iter()
        .map(|p| [p.x as f32, p.y as f32, p.z as f32, w])
        .collect()
}

/// What a readback returns per mesh vertex, exactly as the shaders compute it.
#[derive(Clone, Debug, Default)]
pub struct ReadBack {
    /// In scene coordinates ([`SceneGpu::origin`]) as the renderer reads them;
    /// the editor's read-backs turn them into world coordinates.
    pub positions: Vec<glam::Vec3>,
    /// The colouring value (0 when shaded).
    pub values: Vec<f32>,
    /// The unshaded colour of each value.
    pub colours: Vec<[f32; 3]>,
}

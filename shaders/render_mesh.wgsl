// Deformed mesh: the vertex shader computes p' = p + Σ_k W[i,k] · d_k from the
// dense weights (row-major f32, split by rows over chunk buffers that
// `blend_row`, `blend_other_row`, `lowest_in_row` and `chunk_weight` read;
// render::weight_chunks appends them and their bindings, whose number depends on
// the device; where the device allows, the first columns of each row arrive as
// vertex attributes instead, see render::weight_attributes, whose entry points
// `vs_*_attributes` are appended too) and each weights column's displacement d_k
// (`Method::column_displacements`, uploaded per pose change), so the CPU never
// touches mesh positions per frame. The displacement form is exact at rest for any
// weights and keeps its precision far from the origin. A family whose columns
// also carry matrices (coords::ColumnMoves, normalised: Somigliana coordinates
// with a local blend) has them after the vectors, and the blended position is
// solved with their blend: p' = (I + Σ_k W[i,k] · M_k)⁻¹ (p + Σ_k W[i,k] · d_k).
// Smooth shading reads each vertex's normal of the deformed mesh, recomputed per pose change; faceted
// shading takes screen-space derivatives of the deformed position.
//
// Besides plain shading the mesh can be coloured by a scalar per vertex: the
// weight of one cage vertex, the vertex's most negative weight, or the distance
// between its MVC and PMVC deformations. The colour functions are twins of
// src/render/colormap.rs. Paired with src/render/mesh.rs.

#import frame

@group(0) @binding(0) var<uniform> frame: Frame;
// xyz: rest position; w: 1 for a vertex outside the cage.
@group(0) @binding(1) var<storage, read> rest: array<vec4<f32>>;
// xyz: how far each weights column's vector moved from rest, for the method shown.
@group(0) @binding(2) var<storage, read> displacements: array<vec4<f32>>;
// After them, for a family whose columns may carry matrices, three `vec4`s per
// column (the columns of its matrix, coords::ColumnMoves, normalised); last,
// from `frame.normals_first`, smooth shading's vertex normals of the deformed
// mesh, recomputed per pose change (shaders/render_normals.wgsl).
// The same for the compared method (the difference view).
@group(0) @binding(5) var<storage, read> other_displacements: array<vec4<f32>>;
// The first UNIFORM_COLUMNS of both again, in uniform buffers: where the blend
// reads them (see render::weight_chunks::UNIFORM_COLUMNS for why).
@group(0) @binding(6) var<uniform> uniform_displacements: array<vec4<f32>, UNIFORM_COLUMNS>;
@group(0) @binding(7) var<uniform> uniform_other_displacements: array<vec4<f32>, UNIFORM_COLUMNS>;

const NEGATIVE = vec3<f32>(0.16, 0.29, 0.80);
const ZERO = vec3<f32>(0.97, 0.97, 0.97);
const POSITIVE = vec3<f32>(0.80, 0.08, 0.10);
// colormap::OUTSIDE: the negativity view's vertices outside the cage.
const OUTSIDE = vec3<f32>(0.55, 0.55, 0.55);
// Set from colormap::LOG_DECADES when the pipeline is made.
override LOG_DECADES: f32 = 3.0;
// False in the pipeline that only shades (render::mesh): the colouring code is
// then compiled out, which lavapipe would otherwise run for every vertex and
// fragment, since it runs both sides of a branch it cannot prove uniform.
override COLOURED: bool = true;
const LN_10: f32 = 2.302585093;

// Where a vertex's weights row starts: x, the pool slot of its chunk; y, the
// index of its first weight there.
fn row_start(vertex: u32, rows_per_chunk: u32, columns: u32, first_chunk: u32) -> vec2<u32> {
    let chunk = vertex / max(rows_per_chunk, 1u);
    let row = vertex - chunk * rows_per_chunk;
    return vec2<u32>(first_chunk + chunk, row * columns);
}

fn deformed_position(vertex: u32) -> vec3<f32> {
    return deformed_position_after(vertex, 0u, vec3<f32>(0.0));
}

// The deformed position when the row's first `first_column` columns, blended
// elsewhere (from vertex attributes), moved the vertex by `head`. The sum goes on
// in the same order as from column 0.
fn deformed_position_after(vertex: u32, first_column: u32, head: vec3<f32>) -> vec3<f32> {
    if frame.weights_bound == 0u {
        return rest[vertex].xyz;
    }
    let start = row_start(vertex, frame.rows_per_chunk, frame.columns, 0u);
    let moved = rest[vertex].xyz + blend_row(start.x, start.y, first_column, frame.columns, head);
    return shown_normalised(vertex, moved);
}

// `moved` (p + Σ W d) solved with the shown family's blended matrix; itself for a
// linear family, whose matrix blend is empty.
fn shown_normalised(vertex: u32, moved: vec3<f32>) -> vec3<f32> {
    let start = row_start(vertex, frame.rows_per_chunk, frame.columns, 0u);
    return solved(blend_matrix_row(start.x, start.y, frame.matrix_columns, frame.columns), moved);
}

// (I + stretch)⁻¹ moved, by the adjugate: with a zero `stretch` every product is
// by 0 or 1, so a linear family's position comes back exactly.
fn solved(stretch: mat3x3<f32>, moved: vec3<f32>) -> vec3<f32> {
    let m = mat3x3<f32>(
        stretch[0] + vec3<f32>(1.0, 0.0, 0.0),
        stretch[1] + vec3<f32>(0.0, 1.0, 0.0),
        stretch[2] + vec3<f32>(0.0, 0.0, 1.0),
    );
    let r0 = cross(m[1], m[2]);
    let r1 = cross(m[2], m[0]);
    let r2 = cross(m[0], m[1]);
    let determinant = dot(m[0], r0);
    if abs(determinant) < 1e-30 {
        return moved;
    }
    return vec3<f32>(dot(r0, moved), dot(r1, moved), dot(r2, moved)) / determinant;
}

fn other_deformed_position(vertex: u32) -> vec3<f32> {
    let start = row_start(
        vertex,
        frame.other_rows_per_chunk,
        frame.other_columns,
        frame.other_first_chunk,
    );
    let moved = rest[vertex].xyz
        + blend_other_row(start.x, start.y, 0u, frame.other_columns, vec3<f32>(0.0));
    let base = frame.other_columns;
    let stretch = blend_other_matrix_row(start.x, start.y, frame.other_matrix_columns, base);
    return solved(stretch, moved);
}

// The scalar the mesh is coloured by (0 when shaded or unbound).
fn vertex_value(vertex: u32, position: vec3<f32>) -> f32 {
    let columns = frame.columns;
    if frame.weights_bound == 0u || columns == 0u {
        return 0.0;
    }
    let start = row_start(vertex, frame.rows_per_chunk, columns, 0u);
    switch frame.colouring {
        case COLOURING_COLUMN_WEIGHT: {
            let column = min(frame.colouring_column, columns - 1u);
            return chunk_weight(start.x, start.y + column);
        }
        case COLOURING_MOST_NEGATIVE: {
            let stride = max(frame.vertex_column_stride, 1u);
            return lowest_in_row(start.x, start.y, min(columns, frame.vertex_columns), stride);
        }
        case COLOURING_METHOD_DISTANCE: {
            if frame.other_columns == 0u {
                return 0.0;
            }
            let other = other_deformed_position(vertex);
            return length(position - other) / max(frame.cage_size, 1e-30);
        }
        default: {
            return 0.0;
        }
    }
}

// `value` scaled to [-1, 1] against `limit` (colormap::scaled).
fn scaled(value: f32, limit: f32, log_scale: bool) -> f32 {
    let safe_limit = max(limit, 1e-30);
    if !log_scale {
        return clamp(value / safe_limit, -1.0, 1.0);
    }
    let magnitude = abs(value) / safe_limit;
    if magnitude <= 0.0 {
        return 0.0;
    }
    let strength = clamp(1.0 + log(magnitude) / LN_10 / LOG_DECADES, 0.0, 1.0);
    return select(strength, -strength, value < 0.0);
}

// Blue at -1, white at 0, red at +1 (colormap::diverging).
fn diverging(t: f32) -> vec3<f32> {
    let clamped = clamp(t, -1.0, 1.0);
    if clamped < 0.0 {
        return mix(ZERO, NEGATIVE, -clamped);
    }
    return mix(ZERO, POSITIVE, clamped);
}

fn heat_colour(value: f32) -> vec3<f32> {
    return diverging(scaled(value, frame.colour_limit, frame.log_scale == 1u));
}

// A vertex's colour: the heat colour of its value, but grey in the negativity
// view for a vertex outside the cage, whose weights follow the outside policy.
fn value_colour(value: f32, outside_cage: bool) -> vec3<f32> {
    if frame.colouring == COLOURING_MOST_NEGATIVE && outside_cage {
        return OUTSIDE;
    }
    return heat_colour(value);
}

struct MeshVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) scene_position: vec3<f32>,
    @location(1) outside: f32,
    @location(2) value: f32,
    // 1 for a vertex outside the cage, whether or not it is highlighted.
    @location(3) outside_cage: f32,
    // The deformed mesh's normal (smooth shading; zero when not computed).
    @location(4) normal: vec3<f32>,
}

@vertex
fn vs_mesh(@builtin(vertex_index) vertex: u32) -> MeshVarying {
    return mesh_vertex(vertex);
}

fn mesh_vertex(vertex: u32) -> MeshVarying {
    return mesh_vertex_at(vertex, deformed_position(vertex));
}

// Everything but the blend, for a vertex deformed to `scene_position` (relative to
// the scene origin, as every position uploaded).
fn mesh_vertex_at(vertex: u32, scene_position: vec3<f32>) -> MeshVarying {
    var out: MeshVarying;
    out.clip = frame.view_projection * vec4<f32>(scene_position, 1.0);
    out.scene_position = scene_position;
    out.outside = rest[vertex].w * f32(frame.highlight_outside);
    if COLOURED {
        out.value = vertex_value(vertex, scene_position);
    }
    out.outside_cage = rest[vertex].w;
    if frame.smooth_shading == 1u && frame.weights_bound == 1u {
        out.normal = displacements[frame.normals_first + vertex].xyz;
    }
    return out;
}

// The wireframe overlay: the mesh's edges, deformed as the surface is, pulled a
// little towards the camera so they win against the faces they bound.
@vertex
fn vs_wire(@builtin(vertex_index) vertex: u32) -> MeshVarying {
    return pulled_forward(mesh_vertex(vertex));
}

fn pulled_forward(surface: MeshVarying) -> MeshVarying {
    var out = surface;
    out.clip.z -= 5e-5 * out.clip.w;
    return out;
}

// What the vertex shader draws, read back (render::drawn): vertex i as a point on
// texel (i mod width, i / width) of a float image, carrying its deformed position.
struct ProbeVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) scene_position: vec3<f32>,
}

fn probe_vertex(vertex: u32, scene_position: vec3<f32>) -> ProbeVarying {
    let width = frame.probe_width;
    let height = (frame.vertex_count + width - 1u) / width;
    let texel = vec2<f32>(f32(vertex % width), f32(vertex / width)) + 0.5;
    var out: ProbeVarying;
    out.clip = vec4<f32>(
        texel.x / f32(width) * 2.0 - 1.0,
        1.0 - texel.y / f32(height) * 2.0,
        0.0,
        1.0,
    );
    out.scene_position = scene_position;
    return out;
}

@vertex
fn vs_probe(@builtin(vertex_index) vertex: u32) -> ProbeVarying {
    return probe_vertex(vertex, deformed_position(vertex));
}

@fragment
fn fs_probe(in: ProbeVarying) -> @location(0) vec4<f32> {
    return vec4<f32>(in.scene_position, 1.0);
}

@fragment
fn fs_wire(in: MeshVarying) -> @location(0) vec4<f32> {
    return vec4<f32>(0.12, 0.12, 0.14, 1.0);
}

@fragment
fn fs_mesh(in: MeshVarying) -> @location(0) vec4<f32> {
    var normal = normalize(cross(dpdx(in.scene_position), dpdy(in.scene_position)));
    if frame.smooth_shading == 1u && length(in.normal) > 0.5 {
        normal = normalize(in.normal);
    }
    let to_eye = normalize(frame.eye - in.scene_position);
    // Two-sided: light whichever side faces the camera.
    if dot(normal, to_eye) < 0.0 {
        normal = -normal;
    }
    let key = normalize(to_eye + vec3<f32>(0.3, 0.6, 0.2));
    let diffuse = 0.55 * max(dot(normal, key), 0.0) + 0.3 * max(dot(normal, to_eye), 0.0);
    let half_vector = normalize(key + to_eye);
    let specular = 0.25 * pow(max(dot(normal, half_vector), 0.0), 40.0);
    var colour: vec3<f32>;
    if !COLOURED || frame.colouring == COLOURING_SHADED {
        let base = mix(vec3<f32>(0.78, 0.72, 0.62), vec3<f32>(0.95, 0.2, 0.15), in.outside);
        colour = base * (0.18 + diffuse) + vec3<f32>(specular);
    } else {
        // Mostly flat colour, so the map reads true; a little shading keeps the shape.
        colour = value_colour(in.value, in.outside_cage > 0.5) * (0.55 + 0.53 * diffuse)
            + vec3<f32>(0.3 * specular);
    }
    return vec4<f32>(min(colour, vec3<f32>(1.0)), 1.0);
}

// Readback: the same deformation, value and colour into one buffer, so tests and
// exports can check what the shaders draw (one buffer, for which the pool of
// weight chunks leaves a storage buffer of the stage free). First per vertex xyz: deformed position, w: the
// colouring value; then per vertex rgb: the unshaded colour of the value.
@group(1) @binding(0) var<storage, read_write> output: array<vec4<f32>>;

@compute @workgroup_size(64)
fn cs_deform(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= frame.vertex_count {
        return;
    }
    let position = deformed_position(id.x);
    let value = vertex_value(id.x, position);
    output[id.x] = vec4<f32>(position, value);
    output[frame.vertex_count + id.x] = vec4<f32>(value_colour(value, rest[id.x].w > 0.5), 1.0);
}

// Smooth shading's first pass: the deformed positions of the method shown, as
// the vertex shader computes them, for shaders/render_normals.wgsl.
@compute @workgroup_size(64)
fn cs_positions(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= frame.vertex_count {
        return;
    }
    output[id.x] = vec4<f32>(deformed_position(id.x), 0.0);
}

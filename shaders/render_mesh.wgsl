// Deformed mesh: the vertex shader computes p' = Σ_j W[i,j] · c̃_j from the dense
// weights (row-major f32) and the deformed cage, so the CPU never touches mesh
// positions per frame. Normals come from screen-space derivatives of the deformed
// position, so shading always follows the deformation.
//
// Besides plain shading the mesh can be coloured by a scalar per vertex: the
// weight of one cage vertex, the vertex's most negative weight, or the distance
// between its MVC and PMVC deformations. The colour functions are twins of
// src/render/colormap.rs. Paired with src/render/mesh.rs.

struct Frame {
    view_projection: mat4x4<f32>,
    eye: vec4<f32>,
    // x, y: viewport size in pixels; z: handle radius in pixels.
    viewport: vec4<f32>,
    // x: cage vertex count (weights columns); y: 1 when weights are bound;
    // z: 1 to highlight outside vertices; w: mesh vertex count.
    counts: vec4<u32>,
    // x: colouring (0 shaded, 1 weight of cage vertex y, 2 most negative weight,
    // 3 distance to the other method's deformation); z: 1 for a log-magnitude
    // scale; w: 1 when the other method's weights are bound.
    colouring: vec4<u32>,
    // x: the magnitude at which colours saturate; y: cage size (distances are
    // divided by it).
    colour_scale: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
// The weights of the method shown.
@group(0) @binding(1) var<storage, read> weights: array<f32>;
// xyz: rest position; w: 1 for a vertex outside the cage.
@group(0) @binding(2) var<storage, read> rest: array<vec4<f32>>;
// xyz: deformed cage vertex.
@group(0) @binding(3) var<storage, read> cage: array<vec4<f32>>;
// The other method's weights, for the difference view.
@group(0) @binding(5) var<storage, read> other_weights: array<f32>;

const SHADED: u32 = 0u;
const CAGE_VERTEX_WEIGHT: u32 = 1u;
const MOST_NEGATIVE_WEIGHT: u32 = 2u;
const METHOD_DISTANCE: u32 = 3u;

const NEGATIVE = vec3<f32>(0.16, 0.29, 0.80);
const ZERO = vec3<f32>(0.97, 0.97, 0.97);
const POSITIVE = vec3<f32>(0.80, 0.08, 0.10);
const LOG_DECADES: f32 = 3.0;
const LN_10: f32 = 2.302585093;

fn deformed_position(vertex: u32) -> vec3<f32> {
    if frame.counts.y == 0u {
        return rest[vertex].xyz;
    }
    let columns = frame.counts.x;
    let row = vertex * columns;
    var position = vec3<f32>(0.0);
    for (var column = 0u; column < columns; column++) {
        position += weights[row + column] * cage[column].xyz;
    }
    return position;
}

fn other_deformed_position(vertex: u32) -> vec3<f32> {
    let columns = frame.counts.x;
    let row = vertex * columns;
    var position = vec3<f32>(0.0);
    for (var column = 0u; column < columns; column++) {
        position += other_weights[row + column] * cage[column].xyz;
    }
    return position;
}

// The scalar the mesh is coloured by (0 when shaded or unbound).
fn vertex_value(vertex: u32, position: vec3<f32>) -> f32 {
    let columns = frame.counts.x;
    if frame.counts.y == 0u || columns == 0u {
        return 0.0;
    }
    let row = vertex * columns;
    switch frame.colouring.x {
        case CAGE_VERTEX_WEIGHT: {
            let column = min(frame.colouring.y, columns - 1u);
            return weights[row + column];
        }
        case MOST_NEGATIVE_WEIGHT: {
            var lowest = weights[row];
            for (var column = 1u; column < columns; column++) {
                lowest = min(lowest, weights[row + column]);
            }
            return lowest;
        }
        case METHOD_DISTANCE: {
            if frame.colouring.w == 0u {
                return 0.0;
            }
            let other = other_deformed_position(vertex);
            return length(position - other) / max(frame.colour_scale.y, 1e-30);
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
    return diverging(scaled(value, frame.colour_scale.x, frame.colouring.z == 1u));
}

struct MeshVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) outside: f32,
    @location(2) value: f32,
}

@vertex
fn vs_mesh(@builtin(vertex_index) vertex: u32) -> MeshVarying {
    let world = deformed_position(vertex);
    var out: MeshVarying;
    out.clip = frame.view_projection * vec4<f32>(world, 1.0);
    out.world = world;
    out.outside = rest[vertex].w * f32(frame.counts.z);
    out.value = vertex_value(vertex, world);
    return out;
}

@fragment
fn fs_mesh(in: MeshVarying) -> @location(0) vec4<f32> {
    var normal = normalize(cross(dpdx(in.world), dpdy(in.world)));
    let to_eye = normalize(frame.eye.xyz - in.world);
    // Two-sided: light whichever side faces the camera.
    if dot(normal, to_eye) < 0.0 {
        normal = -normal;
    }
    let key = normalize(to_eye + vec3<f32>(0.3, 0.6, 0.2));
    let diffuse = 0.55 * max(dot(normal, key), 0.0) + 0.3 * max(dot(normal, to_eye), 0.0);
    let half_vector = normalize(key + to_eye);
    let specular = 0.25 * pow(max(dot(normal, half_vector), 0.0), 40.0);
    var colour: vec3<f32>;
    if frame.colouring.x == SHADED {
        let base = mix(vec3<f32>(0.78, 0.72, 0.62), vec3<f32>(0.95, 0.2, 0.15), in.outside);
        colour = base * (0.18 + diffuse) + vec3<f32>(specular);
    } else {
        // Mostly flat colour, so the map reads true; a little shading keeps the shape.
        colour = heat_colour(in.value) * (0.55 + 0.53 * diffuse) + vec3<f32>(0.3 * specular);
    }
    return vec4<f32>(min(colour, vec3<f32>(1.0)), 1.0);
}

// Readback: the same deformation, value and colour into buffers, so tests and
// exports can check what the shaders draw.
// xyz: deformed position; w: the colouring value.
@group(1) @binding(0) var<storage, read_write> deformed: array<vec4<f32>>;
// rgb: the unshaded colour of the value.
@group(1) @binding(1) var<storage, read_write> colours: array<vec4<f32>>;

@compute @workgroup_size(64)
fn cs_deform(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= frame.counts.w {
        return;
    }
    let position = deformed_position(id.x);
    let value = vertex_value(id.x, position);
    deformed[id.x] = vec4<f32>(position, value);
    colours[id.x] = vec4<f32>(heat_colour(value), 1.0);
}

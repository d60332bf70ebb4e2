// Deformed mesh: the vertex shader computes p' = Σ_j W[i,j] · c̃_j from the dense
// weights (row-major f32) and the deformed cage, so the CPU never touches mesh
// positions per frame. Normals come from screen-space derivatives of the deformed
// position, so shading always follows the deformation.
// Paired with src/render/mesh.rs.

struct Frame {
    view_projection: mat4x4<f32>,
    eye: vec4<f32>,
    // x, y: viewport size in pixels; z: handle radius in pixels.
    viewport: vec4<f32>,
    // x: cage vertex count (weights columns); y: 1 when weights are bound;
    // z: 1 to highlight outside vertices; w: mesh vertex count.
    counts: vec4<u32>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> weights: array<f32>;
// xyz: rest position; w: 1 for a vertex outside the cage.
@group(0) @binding(2) var<storage, read> rest: array<vec4<f32>>;
// xyz: deformed cage vertex.
@group(0) @binding(3) var<storage, read> cage: array<vec4<f32>>;

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

struct MeshVarying {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) outside: f32,
}

@vertex
fn vs_mesh(@builtin(vertex_index) vertex: u32) -> MeshVarying {
    let world = deformed_position(vertex);
    var out: MeshVarying;
    out.clip = frame.view_projection * vec4<f32>(world, 1.0);
    out.world = world;
    out.outside = rest[vertex].w * f32(frame.counts.z);
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
    let base = mix(vec3<f32>(0.78, 0.72, 0.62), vec3<f32>(0.95, 0.2, 0.15), in.outside);
    let colour = base * (0.18 + diffuse) + vec3<f32>(specular);
    return vec4<f32>(min(colour, vec3<f32>(1.0)), 1.0);
}

// Readback: the same deformation into a buffer, so tests and exports can check
// what the vertex shader draws.
@group(1) @binding(0) var<storage, read_write> deformed: array<vec4<f32>>;

@compute @workgroup_size(64)
fn cs_deform(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= frame.counts.w {
        return;
    }
    deformed[id.x] = vec4<f32>(deformed_position(id.x), 1.0);
}

// Smooth shading: each mesh vertex's normal, the area-weighted sum of the
// normals of the deformed triangles around it, recomputed per pose change from
// the positions the vertex shader's deformation gives (drawn by vs_probe_attributes
// where the weights are read as attributes, else written by cs_positions; both
// in render_mesh.wgsl). CPU twin: geometry::vertex_normals. Paired with
// src/render/normals.rs.

@group(0) @binding(0) var<storage, read> deformed: array<vec4<f32>>;
// Where each vertex's triangles start in `corners`; one more entry than vertices.
@group(0) @binding(1) var<storage, read> offsets: array<u32>;
// Per (vertex, triangle): the triangle's other two corners, in winding order.
@group(0) @binding(2) var<storage, read> corners: array<vec2<u32>>;
// The family's column displacements, then one normal per vertex: the normals
// are the last `vertex count` entries.
@group(0) @binding(3) var<storage, read_write> displacements_and_normals: array<vec4<f32>>;

@compute @workgroup_size(64)
fn cs_normals(@builtin(global_invocation_id) id: vec3<u32>) {
    let vertex = id.x;
    if vertex + 1u >= arrayLength(&offsets) {
        return;
    }
    let p = deformed[vertex].xyz;
    var sum = vec3<f32>(0.0);
    var first = vec3<f32>(0.0);
    var magnitude = 0.0;
    for (var k = offsets[vertex]; k < offsets[vertex + 1u]; k++) {
        let other = corners[k];
        let n = cross(deformed[other.x].xyz - p, deformed[other.y].xyz - p);
        sum += n;
        magnitude += length(n);
        if all(first == vec3<f32>(0.0)) {
            first = n;
        }
    }
    // As the CPU twin: where the triangles cancel, the first one's normal; with
    // no triangle of positive area, +z.
    var normal = vec3<f32>(0.0, 0.0, 1.0);
    if length(sum) > 1e-6 * magnitude && magnitude > 0.0 {
        normal = normalize(sum);
    } else if length(first) > 0.0 {
        normal = normalize(first);
    }
    let first_normal = arrayLength(&displacements_and_normals) - (arrayLength(&offsets) - 1u);
    displacements_and_normals[first_normal + vertex] = vec4<f32>(normal, 0.0);
}

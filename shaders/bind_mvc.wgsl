// Mean value coordinates in closed form (Ju, Schaefer, Warren 2005), one invocation
// per point, mirroring src/coords/mvc.rs in f32.
//
// Vulkan only promises sin/cos/asin to about 2^-11 absolute, far too coarse here, so
// no builtin trigonometry is used: sines and cosines of the arcs and of the spherical
// angles come from cross and dot products taken on edge vectors (accurate for small
// far triangles), and the arcs from atan2 by a Cephes polynomial.
//
// f32 is not robust where a triangle's spherical projection degenerates (x near a
// cage vertex, near a triangle, or near a triangle's plane): the per-triangle
// weights become 0/0 forms. Such points are flagged FALLBACK and redone on the CPU.

#import bind_params
#import bind_constants
#import angles
#import closed_form_bindings

// Below this |sin| of a spherical angle the 0/0 cancellation (error about 1e-8/|sin|
// in a coordinate) could exceed the accuracy budget. Measured: 1e-3 sent 26% of the
// comb's points to the CPU, 1e-4 sends 2% with max |Δ| 3e-6; 1e-5 gives max |Δ| 1e-5.
const MIN_SINE: f32 = 1e-4;

@compute @workgroup_size(WORKGROUP_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let point = id.x;
    if point >= params.point_count {
        return;
    }
    let x = points[point].xyz;
    let out_base = u32(points[point].w) * params.vertex_count;
    for (var v = 0u; v < params.vertex_count; v++) {
        weights[out_base + v] = 0.0;
    }
    var total = 0.0;
    var robust = true;
    for (var t = 0u; t < params.triangle_count; t++) {
        var index: array<u32, 3>;
        var o: array<vec3<f32>, 3>;
        var d: array<f32, 3>;
        for (var k = 0u; k < 3u; k++) {
            index[k] = topology[3u * t + k];
            o[k] = cage_positions[index[k]].xyz - x;
            d[k] = length(o[k]);
        }
        // normal[k]: o_{k+1} × o_{k+2}, the plane through x and the edge opposite k.
        var normal: array<vec3<f32>, 3>;
        var theta: array<f32, 3>;
        var sin_theta: array<f32, 3>;
        for (var k = 0u; k < 3u; k++) {
            let p = o[(k + 1u) % 3u];
            let q = o[(k + 2u) % 3u];
            normal[k] = cross(p, q - p);
            let lengths = d[(k + 1u) % 3u] * d[(k + 2u) % 3u];
            sin_theta[k] = length(normal[k]) / lengths;
            theta[k] = angle(sin_theta[k], dot(p, q) / lengths);
        }
        let det = dot(o[0], cross(o[1] - o[0], o[2] - o[0])) / (d[0] * d[1] * d[2]);
        // c[k], s[k]: cosine and signed sine of the spherical angle at corner k.
        var c: array<f32, 3>;
        var s: array<f32, 3>;
        for (var k = 0u; k < 3u; k++) {
            let a = normal[(k + 2u) % 3u];
            let b = normal[(k + 1u) % 3u];
            c[k] = -dot(a, b) / (length(a) * length(b));
            s[k] = det / (sin_theta[(k + 1u) % 3u] * sin_theta[(k + 2u) % 3u]);
            if !(abs(s[k]) > MIN_SINE) {
                robust = false;
            }
        }
        for (var k = 0u; k < 3u; k++) {
            let next = (k + 1u) % 3u;
            let previous = (k + 2u) % 3u;
            let w = (theta[k] - c[next] * theta[previous] - c[previous] * theta[next])
                / (d[k] * sin_theta[next] * s[previous]);
            weights[out_base + index[k]] += w;
            total += w;
        }
    }
    if !robust || !(total > 0.0) || !(total < 3.0e38) {
        status[point] = FALLBACK;
        return;
    }
    status[point] = 0u;
    let inverse_total = 1.0 / total;
    for (var v = 0u; v < params.vertex_count; v++) {
        weights[out_base + v] *= inverse_total;
    }
}

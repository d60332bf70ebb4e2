// Green coordinates in closed form (Lipman, Levin, Cohen-Or 2008), one invocation
// per point inside the cage, mirroring src/coords/green/triangle.rs in f32: per
// triangle the solid angle (Van Oosterom and Strackee), the three edge integrals
// of 1/r, then φ of its corners and its ψ. A row is φ for every cage vertex, then
// ψ for every cage triangle.
//
// f32 loses digits where the closed form cancels: a point near a triangle's
// plane, edge or corner. Rather than guess where, the kernel checks the result
// against two identities every exact answer meets: Σ φᵢ = 1 inside, and
// Σ φᵢ (vᵢ − x) + Σ ψⱼ nⱼ = 0 (the rest pose). A row that misses either by more
// than rounding allows is flagged FALLBACK and redone on the CPU in f64.

#import bind_params
#import bind_constants
#import angles
#import closed_form_bindings

// How far the identities may miss, relative to the point's distance to the
// farthest cage vertex (Σφ is dimensionless). Measured on the test cages: rows
// that pass agree with the CPU to about 1e-6; see docs/gpu-binding.md.
const IDENTITY_TOLERANCE: f32 = 4e-6;

// ∫ 1/r ds along the edge from a to b (relative to the point): ln of
// (ra + rb + ℓ) / (ra + rb − ℓ), the denominator rewritten without cancellation
// when the edge is seen under more than 90° (coords::green::edge_log_integral).
fn edge_log_integral(a: vec3<f32>, b: vec3<f32>, ra: f32, rb: f32) -> f32 {
    let edge = b - a;
    let length_ = length(edge);
    let sum = ra + rb;
    let cosine_term = dot(a, b);
    var gap = sum - length_;
    if cosine_term < 0.0 {
        let across = cross(a, edge);
        gap = 2.0 * dot(across, across) / ((ra * rb - cosine_term) * (sum + length_));
    }
    return log((sum + length_) / max(gap, 1e-37));
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let point = id.x;
    if point >= params.point_count {
        return;
    }
    let x = points[point].xyz;
    let columns = params.vertex_count + params.triangle_count;
    let out_base = u32(points[point].w) * columns;
    for (var v = 0u; v < params.vertex_count; v++) {
        weights[out_base + v] = 0.0;
    }
    let quarter_over_pi = 0.25 / PI;
    var phi_sum = 0.0;
    var solid_angle_sum = 0.0;
    // Σ φ (v − x) + Σ ψ n: zero for exact coordinates.
    var residual = vec3<f32>(0.0);
    var farthest = 0.0;
    for (var t = 0u; t < params.triangle_count; t++) {
        var index: array<u32, 3>;
        var o: array<vec3<f32>, 3>;
        var d: array<f32, 3>;
        for (var k = 0u; k < 3u; k++) {
            index[k] = topology[3u * t + k];
            o[k] = cage_positions[index[k]].xyz - x;
            d[k] = length(o[k]);
            farthest = max(farthest, d[k]);
        }
        let area_vector = cross(o[1] - o[0], o[2] - o[0]);
        let doubled_area = length(area_vector);
        let normal = area_vector / max(doubled_area, 1e-37);
        // The plane's height above x, positive on the inner side.
        let height = (dot(normal, o[0]) + dot(normal, o[1]) + dot(normal, o[2])) / 3.0;
        let denominator = d[0] * d[1] * d[2] + dot(o[0], o[1]) * d[2]
            + dot(o[1], o[2]) * d[0] + dot(o[2], o[0]) * d[1];
        let solid_angle = 2.0 * atan2_precise(height * doubled_area, denominator);
        var foot_distance: array<f32, 3>;
        var edge_normal: array<vec3<f32>, 3>;
        var edge_length: array<f32, 3>;
        var psi_sum = 0.0;
        var weighted_normals = vec3<f32>(0.0);
        for (var e = 0u; e < 3u; e++) {
            let next = (e + 1u) % 3u;
            let edge = o[next] - o[e];
            edge_length[e] = length(edge);
            edge_normal[e] = normalize(cross(edge, normal));
            foot_distance[e] = dot(edge_normal[e], o[e]);
            let integral = edge_log_integral(o[e], o[next], d[e], d[next]);
            psi_sum += foot_distance[e] * integral;
            weighted_normals += edge_normal[e] * integral;
        }
        let psi = (psi_sum - height * solid_angle) * quarter_over_pi;
        weights[out_base + params.vertex_count + t] = psi;
        residual += psi * normal;
        for (var k = 0u; k < 3u; k++) {
            let opposite = (k + 1u) % 3u;
            let phi = edge_length[opposite] / doubled_area
                * (foot_distance[opposite] * solid_angle
                    + height * dot(edge_normal[opposite], weighted_normals))
                * quarter_over_pi;
            weights[out_base + index[k]] += phi;
            phi_sum += phi;
            residual += phi * o[k];
        }
        solid_angle_sum += solid_angle;
    }
    let winding = solid_angle_sum * quarter_over_pi;
    let trusted = abs(phi_sum - 1.0) <= IDENTITY_TOLERANCE
        && length(residual) <= IDENTITY_TOLERANCE * farthest
        && abs(winding - 1.0) <= IDENTITY_TOLERANCE;
    // The comparisons are false for NaN, so a NaN row is flagged too.
    status[point] = select(FALLBACK, 0u, trusted);
}

// What both PMVC kernels (bind_pmvc.wgsl, bind_pmvc_tiles.wgsl) compute the same
// way per point and cube face: a triangle relative to the point, whether a
// primitive can reach a face, its conservative texel bounds, and texel centres.
// The importing shader declares `params`, `cage_positions`, `topology` and
// `CORNERS`.

#import cube_faces

const FAR: f32 = 1e30;

struct Triangle {
    a: vec3<f32>,
    b: vec3<f32>,
    c: vec3<f32>,
    // b×c, c×a, a×b: a ray direction dotted with these gives unnormalised barycentrics.
    e0: vec3<f32>,
    e1: vec3<f32>,
    e2: vec3<f32>,
    det: f32,
}

fn triangle_at(t: u32, x: vec3<f32>) -> Triangle {
    let a = cage_positions[topology[CORNERS * t]].xyz - x;
    let b = cage_positions[topology[CORNERS * t + 1u]].xyz - x;
    let c = cage_positions[topology[CORNERS * t + 2u]].xyz - x;
    let e0 = cross(b, c);
    return Triangle(a, b, c, e0, cross(c, a), cross(a, b), dot(a, e0));
}

// False only when no ray through the face can reach primitive t: all its corners
// lie outside one of the four planes that bound the face's pyramid (n·p ≥ |r·p|,
// n·p ≥ |u·p|); a patch lies in its corners' hull. Texel centres lie strictly
// inside, so rounding here cannot drop a hit. A few loads and multiplies instead
// of a full set-up: most primitives of a large cage miss most faces.
fn may_reach_face(t: u32, x: vec3<f32>, axes: mat3x3<f32>, corners: u32) -> bool {
    var outside = 15u;
    for (var k = 0u; k < corners; k++) {
        outside &= planes_outside(cage_positions[topology[CORNERS * t + k]].xyz - x, axes);
    }
    return outside == 0u;
}

// Bit k set: p (relative to the point) lies outside the k-th plane bounding the
// face's pyramid.
fn planes_outside(p: vec3<f32>, axes: mat3x3<f32>) -> u32 {
    let r = dot(p, axes[0]);
    let u = dot(p, axes[1]);
    let n = dot(p, axes[2]);
    return select(0u, 1u, n - r < 0.0) | select(0u, 2u, n + r < 0.0)
        | select(0u, 4u, n - u < 0.0) | select(0u, 8u, n + u < 0.0);
}

// Conservative texel bounds of the triangle's projection on the face, widened by a
// texel against rounding, as in the CPU's `texel_bounds`.
fn texel_range(tri: Triangle, axes: mat3x3<f32>) -> vec4<u32> {
    var corners = array<vec3<f32>, 3>(tri.a, tri.b, tri.c);
    var lo = vec2<f32>(FAR, FAR);
    var hi = vec2<f32>(-FAR, -FAR);
    var any_in_front = false;
    for (var k = 0u; k < 3u; k++) {
        let p3 = corners[k];
        let q3 = corners[(k + 1u) % 3u];
        let p = vec3<f32>(dot(p3, axes[0]), dot(p3, axes[1]), dot(p3, axes[2]));
        let q = vec3<f32>(dot(q3, axes[0]), dot(q3, axes[1]), dot(q3, axes[2]));
        if p.z > 0.0 {
            any_in_front = true;
            let projected = p.xy / p.z;
            lo = min(lo, projected);
            hi = max(hi, projected);
        }
        if (p.z > 0.0) != (q.z > 0.0) {
            // The edge crosses the face's plane: the projection runs off towards the crossing.
            let s = p.z / (p.z - q.z);
            let crossing = p + s * (q - p);
            if crossing.x >= 0.0 { hi.x = FAR; }
            if crossing.x <= 0.0 { lo.x = -FAR; }
            if crossing.y >= 0.0 { hi.y = FAR; }
            if crossing.y <= 0.0 { lo.y = -FAR; }
        }
    }
    return texels_within(lo, hi, any_in_front);
}

// The texel ranges covering face bounds [lo, hi], widened by a texel.
fn texels_within(lo: vec2<f32>, hi: vec2<f32>, any_in_front: bool) -> vec4<u32> {
    if !any_in_front || lo.x > 1.0 || hi.x < -1.0 || lo.y > 1.0 || hi.y < -1.0 {
        return vec4<u32>(0u, 0u, 0u, 0u);
    }
    let r = f32(params.resolution);
    let first = max(floor((clamp(lo, vec2(-1.0), vec2(1.0)) + 1.0) * 0.5 * r - 0.5), vec2(0.0));
    let last = min(floor((clamp(hi, vec2(-1.0), vec2(1.0)) + 1.0) * 0.5 * r - 0.5) + 2.0, vec2(r));
    return vec4<u32>(u32(first.x), u32(last.x), u32(first.y), u32(last.y));
}

// Computed rather than loaded: storage loads dominate the inner loop on lavapipe.
// The same expression for every triangle, so shared edges still cancel exactly.
fn texel_centre(index: u32) -> f32 {
    return f32(2u * index + 1u) / f32(params.resolution) - 1.0;
}

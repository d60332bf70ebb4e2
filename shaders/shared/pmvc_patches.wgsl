// Bilinear patches in bind_pmvc.wgsl's quad pipeline (CORNERS = 4), whose
// bindings, workgroup buffers and passes they use. Quad q0 q1 q2 q3 is
// P(u, v) = (1−u)(1−v)q0 + u(1−v)q1 + uv·q2 + (1−u)v·q3 (src/geometry/quads.rs).
//
// A ray d from x meets the line P(u, 0)..P(u, 1) where a + b·u + c·u² = 0
// (Reshetov, "Cool Patches", Ray Tracing Gems, 2019), then at v and t. In f32:
// corners are taken relative to x and in the face's axes (a signed permutation,
// so exact), so a, a + b + c and c are linear in the texel's (s, r) like a
// triangle's edge functions; the roots come as root/c and a/root, never as a
// difference of close values, so a nearly flat patch (c → 0) keeps its one root;
// both roots are tried and the nearer hit at t > 0 counts, as a ray may meet a
// bent patch twice.
//
// Watertight edges: a ray near an edge is on one side of the plane through x
// and the edge, and a and a + b + c are exactly the edge functions d·(q×p) of
// the u = 0 and u = 1 edges. Near an edge (parameter within EDGE_BAND of it)
// the side is decided by the sign of that edge function, computed from the
// edge's corners as its neighbour (patch or triangle) computes it, times the
// sign the patch's inside has there: P(u, v)·n = u·P(1, v)·n for the u = 0
// edge's normal n, and so on. Neighbours then never both miss a ray between
// them, and a patch does not reach past a silhouette edge.

const NO_CORNER: u32 = 0xffffffffu;
// Parameter distance from an edge within which its edge function decides:
// far above f32 rounding of u and v, far below a texel.
const EDGE_BAND: f32 = 1e-4;

// One patch seen from x through one cube face, in the face's coordinates.
struct PatchSetup {
    // (u0, u1, c): edge functions of the u = 0 and u = 1 edges and c at the ray
    // (s, r, 1) are s·along_right + r·along_up + along_normal; and the range.
    face: FaceSetup,
    // The same for the v = 0 and v = 1 edges (third component unused).
    v_right: vec3<f32>,
    v_up: vec3<f32>,
    v_normal: vec3<f32>,
    // a = signs.x·u0 and a + b + c = signs.y·u1 (edge normals are taken from
    // the lower-numbered corner, as the neighbour takes them).
    signs: vec2<f32>,
    q00: vec3<f32>,
    e10: vec3<f32>,
    e00: vec3<f32>,
    // e11 − e00: P(u, 1) − P(u, 0) = e00 + u·de.
    de: vec3<f32>,
    // Where the inside lies from each edge, α + w·β at the other parameter w:
    // (α, β) of the u = 0 and u = 1 edges, then of the v = 0 and v = 1 edges.
    inside_u: vec4<f32>,
    inside_v: vec4<f32>,
}

fn is_patch(t: u32) -> bool {
    return CORNERS == 4u && topology[4u * t + 3u] != NO_CORNER;
}

// The normal of the plane through x and the edge p q, from the lower-numbered
// corner; w is +1 when that is p × q, −1 when it is q × p.
fn edge_normal(p: vec3<f32>, q: vec3<f32>, ip: u32, iq: u32) -> vec4<f32> {
    if ip < iq {
        return vec4<f32>(cross(p, q), 1.0);
    }
    return vec4<f32>(cross(q, p), -1.0);
}

fn patch_setup(t: u32, x: vec3<f32>, axes: mat3x3<f32>) -> PatchSetup {
    var index: array<u32, 4>;
    var world: array<vec3<f32>, 4>;
    var q: array<vec3<f32>, 4>;
    for (var k = 0u; k < 4u; k++) {
        index[k] = topology[4u * t + k];
        world[k] = cage_positions[index[k]].xyz - x;
        q[k] = world[k] * axes;
    }
    // Natural normals q01 × q00, q11 × q10, q10 × q00 and q11 × q01 up to the sign in w.
    let u0 = edge_normal(world[3], world[0], index[3], index[0]);
    let u1 = edge_normal(world[2], world[1], index[2], index[1]);
    let v0 = edge_normal(world[1], world[0], index[1], index[0]);
    let v1 = edge_normal(world[2], world[3], index[2], index[3]);
    let n_u0 = u0.xyz * axes;
    let n_u1 = u1.xyz * axes;
    let n_v0 = v0.xyz * axes;
    let n_v1 = v1.xyz * axes;
    let e10 = q[1] - q[0];
    let e11 = q[2] - q[1];
    let e00 = q[3] - q[0];
    let qn = cross(e10, q[3] - q[2]);
    var setup: PatchSetup;
    setup.face.along_right = vec3<f32>(n_u0.x, n_u1.x, qn.x);
    setup.face.along_up = vec3<f32>(n_u0.y, n_u1.y, qn.y);
    setup.face.along_normal = vec3<f32>(n_u0.z, n_u1.z, qn.z);
    setup.face.range = patch_texel_range(q);
    setup.v_right = vec3<f32>(n_v0.x, n_v1.x, 0.0);
    setup.v_up = vec3<f32>(n_v0.y, n_v1.y, 0.0);
    setup.v_normal = vec3<f32>(n_v0.z, n_v1.z, 0.0);
    setup.signs = vec2<f32>(u0.w, u1.w);
    setup.q00 = q[0];
    setup.e10 = e10;
    setup.e00 = e00;
    setup.de = e11 - e00;
    // P(1, v)·n_u0, P(0, v)·n_u1, P(u, 1)·n_v0 and P(u, 0)·n_v1.
    setup.inside_u = vec4<f32>(dot(q[1], n_u0), dot(e11, n_u0), dot(q[0], n_u1), dot(e00, n_u1));
    setup.inside_v = vec4<f32>(dot(q[3], n_v0), dot(q[2] - q[3], n_v0), dot(q[0], n_v1), dot(e10, n_v1));
    return setup;
}

// Conservative texel bounds of the hull of the corners (face coordinates), as
// texel_range does for a triangle, over all six corner pairs.
fn patch_texel_range(corners: array<vec3<f32>, 4>) -> vec4<u32> {
    var q = corners;
    var lo = vec2<f32>(FAR, FAR);
    var hi = vec2<f32>(-FAR, -FAR);
    var any_in_front = false;
    for (var k = 0u; k < 4u; k++) {
        let p = q[k];
        if p.z > 0.0 {
            any_in_front = true;
            lo = min(lo, p.xy / p.z);
            hi = max(hi, p.xy / p.z);
        }
        for (var l = k + 1u; l < 4u; l++) {
            let o = q[l];
            if (p.z > 0.0) != (o.z > 0.0) {
                let crossing = p + p.z / (p.z - o.z) * (o - p);
                if crossing.x >= 0.0 { hi.x = FAR; }
                if crossing.x <= 0.0 { lo.x = -FAR; }
                if crossing.y >= 0.0 { hi.y = FAR; }
                if crossing.y <= 0.0 { lo.y = -FAR; }
            }
        }
    }
    return texels_within(lo, hi, any_in_front);
}

// Whether the ray is on the inside of an edge: its edge function has the sign
// of the inside (`inside`), or where that is 0 (x sees the patch edge on), the
// parameter test `fallback`.
fn inside_edge(edge: f32, inside: f32, fallback: bool) -> bool {
    if inside == 0.0 {
        return fallback;
    }
    return select(edge <= 0.0, edge >= 0.0, inside > 0.0);
}

// The hit at root u if it is on the patch and nearer than `best`: (u, v, 1/t).
// The ray (d.z = 1) meets P(u, 0) + v·(P(u, 1) − P(u, 0)) where its z row and
// the better conditioned of its x and y rows hold: v = along / across, and
// t·across = pa.z·across + along·pb.z, tested without dividing (across > 0).
// `edges`: the u = 0 and u = 1 edge functions at the ray.
fn patch_root(setup: PatchSetup, d: vec3<f32>, u: f32, edges: vec2<f32>, best: vec3<f32>) -> vec3<f32> {
    if !(u >= -EDGE_BAND && u <= 1.0 + EDGE_BAND) {
        return best;
    }
    let pa = setup.q00 + u * setup.e10;
    let pb = setup.e00 + u * setup.de;
    let rows = pb.xy - d.xy * pb.z;
    let offs = d.xy * pa.z - pa.xy;
    let by_x = abs(rows.x) >= abs(rows.y);
    let row = select(rows.y, rows.x, by_x);
    let across = abs(row);
    let along = select(offs.y, offs.x, by_x) * sign(row);
    let depth = pa.z * across + along * pb.z;
    let q = across / depth;
    if !(depth > 0.0 && along >= -EDGE_BAND * across && along <= (1.0 + EDGE_BAND) * across && q > best.z) {
        return best;
    }
    // v itself only where needed, so that a pass reading only 1/t skips it.
    let iu = setup.inside_u;
    if u < EDGE_BAND && !inside_edge(edges.x, iu.x + along / across * iu.y, u >= 0.0) {
        return best;
    }
    if u > 1.0 - EDGE_BAND && !inside_edge(edges.y, iu.z + along / across * iu.w, u <= 1.0) {
        return best;
    }
    let near_v0 = along < EDGE_BAND * across;
    let near_v1 = along > (1.0 - EDGE_BAND) * across;
    if near_v0 || near_v1 {
        let ev = d.x * setup.v_right + d.y * setup.v_up + setup.v_normal;
        let iv = setup.inside_v;
        if near_v0 && !inside_edge(ev.x, iv.x + u * iv.y, along >= 0.0) {
            return best;
        }
        if near_v1 && !inside_edge(ev.y, iv.z + u * iv.w, along <= across) {
            return best;
        }
    }
    return vec3<f32>(clamp(u, 0.0, 1.0), clamp(along / across, 0.0, 1.0), q);
}

// Texel (i, j)'s nearest hit on the patch: (u, v, 1/t), or z = 0 when it misses.
// The roots root/c and a/root share one division.
fn patch_hit(setup: PatchSetup, i: u32, j: u32) -> vec3<f32> {
    let d = vec3<f32>(texel_centre(i), texel_centre(j), 1.0);
    let e = d.x * setup.face.along_right + d.y * setup.face.along_up + setup.face.along_normal;
    let a = setup.signs.x * e.x;
    let c = e.z;
    let b = setup.signs.y * e.y - a - c;
    let discriminant = b * b - 4.0 * a * c;
    let root = -0.5 * (b + select(-1.0, 1.0, b >= 0.0) * sqrt(max(discriminant, 0.0)));
    if discriminant < 0.0 || root == 0.0 {
        return vec3<f32>(0.0);
    }
    let flat = c == 0.0;
    let inverse = 1.0 / select(root * c, root, flat);
    var best = vec3<f32>(0.0);
    if !flat {
        best = patch_root(setup, d, root * root * inverse, e.xy, best);
    }
    return patch_root(setup, d, a * select(c, 1.0, flat) * inverse, e.xy, best);
}

fn bilinear_basis(u: f32, v: f32) -> vec4<f32> {
    return vec4<f32>((1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v);
}

// Step 1 at texel (i, j) of the band.
fn raster_patch(setup: PatchSetup, i: u32, j: u32, band_start: u32) {
    let q = patch_hit(setup, i, j).z;
    if q > 0.0 {
        atomicMax(&nearest[(j - band_start) * params.resolution + i], bitcast<u32>(q));
    }
}

// Step 2 at texel (i, j): as `claim`, the texel's Ω/|d|·(1/t) spread by the basis.
fn claim_patch(setup: PatchSetup, t: u32, i: u32, j: u32, band_start: u32) -> vec4<f32> {
    let h = patch_hit(setup, i, j);
    let texel = (j - band_start) * params.resolution + i;
    if h.z > 0.0 && bitcast<u32>(h.z) == atomicLoad(&nearest[texel]) {
        if atomicMin(&nearest_triangle[texel], t) != NO_TRIANGLE {
            atomicStore(&tied, 1u);
        }
        return (texels[j * params.resolution + i] * h.z) * bilinear_basis(h.x, h.y);
    }
    return vec4<f32>(0.0);
}

// Step 3 after a tie: the sums over the texels the patch finally holds.
fn claimed_patch_sums(setup: PatchSetup, t: u32, band_start: u32, band_end: u32) -> vec4<f32> {
    var sums = vec4<f32>(0.0);
    let resolution = params.resolution;
    for (var j = max(setup.face.range.z, band_start); j < min(setup.face.range.w, band_end); j++) {
        for (var i = setup.face.range.x; i < setup.face.range.y; i++) {
            if atomicLoad(&nearest_triangle[(j - band_start) * resolution + i]) == t {
                let h = patch_hit(setup, i, j);
                sums += (texels[j * resolution + i] * h.z) * bilinear_basis(h.x, h.y);
            }
        }
    }
    return sums;
}

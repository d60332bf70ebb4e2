// Positive mean value coordinates by cube-map rasterisation, one workgroup per point.
//
// Follows src/coords/cubemap.rs and src/coords/pmvc.rs exactly: one ray per texel
// centre, first hit at t > 0 on either side of a triangle, weight Ω/r, spread by the
// hit's barycentrics. A face is rasterised in bands of rows that fit the
// workgroup-shared depth buffer; invocations own triangles. Per band:
//   1. keep the largest inverse depth q per texel (atomicMax on its bits: q > 0, so
//      the u32 order of the bits is the float order);
//   2. every triangle reaching that depth claims the texel (atomicMin of its index,
//      as the CPU's strict `>` keeps the lowest) and adds Ω/|d| · E_k / det to its
//      corner sums for the band;
//   3. if two triangles reached the same depth somewhere in the band (rare: a ray
//      exactly through a shared edge), the band's sums are redone from the claims.
// Finally each cage vertex gathers its incident triangles' sums and the row is
// normalised by its total (Σ_k E_k/det · Ω/|d| = w, so the row sum is Σ w).

#import bind_params
#import bind_constants

const NO_TRIANGLE: u32 = 0xffffffffu;
const FAR: f32 = 1e30;

@group(0) @binding(0) var<uniform> params: Params;
// Cage vertices relative to the cage centre, xyz.
@group(0) @binding(1) var<storage, read> cage_positions: array<vec4<f32>>;
// 3 corners per triangle, then incidence offsets (vertex_count + 1), then incident
// corners as triangle * 3 + corner.
@group(0) @binding(2) var<storage, read> topology: array<u32>;
// Ω/|d| per texel of one face (row-major, j is the row).
@group(0) @binding(3) var<storage, read> texels: array<f32>;
// xyz relative to the cage centre; w = output row within the batch.
@group(0) @binding(4) var<storage, read> points: array<vec4<f32>>;
// Per point: the three corner sums of every triangle, then their sums for the
// current band (6 floats per triangle).
@group(0) @binding(5) var<storage, read_write> triangle_sums: array<f32>;
@group(0) @binding(6) var<storage, read_write> weights: array<f32>;
// Per point: 0, or FALLBACK when too many rays escaped (the CPU redoes the row).
@group(0) @binding(7) var<storage, read_write> status: array<u32>;

var<workgroup> nearest: array<atomic<u32>, BAND_TEXELS>;
var<workgroup> nearest_triangle: array<atomic<u32>, BAND_TEXELS>;
var<workgroup> missed: atomic<u32>;
// Set when two triangles claim a texel of the band.
var<workgroup> tied: atomic<u32>;
var<workgroup> partial_totals: array<f32, WORKGROUP_SIZE>;

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

// A triangle's edge functions on one face: E = u·along_right + v·along_up + along_normal.
struct FaceSetup {
    along_right: vec3<f32>,
    along_up: vec3<f32>,
    along_normal: vec3<f32>,
    sign: f32,
    inverse_det: f32,
    // Texel ranges [i0, i1) × [j0, j1); empty when i0 >= i1 or j0 >= j1.
    range: vec4<u32>,
}

fn triangle_at(t: u32, x: vec3<f32>) -> Triangle {
    let a = cage_positions[topology[3u * t]].xyz - x;
    let b = cage_positions[topology[3u * t + 1u]].xyz - x;
    let c = cage_positions[topology[3u * t + 2u]].xyz - x;
    let e0 = cross(b, c);
    return Triangle(a, b, c, e0, cross(c, a), cross(a, b), dot(a, e0));
}

#import cube_faces

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
    if !any_in_front || lo.x > 1.0 || hi.x < -1.0 || lo.y > 1.0 || hi.y < -1.0 {
        return vec4<u32>(0u, 0u, 0u, 0u);
    }
    let r = f32(params.resolution);
    let first = max(floor((clamp(lo, vec2(-1.0), vec2(1.0)) + 1.0) * 0.5 * r - 0.5), vec2(0.0));
    let last = min(floor((clamp(hi, vec2(-1.0), vec2(1.0)) + 1.0) * 0.5 * r - 0.5) + 2.0, vec2(r));
    return vec4<u32>(u32(first.x), u32(last.x), u32(first.y), u32(last.y));
}

fn face_setup(tri: Triangle, axes: mat3x3<f32>) -> FaceSetup {
    var setup: FaceSetup;
    setup.along_right = vec3(dot(tri.e0, axes[0]), dot(tri.e1, axes[0]), dot(tri.e2, axes[0]));
    setup.along_up = vec3(dot(tri.e0, axes[1]), dot(tri.e1, axes[1]), dot(tri.e2, axes[1]));
    setup.along_normal = vec3(dot(tri.e0, axes[2]), dot(tri.e1, axes[2]), dot(tri.e2, axes[2]));
    setup.sign = sign(tri.det);
    setup.inverse_det = 1.0 / tri.det;
    if tri.det == 0.0 {
        // x in the triangle's plane: rays graze it, it never blocks or contributes.
        setup.range = vec4<u32>(0u, 0u, 0u, 0u);
    } else {
        setup.range = texel_range(tri, axes);
    }
    return setup;
}

// Computed rather than loaded: storage loads dominate the inner loop on lavapipe.
// The same expression for every triangle, so shared edges still cancel exactly.
fn texel_centre(index: u32) -> f32 {
    return f32(2u * index + 1u) / f32(params.resolution) - 1.0;
}

// Edge values of texel (i, j); .w is the inverse hit depth, or 0 when the ray misses.
fn hit(setup: FaceSetup, i: u32, j: u32) -> vec4<f32> {
    let e = texel_centre(i) * setup.along_right + texel_centre(j) * setup.along_up + setup.along_normal;
    if setup.sign * e.x >= 0.0 && setup.sign * e.y >= 0.0 && setup.sign * e.z >= 0.0 {
        return vec4<f32>(e, (e.x + e.y + e.z) * setup.inverse_det);
    }
    return vec4<f32>(e, 0.0);
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn main(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let point = group.x;
    if point >= params.point_count {
        return;
    }
    let x = points[point].xyz;
    let row = u32(points[point].w);
    let resolution = params.resolution;
    let sums_base = point * params.triangle_count * 6u;
    let band_base = sums_base + 3u * params.triangle_count;
    for (var t = lane; t < params.triangle_count; t += WORKGROUP_SIZE) {
        triangle_sums[sums_base + 3u * t] = 0.0;
        triangle_sums[sums_base + 3u * t + 1u] = 0.0;
        triangle_sums[sums_base + 3u * t + 2u] = 0.0;
    }
    if lane == 0u {
        atomicStore(&missed, 0u);
    }

    for (var face = 0u; face < 6u; face++) {
        let axes = face_axes(face);
        for (var band_start = 0u; band_start < resolution; band_start += params.band_rows) {
            let band_end = min(band_start + params.band_rows, resolution);
            let band_texels = (band_end - band_start) * resolution;
            for (var texel = lane; texel < band_texels; texel += WORKGROUP_SIZE) {
                atomicStore(&nearest[texel], 0u);
                atomicStore(&nearest_triangle[texel], NO_TRIANGLE);
            }
            if lane == 0u {
                atomicStore(&tied, 0u);
            }
            workgroupBarrier();

            // 1. Nearest inverse depth per texel.
            for (var t = lane; t < params.triangle_count; t += WORKGROUP_SIZE) {
                let setup = face_setup(triangle_at(t, x), axes);
                for (var j = max(setup.range.z, band_start); j < min(setup.range.w, band_end); j++) {
                    for (var i = setup.range.x; i < setup.range.y; i++) {
                        let h = hit(setup, i, j);
                        if h.w > 0.0 {
                            atomicMax(&nearest[(j - band_start) * resolution + i], bitcast<u32>(h.w));
                        }
                    }
                }
            }
            workgroupBarrier();

            // 2. Claim the texels reached at that depth and sum them, assuming no ties.
            for (var t = lane; t < params.triangle_count; t += WORKGROUP_SIZE) {
                let setup = face_setup(triangle_at(t, x), axes);
                var sums = vec3<f32>(0.0);
                for (var j = max(setup.range.z, band_start); j < min(setup.range.w, band_end); j++) {
                    for (var i = setup.range.x; i < setup.range.y; i++) {
                        let h = hit(setup, i, j);
                        let texel = (j - band_start) * resolution + i;
                        if h.w > 0.0 && bitcast<u32>(h.w) == atomicLoad(&nearest[texel]) {
                            if atomicMin(&nearest_triangle[texel], t) != NO_TRIANGLE {
                                atomicStore(&tied, 1u);
                            }
                            sums += (texels[j * resolution + i] * setup.inverse_det) * h.xyz;
                        }
                    }
                }
                triangle_sums[band_base + 3u * t] = sums.x;
                triangle_sums[band_base + 3u * t + 1u] = sums.y;
                triangle_sums[band_base + 3u * t + 2u] = sums.z;
            }
            let any_tie = workgroupUniformLoad(&tied) != 0u;

            // 3. Add the band's sums; after a tie, only the lowest claimant's texels.
            for (var t = lane; t < params.triangle_count; t += WORKGROUP_SIZE) {
                var sums = vec3<f32>(
                    triangle_sums[band_base + 3u * t],
                    triangle_sums[band_base + 3u * t + 1u],
                    triangle_sums[band_base + 3u * t + 2u],
                );
                if any_tie {
                    let setup = face_setup(triangle_at(t, x), axes);
                    sums = vec3<f32>(0.0);
                    for (var j = max(setup.range.z, band_start); j < min(setup.range.w, band_end); j++) {
                        for (var i = setup.range.x; i < setup.range.y; i++) {
                            if atomicLoad(&nearest_triangle[(j - band_start) * resolution + i]) == t {
                                let h = hit(setup, i, j);
                                sums += (texels[j * resolution + i] * setup.inverse_det) * h.xyz;
                            }
                        }
                    }
                }
                if any(sums != vec3<f32>(0.0)) {
                    triangle_sums[sums_base + 3u * t] += sums.x;
                    triangle_sums[sums_base + 3u * t + 1u] += sums.y;
                    triangle_sums[sums_base + 3u * t + 2u] += sums.z;
                }
            }
            for (var texel = lane; texel < band_texels; texel += WORKGROUP_SIZE) {
                if atomicLoad(&nearest_triangle[texel]) == NO_TRIANGLE {
                    atomicAdd(&missed, 1u);
                }
            }
            workgroupBarrier();
        }
    }
    storageBarrier();
    workgroupBarrier();

    // Gather per cage vertex, then normalise by the row total.
    let out_base = row * params.vertex_count;
    var total = 0.0;
    for (var v = lane; v < params.vertex_count; v += WORKGROUP_SIZE) {
        var sum = 0.0;
        let end = topology[params.incidence_offsets + v + 1u];
        for (var n = topology[params.incidence_offsets + v]; n < end; n++) {
            sum += triangle_sums[sums_base + topology[params.incidence_entries + n]];
        }
        weights[out_base + v] = sum;
        total += sum;
    }
    partial_totals[lane] = total;
    workgroupBarrier();
    var row_total = 0.0;
    for (var k = 0u; k < WORKGROUP_SIZE; k++) {
        row_total += partial_totals[k];
    }
    let escaped = atomicLoad(&missed) > params.max_missed;
    if escaped || !(row_total > 0.0) {
        if lane == 0u {
            status[point] = FALLBACK;
        }
        return;
    }
    if lane == 0u {
        status[point] = 0u;
    }
    let inverse_total = 1.0 / row_total;
    for (var v = lane; v < params.vertex_count; v += WORKGROUP_SIZE) {
        weights[out_base + v] *= inverse_total;
    }
}

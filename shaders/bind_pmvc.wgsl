// Positive mean value coordinates by cube-map rasterisation, one workgroup per point.
//
// Follows src/coords/cubemap.rs and src/coords/pmvc/ exactly: one ray per texel
// centre, first hit at t > 0 on either side of a triangle, weight Ω/r, spread by the
// hit's barycentrics (on a patch, by its bilinear basis). A face is rasterised in bands of rows that fit the
// workgroup-shared depth buffer; invocations own triangles. A triangle that cannot
// reach a face (a cheap test against the face's four bounding planes) is skipped
// before its set-up, so a large cage costs little on the faces it misses. Per band:
//   1. keep the largest inverse depth q per texel (atomicMax on its bits: q > 0, so
//      the u32 order of the bits is the float order);
//   2. every triangle reaching that depth claims the texel (atomicMin of its index,
//      as the CPU's strict `>` keeps the lowest) and adds Ω/|d| · E_k / det to its
//      corner sums for the band;
//   3. if two triangles reached the same depth somewhere in the band (rare: a ray
//      exactly through a shared edge), the band's sums are redone from the claims.
// A triangle whose part of a band is large is rasterised by the whole workgroup, a
// texel per invocation, in both passes (the owner adds up the invocations' sums,
// in another order than the CPU's): coarse cages have a few large triangles, which
// would keep one invocation busy while the others wait at the barrier.
// Finally each cage vertex gathers its incident triangles' sums and the row is
// normalised by its total (Σ_k E_k/det · Ω/|d| = w, so the row sum is Σ w).
// On a cage with quads a second pipeline (CORNERS = 4) takes bilinear patches
// among the primitives, in the same passes (shared/pmvc_patches.wgsl). For a cage
// of triangles that import is swapped for shared/pmvc_no_patches.wgsl, and every
// patch branch folds away.

#import bind_params
#import bind_constants
#import pmvc_bindings
#import pmvc_face
#import pmvc_patches

const NO_TRIANGLE: u32 = 0xffffffffu;
// Corner slots per primitive: 3 on a cage of triangles, 4 on a cage with quads
// (set per pipeline; the layout `topology` and `triangle_sums` follow).
override CORNERS: u32 = 3u;

// Per point: the CORNERS corner sums of every primitive, then their sums for the
// current band.
@group(0) @binding(5) var<storage, read_write> triangle_sums: array<f32>;

var<workgroup> nearest: array<atomic<u32>, BAND_TEXELS>;
var<workgroup> nearest_triangle: array<atomic<u32>, BAND_TEXELS>;
var<workgroup> missed: atomic<u32>;
// Set when two triangles claim a texel of the band.
var<workgroup> tied: atomic<u32>;
// The band's shared triangles (more than SHARED_TEXELS texels in it), and the
// invocations' sums over one of them.
var<workgroup> shared_count: atomic<u32>;
var<workgroup> shared_triangles: array<u32, MAX_SHARED>;
var<workgroup> partial_sums: array<vec4<f32>, WORKGROUP_SIZE>;

// Above this many texels in a band, a triangle is rasterised by the whole workgroup.
const SHARED_TEXELS: u32 = 128u;
const MAX_SHARED: u32 = 64u;

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

// The triangle's texels in the band: [x, y) × [z, w), possibly empty.
fn band_part(setup: FaceSetup, band_start: u32, band_end: u32) -> vec4<u32> {
    let j0 = max(setup.range.z, band_start);
    let j1 = max(min(setup.range.w, band_end), j0);
    return vec4<u32>(setup.range.x, max(setup.range.y, setup.range.x), j0, j1);
}

fn texel_count(part: vec4<u32>) -> u32 {
    return (part.y - part.x) * (part.w - part.z);
}

// An invocation's texels of a shared triangle's part: n = lane + k · WORKGROUP_SIZE
// in row-major order, stepped by `texel_step` (columns, rows) with no division per
// texel (CPUs have no vector one). The part is not empty.
fn first_texel(part: vec4<u32>, lane: u32) -> vec2<u32> {
    let width = part.y - part.x;
    return vec2<u32>(part.x + lane % width, part.z + lane / width);
}

fn texel_step(part: vec4<u32>) -> vec2<u32> {
    let width = part.y - part.x;
    return vec2<u32>(WORKGROUP_SIZE % width, WORKGROUP_SIZE / width);
}

fn next_texel(part: vec4<u32>, at: vec2<u32>, step: vec2<u32>) -> vec2<u32> {
    let next = at + step;
    if next.x >= part.y {
        return vec2<u32>(next.x - (part.y - part.x), next.y + 1u);
    }
    return next;
}

fn reaches(reaching: vec2<u32>, owned: u32) -> bool {
    return owned >= 64u || (reaching[owned / 32u] & (1u << (owned % 32u))) != 0u;
}

// Edge values of texel (i, j); .w is the inverse hit depth, or 0 when the ray misses.
fn hit(setup: FaceSetup, i: u32, j: u32) -> vec4<f32> {
    let e = texel_centre(i) * setup.along_right + texel_centre(j) * setup.along_up + setup.along_normal;
    if setup.sign * e.x >= 0.0 && setup.sign * e.y >= 0.0 && setup.sign * e.z >= 0.0 {
        return vec4<f32>(e, (e.x + e.y + e.z) * setup.inverse_det);
    }
    return vec4<f32>(e, 0.0);
}

// Step 2 at texel (i, j) of the band: if triangle t reaches the nearest depth there,
// it claims the texel, and the texel's share of t's corner sums is returned.
fn claim(setup: FaceSetup, t: u32, i: u32, j: u32, band_start: u32) -> vec3<f32> {
    let h = hit(setup, i, j);
    let texel = (j - band_start) * params.resolution + i;
    if h.w > 0.0 && bitcast<u32>(h.w) == atomicLoad(&nearest[texel]) {
        if atomicMin(&nearest_triangle[texel], t) != NO_TRIANGLE {
            atomicStore(&tied, 1u);
        }
        return (texels[j * params.resolution + i] * setup.inverse_det) * h.xyz;
    }
    return vec3<f32>(0.0);
}

// Step 1: t's part of the band is large, and it joins the band's shared list.
fn share(t: u32) -> bool {
    let slot = atomicAdd(&shared_count, 1u);
    if slot < MAX_SHARED {
        shared_triangles[slot] = t;
        return true;
    }
    return false;
}

fn band_sums(base: u32, t: u32) -> vec4<f32> {
    var sums = vec4<f32>(0.0);
    for (var k = 0u; k < CORNERS; k++) {
        sums[k] = triangle_sums[base + CORNERS * t + k];
    }
    return sums;
}

fn store_band_sums(base: u32, t: u32, sums: vec4<f32>) {
    for (var k = 0u; k < CORNERS; k++) {
        triangle_sums[base + CORNERS * t + k] = sums[k];
    }
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
    let sums_base = point * params.triangle_count * 2u * CORNERS;
    let band_base = sums_base + CORNERS * params.triangle_count;
    for (var n = lane; n < CORNERS * params.triangle_count; n += WORKGROUP_SIZE) {
        triangle_sums[sums_base + n] = 0.0;
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
                atomicStore(&shared_count, 0u);
            }
            workgroupBarrier();

            // 1. Nearest inverse depth per texel. Bit k of `shared_mask`: this
            // invocation's k-th triangle is shared.
            var shared_mask = 0u;
            // Bit k: this invocation's k-th triangle may reach the face (only the
            // first 64 are tested; the rest of a huge cage count as reaching).
            var reaching = vec2<u32>(0u, 0u);
            var k = 0u;
            for (var t = lane; t < params.triangle_count; t += WORKGROUP_SIZE) {
                let owned = k;
                k++;
                let on_patch = is_patch(t);
                if owned < 64u {
                    if !may_reach_face(t, x, axes, select(3u, 4u, on_patch)) {
                        continue;
                    }
                    reaching[owned / 32u] |= 1u << (owned % 32u);
                }
                if on_patch {
                    let setup = patch_setup(t, x, axes);
                    let part = band_part(setup.face, band_start, band_end);
                    if owned < 32u && texel_count(part) > SHARED_TEXELS && share(t) {
                        shared_mask |= 1u << owned;
                        continue;
                    }
                    for (var j = part.z; j < part.w; j++) {
                        for (var i = part.x; i < part.y; i++) {
                            raster_patch(setup, i, j, band_start);
                        }
                    }
                    continue;
                }
                let setup = face_setup(triangle_at(t, x), axes);
                let part = band_part(setup, band_start, band_end);
                if owned < 32u && texel_count(part) > SHARED_TEXELS && share(t) {
                    shared_mask |= 1u << owned;
                    continue;
                }
                for (var j = part.z; j < part.w; j++) {
                    for (var i = part.x; i < part.y; i++) {
                        let h = hit(setup, i, j);
                        if h.w > 0.0 {
                            atomicMax(&nearest[(j - band_start) * resolution + i], bitcast<u32>(h.w));
                        }
                    }
                }
            }
            let shared_total = min(workgroupUniformLoad(&shared_count), MAX_SHARED);
            for (var s = 0u; s < shared_total; s++) {
                let t = shared_triangles[s];
                if is_patch(t) {
                    let setup = patch_setup(t, x, axes);
                    let part = band_part(setup.face, band_start, band_end);
                    let step = texel_step(part);
                    var at = first_texel(part, lane);
                    while at.y < part.w {
                        raster_patch(setup, at.x, at.y, band_start);
                        at = next_texel(part, at, step);
                    }
                    continue;
                }
                let setup = face_setup(triangle_at(t, x), axes);
                let part = band_part(setup, band_start, band_end);
                let step = texel_step(part);
                var at = first_texel(part, lane);
                while at.y < part.w {
                    let h = hit(setup, at.x, at.y);
                    if h.w > 0.0 {
                        atomicMax(&nearest[(at.y - band_start) * resolution + at.x], bitcast<u32>(h.w));
                    }
                    at = next_texel(part, at, step);
                }
            }
            workgroupBarrier();

            // 2. Claim the texels reached at that depth and sum them, assuming no ties.
            k = 0u;
            for (var t = lane; t < params.triangle_count; t += WORKGROUP_SIZE) {
                let owned = k;
                k++;
                if !reaches(reaching, owned) {
                    continue;
                }
                if owned < 32u && (shared_mask & (1u << owned)) != 0u {
                    continue;
                }
                if is_patch(t) {
                    let setup = patch_setup(t, x, axes);
                    let part = band_part(setup.face, band_start, band_end);
                    var sums = vec4<f32>(0.0);
                    for (var j = part.z; j < part.w; j++) {
                        for (var i = part.x; i < part.y; i++) {
                            sums += claim_patch(setup, t, i, j, band_start);
                        }
                    }
                    store_band_sums(band_base, t, sums);
                    continue;
                }
                let setup = face_setup(triangle_at(t, x), axes);
                let part = band_part(setup, band_start, band_end);
                var sums = vec3<f32>(0.0);
                for (var j = part.z; j < part.w; j++) {
                    for (var i = part.x; i < part.y; i++) {
                        sums += claim(setup, t, i, j, band_start);
                    }
                }
                store_band_sums(band_base, t, vec4<f32>(sums, 0.0));
            }
            for (var s = 0u; s < shared_total; s++) {
                let t = shared_triangles[s];
                var sums = vec4<f32>(0.0);
                if is_patch(t) {
                    let setup = patch_setup(t, x, axes);
                    let part = band_part(setup.face, band_start, band_end);
                    let step = texel_step(part);
                    var at = first_texel(part, lane);
                    while at.y < part.w {
                        sums += claim_patch(setup, t, at.x, at.y, band_start);
                        at = next_texel(part, at, step);
                    }
                } else {
                    let setup = face_setup(triangle_at(t, x), axes);
                    let part = band_part(setup, band_start, band_end);
                    let step = texel_step(part);
                    var at = first_texel(part, lane);
                    while at.y < part.w {
                        sums += vec4<f32>(claim(setup, t, at.x, at.y, band_start), 0.0);
                        at = next_texel(part, at, step);
                    }
                }
                partial_sums[lane] = sums;
                workgroupBarrier();
                // The owner of t, which adds the band's sums to its totals in step 3.
                if lane == t % WORKGROUP_SIZE {
                    var total = vec4<f32>(0.0);
                    for (var q = 0u; q < WORKGROUP_SIZE; q++) {
                        total += partial_sums[q];
                    }
                    store_band_sums(band_base, t, total);
                }
                workgroupBarrier();
            }
            let any_tie = workgroupUniformLoad(&tied) != 0u;

            // 3. Add the band's sums; after a tie, only the lowest claimant's texels.
            k = 0u;
            for (var t = lane; t < params.triangle_count; t += WORKGROUP_SIZE) {
                let owned = k;
                k++;
                if !reaches(reaching, owned) {
                    continue;
                }
                var sums = band_sums(band_base, t);
                if any_tie && is_patch(t) {
                    sums = claimed_patch_sums(patch_setup(t, x, axes), t, band_start, band_end);
                } else if any_tie {
                    let setup = face_setup(triangle_at(t, x), axes);
                    sums = vec4<f32>(0.0);
                    for (var j = max(setup.range.z, band_start); j < min(setup.range.w, band_end); j++) {
                        for (var i = setup.range.x; i < setup.range.y; i++) {
                            if atomicLoad(&nearest_triangle[(j - band_start) * resolution + i]) == t {
                                let h = hit(setup, i, j);
                                sums += vec4<f32>((texels[j * resolution + i] * setup.inverse_det) * h.xyz, 0.0);
                            }
                        }
                    }
                }
                if any(sums != vec4<f32>(0.0)) {
                    for (var c = 0u; c < CORNERS; c++) {
                        triangle_sums[sums_base + CORNERS * t + c] += sums[c];
                    }
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
    let row_total = workgroup_sum(lane, total);
    finish_row(point, lane, out_base, row_total, atomicLoad(&missed) > params.max_missed);
}

// Positive mean value coordinates by cube-map ray casting, one workgroup per point,
// invocations owning texels: the kernel for cages of triangles with at most
// TILES_MAX_VERTICES vertices (bind_pmvc.wgsl, whose invocations own triangles,
// takes the rest and cages with patches).
//
// The same texels, rays, hit rule, inverse depth and tie rule as bind_pmvc.wgsl
// and the CPU's coords::pmvc. A face is cut into regions of REGION × REGION
// texels; each invocation owns a TILE × TILE tile of the region and keeps its
// texels' nearest hit in registers. Per region:
//   1. the triangles that can reach it are set up once into workgroup memory, up
//      to CHUNK at a time (face test, edge functions in the face's coordinates,
//      texel bounds);
//   2. every invocation tests its texels' rays against each of them, keeping the
//      largest inverse depth and, at equal depth, the lowest triangle index (what
//      the CPU's strict `>` in index order keeps), so the order in which the
//      triangles were set up never shows;
//   3. the texels' weights Ω/|d| · E_k/det are added per cage vertex in fixed
//      point, in units of the region's total / 2^30 (integer atomics: the sums do
//      not depend on timing), and added to the row once per region.
// Why: invocations that own triangles walk bounds of very different sizes and wait
// at every barrier for the largest, with shared-memory atomics per texel; here
// every invocation does the same work on the same triangle at the same time.

#import bind_params
#import bind_constants
#import pmvc_bindings
#import pmvc_face

const NO_TRIANGLE: u32 = 0xffffffffu;
// Texels per side of a region and of an invocation's tile: WORKGROUP_SIZE tiles
// make a region.
const REGION: u32 = 32u;
const TILE: u32 = 4u;
const TILES_PER_ROW: u32 = 8u;
const TILE_TEXELS: u32 = 16u;
const_assert WORKGROUP_SIZE == TILES_PER_ROW * TILES_PER_ROW;
const_assert REGION == TILE * TILES_PER_ROW && TILE_TEXELS == TILE * TILE;
// Triangles set up at a time.
const CHUNK: u32 = 64u;
// 2^30: a region's weights sum to this many units, each vertex's to at most this
// plus the rounding of 3 · REGION² texel shares, so a u32 holds them.
const FIXED_UNITS: f32 = 1073741824.0;
const CORNERS: u32 = 3u;

// A chunk's triangles: the edge functions' coefficients of u, of v and constant
// (E = u·along_right + v·along_up + along_normal, times the sign of det, so a ray
// hits iff all three are ≥ 0), 1/|det| in along_up's w.
var<workgroup> chunk_right: array<vec4<f32>, CHUNK>;
var<workgroup> chunk_up: array<vec4<f32>, CHUNK>;
var<workgroup> chunk_normal: array<vec4<f32>, CHUNK>;
// The triangle's index and its texel bounds within the region, a byte each.
var<workgroup> chunk_ids: array<vec2<u32>, CHUNK>;
// Triangles offered to chunks so far (a slot past the chunk's end is offered again).
var<workgroup> offered: atomic<u32>;
var<workgroup> vertex_units: array<atomic<u32>, TILES_MAX_VERTICES>;
var<workgroup> missed: atomic<u32>;

struct Setup {
    along_right: vec3<f32>,
    along_up: vec3<f32>,
    along_normal: vec3<f32>,
    inverse_det: f32,
    // Texel bounds [x, y) × [z, w) on the face; empty when the triangle cannot be hit.
    range: vec4<u32>,
}

// Triangle t's edge functions on the face with `axes`. One function for the test
// and the sums, so both see the same values. The sums (`bounded` false) take
// triangles that were hit, so they skip the face test and the bounds.
fn setup_of(t: u32, x: vec3<f32>, axes: mat3x3<f32>, bounded: bool) -> Setup {
    var setup: Setup;
    setup.range = vec4<u32>(0u);
    // The corners are loaded once for the face test and the set-up.
    let a = cage_positions[topology[3u * t]].xyz - x;
    let b = cage_positions[topology[3u * t + 1u]].xyz - x;
    let c = cage_positions[topology[3u * t + 2u]].xyz - x;
    if bounded && (planes_outside(a, axes) & planes_outside(b, axes) & planes_outside(c, axes)) != 0u {
        return setup;
    }
    let e0 = cross(b, c);
    let tri = Triangle(a, b, c, e0, cross(c, a), cross(a, b), dot(a, e0));
    if tri.det == 0.0 {
        // x in the triangle's plane: rays graze it, it never blocks or contributes.
        return setup;
    }
    let s = sign(tri.det);
    setup.along_right = s * vec3(dot(tri.e0, axes[0]), dot(tri.e1, axes[0]), dot(tri.e2, axes[0]));
    setup.along_up = s * vec3(dot(tri.e0, axes[1]), dot(tri.e1, axes[1]), dot(tri.e2, axes[1]));
    setup.along_normal = s * vec3(dot(tri.e0, axes[2]), dot(tri.e1, axes[2]), dot(tri.e2, axes[2]));
    setup.inverse_det = 1.0 / abs(tri.det);
    if bounded {
        setup.range = texel_range(tri, axes);
    }
    return setup;
}

// Edge values of the ray through (u, v): sign(det)·E_k, all ≥ 0 iff the ray hits.
// Neighbours sharing an edge compute exactly negated values there (the same
// operations on negated coefficients), so no ray passes between them.
fn edges(right: vec3<f32>, up: vec3<f32>, normal: vec3<f32>, u: f32, v: f32) -> vec3<f32> {
    return fma(vec3(u), right, fma(vec3(v), up, normal));
}

// Bounds [x, y) × [z, w) clipped to the region at `origin`, relative to it.
fn within_region(range: vec4<u32>, origin: vec2<u32>) -> vec4<u32> {
    let lo = max(range.xz, origin);
    let hi = max(min(range.yw, origin + REGION), lo);
    return vec4<u32>(lo.x - origin.x, hi.x - origin.x, lo.y - origin.y, hi.y - origin.y);
}

fn pack_range(r: vec4<u32>) -> u32 {
    return r.x | (r.y << 8u) | (r.z << 16u) | (r.w << 24u);
}

fn unpack_range(packed: u32) -> vec4<u32> {
    return (vec4<u32>(packed) >> vec4<u32>(0u, 8u, 16u, 24u)) & vec4<u32>(0xffu);
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
    let out_base = row * params.vertex_count;
    for (var v = lane; v < params.vertex_count; v += WORKGROUP_SIZE) {
        weights[out_base + v] = 0.0;
        atomicStore(&vertex_units[v], 0u);
    }
    if lane == 0u {
        atomicStore(&missed, 0u);
        atomicStore(&offered, 0u);
    }
    // The tile's first texel within a region.
    let tile = tile_of(lane);
    // Uniform: set when a region's total is not finite (the CPU redoes the row).
    var overflow = false;
    // Uniform: `offered` when the current chunk began. It carries over from one
    // region to the next, where no barrier is needed to read it again.
    var chunk_start = 0u;
    workgroupBarrier();

    for (var face = 0u; face < 6u; face++) {
        let axes = face_axes(face);
        for (var region_j = 0u; region_j < resolution; region_j += REGION) {
            for (var region_i = 0u; region_i < resolution; region_i += REGION) {
                let origin = vec2<u32>(region_i, region_j);
                // The tile's texel centres: its columns' u, and each row's v.
                let first = origin + tile;
                let tile_u = vec4(texel_centre(first.x), texel_centre(first.x + 1u),
                    texel_centre(first.x + 2u), texel_centre(first.x + 3u));
                let tile_v = vec4(texel_centre(first.y), texel_centre(first.y + 1u),
                    texel_centre(first.y + 2u), texel_centre(first.y + 3u));
                // Per row of the tile, its four texels' nearest inverse depth (0:
                // no hit yet) and triangle.
                var row_q = array<vec4<f32>, TILE>();
                var row_t = array<vec4<u32>, TILE>();
                // 1 and 2, a chunk at a time.
                var next = lane;
                loop {
                    while next < params.triangle_count {
                        let setup = setup_of(next, x, axes, true);
                        let part = within_region(setup.range, origin);
                        if part.x >= part.y || part.z >= part.w {
                            next += WORKGROUP_SIZE;
                            continue;
                        }
                        let slot = atomicAdd(&offered, 1u) - chunk_start;
                        if slot >= CHUNK {
                            break;
                        }
                        chunk_right[slot] = vec4<f32>(setup.along_right, 0.0);
                        chunk_up[slot] = vec4<f32>(setup.along_up, setup.inverse_det);
                        chunk_normal[slot] = vec4<f32>(setup.along_normal, 0.0);
                        chunk_ids[slot] = vec2<u32>(next, pack_range(part));
                        next += WORKGROUP_SIZE;
                    }
                    let offered_now = workgroupUniformLoad(&offered);
                    let in_chunk = min(offered_now - chunk_start, CHUNK);
                    for (var s = 0u; s < in_chunk; s++) {
                        let ids = chunk_ids[s];
                        let part = unpack_range(ids.y);
                        if part.x >= tile.x + TILE || part.y <= tile.x || part.z >= tile.y + TILE || part.w <= tile.y {
                            continue;
                        }
                        let right = chunk_right[s].xyz;
                        let up = chunk_up[s];
                        let normal = chunk_normal[s].xyz;
                        // A loop of constant length the compiler unrolls, so the rows
                        // are indexed by constants and stay in registers.
                        for (var r = 0u; r < TILE; r++) {
                            let kept = nearest_of_row(row_q[r], row_t[r], ids.x, right, up, normal, tile_u, tile_v[r]);
                            row_q[r] = kept.q;
                            row_t[r] = kept.t;
                        }
                    }
                    let last_chunk = offered_now - chunk_start <= CHUNK;
                    chunk_start = offered_now;
                    if last_chunk {
                        // The next chunk is written after the barriers of step 3.
                        break;
                    }
                    // Every invocation is done with this chunk before the next is
                    // written.
                    workgroupBarrier();
                }

                // 3. The region's total, then its shares per vertex in fixed point.
                // Copied out in a loop the compiler unrolls, so that the rows
                // above are never indexed at run time, which would move them to
                // memory.
                var nearest_q: array<f32, TILE_TEXELS>;
                var nearest_t: array<u32, TILE_TEXELS>;
                for (var k = 0u; k < TILE_TEXELS; k++) {
                    nearest_q[k] = row_q[k / TILE][k % TILE];
                    nearest_t[k] = select(NO_TRIANGLE, row_t[k / TILE][k % TILE], nearest_q[k] > 0.0);
                }
                var total = 0.0;
                var lane_missed = 0u;
                for (var k = 0u; k < TILE_TEXELS; k++) {
                    let texel = origin + tile + vec2<u32>(k % TILE, k / TILE);
                    if texel.x >= resolution || texel.y >= resolution {
                        continue;
                    }
                    if nearest_t[k] == NO_TRIANGLE {
                        lane_missed++;
                    } else {
                        total += texels[texel.y * resolution + texel.x] * nearest_q[k];
                    }
                }
                if lane_missed != 0u {
                    atomicAdd(&missed, lane_missed);
                }
                let region_total = workgroup_sum(lane, total);
                if !(region_total <= 3.0e38) {
                    overflow = true;
                } else if region_total > 0.0 {
                    let scale = FIXED_UNITS / region_total;
                    // Consecutive texels mostly share their triangle: sum runs.
                    var run_t = NO_TRIANGLE;
                    var run = vec3<u32>(0u);
                    var setup: Setup;
                    for (var k = 0u; k < TILE_TEXELS; k++) {
                        let t = nearest_t[k];
                        let texel = origin + tile + vec2<u32>(k % TILE, k / TILE);
                        if t == NO_TRIANGLE || texel.x >= resolution || texel.y >= resolution {
                            continue;
                        }
                        if t != run_t {
                            if run_t != NO_TRIANGLE {
                                add_run(run_t, run);
                            }
                            run_t = t;
                            run = vec3<u32>(0u);
                            setup = setup_of(t, x, axes, false);
                        }
                        let e = edges(setup.along_right, setup.along_up, setup.along_normal,
                            texel_centre(texel.x), texel_centre(texel.y));
                        let share = texels[texel.y * resolution + texel.x] * setup.inverse_det * e;
                        run += vec3<u32>(share * scale + 0.5);
                    }
                    if run_t != NO_TRIANGLE {
                        add_run(run_t, run);
                    }
                }
                workgroupBarrier();
                let unit = region_total / FIXED_UNITS;
                for (var v = lane; v < params.vertex_count; v += WORKGROUP_SIZE) {
                    let units = atomicLoad(&vertex_units[v]);
                    if units != 0u {
                        weights[out_base + v] += f32(units) * unit;
                        atomicStore(&vertex_units[v], 0u);
                    }
                }
                // No barrier: the next region adds to these sums only after its
                // first chunk's barrier.
            }
        }
    }

    // Normalise by the row total.
    var total = 0.0;
    for (var v = lane; v < params.vertex_count; v += WORKGROUP_SIZE) {
        total += weights[out_base + v];
    }
    let row_total = workgroup_sum(lane, total);
    let redo = atomicLoad(&missed) > params.max_missed || overflow;
    finish_row(point, lane, out_base, row_total, redo);
}

// The tile an invocation owns within a region: the invocation's bits
// interleaved as x, y, x, y, x, y, so that each run of 4, 8, 16 or 32
// invocations (a SIMD group on lavapipe or a GPU) covers a near-square block of
// texels and a small triangle leaves whole groups idle, which then skip it. In
// rows of 8 tiles a group spanned the region's width, and nearly every triangle
// kept it busy.
const_assert TILES_PER_ROW == 8u; // three bits of the index for each of x and y
fn tile_of(lane: u32) -> vec2<u32> {
    let x = (lane & 1u) | ((lane >> 1u) & 2u) | ((lane >> 2u) & 4u);
    let y = ((lane >> 1u) & 1u) | ((lane >> 2u) & 2u) | ((lane >> 3u) & 4u);
    return vec2<u32>(x, y) * TILE;
}

struct Nearest {
    q: vec4<f32>,
    t: vec4<u32>,
}

// One row of a tile against one triangle: four rays at once and no branches, as
// software adapters run both sides of any branch their SIMD lanes disagree on
// (on lavapipe the ray tests took about half as long as with a branch per
// texel). Keeps the largest inverse depth and, at equal depth, the lowest index;
// `q` and `t` start at 0, so only hits in front (q > 0) are kept: a hit at q = 0
// ties and has no lower index than 0. Texels outside the
// triangle's bounds are tested too: they lie a texel or more outside its
// projection, so they miss.
fn nearest_of_row(q: vec4<f32>, t: vec4<u32>, triangle: u32,
    right: vec3<f32>, up: vec4<f32>, normal: vec3<f32>, u: vec4<f32>, v: f32) -> Nearest {
    // Per texel exactly `edges`: fma(u, right, fma(v, up, normal)).
    let at_v = fma(vec3(v), up.xyz, normal);
    let e0 = fma(u, vec4(right.x), vec4(at_v.x));
    let e1 = fma(u, vec4(right.y), vec4(at_v.y));
    let e2 = fma(u, vec4(right.z), vec4(at_v.z));
    let hit_q = (e0 + e1 + e2) * up.w;
    let id = vec4(triangle);
    let hit = min(min(e0, e1), e2) >= vec4(0.0);
    let keep = hit & ((hit_q > q) | ((hit_q == q) & (id < t)));
    return Nearest(select(q, hit_q, keep), select(t, id, keep));
}

fn add_run(t: u32, units: vec3<u32>) {
    for (var k = 0u; k < 3u; k++) {
        if units[k] != 0u {
            atomicAdd(&vertex_units[topology[3u * t + k]], units[k]);
        }
    }
}

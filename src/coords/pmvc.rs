//! The CPU reference for positive mean value coordinates.
//!
//! Implements exactly the discretisation of [`super::cubemap`]: one ray per texel
//! centre of a cube map around x, first hit at t > 0 on either side of a triangle,
//! weight `Ω/r`, spread by the hit's barycentrics.
//!
//! Instead of casting every ray against every triangle, each cube face is
//! rasterised: every triangle is tested only against the texels inside the bounds
//! of its projection, keeping the nearest hit per texel in a depth buffer. The test
//! itself is exact per texel: for a ray direction d and a triangle (a, b, c) taken
//! relative to x, the scalar triple products `d·(b×c)`, `d·(c×a)`, `d·(a×b)` are
//! the unnormalised barycentrics of the hit, and their sum `D` gives the ray
//! parameter `t = det[a,b,c] / D`. A shared edge yields exactly negated values in
//! its two triangles, so no ray slips between them; a texel is covered where no edge
//! value has its sign bit set, so a ray exactly along that edge goes to one of them.
//!
//! The resolve needs only which triangle won each texel: the texel's weight times
//! the hit's barycentrics, `Ω/r · Eₖ/D = Eₖ·(Ω·d̂)/det`, is linear in `Ω·d̂`, so the
//! per-texel vectors `Ω·d̂` are summed per triangle and dotted with its edge normals
//! once. The winner is kept in the depth buffer itself, coded in the low mantissa
//! bits of the inverse depth ([`hit_key`]).

#[cfg(test)]
use super::cubemap::CUBE_FACES;
use super::cubemap::{TexelTable, TEXEL_LANES};
use crate::geometry::Cage;
use glam::DVec3;
use std::ops::Range;

/// Reusable buffers, so that binding allocates nothing per vertex.
#[derive(Debug, Default)]
pub struct PmvcScratch {
    vertices: Vec<VertexSetup>,
    triangles: Vec<TriangleSetup>,
    /// Per texel of the current face (padded rows): the nearest hit's key (0 = none),
    /// see [`hit_key`].
    nearest: Vec<f64>,
    /// Per cube face f, from `f·T` on (T: the cage's triangle count), the indices into
    /// `triangles` of those that may reach it; `face_counts[f]` of them.
    by_face: Vec<u32>,
    /// Triangles rasterised on the current face, with their signed edge functions.
    drawn: Vec<(u32, [DVec3; 3])>,
    /// [`BANKS`] accumulators per hit code (code 0: the misses): the sums of
    /// [`TexelTable::texel_directions`] over the texels each code won.
    sums: Vec<[[f64; 4]; BANKS]>,
}

/// What every triangle at a cage vertex needs, computed once per vertex.
#[derive(Clone, Copy, Debug, Default)]
struct VertexSetup {
    /// Position relative to x.
    relative: DVec3,
    /// Bits `5f..5f + 5`: the vertex's frustum outcode for cube face f, see [`outcode`].
    outcodes: u32,
    /// `(x/z, y/z)` in each face's coordinates; meaningful where the vertex is in front
    /// of the face (outcode bit 0 clear).
    projections: [[f64; 2]; 6],
}

impl VertexSetup {
    #[inline(always)]
    fn new(relative: DVec3) -> Self {
        let inverse = DVec3::ONE / relative;
        let mut outcodes = 0;
        let mut projections = [[0.0; 2]; 6];
        for (f, frame) in FACE_FRAMES.iter().enumerate() {
            let [(r, rs), (u, us), (n, ns)] = frame.axes;
            outcodes |= outcode(&frame.local(relative)) << (5 * f);
            let scale = inverse[n] * ns;
            projections[f] = [relative[r] * rs * scale, relative[u] * us * scale];
        }
        Self {
            relative,
            outcodes,
            projections,
        }
    }
}

#[derive(Clone, Copy, Debug, Default)]
struct TriangleSetup {
    /// Its cage vertices.
    vertices: [u32; 3],
    /// Corners relative to x.
    corners: [DVec3; 3],
    /// `b×c`, `c×a`, `a×b`: a ray direction dotted with these gives unnormalised barycentrics.
    edge_normals: [DVec3; 3],
    /// `det[a, b, c]`; its sign tells which side x is on.
    det: f64,
}

/// Share of texels that may miss every triangle before x is treated as not enclosed.
/// A miss inside a closed cage can only come from a ray through a cage vertex whose
/// edge tests all round the same way, which is vanishingly rare.
const MAX_MISSED_SHARE: f64 = 0.01;

/// Accumulator banks per triangle: consecutive texels add into different ones, so
/// runs of texels won by one triangle do not wait on each other's stores.
const BANKS: usize = 4;

/// PMVC of `x`, written to `out` (one value per cage vertex). Returns `false`, with
/// `out` unspecified, when x is not enclosed by the cage (too many rays escape).
pub fn pmvc_weights(
    x: DVec3,
    cage: &Cage,
    table: &TexelTable,
    out: &mut [f64],
    scratch: &mut PmvcScratch,
) -> bool {
    dispatch::<false>(x, cage, table, out, scratch)
}

/// [`pmvc_weights`] for a point that [`crate::geometry::classify_points`] found
/// strictly inside the cage, which must not intersect itself. Gives the same weights
/// up to rounding, faster: from inside, the first hit of every ray leaves the
/// volume, so it is never on a triangle that x sees from its outer side, and those
/// triangles are skipped.
pub fn pmvc_weights_inside(
    x: DVec3,
    cage: &Cage,
    table: &TexelTable,
    out: &mut [f64],
    scratch: &mut PmvcScratch,
) -> bool {
    dispatch::<true>(x, cage, table, out, scratch)
}

#[inline(always)]
fn dispatch<const CULL: bool>(
    x: DVec3,
    cage: &Cage,
    table: &TexelTable,
    out: &mut [f64],
    scratch: &mut PmvcScratch,
) -> bool {
    // Elsewhere `f64::mul_add` is one instruction on most CPUs, and a slower but exact
    // library call on x86-64 processors older than AVX2.
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU has just been checked to support AVX2 and FMA.
        return unsafe { pmvc_weights_avx2::<CULL>(x, cage, table, out, scratch) };
    }
    pmvc_weights_with::<CULL>(x, cage, table, out, scratch, raster_triangle)
}

/// The same code compiled for AVX2 and FMA, with the depth test written four texels
/// at a time. Both use the same fused multiply-adds, so the results are bit-identical.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn pmvc_weights_avx2<const CULL: bool>(
    x: DVec3,
    cage: &Cage,
    table: &TexelTable,
    out: &mut [f64],
    scratch: &mut PmvcScratch,
) -> bool {
    // Closures inherit the target features of the function they are written in.
    let raster = |triangle: &FaceTriangle,
                  rows: Range<usize>,
                  columns: Range<usize>,
                  table: &TexelTable,
                  nearest: &mut [f64]| {
        raster_triangle_avx2(triangle, rows, columns, table, nearest)
    };
    pmvc_weights_with::<CULL>(x, cage, table, out, scratch, raster)
}

/// One triangle's depth test on one cube face, in the form both rasterisers take.
#[derive(Clone, Copy, Debug)]
struct FaceTriangle {
    /// `s·E_k(u, v) = x·u + y·v + z` per edge, with the sign s of det folded in.
    edges: [DVec3; 3],
    /// `1/t = x·u + y·v + z`.
    depth: DVec3,
    /// See [`hit_key`].
    code_mask: usize,
    code: u64,
}

impl FaceTriangle {
    /// Along the row at `v`: the offsets of the edge functions and of the depth.
    #[inline(always)]
    fn row(&self, v: f64) -> ([f64; 3], f64) {
        let [e0, e1, e2] = self.edges;
        (
            [
                v.mul_add(e0.y, e0.z),
                v.mul_add(e1.y, e1.z),
                v.mul_add(e2.y, e2.z),
            ],
            v.mul_add(self.depth.y, self.depth.z),
        )
    }
}

/// Keeps in `nearest` the larger of its key and the triangle's key at each texel it
/// covers.
#[inline(always)]
fn raster_triangle(
    triangle: &FaceTriangle,
    rows: Range<usize>,
    columns: Range<usize>,
    table: &TexelTable,
    nearest: &mut [f64],
) {
    let [s0, s1, s2] = triangle.edges.map(|edge| edge.x);
    let centres = &table.padded_centres[columns.clone()];
    for j in rows {
        let ([o0, o1, o2], depth_offset) = triangle.row(table.centres[j]);
        let row = j * table.stride;
        let nearest = &mut nearest[row + columns.start..row + columns.end];
        for (&u, nearest) in centres.iter().zip(nearest) {
            // Exact per texel: a shared edge gives exactly negated values in its two
            // triangles, so no ray slips between them. Covered where no sign bit is
            // set; the padding's NaN centres may pass, but their NaN keys never win the
            // maximum below.
            let signs = u.mul_add(s0, o0).to_bits()
                | u.mul_add(s1, o1).to_bits()
                | u.mul_add(s2, o2).to_bits();
            let inside = signs >> 63 == 0;
            // 1/t of the hit, linear in u; larger is nearer.
            let inverse_t = u.mul_add(triangle.depth.x, depth_offset);
            let key = hit_key(inverse_t, triangle.code_mask, triangle.code);
            // A maximum and a plain store: a conditional store would become a masked
            // store, which is slow on some CPUs.
            let offered = if inside { key } else { 0.0 };
            *nearest = if offered > *nearest {
                offered
            } else {
                *nearest
            };
        }
    }
}

/// [`raster_triangle`] four texels at a time, operation for operation. Triangles one
/// to three steps wide get a loop of fixed length, so that the only branch left per
/// row is the rows loop's.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn raster_triangle_avx2(
    triangle: &FaceTriangle,
    rows: Range<usize>,
    columns: Range<usize>,
    table: &TexelTable,
    nearest: &mut [f64],
) {
    match columns.len() / TEXEL_LANES {
        1 => raster_rows_avx2::<1>(triangle, rows, columns, table, nearest),
        2 => raster_rows_avx2::<2>(triangle, rows, columns, table, nearest),
        3 => raster_rows_avx2::<3>(triangle, rows, columns, table, nearest),
        _ => raster_rows_avx2::<0>(triangle, rows, columns, table, nearest),
    }
}

/// The rows of [`raster_triangle_avx2`], `STEPS` steps wide, or as wide as `columns`
/// when `STEPS` is 0.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn raster_rows_avx2<const STEPS: usize>(
    triangle: &FaceTriangle,
    rows: Range<usize>,
    columns: Range<usize>,
    table: &TexelTable,
    nearest: &mut [f64],
) {
    use std::arch::x86_64::*;
    let width = if STEPS == 0 {
        columns.len()
    } else {
        STEPS * TEXEL_LANES
    };
    let splat = |value| _mm256_set1_pd(value);
    let [s0, s1, s2] = triangle.edges.map(|edge| splat(edge.x));
    let depth_slope = splat(triangle.depth.x);
    let depth_bits = _mm256_castsi256_pd(_mm256_set1_epi64x(!(triangle.code_mask as u64) as i64));
    let code = _mm256_castsi256_pd(_mm256_set1_epi64x(triangle.code as i64));
    let zero = _mm256_setzero_pd();
    let edge = |u, slope, offset| _mm256_fmadd_pd(u, slope, offset);
    let centres = &table.padded_centres[columns.start..][..width];
    for j in rows {
        let ([o0, o1, o2], depth_offset) = triangle.row(table.centres[j]);
        let [o0, o1, o2, depth_offset] = [o0, o1, o2, depth_offset].map(splat);
        let row = j * table.stride + columns.start;
        for (u, nearest) in centres
            .chunks_exact(TEXEL_LANES)
            .zip(nearest[row..][..width].chunks_exact_mut(TEXEL_LANES))
        {
            // SAFETY: both chunks hold four f64s; unaligned loads and stores are allowed.
            let u = unsafe { _mm256_loadu_pd(u.as_ptr()) };
            let signs = _mm256_or_pd(
                _mm256_or_pd(edge(u, s0, o0), edge(u, s1, o1)),
                edge(u, s2, o2),
            );
            let inverse_t = _mm256_fmadd_pd(u, depth_slope, depth_offset);
            let key = _mm256_or_pd(_mm256_and_pd(inverse_t, depth_bits), code);
            // blendv picks by each lane's sign bit: 0 where any edge value is negative.
            let offered = _mm256_blendv_pd(key, zero, signs);
            // max_pd(a, b) is `if a > b { a } else { b }`, as in raster_triangle.
            let kept = unsafe { _mm256_loadu_pd(nearest.as_ptr()) };
            unsafe { _mm256_storeu_pd(nearest.as_mut_ptr(), _mm256_max_pd(offered, kept)) };
        }
    }
}

/// The depth test's key: the inverse depth `1/t > 0` with the low bits of its
/// mantissa replaced by the triangle's code. Positive doubles order like their bits,
/// so the largest key is the nearest hit (to 2⁻⁴⁰ relative for up to 4,095
/// triangles), and on a tie the lowest triangle index, as in ascending order with a
/// strict test.
#[inline(always)]
fn hit_key(inverse_t: f64, code_mask: usize, code: u64) -> f64 {
    f64::from_bits((inverse_t.to_bits() & !(code_mask as u64)) | code)
}

/// True when x is certainly on the outer side of the plane of the outward triangle
/// (a, b, c), taken relative to x: `det[a,b,c] < 0` by far more than its rounding.
#[inline(always)]
fn faces_away(det: f64, corners: &[DVec3; 3]) -> bool {
    let scale =
        corners[0].length_squared() * corners[1].length_squared() * corners[2].length_squared();
    det < 0.0 && det * det > 1e-24 * scale
}

#[inline(always)]
fn pmvc_weights_with<const CULL: bool>(
    x: DVec3,
    cage: &Cage,
    table: &TexelTable,
    out: &mut [f64],
    scratch: &mut PmvcScratch,
    raster: impl Fn(&FaceTriangle, Range<usize>, Range<usize>, &TexelTable, &mut [f64]),
) -> bool {
    let resolution = table.resolution as usize;
    let stride = table.stride;
    let texels = stride * resolution;
    out.fill(0.0);
    scratch.vertices.clear();
    // A plain loop, so that this is compiled into the caller (and with its features).
    for &position in &cage.positions {
        scratch.vertices.push(VertexSetup::new(position - x));
    }
    scratch.triangles.clear();
    let triangle_count = cage.triangles.len();
    scratch.by_face.resize(6 * triangle_count, 0);
    let mut face_counts = [0; 6];
    for vertices in &cage.triangles {
        let [a, b, c] = vertices.map(|k| &scratch.vertices[k as usize]);
        let edge_normals = [
            b.relative.cross(c.relative),
            c.relative.cross(a.relative),
            a.relative.cross(b.relative),
        ];
        let det = a.relative.dot(edge_normals[0]);
        let corners = [a.relative, b.relative, c.relative];
        // x in the triangle's plane: rays graze it, so it never blocks or contributes.
        if det == 0.0 || (CULL && faces_away(det, &corners)) {
            continue;
        }
        let faces = faces_reached(a.outcodes & b.outcodes & c.outcodes);
        // Written always and counted only where reached: no branch to mispredict.
        let t = scratch.triangles.len() as u32;
        for (f, count) in face_counts.iter_mut().enumerate() {
            scratch.by_face[f * triangle_count + *count] = t;
            *count += usize::from((faces >> f) & 1);
        }
        scratch.triangles.push(TriangleSetup {
            vertices: *vertices,
            corners,
            edge_normals,
            det,
        });
    }
    // Triangle t is coded as `code_mask − t` in the low bits of its hit keys; 0 is a miss.
    let code_mask = (scratch.triangles.len() + 1).next_power_of_two() - 1;
    scratch.nearest.resize(texels, 0.0);
    scratch.sums.clear();
    scratch.sums.resize(code_mask + 1, [[0.0; 4]; BANKS]);

    let mut total_weight = 0.0;
    let mut missed = 0.0;
    for (f, frame) in FACE_FRAMES.iter().enumerate() {
        scratch.nearest.fill(0.0);
        scratch.drawn.clear();
        let on_face = &scratch.by_face[f * triangle_count..][..face_counts[f]];
        for &t in on_face {
            let t = t as usize;
            let setup = &scratch.triangles[t];
            let [a, b, c] = setup.vertices.map(|k| &scratch.vertices[k as usize]);
            let bounds = if ((a.outcodes | b.outcodes | c.outcodes) >> (5 * f)) & 1 == 0 {
                projected_bounds(
                    [a.projections[f], b.projections[f], c.projections[f]],
                    table,
                )
            } else {
                texel_bounds(&setup.corners.map(|p| frame.local(p)), table)
            };
            let Some((columns, rows)) = bounds else {
                continue;
            };
            let sign = setup.det.signum();
            // s·E_k(u, v) = a·u + b·v + c per edge, with the sign of det folded in.
            let [e0, e1, e2] = setup.edge_normals;
            let edges = [
                frame.local(e0) * sign,
                frame.local(e1) * sign,
                frame.local(e2) * sign,
            ];
            scratch.drawn.push((t as u32, edges));
            let code = (code_mask - t) as u64;
            let depth = (edges[0] + edges[1] + edges[2]) * (sign / setup.det);
            // Whole steps of TEXEL_LANES, from any column; the padding never wins a
            // texel (see raster_triangle) and has zero weight.
            let width = columns.len().div_ceil(TEXEL_LANES) * TEXEL_LANES;
            let first = columns.start.min(stride - width);
            let triangle = FaceTriangle {
                edges,
                depth,
                code_mask,
                code,
            };
            raster(
                &triangle,
                rows,
                first..first + width,
                table,
                &mut scratch.nearest,
            );
        }
        // Sum Ω·d̂ per winning triangle; then w·bₖ = Ω/r · Eₖ/ΣE = sE_k·(Ω·d̂)/|det|,
        // linear in Ω·d̂, so each triangle needs only its sum.
        // As long as the mask, so that indexing by a masked code needs no check.
        let sums = &mut scratch.sums[..=code_mask];
        for (keys, directions) in scratch.nearest[..texels]
            .chunks_exact(BANKS)
            .zip(table.texel_directions.chunks_exact(BANKS))
        {
            for bank in 0..BANKS {
                let code = keys[bank].to_bits() as usize & code_mask;
                let (s, d) = (sums[code][bank], directions[bank]);
                // Whole arrays, so that this is one four-wide add.
                sums[code][bank] = [s[0] + d[0], s[1] + d[1], s[2] + d[2], s[3] + d[3]];
            }
        }
        for &(t, edges) in &scratch.drawn {
            let t = t as usize;
            let code = code_mask - t;
            let mut sum = DVec3::ZERO;
            for bank in &mut scratch.sums[code] {
                sum += DVec3::new(bank[0], bank[1], bank[2]);
                *bank = [0.0; 4];
            }
            let setup = &scratch.triangles[t];
            let inverse_det = 1.0 / setup.det.abs();
            let corners = setup.vertices;
            for k in 0..3 {
                // Non-negative per texel; clamp away the rounding of the sum.
                let weight = (edges[k].dot(sum) * inverse_det).max(0.0);
                out[corners[k] as usize] += weight;
                total_weight += weight;
            }
        }
        for bank in &mut scratch.sums[0] {
            missed += bank[3];
            *bank = [0.0; 4];
        }
    }
    if missed > MAX_MISSED_SHARE * (6 * resolution * resolution) as f64 || total_weight <= 0.0 {
        return false;
    }
    let inverse_total = 1.0 / total_weight;
    for value in out.iter_mut() {
        *value *= inverse_total;
    }
    true
}

/// [`texel_bounds`] of a triangle whose corners are all in front of the face, from
/// their projections `(x/z, y/z)`.
#[inline(always)]
fn projected_bounds(
    projections: [[f64; 2]; 3],
    table: &TexelTable,
) -> Option<(Range<usize>, Range<usize>)> {
    let [[u0, v0], [u1, v1], [u2, v2]] = projections;
    let (u_min, u_max) = (u0.min(u1).min(u2), u0.max(u1).max(u2));
    let (v_min, v_max) = (v0.min(v1).min(v2), v0.max(v1).max(v2));
    if u_min > 1.0 || u_max < -1.0 || v_min > 1.0 || v_max < -1.0 {
        return None;
    }
    Some((
        index_range(u_min, u_max, table),
        index_range(v_min, v_max, table),
    ))
}

/// Texel index ranges (along `right`, along `up`) covering the projection of the
/// triangle onto `face`, or `None` when it lies entirely behind or beside the face.
/// Conservative: the exact per-texel test decides.
#[inline(always)]
fn texel_bounds(local: &[DVec3; 3], table: &TexelTable) -> Option<(Range<usize>, Range<usize>)> {
    let (mut u_min, mut u_max, mut v_min, mut v_max) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    let mut any_in_front = false;
    for k in 0..3 {
        let (p, q) = (local[k], local[(k + 1) % 3]);
        if p.z > 0.0 {
            any_in_front = true;
            let (u, v) = (p.x / p.z, p.y / p.z);
            u_min = u_min.min(u);
            u_max = u_max.max(u);
            v_min = v_min.min(v);
            v_max = v_max.max(v);
        }
        if (p.z > 0.0) != (q.z > 0.0) {
            // The edge crosses the face's plane: its projection runs off to infinity
            // in the direction of the crossing point.
            let s = p.z / (p.z - q.z);
            let crossing = p + s * (q - p);
            if crossing.x >= 0.0 {
                u_max = f64::INFINITY;
            }
            if crossing.x <= 0.0 {
                u_min = f64::NEG_INFINITY;
            }
            if crossing.y >= 0.0 {
                v_max = f64::INFINITY;
            }
            if crossing.y <= 0.0 {
                v_min = f64::NEG_INFINITY;
            }
        }
    }
    if !any_in_front || u_min > 1.0 || u_max < -1.0 || v_min > 1.0 || v_max < -1.0 {
        return None;
    }
    Some((
        index_range(u_min, u_max, table),
        index_range(v_min, v_max, table),
    ))
}

/// Texels whose centres may lie in `[low, high]`, widened by a thousandth of a texel,
/// far above the rounding of the projection (a whole texel more per side would add
/// a row or column to most triangles).
#[inline(always)]
fn index_range(low: f64, high: f64, table: &TexelTable) -> Range<usize> {
    const MARGIN: f64 = 1e-3;
    let resolution = table.resolution as f64;
    // Texel i has its centre at −1 + (2i + 1)/R, so index k = (c + 1)·R/2 − 0.5 ≥ −0.5.
    let index = |coordinate: f64| (coordinate.clamp(-1.0, 1.0) + 1.0) * 0.5 * resolution - 0.5;
    let first = (index(low) - MARGIN).ceil().max(0.0) as usize;
    let last = ((index(high) + MARGIN).floor() + 1.0).min(resolution) as usize;
    first..last.max(first)
}

/// A cube face as axis swizzles: exact, and cheaper than dot products with unit axes.
#[derive(Debug, PartialEq)]
struct FaceFrame {
    axes: [(usize, f64); 3],
}

/// [`CUBE_FACES`] as swizzles (checked by a test), constant so that loops over the
/// faces compile to fixed swizzles.
const FACE_FRAMES: [FaceFrame; 6] = [
    FaceFrame {
        axes: [(1, 1.0), (2, 1.0), (0, 1.0)],
    },
    FaceFrame {
        axes: [(2, 1.0), (1, 1.0), (0, -1.0)],
    },
    FaceFrame {
        axes: [(2, 1.0), (0, 1.0), (1, 1.0)],
    },
    FaceFrame {
        axes: [(0, 1.0), (2, 1.0), (1, -1.0)],
    },
    FaceFrame {
        axes: [(0, 1.0), (1, 1.0), (2, 1.0)],
    },
    FaceFrame {
        axes: [(1, 1.0), (0, 1.0), (2, -1.0)],
    },
];

/// Faces whose frustum a triangle may reach, as bits, from the AND of its corners'
/// outcodes: it misses face f when all three corners are outside one plane of it.
#[inline(always)]
fn faces_reached(common_outcodes: u32) -> u8 {
    let mut faces = 0;
    for f in 0..6 {
        faces |= u8::from((common_outcodes >> (5 * f)) & 0b11111 == 0) << f;
    }
    faces
}

impl FaceFrame {
    #[cfg(test)]
    fn new(face: &super::cubemap::CubeFace) -> Self {
        let axis = |direction: DVec3| {
            let index = (0..3).find(|&k| direction[k] != 0.0).expect("a unit axis");
            (index, direction[index])
        };
        Self {
            axes: [axis(face.right), axis(face.up), axis(face.normal)],
        }
    }

    /// `(p·right, p·up, p·normal)`.
    #[inline(always)]
    fn local(&self, p: DVec3) -> DVec3 {
        let [(r, rs), (u, us), (n, ns)] = self.axes;
        DVec3::new(p[r] * rs, p[u] * us, p[n] * ns)
    }
}

/// Which of a face frustum's planes `z = 0`, `x = ±z`, `y = ±z` the point (in face
/// coordinates, `z` along the face normal) is on the outer side of, as 5 bits.
#[inline(always)]
fn outcode(p: &DVec3) -> u32 {
    u32::from(p.z <= 0.0)
        | (u32::from(p.x > p.z) << 1)
        | (u32::from(p.x < -p.z) << 2)
        | (u32::from(p.y > p.z) << 3)
        | (u32::from(p.y < -p.z) << 4)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::procedural;

    #[test]
    fn face_frames_follow_the_cube_faces() {
        for (face, frame) in CUBE_FACES.iter().zip(&FACE_FRAMES) {
            assert_eq!(&FaceFrame::new(face), frame);
        }
    }

    /// The AVX2 kernel and the portable one do the same operations; they must agree bit
    /// for bit.
    #[test]
    fn every_code_path_gives_identical_weights() {
        let cage = procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5);
        let n = cage.vertex_count();
        // 13 leaves padding at the end of each row; 16 has none.
        for (resolution, x) in [13, 16].into_iter().flat_map(|resolution| {
            procedural::points_inside(&cage, 20, 9, 1e-3)
                .into_iter()
                .map(move |x| (resolution, x))
        }) {
            let table = TexelTable::new(resolution);
            let table = &table;
            let scratch = &mut PmvcScratch::default();
            let (mut dispatched, mut portable) = (vec![0.0; n], vec![0.0; n]);
            assert!(pmvc_weights(x, &cage, table, &mut dispatched, scratch));
            assert!(pmvc_weights_with::<false>(
                x,
                &cage,
                table,
                &mut portable,
                scratch,
                raster_triangle
            ));
            assert_eq!(dispatched, portable);
            assert!(pmvc_weights_inside(
                x,
                &cage,
                table,
                &mut dispatched,
                scratch
            ));
            assert!(pmvc_weights_with::<true>(
                x,
                &cage,
                table,
                &mut portable,
                scratch,
                raster_triangle
            ));
            assert_eq!(dispatched, portable);
        }
    }

    /// The definition, literally: one ray per texel centre against every triangle
    /// (Möller–Trumbore), the first hit at t > 0, weight `Ω/r` spread by barycentrics.
    fn ray_cast_pmvc(x: DVec3, cage: &Cage, resolution: u32) -> Vec<f64> {
        use crate::coords::cubemap::{texel_centre, texel_solid_angle};
        let mut weights = vec![0.0; cage.vertex_count()];
        for face in &CUBE_FACES {
            for j in 0..resolution {
                for i in 0..resolution {
                    let (u, v) = (texel_centre(i, resolution), texel_centre(j, resolution));
                    let direction = (face.normal + u * face.right + v * face.up).normalize();
                    let mut nearest: Option<(f64, usize, DVec3)> = None;
                    for (t, &[a, b, c]) in cage.triangles.iter().enumerate() {
                        let [a, b, c] = [a, b, c].map(|k| cage.positions[k as usize]);
                        let (ab, ac) = (b - a, c - a);
                        let p = direction.cross(ac);
                        let det = ab.dot(p);
                        if det.abs() < 1e-300 {
                            continue;
                        }
                        let s = x - a;
                        let beta = s.dot(p) / det;
                        let q = s.cross(ab);
                        let gamma = direction.dot(q) / det;
                        let distance = ac.dot(q) / det;
                        let hit = beta >= 0.0 && gamma >= 0.0 && beta + gamma <= 1.0;
                        if hit && distance > 0.0 && nearest.is_none_or(|(d, _, _)| distance < d) {
                            let barycentric = DVec3::new(1.0 - beta - gamma, beta, gamma);
                            nearest = Some((distance, t, barycentric));
                        }
                    }
                    let (distance, t, barycentric) = nearest.expect("an enclosed point");
                    let w = texel_solid_angle(i, j, resolution) / distance;
                    for (k, &corner) in cage.triangles[t].iter().enumerate() {
                        weights[corner as usize] += w * barycentric[k];
                    }
                }
            }
        }
        let total: f64 = weights.iter().sum();
        weights.iter().map(|w| w / total).collect()
    }

    /// The rasteriser, its shortcuts and its vector kernel against the definition, in
    /// a non-convex cage where rays pass behind prongs.
    #[test]
    fn rasterised_weights_equal_ray_casting_the_definition() {
        let cage = procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5);
        let scratch = &mut PmvcScratch::default();
        let mut rasterised = vec![0.0; cage.vertex_count()];
        for resolution in [7, 16] {
            let table = TexelTable::new(resolution);
            for x in procedural::points_inside(&cage, 12, 3, 1e-2) {
                let expected = ray_cast_pmvc(x, &cage, resolution);
                for inside in [false, true] {
                    let weights = if inside {
                        pmvc_weights_inside
                    } else {
                        pmvc_weights
                    };
                    assert!(weights(x, &cage, &table, &mut rasterised, scratch));
                    let worst = expected
                        .iter()
                        .zip(&rasterised)
                        .map(|(a, b)| (a - b).abs())
                        .fold(0.0, f64::max);
                    assert!(
                        worst < 1e-9,
                        "R={resolution} x={x} inside={inside}: off by {worst}"
                    );
                }
            }
        }
    }
}

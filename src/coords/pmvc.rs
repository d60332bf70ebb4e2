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
//! its two triangles, so no ray slips between them.
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
    triangles: Vec<TriangleSetup>,
    /// Per texel of the current face (padded rows): the nearest hit's key (0 = none),
    /// see [`hit_key`].
    nearest: Vec<f64>,
    /// Triangles rasterised on the current face, with their signed edge functions.
    drawn: Vec<(u32, [DVec3; 3])>,
    /// Two banks per hit code (code 0: the misses): the sums of
    /// [`TexelTable::texel_directions`] over the texels each code won.
    sums: Vec<[f64; 4]>,
}

#[derive(Clone, Copy, Debug, Default)]
struct TriangleSetup {
    /// Index into the cage's triangles.
    index: u32,
    /// Corners relative to x.
    corners: [DVec3; 3],
    /// `b×c`, `c×a`, `a×b`: a ray direction dotted with these gives unnormalised barycentrics.
    edge_normals: [DVec3; 3],
    /// `det[a, b, c]`; its sign tells which side x is on.
    det: f64,
    /// Bit f: the triangle may reach into the frustum of cube face f.
    faces: u8,
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
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has just been checked to support AVX2.
        return unsafe { pmvc_weights_avx2::<CULL>(x, cage, table, out, scratch) };
    }
    pmvc_weights_any_cpu::<CULL>(x, cage, table, out, scratch)
}

/// The same code compiled for AVX2, so that the texel loops are vectorised four
/// wide. Rust never fuses multiply-adds on its own, so the results are bit-identical.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn pmvc_weights_avx2<const CULL: bool>(
    x: DVec3,
    cage: &Cage,
    table: &TexelTable,
    out: &mut [f64],
    scratch: &mut PmvcScratch,
) -> bool {
    pmvc_weights_any_cpu::<CULL>(x, cage, table, out, scratch)
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
fn pmvc_weights_any_cpu<const CULL: bool>(
    x: DVec3,
    cage: &Cage,
    table: &TexelTable,
    out: &mut [f64],
    scratch: &mut PmvcScratch,
) -> bool {
    let resolution = table.resolution as usize;
    let stride = table.stride;
    let texels = stride * resolution;
    out.fill(0.0);
    scratch.triangles.clear();
    for (index, corners) in cage.triangles.iter().enumerate() {
        let a = cage.positions[corners[0] as usize] - x;
        let b = cage.positions[corners[1] as usize] - x;
        let c = cage.positions[corners[2] as usize] - x;
        let edge_normals = [b.cross(c), c.cross(a), a.cross(b)];
        let det = a.dot(edge_normals[0]);
        // x in the triangle's plane: rays graze it, so it never blocks or contributes.
        if det == 0.0 || (CULL && faces_away(det, &[a, b, c])) {
            continue;
        }
        let faces = faces_reached(&[a, b, c]);
        scratch.triangles.push(TriangleSetup {
            index: index as u32,
            corners: [a, b, c],
            edge_normals,
            det,
            faces,
        });
    }
    // Triangle t is coded as `code_mask − t` in the low bits of its hit keys; 0 is a miss.
    let code_mask = (scratch.triangles.len() + 1).next_power_of_two() - 1;
    scratch.nearest.resize(texels, 0.0);
    scratch.sums.clear();
    scratch.sums.resize(BANKS * (code_mask + 1), [0.0; 4]);

    let mut total_weight = 0.0;
    let mut missed = 0.0;
    for (f, frame) in FACE_FRAMES.iter().enumerate() {
        scratch.nearest.fill(0.0);
        scratch.drawn.clear();
        for (t, setup) in scratch.triangles.iter().enumerate() {
            if setup.faces & (1 << f) == 0 {
                continue;
            }
            let local = [
                frame.local(setup.corners[0]),
                frame.local(setup.corners[1]),
                frame.local(setup.corners[2]),
            ];
            let Some((columns, rows)) = texel_bounds(&local, table) else {
                continue;
            };
            // Whole steps of TEXEL_LANES, from any column; the padding's NaN centres
            // never pass.
            let width = columns.len().div_ceil(TEXEL_LANES) * TEXEL_LANES;
            let first = columns.start.min(stride - width);
            let columns = first..first + width;
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
            let centres = &table.padded_centres[columns.clone()];
            for j in rows {
                let v = table.centres[j];
                let row_offsets = [
                    v * edges[0].y + edges[0].z,
                    v * edges[1].y + edges[1].z,
                    v * edges[2].y + edges[2].z,
                ];
                let row_depth = v * depth.y + depth.z;
                let row = j * stride;
                let texels = row + columns.start..row + columns.end;
                let nearest = &mut scratch.nearest[texels];
                for (&u, nearest) in centres.iter().zip(nearest) {
                    // Exact per texel: a shared edge gives exactly negated values in its
                    // two triangles, so no ray slips between them.
                    let inside = (u * edges[0].x + row_offsets[0] >= 0.0)
                        & (u * edges[1].x + row_offsets[1] >= 0.0)
                        & (u * edges[2].x + row_offsets[2] >= 0.0);
                    // 1/t of the hit, linear in (u, v); larger is nearer.
                    let inverse_t = u * depth.x + row_depth;
                    let key = hit_key(inverse_t, code_mask, code);
                    // A maximum and a plain store: a conditional store would become a
                    // masked store, which is slow on some CPUs.
                    let offered = if inside { key } else { 0.0 };
                    *nearest = if offered > *nearest {
                        offered
                    } else {
                        *nearest
                    };
                }
            }
        }
        // Sum Ω·d̂ per winning triangle; then w·bₖ = Ω/r · Eₖ/ΣE = sE_k·(Ω·d̂)/|det|,
        // linear in Ω·d̂, so each triangle needs only its sum.
        let sums = &mut scratch.sums[..];
        for (keys, directions) in scratch.nearest[..texels]
            .chunks_exact(BANKS)
            .zip(table.texel_directions.chunks_exact(BANKS))
        {
            for bank in 0..BANKS {
                let code = keys[bank].to_bits() as usize & code_mask;
                let (s, d) = (sums[BANKS * code + bank], directions[bank]);
                // Whole arrays, so that this is one four-wide add.
                sums[BANKS * code + bank] = [s[0] + d[0], s[1] + d[1], s[2] + d[2], s[3] + d[3]];
            }
        }
        for &(t, edges) in &scratch.drawn {
            let t = t as usize;
            let code = code_mask - t;
            let mut sum = DVec3::ZERO;
            for bank in &mut scratch.sums[BANKS * code..BANKS * (code + 1)] {
                sum += DVec3::new(bank[0], bank[1], bank[2]);
                *bank = [0.0; 4];
            }
            let setup = &scratch.triangles[t];
            let inverse_det = 1.0 / setup.det.abs();
            let corners = cage.triangles[setup.index as usize];
            for k in 0..3 {
                // Non-negative per texel; clamp away the rounding of the sum.
                let weight = (edges[k].dot(sum) * inverse_det).max(0.0);
                out[corners[k] as usize] += weight;
                total_weight += weight;
            }
        }
        for bank in &mut scratch.sums[..BANKS] {
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

/// Faces whose frustum the triangle (corners relative to x) may reach, as bits.
#[inline(always)]
fn faces_reached(corners: &[DVec3; 3]) -> u8 {
    let mut faces = 0;
    for (f, frame) in FACE_FRAMES.iter().enumerate() {
        let local = corners.map(|p| frame.local(p));
        faces |= u8::from(!outside_frustum(&local)) << f;
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

/// True when the whole triangle (in face coordinates, `z` along the face normal) is
/// on the outer side of one of the face frustum's planes `z = 0`, `x = ±z`, `y = ±z`.
#[inline(always)]
fn outside_frustum(local: &[DVec3; 3]) -> bool {
    let outcode = |p: &DVec3| {
        u8::from(p.z <= 0.0)
            | (u8::from(p.x > p.z) << 1)
            | (u8::from(p.x < -p.z) << 2)
            | (u8::from(p.y > p.z) << 3)
            | (u8::from(p.y < -p.z) << 4)
    };
    outcode(&local[0]) & outcode(&local[1]) & outcode(&local[2]) != 0
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

    /// The AVX2 build and the portable one run the same code; they must agree bit for bit.
    #[test]
    fn every_code_path_gives_identical_weights() {
        let cage = procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5);
        let table = TexelTable::new(16);
        let n = cage.vertex_count();
        for x in procedural::points_inside(&cage, 20, 9, 1e-3) {
            let scratch = &mut PmvcScratch::default();
            let (mut dispatched, mut portable) = (vec![0.0; n], vec![0.0; n]);
            assert!(pmvc_weights(x, &cage, &table, &mut dispatched, scratch));
            assert!(pmvc_weights_any_cpu::<false>(
                x,
                &cage,
                &table,
                &mut portable,
                scratch
            ));
            assert_eq!(dispatched, portable);
            assert!(pmvc_weights_inside(
                x,
                &cage,
                &table,
                &mut dispatched,
                scratch
            ));
            assert!(pmvc_weights_any_cpu::<true>(
                x,
                &cage,
                &table,
                &mut portable,
                scratch
            ));
            assert_eq!(dispatched, portable);
        }
    }
}

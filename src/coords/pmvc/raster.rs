//! The per-face depth test: which triangle each texel of a cube face sees first.

use super::super::cubemap::{TexelTable, TEXEL_LANES};
use glam::DVec3;
use std::ops::Range;

/// One triangle's depth test on one cube face, in the form both rasterisers take.
#[derive(Clone, Copy, Debug)]
pub(super) struct FaceTriangle {
    /// `s·E_k(u, v) = x·u + y·v + z` per edge, with the sign s of det folded in.
    pub(super) edges: [DVec3; 3],
    /// `1/t = x·u + y·v + z`.
    pub(super) depth: DVec3,
    /// See [`hit_key`].
    pub(super) code_mask: usize,
    pub(super) code: u64,
}

impl FaceTriangle {
    /// Along the row at `v`: the offsets of the edge functions and of the depth.
    #[inline(always)]
    pub(super) fn row(&self, v: f64) -> ([f64; 3], f64) {
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
pub(super) fn raster_triangle(
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
pub(super) fn raster_triangle_avx2(
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
pub(super) fn hit_key(inverse_t: f64, code_mask: usize, code: u64) -> f64 {
    f64::from_bits((inverse_t.to_bits() & !(code_mask as u64)) | code)
}

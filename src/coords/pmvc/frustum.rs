//! Which texels of which cube faces a triangle may cover: the faces' frames,
//! frustum outcodes and conservative texel bounds.

use super::super::cubemap::TexelTable;
use glam::DVec3;
use std::ops::Range;

/// [`texel_bounds`] of a triangle whose corners are all in front of the face, from
/// their projections `(x/z, y/z)`.
#[inline(always)]
pub(super) fn projected_bounds<const N: usize>(
    projections: [[f64; 2]; N],
    table: &TexelTable,
) -> Option<(Range<usize>, Range<usize>)> {
    let [mut u_min, mut v_min] = projections[0];
    let (mut u_max, mut v_max) = (u_min, v_min);
    for &[u, v] in &projections[1..] {
        (u_min, u_max) = (u_min.min(u), u_max.max(u));
        (v_min, v_max) = (v_min.min(v), v_max.max(v));
    }
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
pub(super) fn texel_bounds(
    local: &[DVec3; 3],
    table: &TexelTable,
) -> Option<(Range<usize>, Range<usize>)> {
    hull_texel_bounds(local, table)
}

/// [`texel_bounds`] of the convex hull of `local` (a triangle, or a patch's four
/// corners, whose hull holds the patch): its crossings of the face plane are
/// those of all pairs of corners (for a triangle, its edges).
#[inline(always)]
pub(super) fn hull_texel_bounds<const N: usize>(
    local: &[DVec3; N],
    table: &TexelTable,
) -> Option<(Range<usize>, Range<usize>)> {
    let (mut u_min, mut u_max, mut v_min, mut v_max) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    let mut any_in_front = false;
    for (k, p) in local.iter().enumerate() {
        if p.z > 0.0 {
            any_in_front = true;
            let (u, v) = (p.x / p.z, p.y / p.z);
            (u_min, u_max) = (u_min.min(u), u_max.max(u));
            (v_min, v_max) = (v_min.min(v), v_max.max(v));
        }
        for q in &local[k + 1..] {
            if (p.z > 0.0) != (q.z > 0.0) {
                // The segment crosses the face's plane: its projection runs off
                // to infinity in the direction of the crossing point.
                let crossing = *p + p.z / (p.z - q.z) * (*q - *p);
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
pub(crate) struct FaceFrame {
    pub(crate) axes: [(usize, f64); 3],
}

/// [`CUBE_FACES`] as swizzles (checked by a test), constant so that loops over the
/// faces compile to fixed swizzles.
pub(crate) const FACE_FRAMES: [FaceFrame; 6] = [
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
pub(super) fn faces_reached(common_outcodes: u32) -> u8 {
    let mut faces = 0;
    for f in 0..6 {
        faces |= u8::from((common_outcodes >> (5 * f)) & 0b11111 == 0) << f;
    }
    faces
}

impl FaceFrame {
    #[cfg(test)]
    pub(super) fn new(face: &super::super::cubemap::CubeFace) -> Self {
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
    pub(crate) fn local(&self, p: DVec3) -> DVec3 {
        let [(r, rs), (u, us), (n, ns)] = self.axes;
        DVec3::new(p[r] * rs, p[u] * us, p[n] * ns)
    }
}

/// Which of a face frustum's planes `z = 0`, `x = ±z`, `y = ±z` the point (in face
/// coordinates, `z` along the face normal) is on the outer side of, as 5 bits.
#[inline(always)]
pub(super) fn outcode(p: &DVec3) -> u32 {
    u32::from(p.z <= 0.0)
        | (u32::from(p.x > p.z) << 1)
        | (u32::from(p.x < -p.z) << 2)
        | (u32::from(p.y > p.z) << 3)
        | (u32::from(p.y < -p.z) << 4)
}

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

use super::cubemap::{TexelTable, CUBE_FACES};
use crate::geometry::Cage;
use glam::DVec3;
use std::ops::Range;

/// Reusable buffers, so that binding allocates nothing per vertex.
#[derive(Debug, Default)]
pub struct PmvcScratch {
    triangles: Vec<TriangleSetup>,
    /// Per texel of the current face: inverse hit distance along the ray (0 = no hit).
    nearest: Vec<f64>,
    /// Per triangle: its edge functions on the current face (valid where rasterised).
    face_edges: Vec<[DVec3; 3]>,
    /// Per texel: triangle of the nearest hit.
    hit_triangle: Vec<u32>,
}

#[derive(Clone, Copy, Debug, Default)]
struct TriangleSetup {
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

/// PMVC of `x`, written to `out` (one value per cage vertex). Returns `false`, with
/// `out` unspecified, when x is not enclosed by the cage (too many rays escape).
pub fn pmvc_weights(
    x: DVec3,
    cage: &Cage,
    table: &TexelTable,
    out: &mut [f64],
    scratch: &mut PmvcScratch,
) -> bool {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has just been checked to support AVX2.
        return unsafe { pmvc_weights_avx2(x, cage, table, out, scratch) };
    }
    pmvc_weights_any_cpu(x, cage, table, out, scratch)
}

/// The same code compiled for AVX2, so that the texel loops are vectorised four
/// wide. Rust never fuses multiply-adds on its own, so the results are bit-identical.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn pmvc_weights_avx2(
    x: DVec3,
    cage: &Cage,
    table: &TexelTable,
    out: &mut [f64],
    scratch: &mut PmvcScratch,
) -> bool {
    pmvc_weights_any_cpu(x, cage, table, out, scratch)
}

#[inline(always)]
fn pmvc_weights_any_cpu(
    x: DVec3,
    cage: &Cage,
    table: &TexelTable,
    out: &mut [f64],
    scratch: &mut PmvcScratch,
) -> bool {
    let resolution = table.resolution as usize;
    let texels = resolution * resolution;
    out.fill(0.0);
    scratch.triangles.clear();
    for corners in &cage.triangles {
        let a = cage.positions[corners[0] as usize] - x;
        let b = cage.positions[corners[1] as usize] - x;
        let c = cage.positions[corners[2] as usize] - x;
        let edge_normals = [b.cross(c), c.cross(a), a.cross(b)];
        let det = a.dot(edge_normals[0]);
        scratch.triangles.push(TriangleSetup {
            corners: [a, b, c],
            edge_normals,
            det,
        });
    }
    scratch.nearest.resize(texels, 0.0);
    scratch
        .face_edges
        .resize(cage.triangles.len(), [DVec3::ZERO; 3]);
    scratch.hit_triangle.resize(texels, 0);

    let mut total_weight = 0.0;
    let mut missed = 0usize;
    for face in &CUBE_FACES {
        scratch.nearest.fill(0.0);
        let frame = FaceFrame::new(face);
        for (t, setup) in scratch.triangles.iter().enumerate() {
            // x in the triangle's plane: rays graze it, so it never blocks or contributes.
            if setup.det == 0.0 {
                continue;
            }
            let local = [
                frame.local(setup.corners[0]),
                frame.local(setup.corners[1]),
                frame.local(setup.corners[2]),
            ];
            if outside_frustum(&local) {
                continue;
            }
            let Some((columns, rows)) = texel_bounds(&local, table) else {
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
            scratch.face_edges[t] = edges;
            let depth = (edges[0] + edges[1] + edges[2]) * (sign / setup.det);
            for j in rows {
                let v = table.centres[j];
                let row_offsets = [
                    v * edges[0].y + edges[0].z,
                    v * edges[1].y + edges[1].z,
                    v * edges[2].y + edges[2].z,
                ];
                let row_depth = v * depth.y + depth.z;
                let row = j * resolution;
                let texels = row + columns.start..row + columns.end;
                let nearest = &mut scratch.nearest[texels.clone()];
                let hits = &mut scratch.hit_triangle[texels];
                for ((&u, nearest), hit) in
                    table.centres[columns.clone()].iter().zip(nearest).zip(hits)
                {
                    // Exact per texel: a shared edge gives exactly negated values in its
                    // two triangles, so no ray slips between them.
                    let inside = (u * edges[0].x + row_offsets[0] >= 0.0)
                        & (u * edges[1].x + row_offsets[1] >= 0.0)
                        & (u * edges[2].x + row_offsets[2] >= 0.0);
                    // 1/t of the hit, linear in (u, v); larger is nearer.
                    let inverse_t = u * depth.x + row_depth;
                    if inside & (inverse_t > *nearest) {
                        *nearest = inverse_t;
                        *hit = t as u32;
                    }
                }
            }
        }
        for j in 0..resolution {
            let v = table.centres[j];
            for i in 0..resolution {
                let texel = j * resolution + i;
                let inverse_t = scratch.nearest[texel];
                if inverse_t <= 0.0 {
                    missed += 1;
                    continue;
                }
                let triangle = scratch.hit_triangle[texel] as usize;
                let u = table.centres[i];
                let [c0, c1, c2] = scratch.face_edges[triangle];
                let e = [
                    u * c0.x + (v * c0.y + c0.z),
                    u * c1.x + (v * c1.y + c1.z),
                    u * c2.x + (v * c2.y + c2.z),
                ];
                // w = Ω / r with r = t·|(u, v, 1)|, spread by the barycentrics e / Σe.
                let weight = table.solid_angle_over_length[texel] * inverse_t;
                let scale = weight / (e[0] + e[1] + e[2]);
                let corners = cage.triangles[triangle];
                for k in 0..3 {
                    out[corners[k] as usize] += scale * e[k];
                }
                total_weight += weight;
            }
        }
    }
    if missed as f64 > MAX_MISSED_SHARE * (6 * texels) as f64 || total_weight <= 0.0 {
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

/// Texels whose centres may lie in `[low, high]`, widened by one texel against rounding.
#[inline(always)]
fn index_range(low: f64, high: f64, table: &TexelTable) -> Range<usize> {
    let resolution = table.resolution as f64;
    // Texel i has its centre at −1 + (2i + 1)/R. The index is ≥ −0.5 after clamping,
    // so truncating k + 1 gives floor(k) + 1 without a libm call.
    let floor_plus_one =
        |coordinate: f64| ((coordinate.clamp(-1.0, 1.0) + 1.0) * 0.5 * resolution + 0.5) as usize;
    let first = floor_plus_one(low).saturating_sub(1);
    let last = (floor_plus_one(high) + 1).min(table.resolution as usize);
    first..last.max(first)
}

/// A cube face as axis swizzles: exact, and cheaper than dot products with unit axes.
struct FaceFrame {
    axes: [(usize, f64); 3],
}

impl FaceFrame {
    #[inline(always)]
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

    /// The AVX2 build and the portable one run the same code; they must agree bit for bit.
    #[test]
    fn every_code_path_gives_identical_weights() {
        let cage = procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5);
        let table = TexelTable::new(16);
        for x in procedural::points_inside(&cage, 20, 9, 1e-3) {
            let mut dispatched = vec![0.0; cage.vertex_count()];
            let mut portable = vec![0.0; cage.vertex_count()];
            assert!(pmvc_weights(
                x,
                &cage,
                &table,
                &mut dispatched,
                &mut PmvcScratch::default()
            ));
            assert!(pmvc_weights_any_cpu(
                x,
                &cage,
                &table,
                &mut portable,
                &mut PmvcScratch::default()
            ));
            assert_eq!(dispatched, portable);
        }
    }
}

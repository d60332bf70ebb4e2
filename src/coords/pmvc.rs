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

/// Reusable buffers, so that binding allocates nothing per vertex.
#[derive(Debug, Default)]
pub struct PmvcScratch {
    triangles: Vec<TriangleSetup>,
    /// Per texel of the current face: inverse hit distance along the ray (0 = no hit).
    nearest: Vec<f64>,
    /// Per texel: unnormalised barycentrics of the nearest hit.
    barycentric: Vec<[f64; 3]>,
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
    let resolution = table.resolution as usize;
    let texels = resolution * resolution;
    out.fill(0.0);
    scratch.triangles.clear();
    for t in 0..cage.triangles.len() {
        let [a, b, c] = cage.triangle(t).map(|p| p - x);
        let edge_normals = [b.cross(c), c.cross(a), a.cross(b)];
        let det = a.dot(edge_normals[0]);
        scratch.triangles.push(TriangleSetup {
            corners: [a, b, c],
            edge_normals,
            det,
        });
    }
    scratch.nearest.resize(texels, 0.0);
    scratch.barycentric.resize(texels, [0.0; 3]);
    scratch.hit_triangle.resize(texels, 0);

    let mut total_weight = 0.0;
    let mut missed = 0usize;
    for face in &CUBE_FACES {
        scratch.nearest.fill(0.0);
        for (t, setup) in scratch.triangles.iter().enumerate() {
            // x in the triangle's plane: rays graze it, so it never blocks or contributes.
            if setup.det == 0.0 {
                continue;
            }
            let Some((i_range, j_range)) = texel_bounds(setup, face, table) else {
                continue;
            };
            let sign = setup.det.signum();
            let coefficients = setup
                .edge_normals
                .map(|e| [e.dot(face.right), e.dot(face.up), e.dot(face.normal)]);
            let inverse_det = 1.0 / setup.det;
            for j in j_range {
                let v = table.centres[j];
                for i in i_range.clone() {
                    let u = table.centres[i];
                    let e = coefficients.map(|[cu, cv, cn]| u * cu + v * cv + cn);
                    if sign * e[0] >= 0.0 && sign * e[1] >= 0.0 && sign * e[2] >= 0.0 {
                        let sum = e[0] + e[1] + e[2];
                        let inverse_t = sum * inverse_det;
                        let texel = j * resolution + i;
                        if inverse_t > scratch.nearest[texel] {
                            scratch.nearest[texel] = inverse_t;
                            scratch.barycentric[texel] = e;
                            scratch.hit_triangle[texel] = t as u32;
                        }
                    }
                }
            }
        }
        for texel in 0..texels {
            let inverse_t = scratch.nearest[texel];
            if inverse_t <= 0.0 {
                missed += 1;
                continue;
            }
            // w = Ω / r with r = t·|(u, v, 1)|.
            let weight = table.solid_angle_over_length[texel] * inverse_t;
            let e = scratch.barycentric[texel];
            let scale = weight / (e[0] + e[1] + e[2]);
            let corners = cage.triangles[scratch.hit_triangle[texel] as usize];
            for k in 0..3 {
                out[corners[k] as usize] += scale * e[k];
            }
            total_weight += weight;
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
fn texel_bounds(
    setup: &TriangleSetup,
    face: &super::cubemap::CubeFace,
    table: &TexelTable,
) -> Option<(std::ops::Range<usize>, std::ops::Range<usize>)> {
    let local = setup
        .corners
        .map(|p| DVec3::new(p.dot(face.right), p.dot(face.up), p.dot(face.normal)));
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
    let resolution = table.resolution as f64;
    // Texel i has its centre at −1 + (2i + 1)/R; widen by one texel against rounding.
    let to_index =
        |coordinate: f64| ((coordinate.clamp(-1.0, 1.0) + 1.0) * 0.5 * resolution - 0.5).floor();
    let first = |coordinate: f64| (to_index(coordinate).max(0.0)) as usize;
    let last = |coordinate: f64| ((to_index(coordinate) + 2.0).min(resolution)) as usize;
    Some((first(u_min)..last(u_max), first(v_min)..last(v_max)))
}

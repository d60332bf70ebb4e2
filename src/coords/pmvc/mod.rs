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
//! Rays that still slip through, at a cage vertex whose triangles round their edge
//! values each their own way, or along a face that x sees edge on (skipped), are
//! cast again with a little slack ([`catch_missed_texels`]): a lost ray would cost
//! linear precision.
//!
//! The resolve needs only which triangle won each texel: the texel's weight times
//! the hit's barycentrics, `Ω/r · Eₖ/D = Eₖ·(Ω·d̂)/det`, is linear in `Ω·d̂`, so the
//! per-texel vectors `Ω·d̂` are summed per triangle and dotted with its edge normals
//! once. The winner is kept in the depth buffer itself, coded in the low mantissa
//! bits of the inverse depth ([`hit_key`]).
//!
//! A cage with quads keeps each as one bilinear patch ([`patch`]): its lone
//! triangles are drawn as above, and its patches solved exactly per texel into the
//! same depth buffer (keys as the triangles'), so that triangles and patches compete
//! for each ray. A patch's hit spreads `Ω/t` by the bilinear basis, which is not
//! linear in `Ω·d̂`, so each texel a patch wins keeps its u and `(1 − v)/t`, `v/t`,
//! and the patch's weights are summed over the texel groups it was drawn on. Inside
//! points skip a patch only when x is on the outer side of its tangent planes at
//! all four corners, which bound the whole patch (see [`PatchSetup::corner_sides`]).
//! A cage of triangles only takes the triangle code alone, unchanged.

pub(crate) mod frustum;
mod integration;
mod lanes;
mod missed;
pub(crate) mod patch;
#[cfg(test)]
mod quad_tests;
mod raster;
#[cfg(test)]
mod tests;

use super::cubemap::TexelTable;
use super::cubemap::TEXEL_LANES;
use crate::geometry::Cage;
use frustum::{
    faces_reached, hull_texel_bounds, outcode, projected_bounds, texel_bounds, FACE_FRAMES,
};
use glam::DVec3;
#[cfg(target_arch = "x86_64")]
use lanes::Avx2;
use lanes::{Lanes, Portable};
use missed::{catch_missed_texels, Drawn};
use patch::{FacePatch, PatchHits, PatchSetup};
#[cfg(target_arch = "x86_64")]
use raster::raster_triangle_avx2;
use raster::{raster_triangle, FaceTriangle};
use std::ops::Range;

pub use integration::PmvcIntegration;

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
    /// [`TexelTable::texel_directions`] over the texels each code won; for a patch,
    /// of its corners' weights.
    sums: Vec<[[f64; 4]; BANKS]>,
    /// The cage's patches, as `by_face` for triangles, and those drawn on a face.
    patches: Vec<PatchSetup>,
    patches_by_face: Vec<u32>,
    drawn_patches: Vec<(u32, FacePatch, Range<usize>)>,
    /// Per texel of the current face, the hit of the patch that holds it.
    patch_hits: PatchHits,
    /// Exact PMVC's buffers ([`PmvcIntegration::Exact`]).
    exact: crate::coords::exact_pmvc::ExactPmvcScratch,
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
pub(super) struct TriangleSetup {
    /// Its cage vertices.
    pub(super) vertices: [u32; 3],
    /// Corners relative to x.
    corners: [DVec3; 3],
    /// `b×c`, `c×a`, `a×b`: a ray direction dotted with these gives unnormalised barycentrics.
    edge_normals: [DVec3; 3],
    /// `det[a, b, c]`; its sign tells which side x is on.
    pub(super) det: f64,
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
        return unsafe {
            if cage.has_quads() {
                pmvc_weights_avx2::<CULL, true>(x, cage, table, out, scratch)
            } else {
                pmvc_weights_avx2::<CULL, false>(x, cage, table, out, scratch)
            }
        };
    }
    if cage.has_quads() {
        pmvc_weights_with::<CULL, true, Portable>(x, cage, table, out, scratch, raster_triangle)
    } else {
        pmvc_weights_with::<CULL, false, Portable>(x, cage, table, out, scratch, raster_triangle)
    }
}

/// The same code compiled for AVX2 and FMA, with the depth test written four texels
/// at a time. Both use the same fused multiply-adds, so the results are bit-identical.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn pmvc_weights_avx2<const CULL: bool, const QUADS: bool>(
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
    pmvc_weights_with::<CULL, QUADS, Avx2>(x, cage, table, out, scratch, raster)
}

/// True when x is certainly on the outer side of the plane of the outward triangle
/// (a, b, c), taken relative to x: `det[a,b,c] < 0` by far more than its rounding.
#[inline(always)]
fn faces_away(det: f64, corners: &[DVec3; 3]) -> bool {
    let scale =
        corners[0].length_squared() * corners[1].length_squared() * corners[2].length_squared();
    det < 0.0 && det * det > 1e-24 * scale
}

/// Sets up triangle `vertices` at x, unless it can be skipped, and lists it on the
/// cube faces it may reach.
#[inline(always)]
fn push_triangle<const CULL: bool>(
    vertices: &[u32; 3],
    setups: &[VertexSetup],
    triangles: &mut Vec<TriangleSetup>,
    by_face: &mut [u32],
    face_counts: &mut [usize; 6],
    triangle_count: usize,
) {
    let [a, b, c] = vertices.map(|k| &setups[k as usize]);
    let edge_normals = [
        b.relative.cross(c.relative),
        c.relative.cross(a.relative),
        a.relative.cross(b.relative),
    ];
    let det = a.relative.dot(edge_normals[0]);
    let corners = [a.relative, b.relative, c.relative];
    // x in the triangle's plane: rays graze it, so it never blocks or contributes.
    if det == 0.0 || (CULL && faces_away(det, &corners)) {
        return;
    }
    let faces = faces_reached(a.outcodes & b.outcodes & c.outcodes);
    // Written always and counted only where reached: no branch to mispredict.
    let t = triangles.len() as u32;
    for (f, count) in face_counts.iter_mut().enumerate() {
        by_face[f * triangle_count + *count] = t;
        *count += usize::from((faces >> f) & 1);
    }
    triangles.push(TriangleSetup {
        vertices: *vertices,
        corners,
        edge_normals,
        det,
    });
}

/// Sets up the cage's quads as patches at x, unless they can be skipped, listing
/// each on the cube faces it may reach. Returns how many per face.
#[inline(always)]
fn push_patches<const CULL: bool>(cage: &Cage, scratch: &mut PmvcScratch) -> [usize; 6] {
    let quad_count = cage.quads().len();
    scratch.patches.clear();
    scratch.patches_by_face.resize(6 * quad_count, 0);
    let mut face_counts = [0; 6];
    for quad in cage.quads() {
        let corners = quad.corners.map(|k| &scratch.vertices[k as usize]);
        let setup = PatchSetup::new(quad.corners, corners.map(|c| c.relative));
        let sides = setup.corner_sides();
        // x in the plane of a flat patch: rays graze it, as a triangle's.
        if sides == [0.0; 4] {
            continue;
        }
        // x on the outer side of the tangent plane at every corner is on the outer
        // side of the whole patch, which then never holds a ray's exit from inside.
        if CULL
            && (0..4).all(|k| {
                let q = &setup.corners;
                faces_away(sides[k], &[q[k], q[(k + 1) % 4], q[(k + 3) % 4]])
            })
        {
            continue;
        }
        let common = corners.iter().fold(!0, |codes, c| codes & c.outcodes);
        let faces = faces_reached(common);
        let p = scratch.patches.len() as u32;
        for (f, count) in face_counts.iter_mut().enumerate() {
            scratch.patches_by_face[f * quad_count + *count] = p;
            *count += usize::from((faces >> f) & 1);
        }
        scratch.patches.push(setup);
    }
    face_counts
}

#[inline(always)]
fn pmvc_weights_with<const CULL: bool, const QUADS: bool, V: Lanes>(
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
    for &position in cage.positions() {
        scratch.vertices.push(VertexSetup::new(position - x));
    }
    scratch.triangles.clear();
    let triangle_count = cage.triangle_count();
    scratch.by_face.resize(6 * triangle_count, 0);
    let mut face_counts = [0; 6];
    let setups = &scratch.vertices;
    let mut push = |vertices: &[u32; 3]| {
        push_triangle::<CULL>(
            vertices,
            setups,
            &mut scratch.triangles,
            &mut scratch.by_face,
            &mut face_counts,
            triangle_count,
        )
    };
    // A cage of triangles takes the plain loop, with no test per triangle.
    if QUADS {
        for t in cage.lone_triangles() {
            push(&cage.triangles()[t]);
        }
    } else {
        for vertices in cage.triangles() {
            push(vertices);
        }
    }
    let (patch_face_counts, patch_count) = if QUADS {
        let counts = push_patches::<CULL>(cage, scratch);
        (counts, scratch.patches.len())
    } else {
        ([0; 6], 0)
    };
    // Patch p is coded as `code_mask − p` and triangle t as `code_mask − P − t` in the
    // low bits of their hit keys (P patches); 0 is a miss.
    let code_mask = (scratch.triangles.len() + patch_count + 1).next_power_of_two() - 1;
    let first_triangle_code = code_mask - patch_count;
    scratch.nearest.resize(texels, 0.0);
    scratch.sums.clear();
    scratch.sums.resize(code_mask + 1, [[0.0; 4]; BANKS]);
    if QUADS {
        scratch.patch_hits.prepare(table);
    }

    let mut total_weight = 0.0;
    let mut missed = 0.0;
    let most_missed = MAX_MISSED_SHARE * (6 * resolution * resolution) as f64;
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
            let code = (first_triangle_code - t) as u64;
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
        if QUADS {
            draw_patches::<V>(f, patch_face_counts[f], code_mask, cage, table, scratch);
        }
        // Sum Ω·d̂ per winning triangle; then w·bₖ = Ω/r · Eₖ/ΣE = sE_k·(Ω·d̂)/|det|,
        // linear in Ω·d̂, so each triangle needs only its sum.
        // As long as the mask, so that indexing by a masked code needs no check.
        let sums = &mut scratch.sums[..=code_mask];
        if QUADS && scratch.drawn.is_empty() {
            // Patches only: their resolve is their own; count the misses alone (in
            // integers, which add four at a time), the padding's weightless texels not.
            let missed: usize = scratch.nearest[..texels]
                .iter()
                .zip(&table.texel_directions)
                .map(|(key, direction)| {
                    let missed = key.to_bits() as usize & code_mask == 0;
                    usize::from(missed & (direction[3] != 0.0))
                })
                .sum();
            sums[0][0][3] += missed as f64;
        } else {
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
        }
        for &(t, edges) in &scratch.drawn {
            let t = t as usize;
            let code = first_triangle_code - t;
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
        if QUADS {
            // A patch's texels were summed as a triangle's above, to no use; its
            // weights are summed over its candidate groups instead.
            for (p, _, candidates) in &scratch.drawn_patches {
                let code = code_mask - *p as usize;
                scratch.sums[code] = [[0.0; 4]; BANKS];
                let weights = scratch.patch_hits.resolve::<V>(
                    candidates.clone(),
                    stride,
                    &scratch.nearest,
                    code_mask,
                    code as u64,
                );
                // Each texel's share is non-negative: the sums are.
                let corners = scratch.patches[*p as usize].vertices;
                for (&corner, weight) in corners.iter().zip(weights) {
                    out[corner as usize] += weight;
                    total_weight += weight;
                }
            }
        }
        let mut face_missed = 0.0;
        for bank in &mut scratch.sums[0] {
            face_missed += bank[3];
            *bank = [0.0; 4];
        }
        if face_missed > 0.0 && face_missed <= most_missed {
            let drawn = Drawn {
                triangles: &scratch.drawn,
                triangle_setups: &scratch.triangles,
                patches: if QUADS { &scratch.drawn_patches } else { &[] },
                patch_setups: &scratch.patches,
            };
            face_missed -= catch_missed_texels(
                &scratch.nearest[..texels],
                code_mask,
                table,
                &drawn,
                out,
                &mut total_weight,
            );
        }
        missed += face_missed;
    }
    if missed > most_missed || total_weight <= 0.0 {
        return false;
    }
    let inverse_total = 1.0 / total_weight;
    for value in out.iter_mut() {
        *value *= inverse_total;
    }
    true
}

/// Draws the patches listed on cube face `f` into its depth buffer, keeping those
/// drawn, with their candidate groups, in `scratch.drawn_patches`.
#[inline(always)]
fn draw_patches<V: Lanes>(
    f: usize,
    count: usize,
    code_mask: usize,
    cage: &Cage,
    table: &TexelTable,
    scratch: &mut PmvcScratch,
) {
    let frame = &FACE_FRAMES[f];
    let stride = table.stride;
    scratch.drawn_patches.clear();
    scratch.patch_hits.start_face();
    let quad_count = cage.quads().len();
    for &p in &scratch.patches_by_face[f * quad_count..][..count] {
        let setup = &scratch.patches[p as usize];
        let corners = setup.vertices.map(|k| &scratch.vertices[k as usize]);
        let any_behind = corners.iter().fold(0, |codes, c| codes | c.outcodes);
        let bounds = if (any_behind >> (5 * f)) & 1 == 0 {
            projected_bounds(corners.map(|c| c.projections[f]), table)
        } else {
            hull_texel_bounds(&setup.corners.map(|p| frame.local(p)), table)
        };
        let Some((columns, rows)) = bounds else {
            continue;
        };
        let patch = setup.on_face(frame, code_mask, (code_mask - p as usize) as u64);
        let width = columns.len().div_ceil(TEXEL_LANES) * TEXEL_LANES;
        let first = columns.start.min(stride - width);
        let start = scratch.patch_hits.candidate_count();
        patch.raster::<V>(
            rows,
            first..first + width,
            table,
            &mut scratch.nearest,
            &mut scratch.patch_hits,
        );
        let end = scratch.patch_hits.candidate_count();
        scratch.drawn_patches.push((p, patch, start..end));
    }
}

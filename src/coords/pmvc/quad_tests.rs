//! Quad-native PMVC: the five properties on bent and non-convex quad cages, the
//! independence from how a quad's corners are listed, and the rasteriser against
//! an independent ray caster of the definition.

use super::*;
use crate::coords::cubemap::{texel_centre, texel_solid_angle, CUBE_FACES};
use crate::geometry::procedural::points_inside;
use crate::geometry::procedural_quads::{cage_from_polygons, quad_comb, twisted_box};
use crate::geometry::quads::{bilinear_basis, out_of_plane, QuadSplit};
use glam::DMat3;

/// Points inside the patches' volume: farther from the cage's triangles than any
/// patch bulges out of them, and `margin` (of the diagonal) more.
fn inside_points(cage: &Cage, count: usize, seed: u64, margin: f64) -> Vec<DVec3> {
    let bulge = (0..cage.quads().len())
        .map(|k| out_of_plane(&cage.quad(k)))
        .fold(0.0, f64::max);
    points_inside(cage, count, seed, margin + bulge / cage.diagonal())
}

/// The nearest hit at t > 0 of the ray `x + t·d` (d a unit vector) on the patch
/// q0..q3, as (t, u, v): the other family of the patch's lines than the
/// rasteriser's (segments P(0, v)–P(1, v)), and Newton's method on `P(u, v) − x − t·d`.
fn ray_patch(x: DVec3, d: DVec3, q: &[DVec3; 4]) -> Option<(f64, f64, f64)> {
    let point = |u: f64, v: f64| {
        let [a, b, c, e] = bilinear_basis(u, v);
        a * q[0] + b * q[1] + c * q[2] + e * q[3]
    };
    let h = |v: f64| d.dot((point(0.0, v) - x).cross(point(1.0, v) - x));
    let (h0, h1, h2) = (h(0.0), h(0.5), h(1.0));
    let (a, b, c) = (2.0 * h2 - 4.0 * h1 + 2.0 * h0, 4.0 * h1 - h2 - 3.0 * h0, h0);
    let mut roots = Vec::new();
    if a.abs() <= 1e-14 * (b.abs() + c.abs()) {
        roots.push(-c / b);
    } else {
        let discriminant = b * b - 4.0 * a * c;
        if discriminant < 0.0 {
            return None;
        }
        roots.extend([1.0, -1.0].map(|sign| (-b + sign * discriminant.sqrt()) / (2.0 * a)));
    }
    let mut nearest: Option<(f64, f64, f64)> = None;
    for v in roots {
        // u and t by least squares along the segment, then Newton in (u, v, t).
        let (start, end) = (point(0.0, v) - x, point(1.0, v) - x);
        let e = end - start;
        let (ee, ed, dd) = (e.dot(e), e.dot(d), d.dot(d));
        let det = ee * dd - ed * ed;
        let (rhs_u, rhs_t) = (-start.dot(e), start.dot(d));
        let mut u = (dd * rhs_u + ed * rhs_t) / det;
        let mut t = (ed * rhs_u + ee * rhs_t) / det;
        let mut v = v;
        for _ in 0..4 {
            let residual = point(u, v) - x - t * d;
            let along_u = (1.0 - v) * (q[1] - q[0]) + v * (q[2] - q[3]);
            let along_v = (1.0 - u) * (q[3] - q[0]) + u * (q[2] - q[1]);
            let jacobian = DMat3::from_cols(along_u, along_v, -d);
            if jacobian.determinant().abs() < 1e-300 {
                break;
            }
            let step = jacobian.inverse() * residual;
            (u, v, t) = (u - step.x, v - step.y, t - step.z);
        }
        let inside = |p: f64| (-1e-12..=1.0 + 1e-12).contains(&p);
        // Newton from a root of a degenerate h may not converge: no hit then.
        let converged = (point(u, v) - x - t * d).length() <= 1e-12 * (q[0] - x).length();
        if converged
            && inside(u)
            && inside(v)
            && t > 0.0
            && nearest.is_none_or(|(near, _, _)| t < near)
        {
            nearest = Some((t, u.clamp(0.0, 1.0), v.clamp(0.0, 1.0)));
        }
    }
    nearest
}

/// The nearest hit at t > 0 on triangle (a, b, c), as (t, barycentrics).
fn ray_triangle(x: DVec3, d: DVec3, [a, b, c]: [DVec3; 3]) -> Option<(f64, DVec3)> {
    let m = DMat3::from_cols(b - a, c - a, -d);
    if m.determinant().abs() < 1e-300 {
        return None;
    }
    let solved = m.inverse() * (x - a);
    let (beta, gamma, t) = (solved.x, solved.y, solved.z);
    let inside = beta >= 0.0 && gamma >= 0.0 && beta + gamma <= 1.0;
    (inside && t > 0.0).then(|| (t, DVec3::new(1.0 - beta - gamma, beta, gamma)))
}

/// The definition with quads as patches, literally: one ray per texel centre
/// against every lone triangle and every patch, the first hit at t > 0, weight
/// `Ω/r` spread by barycentrics or by the bilinear basis.
fn ray_cast_quad_pmvc(x: DVec3, cage: &Cage, resolution: u32) -> Vec<f64> {
    let mut weights = vec![0.0; cage.vertex_count()];
    for face in &CUBE_FACES {
        for j in 0..resolution {
            for i in 0..resolution {
                let (s, r) = (texel_centre(i, resolution), texel_centre(j, resolution));
                let d = (face.normal + s * face.right + r * face.up).normalize();
                let mut nearest: Option<(f64, Vec<(u32, f64)>)> = None;
                for t in cage.lone_triangles() {
                    if let Some((distance, barycentric)) = ray_triangle(x, d, cage.triangle(t)) {
                        if nearest.as_ref().is_none_or(|(near, _)| distance < *near) {
                            let corners = cage.triangles()[t];
                            let spread = (0..3).map(|k| (corners[k], barycentric[k])).collect();
                            nearest = Some((distance, spread));
                        }
                    }
                }
                for (k, quad) in cage.quads().iter().enumerate() {
                    if let Some((distance, u, v)) = ray_patch(x, d, &cage.quad(k)) {
                        if nearest.as_ref().is_none_or(|(near, _)| distance < *near) {
                            let basis = bilinear_basis(u, v);
                            let spread = (0..4).map(|k| (quad.corners[k], basis[k])).collect();
                            nearest = Some((distance, spread));
                        }
                    }
                }
                let (distance, spread) = nearest.expect("an enclosed point");
                let w = texel_solid_angle(i, j, resolution) / distance;
                for (corner, share) in spread {
                    weights[corner as usize] += w * share;
                }
            }
        }
    }
    let total: f64 = weights.iter().sum();
    weights.iter().map(|w| w / total).collect()
}

fn worst_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// Both variants' weights at x.
fn both_weights(x: DVec3, cage: &Cage, table: &TexelTable) -> [Vec<f64>; 2] {
    let scratch = &mut PmvcScratch::default();
    [false, true].map(|inside| {
        let mut weights = vec![f64::NAN; cage.vertex_count()];
        let weigh = if inside {
            pmvc_weights_inside
        } else {
            pmvc_weights
        };
        assert!(weigh(x, cage, table, &mut weights, scratch), "x = {x}");
        weights
    })
}

/// A box of quads with a roof of four triangles: patches beside lone triangles.
fn house() -> Cage {
    let mut positions: Vec<DVec3> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .flat_map(|&(x, y)| [DVec3::new(x, y, 0.0), DVec3::new(x * 0.8, y, 1.5)])
        .collect();
    positions.push(DVec3::new(0.1, 0.0, 2.5));
    // Corner k at the bottom is 2k, at the top 2k + 1; the apex is 8.
    let mut polygons = vec![vec![0, 6, 4, 2]];
    for k in 0..4u32 {
        let (a, b) = (2 * k, 2 * ((k + 1) % 4));
        polygons.push(vec![a, b, b + 1, a + 1]);
        polygons.push(vec![a + 1, b + 1, 8]);
    }
    cage_from_polygons(&positions, &polygons)
        .expect("a valid cage")
        .0
}

/// A cube of six planar square quads.
fn cube_of_quads() -> Cage {
    let positions: Vec<DVec3> = (0..8)
        .map(|k| DVec3::new((k & 1) as f64, ((k >> 1) & 1) as f64, (k >> 2) as f64) * 2.0 - 1.0)
        .collect();
    let polygons = vec![
        vec![0, 2, 3, 1],
        vec![4, 5, 7, 6],
        vec![0, 1, 5, 4],
        vec![2, 6, 7, 3],
        vec![0, 4, 6, 2],
        vec![1, 3, 7, 5],
    ];
    cage_from_polygons(&positions, &polygons)
        .expect("a valid cage")
        .0
}

#[test]
fn quad_weights_are_positive_partitions_of_unity_with_linear_precision() {
    let cages = [
        ("twisted box", twisted_box(2.0, 0.6)),
        ("quad comb", quad_comb(3, 1.0, 0.5, 3.0, 1.0, 0.3)),
        ("house", house()),
    ];
    for (name, cage) in &cages {
        assert!(cage.has_quads());
        for resolution in [16, 32] {
            let table = TexelTable::new(resolution);
            for x in inside_points(cage, 25, 5, 1e-2) {
                for weights in both_weights(x, cage, &table) {
                    let sum: f64 = weights.iter().sum();
                    let reproduced: DVec3 = weights
                        .iter()
                        .zip(cage.positions())
                        .map(|(&w, &v)| w * v)
                        .sum();
                    let precision = reproduced.distance(x) / cage.diagonal();
                    assert!(weights.iter().all(|&w| w >= 0.0), "{name}: {weights:?}");
                    assert!((sum - 1.0).abs() < 1e-9, "{name} x={x}: sum {sum}");
                    assert!(
                        precision < 1e-9,
                        "{name} R={resolution} x={x}: {precision:e}"
                    );
                }
            }
        }
    }
}

/// The rasteriser (both variants, its bounds and shortcuts) against the ray caster,
/// on planar squares, bent quads, a non-convex comb and patches beside triangles.
#[test]
fn quad_weights_equal_ray_casting_the_definition() {
    let cages = [
        ("cube", cube_of_quads()),
        ("twisted box", twisted_box(2.0, 0.6)),
        ("quad comb", quad_comb(3, 1.0, 0.5, 3.0, 1.0, 0.3)),
        ("house", house()),
    ];
    for (name, cage) in &cages {
        for resolution in [8, 13] {
            let table = TexelTable::new(resolution);
            for x in inside_points(cage, 6, 11, 1e-2) {
                let expected = ray_cast_quad_pmvc(x, cage, resolution);
                for (inside, weights) in both_weights(x, cage, &table).iter().enumerate() {
                    let worst = worst_difference(&expected, weights);
                    assert!(
                        worst < 1e-9,
                        "{name} R={resolution} x={x} inside={inside}: off by {worst:e}"
                    );
                }
            }
        }
    }
}

/// The twisted box with each quad's corners listed from another corner: the same
/// patches, so the same weights; while either split of the quads changes them.
#[test]
fn quad_weights_do_not_depend_on_the_first_corner_but_splits_do() {
    let cage = twisted_box(2.0, 0.6);
    let table = TexelTable::new(16);
    let points = inside_points(&cage, 12, 3, 1e-2);
    let weights = |cage: &Cage| -> Vec<Vec<f64>> {
        points
            .iter()
            .map(|&x| both_weights(x, cage, &table)[0].clone())
            .collect()
    };
    let worst = |a: &[Vec<f64>], b: &[Vec<f64>]| {
        a.iter()
            .zip(b)
            .map(|(a, b)| worst_difference(a, b))
            .fold(0.0, f64::max)
    };
    let original = weights(&cage);
    for turn in 1..4 {
        let polygons: Vec<Vec<u32>> = cage
            .quads()
            .iter()
            .map(|quad| (0..4).map(|k| quad.corners[(k + turn) % 4]).collect())
            .collect();
        let (turned, _) = cage_from_polygons(cage.positions(), &polygons).expect("valid");
        for (quad, polygon) in turned.quads().iter().zip(&polygons) {
            assert_eq!(quad.corners.to_vec(), *polygon, "corners kept as listed");
        }
        let difference = worst(&original, &weights(&turned));
        assert!(difference < 1e-6, "turned by {turn}: {difference:e}");
    }
    let shorter = weights(&cage.split_quads(QuadSplit::Shorter));
    let longer = weights(&cage.split_quads(QuadSplit::Longer));
    for (name, split) in [("shorter", &shorter), ("longer", &longer)] {
        let difference = worst(&original, split);
        assert!(difference > 1e-3, "{name} split: only {difference:e}");
    }
    assert!(worst(&shorter, &longer) > 1e-3);
}

/// On a cage of planar squares the patches' weights differ from either split's
/// only in how each texel's weight is spread: the totals per quad agree.
#[test]
fn planar_quads_spread_the_splits_weight_differently() {
    let cage = cube_of_quads();
    let split = cage.split_quads(QuadSplit::Shorter);
    let table = TexelTable::new(16);
    for x in inside_points(&cage, 8, 2, 1e-2) {
        let [quads, _] = both_weights(x, &cage, &table);
        let [triangles, _] = both_weights(x, &split, &table);
        assert!(worst_difference(&quads, &triangles) > 1e-4, "x = {x}");
        for weights in [&quads, &triangles] {
            let reproduced: DVec3 = weights
                .iter()
                .zip(cage.positions())
                .map(|(&w, &v)| w * v)
                .sum();
            assert!(reproduced.distance(x) < 1e-12);
        }
    }
}

/// The AVX2 kernel and the portable one do the same operations on patches too.
#[test]
fn every_code_path_gives_identical_quad_weights() {
    let cage = quad_comb(3, 1.0, 0.5, 3.0, 1.0, 0.3);
    let n = cage.vertex_count();
    for resolution in [13, 16] {
        let table = TexelTable::new(resolution);
        let scratch = &mut PmvcScratch::default();
        for x in inside_points(&cage, 10, 9, 1e-3) {
            let (mut dispatched, mut portable) = (vec![0.0; n], vec![0.0; n]);
            assert!(pmvc_weights(x, &cage, &table, &mut dispatched, scratch));
            assert!(pmvc_weights_with::<false, true, Portable>(
                x,
                &cage,
                &table,
                &mut portable,
                scratch,
                raster_triangle
            ));
            assert_eq!(dispatched, portable);
            assert!(pmvc_weights_inside(
                x,
                &cage,
                &table,
                &mut dispatched,
                scratch
            ));
            assert!(pmvc_weights_with::<true, true, Portable>(
                x,
                &cage,
                &table,
                &mut portable,
                scratch,
                raster_triangle
            ));
            assert_eq!(dispatched, portable);
        }
    }
}

/// Points placed so that whole columns of texel rays run exactly along the edges
/// two patches of a cube share (x = 1 − s·(1 − z) for a texel centre s), where each
/// patch's solve may put the ray just outside it: the rays must still be caught
/// (linear precision to rounding) and the weights must be the definition's.
#[test]
fn rays_along_shared_patch_edges_are_caught() {
    let cage = cube_of_quads();
    for resolution in [8, 16] {
        let table = TexelTable::new(resolution);
        for i in [resolution / 2, resolution / 2 + 1, resolution - 2] {
            let s = texel_centre(i, resolution);
            for (y, z) in [(0.0, 0.0), (0.3, -0.25), (-0.5, 0.5)] {
                let x = DVec3::new(1.0 - s * (1.0 - z), y, z);
                let expected = ray_cast_quad_pmvc(x, &cage, resolution);
                for weights in both_weights(x, &cage, &table) {
                    let reproduced: DVec3 = weights
                        .iter()
                        .zip(cage.positions())
                        .map(|(&w, &v)| w * v)
                        .sum();
                    let precision = reproduced.distance(x) / cage.diagonal();
                    assert!(precision < 1e-12, "R={resolution} x={x}: {precision:e}");
                    let worst = worst_difference(&expected, &weights);
                    assert!(worst < 1e-9, "R={resolution} x={x}: off by {worst:e}");
                }
            }
        }
    }
}

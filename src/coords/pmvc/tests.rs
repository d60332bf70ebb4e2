//! The rasterised PMVC against ray casting the definition, and the code paths
//! against each other.

use super::frustum::{FaceFrame, FACE_FRAMES};
use super::*;
use crate::coords::cubemap::CUBE_FACES;
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
        assert!(pmvc_weights_with::<false, false, Portable>(
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
        assert!(pmvc_weights_with::<true, false, Portable>(
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
                for (t, &[a, b, c]) in cage.triangles().iter().enumerate() {
                    let [a, b, c] = [a, b, c].map(|k| cage.positions()[k as usize]);
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
                for (k, &corner) in cage.triangles()[t].iter().enumerate() {
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

/// `|Σ wᵢ vᵢ − x|` over the cage diagonal: PMVC reproduce x (linear precision) up to
/// rounding at every resolution, because the texels' `Ω·d̂` sum to zero.
fn linear_precision_error(x: DVec3, cage: &Cage, table: &TexelTable) -> f64 {
    let mut weights = vec![0.0; cage.vertex_count()];
    let scratch = &mut PmvcScratch::default();
    assert!(pmvc_weights_inside(x, cage, table, &mut weights, scratch));
    let reproduced: DVec3 = weights
        .iter()
        .zip(cage.positions())
        .map(|(&w, &v)| w * v)
        .sum();
    reproduced.distance(x) / cage.diagonal()
}

/// Points in the plane of a reflex face (one whose plane runs through the inside of
/// the cage) see it edge on, so it is skipped; where such a point is also lined up
/// with a cage vertex and a texel centre (odd resolutions put texel centres in the
/// comb's axis planes), a ray through that vertex can slip between the triangles
/// around it and hit nothing. A lost ray takes its share of the linear precision
/// with it: (3.75, 1/3, 0) at R = 33 was off by 2.8e-5 of the diagonal.
#[test]
fn points_in_a_reflex_face_plane_keep_linear_precision() {
    let cage = procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5);
    // The comb's reflex faces: the inner prong walls (x = 1, 1.25, 2.25, …), whose
    // planes run through the spine (y < 1), and the gap floors (y = 1), whose plane
    // runs through the prongs' roots.
    let mut on_planes = Vec::new();
    for wall in [1.0, 1.25, 2.25, 2.5, 3.5, 3.75] {
        for y in [0.2, 1.0 / 3.0, 0.5, 0.8] {
            for z in [-0.3, 0.0, 0.1] {
                on_planes.push((DVec3::new(wall, y, z), DVec3::X));
            }
        }
    }
    for x in [0.3, 0.5, 1.7, 2.9, 4.1] {
        for z in [-0.2, 0.0, 0.3] {
            on_planes.push((DVec3::new(x, 1.0, z), DVec3::Y));
        }
    }
    let mut worst_on = (0.0f64, DVec3::ZERO, 0);
    let mut worst_off = 0.0f64;
    for resolution in [16, 31, 32, 33] {
        let table = TexelTable::new(resolution);
        for &(point, normal) in &on_planes {
            let on = linear_precision_error(point, &cage, &table);
            if on > worst_on.0 {
                worst_on = (on, point, resolution);
            }
            let off_plane = point + 1e-7 * cage.diagonal() * normal;
            worst_off = worst_off.max(linear_precision_error(off_plane, &cage, &table));
        }
    }
    let (on, point, resolution) = worst_on;
    assert!(worst_off < 1e-12, "just off the planes: {worst_off:e}");
    assert!(
        on < 1e-12,
        "in a reflex face's plane: {on:e} at {point} (R = {resolution}); just off the planes: {worst_off:e}"
    );
}

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

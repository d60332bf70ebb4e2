//! Exact PMVC on cages of bilinear quads, against references written here:
//! QMVC where nothing is hidden, rays cast over a dense set of directions
//! with a ray–patch solve of this file's own, the cube map as it refines,
//! and the properties every point must have.

use super::*;
use crate::coords::cubemap::TexelTable;
use crate::coords::mvc::{mvc_weights, MvcScratch};
use crate::coords::pmvc::{pmvc_weights_inside, PmvcScratch};
use crate::geometry::procedural::{self, SplitMix64};
use crate::geometry::procedural_quads::{quad_comb, twisted_box};
use crate::geometry::quads::bilinear_basis;
use glam::DQuat;

fn exact_with_stats(x: DVec3, cage: &Cage) -> (Vec<f64>, ExactPmvcStats) {
    let mut out = vec![0.0; cage.vertex_count()];
    let scratch = &mut ExactPmvcScratch::default();
    exact_pmvc_weights_inside(x, cage, &mut out, scratch).unwrap_or_else(|e| panic!("{x}: {e}"));
    (out, scratch.stats())
}

fn exact(x: DVec3, cage: &Cage) -> Vec<f64> {
    exact_with_stats(x, cage).0
}

/// A non-convex cage of quads, some of them bent.
fn bent_comb() -> Cage {
    quad_comb(3, 1.0, 0.5, 2.0, 1.0, 0.3)
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// `|Σ wᵢ vᵢ − x|` relative to the cage diagonal.
fn linear_error(w: &[f64], cage: &Cage, x: DVec3) -> f64 {
    let p: DVec3 = w
        .iter()
        .zip(cage.positions())
        .map(|(&w, &v)| w * (v - x))
        .sum();
    p.length() / cage.diagonal()
}

/// Points strictly inside `cage` that see no quad folded (see
/// [`ExactPmvcStats::folded`]), with how many of `count` did.
fn unfolded_points(cage: &Cage, count: usize, seed: u64) -> (Vec<DVec3>, usize) {
    let points = procedural::points_inside(cage, count, seed, 1e-2);
    let total = points.len();
    let kept: Vec<DVec3> = points
        .into_iter()
        .filter(|&x| exact_with_stats(x, cage).1.folded == 0)
        .collect();
    let folded = total - kept.len();
    (kept, folded)
}

/// Inside a convex cage every point sees every face whole, so PMVC are MVC:
/// on quads, QMVC (accurate to about 1e-7 in the weights).
#[test]
fn a_convex_cage_of_quads_gives_qmvc() {
    for angle in [0.0, 0.3] {
        let cage = twisted_box(2.0, angle);
        let mut rng = SplitMix64(7);
        let mut qmvc = vec![0.0; cage.vertex_count()];
        let mut largest: f64 = 0.0;
        for _ in 0..20 {
            let x = DVec3::new(
                1.2 * rng.unit() - 0.6,
                1.2 * rng.unit() - 0.6,
                0.4 + 1.2 * rng.unit(),
            );
            let (w, stats) = exact_with_stats(x, &cage);
            assert_eq!(stats.folded, 0, "{x}");
            assert_eq!(stats.missed, 0, "{x}");
            mvc_weights(x, &cage, &mut qmvc, &mut MvcScratch::default());
            largest = largest.max(max_difference(&w, &qmvc));
        }
        eprintln!("twist {angle}: largest difference from QMVC {largest:.2e}");
        assert!(largest < 1e-6, "twist {angle}: {largest:e}");
    }
}

#[test]
fn weights_are_a_non_negative_partition_of_unity_with_linear_precision() {
    let cage = bent_comb();
    let points = procedural::points_inside(&cage, 60, 3, 1e-3);
    let mut largest_linear: f64 = 0.0;
    let mut folded = 0;
    for &x in &points {
        let (w, stats) = exact_with_stats(x, &cage);
        folded += usize::from(stats.folded > 0);
        assert_eq!(stats.missed, 0, "{x}");
        assert!(w.iter().all(|&v| v >= 0.0), "{x}: {w:?}");
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-13, "{x}");
        largest_linear = largest_linear.max(linear_error(&w, &cage, x));
    }
    // Σ ψₖ(y)(qₖ − x) = y − x on a patch, so Σ wₖ(vₖ − x) = ∫ σ dσ = 0 over
    // the sphere: linear precision holds, to the quadrature's tolerance.
    eprintln!(
        "{} points ({folded} seeing a fold): largest |Σ wᵢ vᵢ − x| / diagonal {largest_linear:.2e}",
        points.len()
    );
    assert!(largest_linear < 1e-8, "{largest_linear:e}");
}

/// Where the ray from the origin along `d` meets the patch `q` (relative to
/// the origin): its distance and (u, v). The two bilinear equations of the
/// hit across d (planes through d), v eliminated, leave a quadratic in u.
fn ray_patch(q: &[DVec3; 4], d: DVec3) -> Option<(f64, f64, f64)> {
    let e1 = d.any_orthonormal_vector();
    let e2 = d.cross(e1);
    // P(u, v) = a + u·b + v·c + uv·e.
    let (a, b, c, e) = (q[0], q[1] - q[0], q[3] - q[0], q[0] - q[1] + q[2] - q[3]);
    let [a1, b1, c1, e1] = [a, b, c, e].map(|p| p.dot(e1));
    let [a2, b2, c2, e2] = [a, b, c, e].map(|p| p.dot(e2));
    // v = −(a1 + b1 u)/(c1 + e1 u), into the second equation.
    let (qa, qb, qc) = (
        b2 * e1 - e2 * b1,
        a2 * e1 + b2 * c1 - c2 * b1 - e2 * a1,
        a2 * c1 - c2 * a1,
    );
    let mut roots = Vec::new();
    if qa.abs() < 1e-14 * (qb.abs() + qc.abs()) {
        roots.push(-qc / qb);
    } else {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        roots.extend([(-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa)]);
    }
    let mut best: Option<(f64, f64, f64)> = None;
    for u in roots {
        let (den1, den2) = (c1 + e1 * u, c2 + e2 * u);
        let v = if den1.abs() > den2.abs() {
            -(a1 + b1 * u) / den1
        } else {
            -(a2 + b2 * u) / den2
        };
        let range = -1e-12..=1.0 + 1e-12;
        if !(range.contains(&u) && range.contains(&v)) {
            continue;
        }
        let t = (a + u * b + v * c + u * v * e).dot(d);
        if t > 0.0 && best.is_none_or(|(nearest, ..)| t < nearest) {
            best = Some((t, u, v));
        }
    }
    best
}

/// PMVC by casting `n` rays from x over a Fibonacci lattice of directions,
/// each standing for `4π/n` of the sphere: its first hit on any quad.
fn ray_cast_reference(x: DVec3, cage: &Cage, n: usize) -> Vec<f64> {
    let quads: Vec<[DVec3; 4]> = (0..cage.quads().len())
        .map(|k| cage.quad(k).map(|p| p - x))
        .collect();
    let golden = PI * (3.0 - 5f64.sqrt());
    let mut w = vec![0.0; cage.vertex_count()];
    for i in 0..n {
        let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
        let r = (1.0 - z * z).sqrt();
        let phi = i as f64 * golden;
        let d = DVec3::new(r * phi.cos(), r * phi.sin(), z);
        let hit = quads
            .iter()
            .enumerate()
            .filter_map(|(k, q)| ray_patch(q, d).map(|(t, u, v)| (t, u, v, k)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let (t, u, v, k) = hit.expect("every ray leaves the cage");
        for (&corner, psi) in cage.quads()[k].corners.iter().zip(bilinear_basis(u, v)) {
            w[corner as usize] += psi / t;
        }
    }
    let total: f64 = w.iter().sum();
    w.iter().map(|v| v / total).collect()
}

/// Against rays cast over a dense set of directions (the reference's own
/// error shrinks as they grow), on a non-convex cage of bent quads.
#[test]
fn a_non_convex_quad_cage_agrees_with_rays_cast_densely() {
    let cage = bent_comb();
    let (points, _) = unfolded_points(&cage, 6, 11);
    let (mut coarse, mut fine): (f64, f64) = (0.0, 0.0);
    for &x in &points {
        let w = exact(x, &cage);
        coarse = coarse.max(max_difference(&w, &ray_cast_reference(x, &cage, 20_000)));
        fine = fine.max(max_difference(&w, &ray_cast_reference(x, &cage, 320_000)));
    }
    eprintln!("largest difference from rays: {coarse:.2e} (2e4 rays), {fine:.2e} (3.2e5 rays)");
    assert!(fine < 2e-4, "{fine:e}");
    assert!(fine < coarse / 4.0, "{coarse:e} → {fine:e}");
}

/// Where x sees a quad folded, the quad is cut into a grid of sub-patches
/// and those still folded are taken as triangles: no longer exact, but close
/// to the rays' reference (2.0e-6 here against 3.2e5 rays, whose own error
/// at points with no fold is 2.1e-7).
#[test]
fn points_that_see_a_fold_stay_close_to_rays_cast_densely() {
    let cage = bent_comb();
    let points: Vec<DVec3> = procedural::points_inside(&cage, 40, 3, 1e-3)
        .into_iter()
        .filter(|&x| exact_with_stats(x, &cage).1.folded > 0)
        .take(6)
        .collect();
    assert!(!points.is_empty());
    let mut largest: f64 = 0.0;
    for &x in &points {
        let w = exact(x, &cage);
        largest = largest.max(max_difference(&w, &ray_cast_reference(x, &cage, 320_000)));
    }
    eprintln!(
        "{} points seeing a fold: largest difference from rays {largest:.2e}",
        points.len()
    );
    assert!(largest < 2e-5, "{largest:e}");
}

/// The cube map samples the same integral over bilinear patches: its error
/// shrinks as its resolution grows.
#[test]
fn the_cube_map_on_quads_converges_to_exact() {
    let cage = bent_comb();
    let (points, _) = unfolded_points(&cage, 10, 5);
    let reference: Vec<Vec<f64>> = points.iter().map(|&x| exact(x, &cage)).collect();
    let scratch = &mut PmvcScratch::default();
    let mean_error = |resolution: u32, scratch: &mut PmvcScratch| {
        let table = TexelTable::new(resolution);
        let mut out = vec![0.0; cage.vertex_count()];
        let mut sum = 0.0;
        for (&x, w) in points.iter().zip(&reference) {
            assert!(pmvc_weights_inside(x, &cage, &table, &mut out, scratch));
            sum += max_difference(&out, w);
        }
        sum / points.len() as f64
    };
    let errors = [16, 32, 64].map(|r| mean_error(r, scratch));
    eprintln!(
        "cube map on quads, mean largest error at 16², 32², 64²: {:.2e} {:.2e} {:.2e}",
        errors[0], errors[1], errors[2]
    );
    assert!(errors[1] < 0.8 * errors[0], "{errors:?}");
    assert!(errors[2] < 0.8 * errors[1], "{errors:?}");
    assert!(errors[2] < 5e-3, "{errors:?}");
}

/// Turned, and moved 1e7 from the origin, the cage and point give the same
/// weights (the quadrature's nodes turn with them; its decisions to split
/// may differ within its tolerance).
#[test]
fn weights_are_invariant_under_rotation_and_translation() {
    let cage = bent_comb();
    let (points, _) = unfolded_points(&cage, 8, 17);
    let turn = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 0.7);
    let shift = DVec3::new(1e7, -1e7, 1e7);
    let turned = cage.with_positions(cage.positions().iter().map(|&p| turn * p).collect());
    let moved = cage.with_positions(cage.positions().iter().map(|&p| p + shift).collect());
    let (mut rotation, mut translation): (f64, f64) = (0.0, 0.0);
    for &x in &points {
        let w = exact(x, &cage);
        rotation = rotation.max(max_difference(&w, &exact(turn * x, &turned)));
        translation = translation.max(max_difference(&w, &exact(x + shift, &moved)));
    }
    eprintln!("largest difference: turned {rotation:.2e}, moved 1e7 {translation:.2e}");
    assert!(rotation < 1e-9, "{rotation:e}");
    assert!(translation < 1e-7, "{translation:e}");
}

/// On a quad, a bind gives the patch's bilinear basis there (the surface
/// policy); just inside, exact PMVC tend to it.
#[test]
fn on_and_near_a_quad_the_weights_are_its_bilinear_basis() {
    // The top of the twisted box is a planar quad: seen from inside near it,
    // it has no fold.
    let cage = twisted_box(2.0, 0.3);
    let k = 1;
    let (u, v) = (0.3, 0.6);
    let q = cage.quad(k);
    let on = crate::geometry::quads::bilinear_point(&q, u, v);
    let inward = -crate::geometry::quads::bilinear_normal(&q, u, v).normalize();
    let mut expected = vec![0.0; cage.vertex_count()];
    for (&corner, psi) in cage.quads()[k].corners.iter().zip(bilinear_basis(u, v)) {
        expected[corner as usize] = psi;
    }
    let options = crate::coords::BindOptions {
        resolution: crate::coords::EXACT_RESOLUTION,
        ..crate::coords::BindOptions::for_method(crate::coords::Method::Pmvc)
    };
    assert_eq!(options.split_applied(&cage), None);
    let points = [on, on + 1e-3 * inward];
    let classes = options.classify(&cage, &points).classes;
    let progress = crate::coords::BindProgress::new(points.len());
    let bound = crate::coords::bind_cpu(&points, &classes, &cage, options, &progress).unwrap();
    let row = |r: usize| &bound.values[r * bound.cols..(r + 1) * bound.cols];
    let on_error = row(0)
        .iter()
        .zip(&expected)
        .map(|(&a, b)| (f64::from(a) - b).abs())
        .fold(0.0, f64::max);
    assert!(on_error < 1e-6, "on the quad: {on_error:e}");
    let mut last = f64::INFINITY;
    for depth in [1e-2, 1e-3, 1e-4] {
        let w = exact(on + depth * inward, &cage);
        let error = max_difference(&w, &expected);
        eprintln!("{depth:e} inside: {error:.2e} from the bilinear basis");
        assert!(error < last, "{depth:e}: {error:e}");
        last = error;
    }
    assert!(last < 1e-2, "{last:e}");
}

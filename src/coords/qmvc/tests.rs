//! QMVC against the definition integrated independently, and their properties:
//! partition of unity and linear precision inside and out, invariance to the
//! corners' order, behaviour at and near the patches.

use super::reference::{face_integral, legendre_nodes, reference_weights};
use super::*;
use crate::coords::mvc::{mvc_weights, MvcScratch, FAR_FIELD_DIAGONALS};
use crate::geometry::procedural::{self, CUBE_QUADS};
use crate::geometry::procedural_quads::{cage_from_polygons, quad_comb, twisted_box};
use crate::geometry::quads::{bilinear_basis, bilinear_point, out_of_plane};
use crate::geometry::{Cage, QuadSplit};

pub(super) fn weights(x: DVec3, cage: &Cage) -> Vec<f64> {
    let mut out = vec![0.0; cage.vertex_count()];
    mvc_weights(x, cage, &mut out, &mut MvcScratch::default());
    out
}

pub(super) fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// `|Σ wᵢ vᵢ − x|` over the cage diagonal, and `|Σ wᵢ − 1|`.
fn precision(x: DVec3, cage: &Cage, w: &[f64]) -> (f64, f64) {
    let reproduced: DVec3 = w.iter().zip(cage.positions()).map(|(&w, &p)| w * p).sum();
    let sum: f64 = w.iter().sum();
    (
        (reproduced - x).length() / cage.diagonal(),
        (sum - 1.0).abs(),
    )
}

/// A parallelepiped: six flat parallelogram quads.
fn parallelepiped() -> Cage {
    let (a, b, c) = (
        DVec3::new(2.0, 0.3, 0.1),
        DVec3::new(0.8, 1.6, -0.2),
        DVec3::new(0.4, -0.3, 1.8),
    );
    let positions: Vec<DVec3> = (0..8)
        .map(|i| (i & 1) as f64 * a + ((i >> 1) & 1) as f64 * b + ((i >> 2) & 1) as f64 * c)
        .collect();
    let polygons: Vec<Vec<u32>> = CUBE_QUADS.iter().map(|q| q.to_vec()).collect();
    cage_from_polygons(&positions, &polygons).unwrap().0
}

/// A triangular prism whose top is turned: two lone triangles, three bent quads.
fn twisted_prism() -> Cage {
    let turn = glam::DQuat::from_rotation_z(0.5);
    let base: Vec<DVec3> = (0..3)
        .map(|k| {
            let angle = k as f64 * std::f64::consts::TAU / 3.0;
            DVec3::new(angle.cos(), angle.sin(), 0.0)
        })
        .collect();
    let mut positions = base.clone();
    positions.extend(base.iter().map(|&p| turn * p + DVec3::Z * 1.5));
    let polygons = vec![
        vec![0, 2, 1],
        vec![3, 4, 5],
        vec![0, 1, 4, 3],
        vec![1, 2, 5, 4],
        vec![2, 0, 3, 5],
    ];
    cage_from_polygons(&positions, &polygons).unwrap().0
}

#[test]
fn gauss_legendre_tables_match_newton() {
    for order in 2..=8 {
        let (nodes, weights) = quadrature::gauss_legendre(order);
        let mut newton = legendre_nodes(order);
        newton.sort_by(|a, b| a.0.total_cmp(&b.0));
        for ((&x, &w), (xn, wn)) in nodes.iter().zip(weights).zip(newton) {
            assert!(
                (x - xn).abs() < 1e-15 && (w - wn).abs() < 1e-15,
                "order {order}"
            );
        }
    }
}

/// The three closed-form equations hold for the integral itself: `Σ wᵢ (qᵢ − x)`
/// of the reference integral is the mean vector, and `N` is a null vector.
#[test]
fn closed_form_equations_hold_for_the_definition() {
    let cage = twisted_box(2.0, 0.6);
    for x in [DVec3::new(0.1, -0.2, 0.9), DVec3::new(3.0, 1.0, -2.0)] {
        for k in 0..6 {
            let q = cage.quad(k);
            let a = q.map(|p| p - x);
            let w = face_integral(x, &q, 24, 10);
            let lhs: DVec3 = (0..4).map(|i| w[i] * a[i]).sum();
            let m = mean_vector(&a.map(DVec3::normalize));
            assert!(
                (lhs - m).length() < 1e-12 * m.length().max(1e-3),
                "{lhs} {m}"
            );
            let null = null_vector(&q, &a);
            let residual: DVec3 = (0..4).map(|i| null[i] * a[i]).sum();
            assert!(residual.length() < 1e-13 * dot4(&null, &null).sqrt() * 4.0);
        }
    }
}

/// Well inside the twisted box, QMVC and the definition integrated by brute
/// force agree to 1e-6, the target of the quadrature there; the brute force
/// itself moves by below 1e-12 between 16² and 24² cells, so the bound is
/// QMVC's error.
#[test]
fn qmvc_is_the_definition_inside_a_twisted_box() {
    let cage = twisted_box(2.0, 0.6);
    let mut worst: f64 = 0.0;
    for x in procedural::points_inside(&cage, 24, 7, 0.1) {
        let reference = reference_weights(x, &cage, 16, 8);
        let finer = reference_weights(x, &cage, 24, 8);
        assert!(max_difference(&reference, &finer) < 1e-12);
        worst = worst.max(max_difference(&weights(x, &cage), &reference));
    }
    println!("QMVC against the definition: {worst:.1e}");
    assert!(worst < 1e-6, "QMVC differ from the definition by {worst:e}");
}

/// With triangles as well as quads, the triangles' closed form and the quads'
/// terms are the same measure: the row is the definition's.
#[test]
fn triangles_and_quads_mix() {
    let cage = twisted_prism();
    assert_eq!((cage.quads().len(), cage.lone_triangles().count()), (3, 2));
    for x in procedural::points_inside(&cage, 12, 3, 0.08) {
        let difference = max_difference(&weights(x, &cage), &reference_weights(x, &cage, 16, 8));
        assert!(difference < 1e-6, "{x}: {difference:e}");
    }
}

/// On a cage of triangles the closed form is Ju et al.'s MVC, which is the
/// definition with barycentric bases.
#[test]
fn triangle_cages_are_mvc() {
    let cage = procedural::cube_cage(1.0);
    assert!(!cage.has_quads());
    for x in procedural::points_inside(&cage, 8, 5, 0.1) {
        let difference = max_difference(&weights(x, &cage), &reference_weights(x, &cage, 16, 8));
        assert!(difference < 1e-10, "{difference:e}");
    }
}

/// Flat parallelograms: their quad terms are the bilinear definition, not the
/// triangles of either split, which differ from it by far more.
#[test]
fn flat_quads_are_patches_not_triangles() {
    let cage = parallelepiped();
    assert_eq!(cage.quads().len(), 6);
    for k in 0..6 {
        assert!(out_of_plane(&cage.quad(k)) < 1e-12);
    }
    let split = cage.split_quads(QuadSplit::Shorter);
    let mut split_difference: f64 = 0.0;
    for x in procedural::points_inside(&cage, 12, 11, 0.08) {
        let w = weights(x, &cage);
        let reference = reference_weights(x, &cage, 16, 8);
        assert!(max_difference(&w, &reference) < 1e-6);
        split_difference = split_difference.max(max_difference(&w, &weights(x, &split)));
    }
    assert!(split_difference > 1e-3, "{split_difference:e}");
}

/// The same surface from rotated corner lists gives the same weights, while
/// splitting the bent quads either way gives other ones.
#[test]
fn corner_order_does_not_matter_but_splits_do() {
    let cage = twisted_box(2.0, 0.6);
    let polygons: Vec<Vec<u32>> = cage
        .quads()
        .iter()
        .enumerate()
        .map(|(k, quad)| {
            let mut corners = quad.corners.to_vec();
            corners.rotate_left(k % 4);
            corners
        })
        .collect();
    let rotated = cage_from_polygons(cage.positions(), &polygons).unwrap().0;
    assert_ne!(rotated.quads()[1].corners, cage.quads()[1].corners);
    let (shorter, longer) = (
        cage.split_quads(QuadSplit::Shorter),
        cage.split_quads(QuadSplit::Longer),
    );
    let (mut rotation, mut split): (f64, f64) = (0.0, 0.0);
    for x in procedural::points_inside(&cage, 40, 13, 0.01) {
        rotation = rotation.max(max_difference(&weights(x, &cage), &weights(x, &rotated)));
        split = split.max(max_difference(&weights(x, &shorter), &weights(x, &longer)));
    }
    println!("rotated corners: {rotation:.1e}; shorter against longer split: {split:.1e}");
    assert!(rotation < 1e-6, "{rotation:e}");
    assert!(split > 1e-2, "{split:e}");
}

/// Partition of unity and linear precision inside, near, and out to 1e3
/// diagonals, where the far field carries them.
#[test]
fn partition_of_unity_and_linear_precision() {
    for cage in [
        twisted_box(2.0, 0.6),
        quad_comb(3, 1.0, 0.5, 3.0, 1.0, 0.3),
        twisted_prism(),
    ] {
        let centre = cage.positions().iter().sum::<DVec3>() / cage.vertex_count() as f64;
        let mut points = procedural::points_inside(&cage, 30, 17, 1e-4);
        for (k, direction) in [
            DVec3::new(0.3, 0.8, 0.52),
            DVec3::new(-1.0, 0.1, 0.0),
            DVec3::new(0.2, -0.6, -0.8),
        ]
        .into_iter()
        .enumerate()
        {
            let direction = direction.normalize();
            for distance in [0.6, 1.0, 3.0, 1e3] {
                points
                    .push(centre + direction * distance * cage.diagonal() * (1.0 + 0.1 * k as f64));
            }
        }
        for x in points {
            let w = weights(x, &cage);
            let (linear, unity) = precision(x, &cage, &w);
            assert!(linear < 1e-9 && unity < 1e-9, "{x}: {linear:e} {unity:e}");
        }
    }
}

/// On a patch the row is its bilinear weights, on an edge the edge's; the row
/// tends there from inside and from outside, exact all the way (no blow-up down
/// to the on-surface tolerance) and at least linearly in the distance.
#[test]
fn near_and_on_a_bent_patch() {
    let cage = twisted_box(2.0, 0.6);
    let k = (0..6)
        .find(|&k| out_of_plane(&cage.quad(k)) > 0.01)
        .unwrap();
    let q = cage.quad(k);
    let corners = cage.quads()[k].corners.map(|i| i as usize);
    let parameters = [
        (0.3, 0.6),
        (0.5, 0.5),
        (1e-3, 0.4),
        (0.999, 0.999),
        (0.5, 0.0),
    ];
    for ((u, v), side) in parameters.into_iter().flat_map(|p| [(p, 1.0), (p, -1.0)]) {
        let on = bilinear_point(&q, u, v);
        let normal = crate::geometry::quads::bilinear_normal(&q, u, v).normalize();
        let mut expected = vec![0.0; cage.vertex_count()];
        for (&i, b) in corners.iter().zip(bilinear_basis(u, v)) {
            expected[i] += b;
        }
        assert!(max_difference(&weights(on, &cage), &expected) < 1e-9);
        let mut previous = f64::INFINITY;
        for exponent in 1..=13 {
            let h = 10f64.powi(-exponent);
            let x = on + side * normal * h;
            let w = weights(x, &cage);
            let (linear, unity) = precision(x, &cage, &w);
            assert!(
                linear < 1e-9 && unity < 1e-12,
                "{u} {v} {side} {h:e}: {linear:e} {unity:e}"
            );
            let gap = max_difference(&w, &expected);
            assert!(
                gap <= previous.max(1e-11) && gap < 20.0 * h + 1e-11,
                "{u} {v} {side} {h:e}: {gap:e}"
            );
            previous = gap;
        }
    }
}

/// Outside the cage in the plane of a flat quad, which subtends nothing there,
/// and beside it: rows stay exact.
#[test]
fn in_the_plane_of_a_flat_quad() {
    let cage = twisted_box(2.0, 0.6);
    for x in [
        DVec3::new(3.0, 0.5, 0.0),
        DVec3::new(1.0 + 1e-7, 0.3, 0.0),
        DVec3::new(1.0 + 1e-11, -0.2, 1e-12),
        DVec3::new(-2.0, -2.0, 0.0),
    ] {
        let (linear, unity) = precision(x, &cage, &weights(x, &cage));
        assert!(linear < 1e-9 && unity < 1e-12, "{x}: {linear:e} {unity:e}");
    }
}

/// With quads the far field still gives rows that sum to one and reproduce
/// their point at every distance, and meets the closed form continuously.
#[test]
fn far_field_with_quads() {
    for cage in [
        twisted_box(2.0, 0.6),
        quad_comb(3, 1.0, 0.5, 3.0, 1.0, 0.3),
        twisted_prism(),
    ] {
        let centre = cage.positions().iter().sum::<DVec3>() / cage.vertex_count() as f64;
        let radius = FAR_FIELD_DIAGONALS * cage.diagonal();
        let near = [
            0.6,
            1.0,
            2.0,
            0.999 * FAR_FIELD_DIAGONALS,
            1.001 * FAR_FIELD_DIAGONALS,
        ];
        let distances = near.into_iter().chain((1..=30).map(|e| 10f64.powi(e)));
        for (diagonals, direction) in distances.flat_map(|d| {
            [
                DVec3::new(0.3, 0.8, 0.52),
                DVec3::new(-1.0, 0.0, 0.0),
                DVec3::new(0.577, -0.577, -0.577),
            ]
            .map(|direction| (d, direction.normalize()))
        }) {
            let x = centre + direction * diagonals * cage.diagonal();
            let w = weights(x, &cage);
            let magnitude: f64 = w.iter().map(|w| w.abs()).sum();
            let (linear, unity) = precision(x, &cage, &w);
            let relative = linear * cage.diagonal() / (x - centre).length();
            assert!(
                unity <= 1e-13 * magnitude.max(1.0),
                "{diagonals:e}: {unity:e}"
            );
            assert!(relative <= 1e-9, "{diagonals:e}: {relative:e}");
        }
        let direction = DVec3::new(0.3, 0.8, 0.52).normalize();
        let (inner, outer) = (
            weights(centre + direction * radius * (1.0 - 1e-9), &cage),
            weights(centre + direction * radius * (1.0 + 1e-9), &cage),
        );
        assert!(max_difference(&inner, &outer) < 1e-8);
    }
}

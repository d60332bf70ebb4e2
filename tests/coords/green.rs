//! Green coordinates: the rest pose, partition of unity, similarity invariance, the
//! column order, the surface and the outside, and φ and ψ against their defining
//! boundary integrals evaluated by adaptive quadrature that shares no code with the
//! library's closed form.
//!
//! Figures are printed with `--nocapture` (docs/green.md quotes them).

use glam::{DMat3, DVec3};
use pmvc::coords::green::{
    bind_green, face_vectors, green_coordinates, stretch_factors, GreenError,
};
use pmvc::coords::{BindProgress, Cancelled};
use pmvc::geometry::procedural::{self, SplitMix64};
use pmvc::geometry::{generalized_winding_number, Cage, TriMesh};
use std::f64::consts::PI;

fn cages() -> Vec<(&'static str, Cage)> {
    vec![
        ("cube", procedural::cube_cage(1.0)),
        ("icosphere", procedural::icosphere(1.0, 2)),
        (
            "comb",
            procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5),
        ),
        (
            "star",
            procedural::extrude(&procedural::star_outline(5, 0.4, 1.0), -0.3, 0.3),
        ),
    ]
}

fn coordinates(cage: &Cage, x: DVec3) -> (Vec<f64>, Vec<f64>) {
    let mut phi = vec![0.0; cage.vertex_count()];
    let mut psi = vec![0.0; cage.triangle_count()];
    green_coordinates(x, cage, &mut phi, &mut psi).unwrap();
    (phi, psi)
}

/// Σ φᵢ vᵢ + Σ ψⱼ nⱼ with the cage at rest.
fn reproduce(cage: &Cage, phi: &[f64], psi: &[f64]) -> DVec3 {
    let normals = face_vectors(cage, cage.positions()).unwrap();
    let from_vertices: DVec3 = phi.iter().zip(cage.positions()).map(|(&w, &p)| w * p).sum();
    let from_faces: DVec3 = psi.iter().zip(&normals).map(|(&w, &n)| w * n).sum();
    from_vertices + from_faces
}

/// Points outside the cage, at least `margin` (of the diagonal) from its surface.
fn points_outside(cage: &Cage, count: usize, seed: u64, margin: f64) -> Vec<DVec3> {
    let (lo, hi) = pmvc::geometry::bounds_of(cage.positions());
    let (centre, half) = ((lo + hi) / 2.0, (hi - lo) * 0.75);
    let mut random = SplitMix64(seed);
    let mut points = Vec::new();
    while points.len() < count {
        let unit = DVec3::new(random.unit(), random.unit(), random.unit()) * 2.0 - 1.0;
        let x = centre + unit * half;
        if generalized_winding_number(cage, x) < 0.5
            && procedural::distance_to_surface(cage, x) > margin * cage.diagonal()
        {
            points.push(x);
        }
    }
    points
}

#[test]
fn rest_pose_and_partition_of_unity_inside_and_outside() {
    for (name, cage) in cages() {
        let diagonal = cage.diagonal();
        for (side, points) in [
            ("inside", procedural::points_inside(&cage, 60, 11, 1e-3)),
            ("outside", points_outside(&cage, 60, 12, 1e-3)),
        ] {
            let (mut worst_position, mut worst_sum) = (0.0f64, 0.0f64);
            for &x in &points {
                let (phi, psi) = coordinates(&cage, x);
                worst_position = worst_position.max((reproduce(&cage, &phi, &psi) - x).length());
                worst_sum = worst_sum.max((phi.iter().sum::<f64>() - 1.0).abs());
            }
            eprintln!(
                "{name} {side}: rest error {:.1e} of the diagonal, |Σφ − 1| {worst_sum:.1e}",
                worst_position / diagonal
            );
            assert!(worst_position <= 1e-6 * diagonal, "{name} {side}");
            assert!(worst_sum <= 1e-9, "{name} {side}");
        }
    }
}

fn similarity(x: DVec3) -> DVec3 {
    let rotation = DMat3::from_axis_angle(DVec3::new(1.0, -2.0, 0.5).normalize(), 0.9);
    1.7 * (rotation * x) + DVec3::new(3.0, -1.0, 2.5)
}

#[test]
fn similarity_transforms_of_the_cage_move_points_alike() {
    for (name, cage) in cages() {
        let diagonal = cage.diagonal();
        let mut points = procedural::points_inside(&cage, 80, 21, 1e-3);
        points.extend(points_outside(&cage, 40, 22, 1e-3));
        let weights = bind_green(&points, &cage, &BindProgress::new(points.len())).unwrap();
        let posed: Vec<DVec3> = cage.positions().iter().map(|&p| similarity(p)).collect();
        let stretch = stretch_factors(&cage, &posed).unwrap();
        assert!(
            stretch.iter().all(|s| (s - 1.7).abs() < 1e-9),
            "{stretch:?}"
        );
        let moved = weights.deform(&cage, &posed).unwrap();
        let worst = points
            .iter()
            .zip(&moved)
            .map(|(&x, &y)| (similarity(x) - y).length())
            .fold(0.0, f64::max);
        eprintln!(
            "{name}: similarity error {:.1e} of the diagonal (f32 weights)",
            worst / diagonal
        );
        assert!(worst <= 1e-5 * diagonal, "{name}: {worst}");
        let at_rest = weights.deform(&cage, cage.positions()).unwrap();
        for (x, y) in points.iter().zip(&at_rest) {
            assert!((*x - *y).length() <= 1e-5 * diagonal);
        }
    }
}

#[test]
fn a_deformation_that_is_not_a_similarity_moves_points() {
    // Guards the similarity test against weights that ignore the cage.
    let cage = procedural::cube_cage(1.0);
    let x = DVec3::new(0.3, 0.2, -0.1);
    let weights = bind_green(&[x], &cage, &BindProgress::new(1)).unwrap();
    let stretched: Vec<DVec3> = cage
        .positions()
        .iter()
        .map(|p| DVec3::new(2.0 * p.x, p.y, p.z))
        .collect();
    let moved = weights.deform(&cage, &stretched).unwrap()[0];
    assert!((moved.x - 2.0 * x.x).abs() > 1e-3 || (moved - x).length() > 1e-3);
}

/// The cage with its vertices renumbered by `order` (new index of old vertex i is
/// `order[i]`), triangles kept in their order.
fn renumbered(cage: &Cage, order: &[usize]) -> Cage {
    let mut positions = vec![DVec3::ZERO; cage.vertex_count()];
    for (old, &new) in order.iter().enumerate() {
        positions[new] = cage.positions()[old];
    }
    let triangles = cage
        .triangles()
        .iter()
        .map(|t| t.map(|i| order[i as usize] as u32))
        .collect();
    let mesh = TriMesh {
        positions,
        triangles,
        triangle_faces: cage.triangle_faces().to_vec(),
    };
    Cage::new(mesh).unwrap().0
}

#[test]
fn shuffled_vertex_order_permutes_the_columns() {
    for (name, cage) in cages() {
        let mut order: Vec<usize> = (0..cage.vertex_count()).collect();
        let mut random = SplitMix64(7);
        for i in (1..order.len()).rev() {
            order.swap(i, (random.next_u64() % (i as u64 + 1)) as usize);
        }
        let shuffled = renumbered(&cage, &order);
        let mut points = procedural::points_inside(&cage, 20, 31, 1e-3);
        points.extend(points_outside(&cage, 10, 32, 1e-3));
        for &x in &points {
            let (phi, psi) = coordinates(&cage, x);
            let (shuffled_phi, shuffled_psi) = coordinates(&shuffled, x);
            for (old, &new) in order.iter().enumerate() {
                assert!((phi[old] - shuffled_phi[new]).abs() < 1e-12, "{name}");
            }
            for (a, b) in psi.iter().zip(&shuffled_psi) {
                assert!((a - b).abs() < 1e-12, "{name}");
            }
        }
    }
}

/// Radon's 7-point rule, exact for polynomials of degree 5: barycentric points and
/// weights summing to 1.
fn radon_rule() -> [([f64; 3], f64); 7] {
    let root = 15f64.sqrt();
    let (a1, a2) = ((6.0 - root) / 21.0, (6.0 + root) / 21.0);
    let (w1, w2) = ((155.0 - root) / 1200.0, (155.0 + root) / 1200.0);
    let third = 1.0 / 3.0;
    [
        ([third, third, third], 9.0 / 40.0),
        ([a1, a1, 1.0 - 2.0 * a1], w1),
        ([a1, 1.0 - 2.0 * a1, a1], w1),
        ([1.0 - 2.0 * a1, a1, a1], w1),
        ([a2, a2, 1.0 - 2.0 * a2], w2),
        ([a2, 1.0 - 2.0 * a2, a2], w2),
        ([1.0 - 2.0 * a2, a2, a2], w2),
    ]
}

/// The defining integrals over one cage triangle `corners` for the point x, as
/// `[φ₀, φ₁, φ₂, ψ]`: φₖ = ∫ Γₖ ∂G/∂n, ψ = −∫ G with G(ξ, x) = −1/(4π|ξ − x|), Γₖ
/// the hat function of corner k and n the outward normal. `sub` is a sub-triangle
/// in barycentric coordinates of the cage triangle; it is split in four until the
/// 7-point rule agrees with the sum over the four halves.
fn integrate(corners: [DVec3; 3], x: DVec3, sub: [[f64; 3]; 3], depth: u32) -> [f64; 4] {
    let normal = (corners[1] - corners[0])
        .cross(corners[2] - corners[0])
        .normalize();
    let area = 0.5
        * (corners[1] - corners[0])
            .cross(corners[2] - corners[0])
            .length();
    let rule = |sub: [[f64; 3]; 3]| {
        let sub_area = area * {
            let [p, q, r] = sub.map(DVec3::from_array);
            // Barycentric area ratio of the sub-triangle.
            (q - p).cross(r - p).length() / 3f64.sqrt()
        };
        let mut sum = [0.0; 4];
        for (point, weight) in radon_rule() {
            let hat: [f64; 3] = std::array::from_fn(|k| {
                point[0] * sub[0][k] + point[1] * sub[1][k] + point[2] * sub[2][k]
            });
            let xi = hat[0] * corners[0] + hat[1] * corners[1] + hat[2] * corners[2];
            let r = (xi - x).length();
            let double_layer = normal.dot(xi - x) / (4.0 * PI * r * r * r);
            for k in 0..3 {
                sum[k] += weight * sub_area * hat[k] * double_layer;
            }
            sum[3] += weight * sub_area / (4.0 * PI * r);
        }
        sum
    };
    let whole = rule(sub);
    let mid = |i: usize, j: usize| std::array::from_fn(|k| 0.5 * (sub[i][k] + sub[j][k]));
    let (m01, m12, m20) = (mid(0, 1), mid(1, 2), mid(2, 0));
    let children = [
        [sub[0], m01, m20],
        [m01, sub[1], m12],
        [m20, m12, sub[2]],
        [m01, m12, m20],
    ];
    let split: [f64; 4] = children
        .iter()
        .map(|&c| rule(c))
        .fold([0.0; 4], |a, b| std::array::from_fn(|k| a[k] + b[k]));
    let difference = (0..4)
        .map(|k| (whole[k] - split[k]).abs())
        .fold(0.0, f64::max);
    if difference < 1e-13 || depth >= 9 {
        return split;
    }
    children
        .iter()
        .map(|&c| integrate(corners, x, c, depth + 1))
        .fold([0.0; 4], |a, b| std::array::from_fn(|k| a[k] + b[k]))
}

#[test]
fn coordinates_match_the_boundary_integrals_by_quadrature() {
    let whole = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for (name, cage) in cages() {
        let mut worst = 0.0f64;
        for x in procedural::points_inside(&cage, 4, 41, 0.02) {
            let mut phi = vec![0.0; cage.vertex_count()];
            let mut psi = vec![0.0; cage.triangle_count()];
            for (t, corners) in cage.triangles().iter().enumerate() {
                let [p0, p1, p2, single] = integrate(cage.triangle(t), x, whole, 0);
                for (&corner, value) in corners.iter().zip([p0, p1, p2]) {
                    phi[corner as usize] += value;
                }
                psi[t] = single;
            }
            let (closed_phi, closed_psi) = coordinates(&cage, x);
            for (a, b) in phi
                .iter()
                .zip(&closed_phi)
                .chain(psi.iter().zip(&closed_psi))
            {
                worst = worst.max((a - b).abs());
            }
        }
        eprintln!("{name}: closed form vs quadrature, largest difference {worst:.1e}");
        assert!(worst < 1e-8, "{name}: {worst}");
    }
}

/// Points at and around the surface of every triangle: centroid, edge midpoint and
/// corner, offset along the normal by ±d for several d (and exactly on it).
fn points_around_surface(cage: &Cage) -> Vec<DVec3> {
    let diagonal = cage.diagonal();
    let mut points = Vec::new();
    for t in (0..cage.triangle_count()).step_by(3) {
        let [a, b, c] = cage.triangle(t);
        let normal = (b - a).cross(c - a).normalize();
        for base in [(a + b + c) / 3.0, (a + b) / 2.0, a] {
            points.push(base);
            for d in [1e-14, 1e-11, 1e-9, 1e-7, 1e-5, 1e-3] {
                points.push(base + d * diagonal * normal);
                points.push(base - d * diagonal * normal);
            }
        }
    }
    points
}

#[test]
fn points_on_and_near_the_surface_are_finite_and_reproduced() {
    for (name, cage) in cages() {
        let diagonal = cage.diagonal();
        let mut worst = 0.0f64;
        for x in points_around_surface(&cage) {
            let (phi, psi) = coordinates(&cage, x);
            assert!(
                phi.iter().chain(&psi).all(|v| v.is_finite()),
                "{name}: not finite at {x}"
            );
            let sum = phi.iter().sum::<f64>();
            assert!((sum - 1.0).abs() < 1e-6, "{name} at {x}: Σφ = {sum}");
            worst = worst.max((reproduce(&cage, &phi, &psi) - x).length());
        }
        eprintln!(
            "{name}: on/near the surface, rest error {:.1e} of the diagonal",
            worst / diagonal
        );
        assert!(worst <= 1e-6 * diagonal, "{name}: {worst}");
    }
}

/// Largest difference of any coordinate between the points `step` (of the
/// diagonal) inside and outside the centre of every face.
fn jump_across_faces(cage: &Cage, step: f64) -> f64 {
    let mut worst = 0.0f64;
    for t in 0..cage.triangle_count() {
        let [a, b, c] = cage.triangle(t);
        let offset = step * cage.diagonal() * (b - a).cross(c - a).normalize();
        let centre = (a + b + c) / 3.0;
        let (inner_phi, inner_psi) = coordinates(cage, centre - offset);
        let (outer_phi, outer_psi) = coordinates(cage, centre + offset);
        let pairs = inner_phi.iter().zip(&outer_phi);
        for (p, q) in pairs.chain(inner_psi.iter().zip(&outer_psi)) {
            worst = worst.max((p - q).abs());
        }
    }
    worst
}

#[test]
fn coordinates_are_continuous_across_faces() {
    // The exterior continuation meets the inside coordinates on every face: the
    // difference across a face shrinks with the distance between the two points.
    for (name, cage) in cages() {
        let (far, near) = (
            jump_across_faces(&cage, 1e-5),
            jump_across_faces(&cage, 1e-7),
        );
        eprintln!("{name}: largest jump across faces at ±1e-5 of the diagonal {far:.1e}, at ±1e-7 {near:.1e}");
        assert!(far < 1e-2, "{name}: {far}");
        assert!(near < far / 30.0, "{name}: {near} against {far}");
    }
}

#[test]
fn stretch_is_one_at_rest_and_face_vectors_are_unit_normals() {
    let cage = procedural::icosphere(2.0, 1);
    assert!(stretch_factors(&cage, cage.positions())
        .unwrap()
        .iter()
        .all(|s| (s - 1.0).abs() < 1e-12));
    for (t, f) in face_vectors(&cage, cage.positions())
        .unwrap()
        .iter()
        .enumerate()
    {
        let [a, b, c] = cage.triangle(t);
        assert!((*f - (b - a).cross(c - a).normalize()).length() < 1e-12);
    }
}

#[test]
fn binder_rows_match_single_points_and_report_progress() {
    let cage = procedural::extrude(&procedural::star_outline(5, 0.4, 1.0), -0.3, 0.3);
    let mut points = procedural::points_inside(&cage, 70, 51, 1e-3);
    points.extend(points_outside(&cage, 5, 52, 1e-3));
    let progress = BindProgress::new(points.len());
    let weights = bind_green(&points, &cage, &progress).unwrap();
    assert_eq!(progress.done(), points.len());
    assert_eq!(
        (weights.phi.rows, weights.phi.cols),
        (75, cage.vertex_count())
    );
    assert_eq!(
        (weights.psi.rows, weights.psi.cols),
        (75, cage.triangle_count())
    );
    for (row, &x) in points.iter().enumerate() {
        let (phi, psi) = coordinates(&cage, x);
        for (a, b) in weights.phi.row(row).iter().zip(&phi) {
            assert_eq!(*a, *b as f32);
        }
        for (a, b) in weights.psi.row(row).iter().zip(&psi) {
            assert_eq!(*a, *b as f32);
        }
    }
}

#[test]
fn bad_input_gives_errors() {
    let cage = procedural::cube_cage(1.0);
    let (mut phi, mut psi) = (vec![0.0; 8], vec![0.0; 12]);
    let mut short = vec![0.0; 7];
    assert!(matches!(
        green_coordinates(DVec3::ZERO, &cage, &mut short, &mut psi),
        Err(GreenError::PhiLength {
            expected: 8,
            actual: 7
        })
    ));
    assert!(matches!(
        green_coordinates(DVec3::ZERO, &cage, &mut phi, &mut short),
        Err(GreenError::PsiLength {
            expected: 12,
            actual: 7
        })
    ));
    assert!(matches!(
        green_coordinates(DVec3::NAN, &cage, &mut phi, &mut psi),
        Err(GreenError::NonFinitePoint { .. })
    ));
    let points = [DVec3::ZERO, DVec3::new(0.0, f64::INFINITY, 0.0)];
    assert_eq!(
        bind_green(&points, &cage, &BindProgress::new(2)),
        Err(GreenError::NonFinitePoint { index: 1 })
    );
    let cancelled = BindProgress::new(1);
    cancelled.cancel();
    assert_eq!(
        bind_green(&[DVec3::ZERO], &cage, &cancelled),
        Err(GreenError::Cancelled(Cancelled))
    );
    let weights = bind_green(&[DVec3::ZERO], &cage, &BindProgress::new(1)).unwrap();
    assert!(matches!(
        weights.deform(&cage, &cage.positions()[..5]),
        Err(GreenError::PositionCount {
            expected: 8,
            actual: 5
        })
    ));
    assert!(matches!(
        weights.deform_with_face_vectors(cage.positions(), &[DVec3::Z]),
        Err(GreenError::FaceVectorCount {
            expected: 12,
            actual: 1
        })
    ));
}

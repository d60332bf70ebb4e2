use super::*;
use crate::geometry::procedural_quads::cage_from_polygons;
use crate::geometry::{procedural, Cage};

fn solve(cage: &Cage, x: DVec3) -> (Vec<f64>, MecSolve) {
    let mut out = vec![f64::NAN; cage.vertex_count()];
    let solve = mec_weights_inside(x, cage, &mut out, &mut MecScratch::default())
        .unwrap_or_else(|error| panic!("{x}: {error}"));
    (out, solve)
}

fn tetrahedron(corners: [DVec3; 4]) -> Cage {
    let faces = vec![vec![0, 2, 1], vec![0, 1, 3], vec![1, 2, 3], vec![0, 3, 2]];
    cage_from_polygons(&corners, &faces).unwrap().0
}

/// On a tetrahedron partition of unity and linear precision leave one
/// solution, the barycentric coordinates (by Cramer's rule here), whatever
/// the prior.
#[test]
fn a_tetrahedron_gets_its_barycentric_coordinates() {
    let corners = [
        DVec3::new(0.1, -0.2, 0.0),
        DVec3::new(2.0, 0.1, 0.3),
        DVec3::new(0.4, 1.7, -0.2),
        DVec3::new(0.6, 0.5, 1.9),
    ];
    let cage = tetrahedron(corners);
    let volume = |p: [DVec3; 4]| (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]));
    for x in [
        DVec3::new(0.7, 0.5, 0.4),
        DVec3::new(0.3, 0.0, 0.05),
        DVec3::new(0.62, 0.52, 1.8),
    ] {
        let (weights, solve) = solve(&cage, x);
        for (i, &w) in weights.iter().enumerate() {
            let mut replaced = corners;
            replaced[i] = x;
            let expected = volume(replaced) / volume(corners);
            assert!(
                (w - expected).abs() < 1e-11,
                "{x}: w{i} {w} against {expected} ({solve:?})"
            );
        }
    }
}

/// A box of six quads: every corner is on three faces, so at the centre the
/// priors are equal and so are the weights. (On a cube of twelve triangles the
/// corners are on three or six faces and the priors differ, see the docs.)
#[test]
fn the_centre_of_a_box_of_quads_weighs_its_corners_equally() {
    let cage = crate::geometry::procedural_quads::twisted_box(2.0, 0.0);
    let (weights, _) = solve(&cage, DVec3::new(0.0, 0.0, 1.0));
    for &w in &weights {
        assert!((w - 0.125).abs() < 1e-13, "{weights:?}");
    }
}

/// Nearing a well-shaped face the weights go to its barycentric coordinates,
/// linearly in the distance, however many orders of magnitude the prior spans.
#[test]
fn near_a_triangle_the_weights_tend_to_its_barycentric_coordinates() {
    let comb = procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5);
    for (cage, t) in [
        (procedural::icosphere(1.0, 1), 5),
        (procedural::cube_cage(1.0), 3),
        (comb, 30),
    ] {
        let [a, b, c] = cage.triangle(t);
        let normal = (b - a).cross(c - a).normalize();
        let foot = (a + 2.0 * b + 3.0 * c) / 6.0;
        let corners = cage.triangles()[t];
        for h in [1e-1, 1e-2, 1e-4, 1e-6, 1e-8] {
            let (weights, solve) = solve(&cage, foot - h * normal);
            assert!(solve.residual <= TOLERANCE, "{solve:?}");
            let mut error = 0.0f64;
            for (i, &w) in weights.iter().enumerate() {
                let expected = match corners.iter().position(|&k| k as usize == i) {
                    Some(k) => (k + 1) as f64 / 6.0,
                    None => 0.0,
                };
                error = error.max((w - expected).abs());
            }
            assert!(error <= 5.0 * h, "triangle {t}, h {h}: error {error}");
        }
    }
}

#[test]
fn a_point_outside_the_hull_is_refused_not_answered() {
    let cage = procedural::cube_cage(1.0);
    let mut out = vec![0.5; cage.vertex_count()];
    let error = mec_weights_inside(
        DVec3::new(3.0, 0.0, 0.0),
        &cage,
        &mut out,
        &mut MecScratch::default(),
    )
    .unwrap_err();
    assert!(matches!(error, MecError::NotConverged { .. }), "{error}");
    assert!(out.iter().all(|&w| w == 0.5), "out untouched on error");
    let error = mec_weights_inside(
        DVec3::new(f64::NAN, 0.0, 0.0),
        &cage,
        &mut out,
        &mut MecScratch::default(),
    );
    assert_eq!(error, Err(MecError::NotFinite));
}

#[test]
fn the_cholesky_solve_matches_the_inverse_and_refuses_an_indefinite_matrix() {
    let a = DMat3::from_cols(
        DVec3::new(4.0, 1.0, 0.5),
        DVec3::new(1.0, 3.0, -0.2),
        DVec3::new(0.5, -0.2, 2.0),
    );
    let b = DVec3::new(1.0, -2.0, 0.3);
    let x = cholesky_solve(a, b).unwrap();
    assert!((x - a.inverse() * b).length() < 1e-14);
    let indefinite = DMat3::from_diagonal(DVec3::new(1.0, -1.0, 1.0));
    assert_eq!(cholesky_solve(indefinite, b), None);
}

/// A vertex no face uses has no prior (`−∞` in the log domain): weight zero,
/// and the others are those of the cage without it.
#[test]
fn a_vertex_no_face_uses_gets_no_weight() {
    let cage = procedural::cube_cage(1.0);
    let mut positions = cage.positions().to_vec();
    positions.push(DVec3::new(0.1, 0.2, 0.3));
    let (with_spare, report) = Cage::new(crate::geometry::TriMesh {
        positions,
        triangles: cage.triangles().to_vec(),
        triangle_faces: cage.triangle_faces().to_vec(),
    })
    .unwrap();
    assert_eq!(report.unreferenced, [8]);
    let x = DVec3::new(0.3, -0.2, 0.1);
    let (weights, _) = solve(&with_spare, x);
    let (without, _) = solve(&cage, x);
    assert_eq!(weights[8], 0.0);
    for (a, b) in weights.iter().zip(&without) {
        assert!((a - b).abs() < 1e-14, "{weights:?} {without:?}");
    }
}

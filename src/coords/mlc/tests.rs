use super::*;
use crate::geometry::procedural_quads::cage_from_polygons;
use crate::geometry::{procedural, Cage};

fn solve(cage: &Cage, x: DVec3) -> (Vec<f64>, MlcSolve) {
    let mut out = vec![f64::NAN; cage.vertex_count()];
    let solve = mlc_weights_inside(x, cage, &mut out, &mut MlcScratch::default())
        .unwrap_or_else(|error| panic!("{x}: {error}"));
    (out, solve)
}

/// On a tetrahedron partition of unity and linear precision leave one
/// solution, the barycentric coordinates (by Cramer's rule here).
#[test]
fn a_tetrahedron_gets_its_barycentric_coordinates() {
    let corners = [
        DVec3::new(0.1, -0.2, 0.0),
        DVec3::new(2.0, 0.1, 0.3),
        DVec3::new(0.4, 1.7, -0.2),
        DVec3::new(0.6, 0.5, 1.9),
    ];
    let faces = vec![vec![0, 2, 1], vec![0, 1, 3], vec![1, 2, 3], vec![0, 3, 2]];
    let cage = cage_from_polygons(&corners, &faces).unwrap().0;
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
                "{x} corner {i}: {w} vs {expected}"
            );
        }
        assert!(solve.residual <= TOLERANCE);
    }
}

/// At the centre of a cube every corner sees the others alike: `φ = 0`, each
/// weight 1/8, with no Newton step.
#[test]
fn the_centre_of_a_cube_weighs_every_corner_equally() {
    let (weights, solve) = solve(&procedural::cube_cage(1.0), DVec3::ZERO);
    assert_eq!(solve.iterations, 0);
    for w in weights {
        assert!((w - 0.125).abs() < 1e-15, "{w}");
    }
}

/// A point on a vertex and a point outside the hull have no coordinates here;
/// the bind's policies answer for them. The output is left untouched.
#[test]
fn a_vertex_and_an_outside_point_are_refused() {
    let cage = procedural::cube_cage(1.0);
    let mut out = vec![7.0; 8];
    let mut scratch = MlcScratch::default();
    let on_vertex = mlc_weights_inside(cage.positions()[3], &cage, &mut out, &mut scratch);
    assert_eq!(on_vertex, Err(MlcError::OnVertex { vertex: 3 }));
    let outside = mlc_weights_inside(DVec3::new(1.5, 0.2, 0.1), &cage, &mut out, &mut scratch);
    assert!(
        matches!(outside, Err(MlcError::NotConverged { .. })),
        "{outside:?}"
    );
    let nan = mlc_weights_inside(DVec3::NAN, &cage, &mut out, &mut scratch);
    assert_eq!(nan, Err(MlcError::NotFinite));
    assert!(out.iter().all(|&w| w == 7.0));
}

/// The Newton step solves `H Δ = g` although it never forms `H`.
#[test]
fn the_least_squares_step_solves_the_newton_system() {
    let u: Vec<DVec3> = [
        DVec3::new(1.0, 0.2, -0.3),
        DVec3::new(-0.4, 1.0, 0.1),
        DVec3::new(0.2, -0.7, 1.0),
        DVec3::new(-0.5, -0.5, -0.6),
        DVec3::new(0.3, 0.3, -1.0),
    ]
    .iter()
    .map(|v| v.normalize())
    .collect();
    let s = [0.7, 2.0, 1.3, 4.1, 0.9];
    let mut columns = Default::default();
    let mut rhs = Vec::new();
    let step = newton_step(&u, &s, &mut columns, &mut rhs).unwrap();
    let (mut h_step, mut g) = (DVec3::ZERO, DVec3::ZERO);
    for (ui, si) in u.iter().zip(s) {
        h_step += *ui * ui.dot(step) / (si * si);
        g += *ui / si;
    }
    assert!((h_step - g).length() < 1e-14, "{h_step} vs {g}");
}

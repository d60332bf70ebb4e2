//! Exactness at any distance: MVC's outside policy far from the cage, the
//! displacement form far from the origin, and OBJ positions that round-trip f64.

use glam::{DMat3, DVec3};
use pmvc::coords::mvc::{mvc_weights, MvcScratch, FAR_FIELD_DIAGONALS};
use pmvc::formats::{parse_mesh, write_obj_to};
use pmvc::geometry::{procedural, Cage};
use std::path::Path;

#[cfg(feature = "editor")]
use crate::common;

fn cages() -> Vec<(&'static str, Cage)> {
    vec![
        ("cube", procedural::cube_cage(0.5)),
        (
            "comb",
            procedural::extrude(&procedural::comb_outline(5, 1.0, 0.25, 4.0), -0.5, 0.5),
        ),
        (
            "star",
            procedural::extrude(&procedural::star_outline(6, 0.4, 1.0), -0.3, 0.3),
        ),
    ]
}

fn directions() -> [DVec3; 4] {
    [
        DVec3::new(0.3, 0.8, 0.52).normalize(),
        DVec3::new(-1.0, 0.0, 0.0),
        DVec3::new(0.0, -0.6, 0.8),
        DVec3::new(0.577, -0.577, -0.577).normalize(),
    ]
}

/// Distances from the cage's vertex centroid in cage diagonals: on both sides of
/// where the far field begins, then out to 10³⁰.
fn distances() -> Vec<f64> {
    let near = [
        0.6,
        1.0,
        2.0,
        0.999 * FAR_FIELD_DIAGONALS,
        1.001 * FAR_FIELD_DIAGONALS,
    ];
    near.into_iter()
        .chain((1..=30).map(|exponent| 10f64.powi(exponent)))
        .collect()
}

fn centroid(cage: &Cage) -> DVec3 {
    cage.positions().iter().sum::<DVec3>() / cage.vertex_count() as f64
}

fn weights(x: DVec3, cage: &Cage) -> Vec<f64> {
    let mut out = vec![0.0; cage.vertex_count()];
    mvc_weights(x, cage, &mut out, &mut MvcScratch::default());
    out
}

/// From the cage's size out to 10³⁰ of it, every row sums to one and reproduces
/// its point. The closed form alone loses linear precision from about 10³
/// diagonals and returns all-zero rows from about 10¹⁷.
#[test]
fn far_points_sum_to_one_and_reproduce_themselves_at_every_distance() {
    for (name, cage) in cages() {
        let (centre, diagonal) = (centroid(&cage), cage.diagonal());
        for diagonals in distances() {
            for direction in directions() {
                let x = centre + direction * diagonals * diagonal;
                let row = weights(x, &cage);
                let magnitude: f64 = row.iter().map(|w| w.abs()).sum();
                let sum: f64 = row.iter().sum();
                assert!(
                    (sum - 1.0).abs() <= 1e-13 * magnitude.max(1.0),
                    "{name} at {diagonals:e} diagonals: weights sum to {sum} (Σ|w| = {magnitude})"
                );
                let reproduced: DVec3 =
                    row.iter().zip(cage.positions()).map(|(w, v)| *w * *v).sum();
                let error = (reproduced - x).length() / (x - centre).length();
                assert!(
                    error <= 1e-8,
                    "{name} at {diagonals:e} diagonals: reproduces its point to {error:.1e} of its distance"
                );
            }
        }
    }
}

/// An affine motion of the cage moves far points by the same map, in the
/// displacement form the product deforms with.
#[test]
fn an_affine_motion_of_the_cage_moves_far_points_by_the_same_map() {
    let linear = DMat3::from_cols(
        DVec3::new(1.2, 0.1, 0.0),
        DVec3::new(-0.2, 0.9, 0.3),
        DVec3::new(0.05, 0.0, 1.4),
    );
    let translation = DVec3::new(0.3, -0.7, 2.0);
    for (name, cage) in cages() {
        let (centre, diagonal) = (centroid(&cage), cage.diagonal());
        let moves: Vec<DVec3> = cage
            .positions()
            .iter()
            .map(|&v| linear * v + translation - v)
            .collect();
        for diagonals in distances() {
            for direction in directions() {
                let x = centre + direction * diagonals * diagonal;
                let row = weights(x, &cage);
                let moved: DVec3 = x + row.iter().zip(&moves).map(|(w, d)| *w * *d).sum::<DVec3>();
                let expected = linear * x + translation;
                let error = (moved - expected).length() / (x - centre).length();
                assert!(
                    error <= 1e-8,
                    "{name} at {diagonals:e} diagonals: off the affine image by {error:.1e} of its distance"
                );
            }
        }
    }
}

/// Positions written by the OBJ writer read back as the same f64 values.
#[test]
fn obj_positions_round_trip_every_f64() {
    let values = [
        0.1,
        -0.3,
        1.0 / 3.0,
        123_456_789.123_456_78,
        2.5e-7,
        -1e-300,
        1e300,
        6.02214076e23,
        0.0,
        -0.0,
        f64::MIN_POSITIVE,
        f64::MAX,
    ];
    let positions: Vec<DVec3> = values
        .chunks(3)
        .map(|c| DVec3::new(c[0], c[1], c[2]))
        .collect();
    let mut text = Vec::new();
    write_obj_to(&mut text, &positions, &[]).unwrap();
    let text = String::from_utf8(text).unwrap();
    assert!(text.contains("v 0.1 -0.3 "), "{text}");
    assert!(text.lines().all(|line| line.len() < 80), "{text}");
    let read = parse_mesh(Path::new("round-trip.obj"), text.clone()).unwrap();
    for (written, read) in positions.iter().zip(&read.mesh.positions) {
        for axis in 0..3 {
            assert_eq!(
                written[axis].to_bits(),
                read[axis].to_bits(),
                "{} came back as {}\n{text}",
                written[axis],
                read[axis]
            );
        }
    }
}

/// `pmvc deform` on a unit cage 10⁶ from the origin: the rest pose comes back
/// bit for bit, and a translated cage moves every point, inside and outside, by
/// the translation to 1e-6 of the cage's size. Blending absolute positions with
/// f32 weights loses about 6e-2 there.
#[cfg(feature = "editor")]
#[test]
fn deform_is_exact_for_a_cage_far_from_the_origin() {
    use common::*;
    let dir = tempfile::tempdir().unwrap();
    let offset = DVec3::new(1e6, -2e6, 5e5);
    let unit = procedural::cube_cage(0.5);
    let cage = unit.with_positions(unit.positions().iter().map(|&p| p + offset).collect());
    let mut points: Vec<DVec3> = procedural::points_inside(&unit, 50, 3, 1e-3)
        .into_iter()
        .map(|p| p + offset)
        .collect();
    points.push(offset + DVec3::new(3.0, 0.2, -0.1)); // outside
    points.push(offset + DVec3::new(0.0, 40.0, 0.0)); // in the far field
    let mesh = write(dir.path(), "mesh.obj", &points_obj(&points));
    let cage_path = write(dir.path(), "cage.obj", &cage_obj(&cage));
    let translation = DVec3::new(0.1, 0.25, -0.3);
    for (name, shift) in [("rest", DVec3::ZERO), ("moved", translation)] {
        let pose: Vec<DVec3> = cage.positions().iter().map(|&p| p + shift).collect();
        let pose_path = write(
            dir.path(),
            &format!("{name}.obj"),
            &triangles_obj(&pose, cage.triangles()),
        );
        let out = dir.path().join(format!("{name}-out.obj"));
        let output = pmvc(&[
            "deform",
            "--mesh",
            path_str(&mesh),
            "--cage",
            path_str(&cage_path),
            "--deformed-cage",
            path_str(&pose_path),
            "--backend",
            "cpu",
            "--out",
            path_str(&out),
        ]);
        assert!(output.status.success(), "{}", stderr(&output));
        let deformed = pmvc::formats::load_mesh(&out).unwrap().mesh.positions;
        assert_eq!(deformed.len(), points.len());
        for (k, (before, after)) in points.iter().zip(&deformed).enumerate() {
            let error = (*after - (*before + shift)).length();
            if name == "rest" {
                assert_eq!(before, after, "{name}: vertex {}", k + 1);
            } else {
                assert!(error <= 1e-6, "{name}: vertex {} off by {error:.1e}", k + 1);
            }
        }
    }
}

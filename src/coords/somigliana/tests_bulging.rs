//! The bulging term: the swept volumes it reads, the tractions it gives (no net
//! force, none at all for a similarity), the bulge it makes and its setting.

use super::bulging::{face_tractions, swept_volume};
use super::tests::box_cage;
use super::tests_family::{bent, bind, diagonal, inside_points, options};
use super::*;
use crate::coords::{Method, Parameter};
use glam::DQuat;

/// The box squashed to 0.6 of its height: no similarity.
fn squashed(cage: &Cage) -> Vec<DVec3> {
    (cage.positions().iter())
        .map(|&p| DVec3::new(p.x, p.y, 0.6 * p.z))
        .collect()
}

fn net_force(cage: &Cage, tractions: &[f64]) -> DVec3 {
    (0..cage.triangle_count())
        .map(|t| {
            let [a, b, c] = cage.triangle(t);
            (b - a).cross(c - a) / 2.0 * tractions[t]
        })
        .sum()
}

#[test]
fn swept_volume_is_the_prism_between_two_triangles() {
    // Far from the origin: the volume is taken about the triangle itself.
    let offset = DVec3::new(1e7, -3e6, 2e6);
    let from = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
    ]
    .map(|p| p + offset);
    let (area, lift) = (1.0, DVec3::new(0.0, 0.0, 0.3));
    let out = from.map(|p| p + lift);
    assert!((swept_volume(out, from) - area * 0.3).abs() < 1e-8);
    assert!((swept_volume(from, out) + area * 0.3).abs() < 1e-8);
    // One corner lifted: the ruled prism holds a third of the full lift.
    let corner = [from[0], from[1], from[2] + lift];
    assert!((swept_volume(corner, from) - area * 0.1).abs() < 1e-8);
    // A slide within the plane sweeps nothing.
    let slid = from.map(|p| p + DVec3::new(0.2, 0.1, 0.0));
    assert!(swept_volume(slid, from).abs() < 1e-8);
}

#[test]
fn a_similarity_of_the_cage_is_followed_whatever_the_bulging() {
    let cage = box_cage();
    let turn = DQuat::from_axis_angle(DVec3::new(0.3, -1.0, 0.6).normalize(), 1.1);
    let pose: Vec<DVec3> = (cage.positions().iter())
        .map(|&p| 1.3 * (turn * p) + DVec3::new(-2.0, 5.0, 1.0))
        .collect();
    let fit = fit::fit_similarity(cage.positions(), &pose);
    let tractions = face_tractions(&cage, &pose, &fit, 0.3, 4.0);
    assert!(
        tractions.iter().all(|t| (t - 1.3).abs() < 1e-12),
        "{tractions:?}"
    );
    let points = [DVec3::new(0.2, -0.1, 0.3), DVec3::new(-0.8, 0.4, -0.45)];
    let blocks = somigliana_blocks(&points, &cage, 0.3).unwrap();
    let moved = deform(&blocks, &cage, &pose, 4.0).unwrap();
    for (&x, moved) in points.iter().zip(moved) {
        let want = 1.3 * (turn * x) + DVec3::new(-2.0, 5.0, 1.0);
        assert!(
            (moved - want).length() / diagonal(&cage) < 1e-10,
            "{moved} {want}"
        );
    }
}

#[test]
fn bulging_tractions_exert_no_net_force() {
    let cage = box_cage();
    let pose = squashed(&cage);
    let fit = fit::fit_similarity(cage.positions(), &pose);
    let tractions = face_tractions(&cage, &pose, &fit, 0.0, 2.0);
    let force = net_force(&cage, &tractions);
    assert!(force.length() < 1e-12, "{force}");
    // The squash sweeps the sides outward and the top and bottom inward of the
    // fitted similarity: the sides push harder.
    for (t, &traction) in tractions.iter().enumerate() {
        let [a, b, c] = cage.triangle(t);
        let normal = (b - a).cross(c - a).normalize();
        let side = normal.z.abs() < 0.5;
        let beyond = if side {
            traction > fit.scale
        } else {
            traction < fit.scale
        };
        assert!(
            beyond,
            "triangle {t} ({normal}): {traction} against s {}",
            fit.scale
        );
    }
}

#[test]
fn a_squashed_box_bulges_more_as_gamma_grows() {
    let cage = box_cage();
    let pose = squashed(&cage);
    let probe = [DVec3::new(0.0, 0.4, 0.0), DVec3::ZERO];
    let blocks = somigliana_blocks(&probe, &cage, 0.0).unwrap();
    let gammas = [0.0, 1.0, 2.0, 4.0];
    let moved: Vec<Vec<DVec3>> = (gammas.iter())
        .map(|&gamma| deform(&blocks, &cage, &pose, gamma).unwrap())
        .collect();
    for (gamma, moved) in gammas.iter().zip(&moved) {
        println!(
            "γ {gamma}: side probe y {:.6}, centre {:.6}",
            moved[0].y, moved[1]
        );
    }
    // The probe near a side goes further out with γ (0.4 at rest: 0.369 at
    // γ 0, as the fitted s = 0.93 shrinks it, 0.447 at γ 4); the centre stays,
    // the squash being symmetric.
    assert!(
        moved.windows(2).all(|w| w[1][0].y > w[0][0].y + 1e-4),
        "{moved:?}"
    );
    for moved in &moved {
        assert!(moved[1].length() < 1e-9 * diagonal(&cage), "{}", moved[1]);
    }
}

#[test]
fn the_column_vectors_follow_the_bulging_deformation() {
    let (cage, points) = (super::tests::l_cage(), inside_points());
    let mut options = options(0.3);
    options.set(
        Parameter::Bulging,
        Parameter::Bulging.spec().parse("2.5").unwrap(),
    );
    assert_eq!(options.bulging(), 2.5);
    let weights = bind(&cage, &points, options);
    let pose = bent(&cage);
    let blocks = somigliana_blocks(&points, &cage, 0.3).unwrap();
    let expected = deform(&blocks, &cage, &pose, 2.5).unwrap();
    let without = deform(&blocks, &cage, &pose, 0.0).unwrap();
    let moves = options.column_moves(&cage, &pose);
    let displaced = weights.apply_moves(&points, &moves);
    let scale = diagonal(&cage);
    let mut largest_bulge = 0.0f64;
    for ((want, got), plain) in expected.iter().zip(&displaced).zip(&without) {
        assert!((*want - *got).length() / scale < 1e-5, "{want} {got}");
        largest_bulge = largest_bulge.max((*want - *plain).length() / scale);
    }
    // The setting does move the points, and at rest nothing moves.
    assert!(largest_bulge > 1e-3, "{largest_bulge}");
    let still = options.column_moves(&cage, cage.positions());
    assert!(still.is_linear() && still.vectors().iter().all(|d| d.length() < 1e-12));
}

#[test]
fn bulging_is_a_setting_of_the_deformation_checked_by_its_spec() {
    let spec = Parameter::Bulging.spec();
    assert_eq!(spec.parse("0.5"), Ok(50));
    assert_eq!(spec.parse("10"), Ok(1000));
    for refused in ["10.01", "-1", "a lot"] {
        assert!(spec.parse(refused).is_err(), "{refused}");
    }
    assert!(matches!(
        validate_bulging(f64::NAN),
        Err(SomiglianaError::Bulging { .. })
    ));
    let cage = box_cage();
    let blocks = somigliana_blocks(&[DVec3::ZERO], &cage, 0.0).unwrap();
    assert!(deform(&blocks, &cage, cage.positions(), -0.5).is_err());
    // Read when deforming: options differing only in it share their weights,
    // and the family lists it among its deformation settings.
    let (plain, mut bulged) = (options(0.0), options(0.0));
    bulged.bulging = 300;
    assert!(plain.same_weights_as(&bulged));
    assert!(bulged.validate().is_ok());
    bulged.bulging = 1001;
    assert!(bulged.validate().is_err());
    let listed: Vec<Parameter> = (Method::Somigliana.spec().deform_parameters.iter())
        .map(|spec| spec.key)
        .collect();
    assert_eq!(listed, [Parameter::Bulging, Parameter::LocalBlend]);
}

//! The local/global blend: the global variant at 0, similarities followed at
//! every blend, and a pose that turns one end of a bar followed more closely
//! by the local variant there.

use super::tests::{box_cage, l_cage};
use super::tests_family::{bent, diagonal, inside_points};
use super::*;
use glam::DQuat;

#[test]
fn blend_zero_is_the_global_variant() {
    let (cage, points) = (l_cage(), inside_points());
    let blocks = somigliana_blocks(&points, &cage, 0.3).unwrap();
    let pose = bent(&cage);
    for bulging in [0.0, 2.5] {
        let global = deform(&blocks, &cage, &pose, bulging).unwrap();
        let blended = deform_blended(&blocks, &cage, &pose, bulging, 0.0).unwrap();
        for (a, b) in global.iter().zip(&blended) {
            assert!((*a - *b).length() / diagonal(&cage) < 1e-12, "{a} {b}");
        }
    }
}

#[test]
fn a_similarity_is_followed_at_every_blend() {
    let cage = l_cage();
    let points = inside_points();
    let blocks = somigliana_blocks(&points, &cage, 0.0).unwrap();
    let turn = DQuat::from_axis_angle(DVec3::new(0.3, -1.0, 0.6).normalize(), 1.1);
    let shift = DVec3::new(-2.0, 5.0, 1.0);
    let pose: Vec<DVec3> = (cage.positions().iter())
        .map(|&p| 1.3 * (turn * p) + shift)
        .collect();
    for blend in [0.25, 0.5, 1.0] {
        let posed = blended_pose(&cage, &pose, 0.0, 0.0, blend);
        let turned = glam::DMat3::from_quat(turn);
        for rotation in posed.vertex_rotations.iter().chain(&posed.face_rotations) {
            let gap = (*rotation - turned)
                .to_cols_array()
                .iter()
                .fold(0.0f64, |m, e| m.max(e.abs()));
            assert!(gap < 1e-12, "blend {blend}: {gap}");
        }
        let moved = deform_blended(&blocks, &cage, &pose, 0.0, blend).unwrap();
        for (&x, moved) in points.iter().zip(moved) {
            let want = 1.3 * (turn * x) + shift;
            assert!(
                (moved - want).length() / diagonal(&cage) < 1e-10,
                "blend {blend}: {moved} {want}"
            );
        }
    }
}

#[test]
fn the_blend_is_checked_and_moves_points_continuously() {
    let (cage, points) = (
        box_cage(),
        [DVec3::new(0.6, 0.1, 0.2), DVec3::new(-0.7, -0.2, 0.1)],
    );
    let blocks = somigliana_blocks(&points, &cage, 0.0).unwrap();
    // One end of the bar turned by 0.6 rad about the bar's axis.
    let twist = DQuat::from_axis_angle(DVec3::X, 0.6);
    let pose: Vec<DVec3> = (cage.positions().iter())
        .map(|&p| if p.x > 0.0 { twist * p } else { p })
        .collect();
    for refused in [-0.1, 1.5, f64::NAN] {
        assert!(
            deform_blended(&blocks, &cage, &pose, 0.0, refused).is_err(),
            "{refused}"
        );
    }
    let at = |blend: f64| deform_blended(&blocks, &cage, &pose, 0.0, blend).unwrap();
    let (near, far) = (at(0.5), at(0.5 + 1e-6));
    for (a, b) in near.iter().zip(&far) {
        assert!((*a - *b).length() < 1e-4, "{a} {b}");
    }
    // Every face and vertex rotation of the twisted pose differs from the
    // fitted one once blended, and not at 0.
    let posed = blended_pose(&cage, &pose, 0.0, 0.0, 1.0);
    let fitted = fit_similarity(&cage, &pose).unwrap().rotation;
    let spread = (posed.face_rotations.iter())
        .map(|r| {
            (*r - fitted)
                .to_cols_array()
                .iter()
                .fold(0.0f64, |m, e| m.max(e.abs()))
        })
        .fold(0.0f64, f64::max);
    assert!(spread > 0.1, "{spread}");
    let moved: Vec<f64> = [0.0, 0.5, 1.0].iter().map(|&b| at(b)[0].z).collect();
    println!("twisted end's probe z by blend 0, 0.5, 1: {moved:?}");
}

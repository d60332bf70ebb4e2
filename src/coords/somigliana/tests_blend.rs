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

/// The blend as a deformation setting: the normalised column moves, applied
/// to the family's weights as every consumer applies them, give the blended
/// deformation of the blocks; at blend 0 they are the global variant's linear
/// ones; far from the origin and about another origin they give the same.
#[test]
fn the_normalised_columns_give_the_blended_deformation() {
    use super::tests_family::{bind, options};
    use crate::coords::{Parameter, WeightsF64};
    let (cage, points) = (l_cage(), inside_points());
    let mut settings = options(0.3);
    settings.set(
        Parameter::Bulging,
        Parameter::Bulging.spec().parse("2.5").unwrap(),
    );
    let blend = Parameter::LocalBlend.spec().parse("0.6").unwrap();
    settings.set(Parameter::LocalBlend, blend);
    assert_eq!(settings.local_blend(), 0.6);
    assert!(settings.validate().is_ok());
    let weights = bind(&cage, &points, settings);
    let pose = bent(&cage);
    let blocks = somigliana_blocks(&points, &cage, 0.3).unwrap();
    let expected = deform_blended(&blocks, &cage, &pose, 2.5, 0.6).unwrap();
    let global = deform(&blocks, &cage, &pose, 2.5).unwrap();
    let moves = settings.column_moves(&cage, &pose);
    // A matrix per vertex column; the face columns carry none.
    assert!(!moves.is_linear() && moves.matrices().len() == BLOCK_COLUMNS * cage.vertex_count());
    let scale = diagonal(&cage);
    let largest = |a: &[DVec3], b: &[DVec3]| {
        (a.iter().zip(b))
            .map(|(p, q)| (*p - *q).length() / scale)
            .fold(0.0f64, f64::max)
    };
    // Through the f32 weights every consumer holds.
    let applied = weights.apply_moves(&points, &moves);
    assert!(
        largest(&applied, &expected) < 1e-5,
        "{applied:?} {expected:?}"
    );
    // Through the blocks in f64: the column form is exact.
    let exact = WeightsF64 {
        rows: points.len(),
        cols: column_count(&cage),
        values: (0..points.len())
            .flat_map(|p| {
                let mut row = vec![0.0; column_count(&cage)];
                let blocks_row = blocks.vertex_blocks(p).iter().chain(blocks.face_blocks(p));
                for (k, block) in blocks_row.enumerate() {
                    for a in 0..3 {
                        for b in 0..3 {
                            row[BLOCK_COLUMNS * k + 3 * a + b] = block.col(b)[a];
                        }
                    }
                }
                row
            })
            .collect(),
    };
    let exact_applied = exact.apply_moves(&points, &moves);
    assert!(largest(&exact_applied, &expected) < 1e-12);
    // The blend moves the points off the global variant.
    assert!(
        largest(&expected, &global) > 1e-3,
        "{}",
        largest(&expected, &global)
    );
    // About another origin: the same points.
    let about = exact.apply_moves(&points, &moves.about(DVec3::new(40.0, -7.0, 3.0)));
    assert!(largest(&about, &exact_applied) < 1e-12);
    // Blend 0 is the global variant's linear moves.
    settings.set(Parameter::LocalBlend, 0);
    let linear = settings.column_moves(&cage, &pose);
    assert!(linear.is_linear());
    assert!(largest(&weights.apply_moves(&points, &linear), &global) < 1e-5);
    // The same cage, points and pose 1e7 from the origin: the same deformation.
    let far = DVec3::new(1e7, -1e7, 1e7);
    let shifted = |list: &[DVec3]| list.iter().map(|&p| p + far).collect::<Vec<_>>();
    let far_cage = cage.with_positions(shifted(cage.positions()));
    settings.set(Parameter::LocalBlend, blend);
    let far_moves = settings.column_moves(&far_cage, &shifted(&pose));
    let far_weights = bind(&far_cage, &shifted(&points), settings);
    let far_applied = far_weights.apply_moves(&shifted(&points), &far_moves);
    let back: Vec<DVec3> = far_applied.iter().map(|&p| p - far).collect();
    assert!(
        largest(&back, &expected) < 1e-5,
        "{}",
        largest(&back, &expected)
    );
}

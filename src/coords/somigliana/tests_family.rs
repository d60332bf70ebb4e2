//! Somigliana coordinates as a family: the 9-column rows of a bind, their
//! deformation through the column vectors, the outside policy and ν's setting.

use super::tests::l_cage;
use super::*;
use crate::coords::{bind_cpu, BindOptions, BindProgress, Method, Parameter};
use glam::DQuat;

pub(super) fn inside_points() -> Vec<DVec3> {
    vec![
        DVec3::new(0.5, 0.5, 0.5),
        DVec3::new(1.7, 0.3, 0.2),
        DVec3::new(0.2, 1.8, 0.9),
        DVec3::new(0.9, 0.9, 0.05),
        DVec3::new(0.5, 1.0, 0.5),
    ]
}

/// The family's options with Poisson ratio `nu`, read by the setting's one check.
pub(super) fn options(nu: f64) -> BindOptions {
    let mut options = BindOptions::for_method(Method::Somigliana);
    let held = Parameter::PoissonRatio.spec().validate_decimal(nu).unwrap();
    options.set(Parameter::PoissonRatio, held);
    options
}

pub(super) fn bind(cage: &Cage, points: &[DVec3], options: BindOptions) -> crate::coords::Weights {
    let classes = options.classify(cage, points);
    bind_cpu(
        points,
        &classes.classes,
        cage,
        options,
        &BindProgress::new(points.len()),
    )
    .unwrap()
}

/// A pose that is no similarity: the L's arm bent and the whole turned,
/// scaled and moved.
pub(super) fn bent(cage: &Cage) -> Vec<DVec3> {
    let turn = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 0.5).normalize(), 0.7);
    cage.positions()
        .iter()
        .map(|&p| {
            let bend = DVec3::new(0.3 * p.y * p.y, 0.1 * p.x, 0.2 * p.x * p.y);
            1.3 * (turn * (p + bend)) + DVec3::new(3.0, -1.0, 2.0)
        })
        .collect()
}

pub(super) fn diagonal(cage: &Cage) -> f64 {
    let (lo, hi) = crate::geometry::bounds_of(cage.positions());
    (hi - lo).length()
}

#[test]
fn rows_are_the_blocks_row_major() {
    let (cage, points) = (l_cage(), inside_points());
    let weights = bind(&cage, &points, options(0.3));
    assert_eq!(
        weights.cols,
        9 * (cage.vertex_count() + cage.triangle_count())
    );
    assert_eq!(Method::Somigliana.columns(&cage), weights.cols);
    let blocks = somigliana_blocks(&points, &cage, 0.3).unwrap();
    let mut worst = 0.0f64;
    for (point, _) in points.iter().enumerate() {
        let row = weights.row(point);
        let all = blocks
            .vertex_blocks(point)
            .iter()
            .chain(blocks.face_blocks(point));
        for (k, block) in all.enumerate() {
            for (a, b) in (0..3).flat_map(|a| (0..3).map(move |b| (a, b))) {
                let stored = f64::from(row[9 * k + 3 * a + b]);
                worst = worst.max((stored - block.col(b)[a]).abs());
            }
        }
    }
    assert!(worst < 1e-6, "{worst}");
}

#[test]
fn the_column_vectors_give_the_global_deformation() {
    let (cage, points) = (l_cage(), inside_points());
    let weights = bind(&cage, &points, options(0.3));
    let pose = bent(&cage);
    let expected = deform(
        &somigliana_blocks(&points, &cage, 0.3).unwrap(),
        &cage,
        &pose,
        0.0,
    )
    .unwrap();
    let moves = Method::Somigliana.column_displacements(&cage, &pose);
    let displaced = weights.apply_displacements(&points, &moves);
    let posed: Vec<DVec3> = (Method::Somigliana.rest_columns(&cage).iter())
        .zip(&moves)
        .map(|(&rest, &moved)| rest + moved)
        .collect();
    let direct = weights.apply(&posed);
    let scale = diagonal(&cage);
    for ((want, displaced), direct) in expected.iter().zip(&displaced).zip(&direct) {
        assert!(
            (*want - *displaced).length() / scale < 1e-5,
            "{want} {displaced}"
        );
        assert!((*want - *direct).length() / scale < 1e-5, "{want} {direct}");
    }
    // At rest the columns reproduce the points, and nothing moves.
    let rest = weights.apply(&Method::Somigliana.rest_columns(&cage));
    for (x, reproduced) in points.iter().zip(rest) {
        assert!(
            (*x - reproduced).length() / scale < 1e-6,
            "{x} {reproduced}"
        );
    }
    let still = Method::Somigliana.column_displacements(&cage, cage.positions());
    assert!(still.iter().all(|d| d.length() < 1e-12));
}

#[test]
fn points_outside_follow_mvc_as_identity_blocks() {
    let cage = l_cage();
    let points = [DVec3::new(1.5, 1.5, 0.5), DVec3::new(4.0, -1.0, 2.0)];
    let weights = bind(&cage, &points, options(0.0));
    let mvc = bind(&cage, &points, BindOptions::for_method(Method::Mvc));
    let pose = bent(&cage);
    let ours = weights.apply_displacements(
        &points,
        &Method::Somigliana.column_displacements(&cage, &pose),
    );
    let theirs = mvc.apply_displacements(&points, &Method::Mvc.column_displacements(&cage, &pose));
    for (ours, theirs) in ours.iter().zip(&theirs) {
        assert!((*ours - *theirs).length() < 1e-5, "{ours} {theirs}");
    }
    assert!(weights.values.iter().all(|w| w.is_finite()));
}

#[test]
fn the_poisson_ratio_reads_as_a_signed_decimal_and_is_refused_out_of_range() {
    let spec = Parameter::PoissonRatio.spec();
    let held = |text: &str| spec.parse(text).map(|value| spec.number(value));
    assert_eq!(held("0.3"), Ok(0.3));
    assert_eq!(held(" 0 "), Ok(0.0));
    assert_eq!(held("-0.45"), Ok(-0.45));
    assert_eq!(spec.number(spec.default), 0.0);
    assert_eq!((spec.format)(spec.parse("0.45").unwrap()), "ν 0.45");
    assert_eq!((spec.format)(spec.parse("-0.2").unwrap()), "ν -0.2");
    assert_eq!(spec.text(spec.parse("-0.25").unwrap()), "-0.25");
    for (text, said) in [
        ("0.7", "0.7"),
        ("0.5", "0.5"),
        ("-1", "-1"),
        ("-3.5", "-3.5"),
    ] {
        assert_eq!(
            spec.parse(text).unwrap_err(),
            format!(
                "poisson_ratio {said} is out of range: the Poisson ratio must be -0.999 to 0.499"
            )
        );
    }
    assert!(spec.parse("abc").is_err());
    let mut too_soft = BindOptions::for_method(Method::Somigliana);
    too_soft.set(Parameter::PoissonRatio, spec.max + 1);
    assert!(too_soft.validate().is_err());
    assert_eq!(options(0.3).poisson_ratio(), 0.3);
    assert_eq!(options(-0.6).poisson_ratio(), -0.6);
    // Every value the setting holds passes the family's own check.
    for held in [spec.min, spec.max] {
        let mut extreme = BindOptions::for_method(Method::Somigliana);
        extreme.set(Parameter::PoissonRatio, held);
        assert!(validate_poisson_ratio(extreme.poisson_ratio()).is_ok());
    }
}

#[test]
fn options_differing_in_the_poisson_ratio_are_different_weights() {
    assert!(!options(0.3).same_weights_as(&options(0.25)));
    assert!(options(0.3).same_weights_as(&options(0.3)));
}

#[test]
fn quality_reads_the_blocks_partition_and_linear_precision() {
    let (cage, points) = (l_cage(), inside_points());
    let weights = bind(&cage, &points, options(0.3));
    let quality = crate::coords::WeightQuality::measure_family(
        &weights,
        &points,
        Method::Somigliana,
        &cage,
        &[],
    );
    assert!(quality.max_partition_error < 1e-5, "{quality:?}");
    assert!(quality.max_linear_precision_error < 1e-6, "{quality:?}");
}

#[test]
fn the_poisson_ratio_is_saved_as_a_decimal() {
    #[derive(serde::Serialize, serde::Deserialize)]
    struct File {
        #[serde(with = "crate::coords::parameter_values")]
        parameters: std::collections::BTreeMap<String, u32>,
    }
    let spec = Parameter::PoissonRatio.spec();
    for (nu, written) in [(0.3, "0.3"), (-0.25, "-0.25"), (0.0, "0.0")] {
        let held = spec.validate_decimal(nu).unwrap();
        let file = File {
            parameters: [("poisson_ratio".to_owned(), held)].into(),
        };
        let text = serde_json::to_string(&file).unwrap();
        assert_eq!(
            text,
            format!(r#"{{"parameters":{{"poisson_ratio":{written}}}}}"#)
        );
        let back: File = serde_json::from_str(&text).unwrap();
        assert_eq!(back.parameters["poisson_ratio"], held);
    }
    // ν 0 written as a whole number.
    let zero: File = serde_json::from_str(r#"{"parameters":{"poisson_ratio":0}}"#).unwrap();
    assert_eq!(spec.number(zero.parameters["poisson_ratio"]), 0.0);
    let refused = serde_json::from_str::<File>(r#"{"parameters":{"poisson_ratio":0.7}}"#);
    assert!(refused
        .err()
        .unwrap()
        .to_string()
        .contains("-0.999 to 0.499"));
}

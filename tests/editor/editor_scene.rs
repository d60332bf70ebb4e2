//! The default scene shows what PMVC is for: moving one cage prong drags the
//! neighbouring fingers under MVC but not under PMVC.

use glam::DVec3;
use pmvc::app::scenes::{comb_cage, comb_mesh};
use pmvc::coords::{bind_cpu, BindOptions, BindProgress, Method, WeightQuality, Weights};
use pmvc::geometry::classify_points;

/// Largest displacement of `points` when the middle prong's tip moves sideways.
fn neighbour_drag(method: Method) -> f64 {
    let mesh = comb_mesh();
    let cage = comb_cage();
    // Upper halves of the fingers next to the middle one.
    let points: Vec<DVec3> = mesh
        .positions
        .iter()
        .copied()
        .filter(|p| p.y > 3.0 && ((1.4..2.4).contains(&p.x) || (4.2..5.2).contains(&p.x)))
        .collect();
    assert!(points.len() > 100);
    let classes = classify_points(&cage, &points);
    let weights: Weights = bind_cpu(
        &points,
        &classes.classes,
        &cage,
        BindOptions {
            method,
            resolution: 16,
            ..Default::default()
        },
        &BindProgress::default(),
    )
    .unwrap();
    let tip = |p: &DVec3| p.y > 5.0 && p.x > 2.6 && p.x < 4.0;
    assert_eq!(cage.positions().iter().filter(|p| tip(p)).count(), 4);
    let pose: Vec<DVec3> = cage
        .positions()
        .iter()
        .map(|p| {
            if tip(p) {
                *p + DVec3::new(0.0, 0.0, 1.5)
            } else {
                *p
            }
        })
        .collect();
    weights
        .apply(&pose)
        .iter()
        .zip(&points)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max)
}

#[test]
fn mvc_drags_the_neighbouring_fingers_and_pmvc_does_not() {
    let mvc = neighbour_drag(Method::Mvc);
    let pmvc = neighbour_drag(Method::Pmvc);
    eprintln!("neighbour displacement: MVC {mvc:.4}, PMVC {pmvc:.4}");
    assert!(mvc > 0.05, "MVC moves the neighbours visibly ({mvc})");
    assert!(
        pmvc < 0.2 * mvc,
        "PMVC keeps them (nearly) still ({pmvc} vs {mvc})"
    );
}

/// The whole default scene at the editor's default resolution: MVC has clearly
/// negative weights, PMVC none.
#[test]
fn on_the_default_scene_mvc_is_negative_and_pmvc_is_not() {
    let mesh = comb_mesh();
    let cage = comb_cage();
    let classes = classify_points(&cage, &mesh.positions);
    let quality = |method| {
        let options = BindOptions {
            method,
            resolution: pmvc::coords::DEFAULT_RESOLUTION,
            ..Default::default()
        };
        let weights = bind_cpu(
            &mesh.positions,
            &classes.classes,
            &cage,
            options,
            &BindProgress::default(),
        )
        .expect("not cancelled");
        WeightQuality::measure(
            &weights,
            &mesh.positions,
            cage.positions(),
            &classes.outside,
        )
    };
    let mvc = quality(Method::Mvc);
    let pmvc = quality(Method::Pmvc);
    assert!(mvc.negative_share > 0.5, "{mvc:?}");
    assert!(mvc.most_negative < -0.05, "{mvc:?}");
    assert_eq!(pmvc.negative_vertices, 0, "{pmvc:?}");
    assert!(pmvc.most_negative >= 0.0);
    for quality in [mvc, pmvc] {
        assert!(quality.max_partition_error < 1e-5, "{quality:?}");
        assert!(quality.max_linear_precision_error < 1e-5, "{quality:?}");
    }
}

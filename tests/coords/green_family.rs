//! Green coordinates as one of the product's families: the bind every front end
//! uses (`coords::bind_cpu`), the displacement form the command line, the editor's
//! CPU read-outs and its vertex shader apply (`Method::column_displacements`), and
//! the quality table's measures over φ and the rest vectors of all columns.

use glam::{DMat3, DVec3};
use pmvc::coords::green::{bind_green, face_vectors};
use pmvc::coords::{bind_cpu, BindOptions, BindProgress, Method, WeightQuality};
use pmvc::geometry::procedural::{self, SplitMix64};
use pmvc::geometry::{classify_points, Cage};

fn comb() -> Cage {
    procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5)
}

/// Points inside the comb, and a few outside it and on its surface.
fn points_of(cage: &Cage) -> Vec<DVec3> {
    let mut points = procedural::points_inside(cage, 150, 3, 1e-3);
    let (lo, hi) = pmvc::geometry::bounds_of(cage.positions());
    points.extend([
        hi + DVec3::splat(0.3),
        lo - DVec3::X,
        (lo + hi) * 0.5 + DVec3::Z * 2.0,
    ]);
    points.push(cage.positions()[0]);
    points.push((cage.positions()[1] + cage.positions()[2]) * 0.5);
    points
}

fn bind(cage: &Cage, points: &[DVec3]) -> pmvc::coords::Weights {
    let classes = classify_points(cage, points);
    bind_cpu(
        points,
        &classes.classes,
        cage,
        BindOptions::for_method(Method::Green),
        &BindProgress::default(),
    )
    .expect("bound")
}

#[test]
fn a_green_bind_holds_phi_then_psi_as_the_library_computes_them() {
    let cage = comb();
    let points = points_of(&cage);
    let weights = bind(&cage, &points);
    let (vertices, triangles) = (cage.vertex_count(), cage.triangle_count());
    assert_eq!(Method::Green.columns(&cage), vertices + triangles);
    assert_eq!(
        (weights.rows, weights.cols),
        (points.len(), vertices + triangles)
    );
    let library = bind_green(&points, &cage, &BindProgress::default()).expect("bound");
    for row in 0..points.len() {
        assert_eq!(
            &weights.row(row)[..vertices],
            library.phi.row(row),
            "φ of row {row}"
        );
        assert_eq!(
            &weights.row(row)[vertices..],
            library.psi.row(row),
            "ψ of row {row}"
        );
    }
}

/// A rotation by `angle` about `axis`, a uniform scale and a translation.
fn similarity(angle: f64, axis: DVec3, scale: f64, shift: DVec3) -> impl Fn(DVec3) -> DVec3 {
    let rotation = DMat3::from_axis_angle(axis.normalize(), angle);
    move |x| scale * (rotation * x) + shift
}

#[test]
fn the_displacement_form_follows_similarities_of_the_cage_and_not_other_moves() {
    let cage = comb();
    let points = points_of(&cage);
    let weights = bind(&cage, &points);
    let diagonal = cage.diagonal();
    let mut random = SplitMix64(11);
    for _ in 0..4 {
        let axis = DVec3::new(random.unit(), random.unit(), random.unit()) - 0.5;
        let moved = similarity(
            random.unit() * 6.0,
            axis,
            0.4 + 2.0 * random.unit(),
            DVec3::new(random.unit(), random.unit(), random.unit()) * 5.0,
        );
        let pose: Vec<DVec3> = cage.positions().iter().map(|&p| moved(p)).collect();
        let moves = Method::Green.column_displacements(&cage, &pose);
        let deformed = weights.apply_displacements(&points, &moves);
        let worst = points
            .iter()
            .zip(&deformed)
            .map(|(&x, &y)| (moved(x) - y).length())
            .fold(0.0, f64::max);
        assert!(
            worst <= 1e-5 * diagonal,
            "worst {worst:e} of diagonal {diagonal}"
        );
    }
    // Stretching one axis is not a similarity: Green moves inside points off the
    // affine image (their details keep shape), which the face terms cause.
    let stretch = |p: DVec3| DVec3::new(p.x * 2.0, p.y, p.z);
    let pose: Vec<DVec3> = cage.positions().iter().map(|&p| stretch(p)).collect();
    let moves = Method::Green.column_displacements(&cage, &pose);
    let deformed = weights.apply_displacements(&points, &moves);
    let off = points
        .iter()
        .zip(&deformed)
        .map(|(&x, &y)| (stretch(x) - y).length())
        .fold(0.0, f64::max);
    assert!(
        off > 1e-3 * diagonal,
        "a stretch moved points affinely: {off:e}"
    );
}

#[test]
fn the_face_columns_move_by_the_stretched_deformed_normal_less_the_rest_normal() {
    let cage = comb();
    let pose: Vec<DVec3> = cage
        .positions()
        .iter()
        .map(|&p| p + DVec3::new(0.1 * p.y, 0.0, 0.05 * p.x * p.x))
        .collect();
    let moves = Method::Green.column_displacements(&cage, &pose);
    let vertices = cage.vertex_count();
    let posed = face_vectors(&cage, &pose).expect("posed");
    let rest = face_vectors(&cage, cage.positions()).expect("rest");
    for (t, ((moved, posed), rest)) in moves[vertices..].iter().zip(&posed).zip(&rest).enumerate() {
        assert!((*moved - (*posed - *rest)).length() < 1e-12, "triangle {t}");
    }
    for (i, moved) in moves[..vertices].iter().enumerate() {
        assert_eq!(*moved, pose[i] - cage.positions()[i]);
    }
}

#[test]
fn quality_measures_partition_over_phi_and_precision_over_every_column() {
    let cage = comb();
    let points = points_of(&cage);
    let weights = bind(&cage, &points);
    let classes = classify_points(&cage, &points);
    let columns = Method::Green.rest_columns(&cage);
    let vertices = Method::Green.vertex_columns(&cage);
    let quality =
        WeightQuality::measure_columns(&weights, &points, &columns, vertices, &classes.outside);
    assert!(quality.max_partition_error < 1e-5, "{quality:?}");
    assert!(quality.max_linear_precision_error < 1e-5, "{quality:?}");
    assert_eq!(quality.outside_vertices, classes.outside.len());
    assert!(quality.outside_vertices >= 3);
    // φ goes negative inside a comb: Green coordinates are not positive, and the
    // table says so rather than hiding it.
    assert!(quality.negative_vertices > 0, "{quality:?}");
    assert!(!Method::Green.spec().positive_inside);
    // Leaving the face columns out of the reproduction breaks it: they carry part
    // of every point's position.
    let vertex_only = WeightQuality::measure_columns(
        &weights,
        &points,
        &[
            &columns[..vertices],
            &vec![DVec3::ZERO; columns.len() - vertices][..],
        ]
        .concat(),
        vertices,
        &classes.outside,
    );
    assert!(
        vertex_only.max_linear_precision_error > 1e-3,
        "{vertex_only:?}"
    );
}

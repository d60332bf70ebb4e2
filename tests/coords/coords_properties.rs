//! Properties of the coordinates on a convex cage and on non-convex cages (a comb
//! of close prongs, an extruded star): positivity, partition of unity, linear
//! precision, interpolation at the surface, and agreement of PMVC with MVC where
//! every point sees the whole cage.

use glam::DVec3;
use pmvc::coords::{
    bind_cpu, cubemap::TexelTable, mvc, pmvc as pmvc_ref, BindOptions, BindProgress, Method,
    Weights,
};
use pmvc::geometry::{classify_points, procedural, Cage, PointClass};

fn comb() -> Cage {
    procedural::extrude(&procedural::comb_outline(5, 1.0, 0.25, 4.0), -0.5, 0.5)
}

fn star() -> Cage {
    procedural::extrude(&procedural::star_outline(6, 0.4, 1.0), -0.3, 0.3)
}

fn convex() -> Cage {
    procedural::icosphere(1.0, 1)
}

fn bind(cage: &Cage, points: &[DVec3], method: Method, resolution: u32) -> Weights {
    let classes = classify_points(cage, points);
    assert!(classes.outside.is_empty(), "test points must be inside");
    bind_cpu(
        points,
        &classes.classes,
        cage,
        BindOptions {
            method,
            resolution,
            ..Default::default()
        },
        &BindProgress::default(),
    )
    .unwrap()
}

fn pmvc_f64(cage: &Cage, x: DVec3, resolution: u32) -> Vec<f64> {
    let mut out = vec![0.0; cage.vertex_count()];
    let enclosed = pmvc_ref::pmvc_weights(
        x,
        cage,
        &TexelTable::new(resolution),
        &mut out,
        &mut Default::default(),
    );
    assert!(enclosed);
    out
}

fn mvc_f64(cage: &Cage, x: DVec3) -> Vec<f64> {
    let mut out = vec![0.0; cage.vertex_count()];
    mvc::mvc_weights(x, cage, &mut out, &mut Default::default());
    out
}

/// Partition of unity and linear precision of every row; returns the worst errors.
fn check_affine(cage: &Cage, points: &[DVec3], weights: &Weights) -> (f64, f64) {
    let reproduced = weights.apply(cage.positions());
    let mut worst_sum = 0.0f64;
    let mut worst_position = 0.0f64;
    for (i, x) in points.iter().enumerate() {
        let sum: f64 = weights.row(i).iter().map(|&w| f64::from(w)).sum();
        worst_sum = worst_sum.max((sum - 1.0).abs());
        worst_position = worst_position.max(reproduced[i].distance(*x));
    }
    (worst_sum, worst_position / cage.diagonal())
}

#[test]
fn pmvc_is_nonnegative_affine_and_linearly_precise_on_all_test_cages() {
    for (name, cage) in [("convex", convex()), ("comb", comb()), ("star", star())] {
        let points = procedural::points_inside(&cage, 300, 7, 1e-3);
        let weights = bind(&cage, &points, Method::Pmvc, 32);
        let min = weights.min();
        let (sum_error, position_error) = check_affine(&cage, &points, &weights);
        println!(
            "{name}: PMVC min {min:e}, |Σλ−1| {sum_error:e}, linear precision {position_error:e}"
        );
        assert!(min >= 0.0, "{name}: negative PMVC weight {min}");
        assert!(
            sum_error <= 1e-6,
            "{name}: partition of unity off by {sum_error}"
        );
        assert!(
            position_error <= 1e-6,
            "{name}: linear precision off by {position_error} of the diagonal"
        );
    }
}

#[test]
fn mvc_is_affine_and_linearly_precise_on_all_test_cages() {
    for (name, cage) in [("convex", convex()), ("comb", comb()), ("star", star())] {
        let points = procedural::points_inside(&cage, 300, 11, 1e-3);
        let weights = bind(&cage, &points, Method::Mvc, 32);
        let (sum_error, position_error) = check_affine(&cage, &points, &weights);
        println!("{name}: MVC |Σλ−1| {sum_error:e}, linear precision {position_error:e}");
        assert!(
            sum_error <= 1e-6,
            "{name}: partition of unity off by {sum_error}"
        );
        assert!(
            position_error <= 1e-6,
            "{name}: linear precision off by {position_error}"
        );
    }
}

#[test]
fn mvc_goes_clearly_negative_in_the_comb_and_pmvc_does_not() {
    let cage = comb();
    // Points along the middle of the second prong, where the neighbouring prongs pull.
    let points: Vec<DVec3> = (1..20)
        .map(|k| DVec3::new(1.25 + 0.5, 1.0 + 0.2 * f64::from(k), 0.0))
        .collect();
    let mvc = bind(&cage, &points, Method::Mvc, 32);
    let pmvc = bind(&cage, &points, Method::Pmvc, 32);
    println!("comb: MVC min {}, PMVC min {}", mvc.min(), pmvc.min());
    assert!(
        mvc.min() < -0.01,
        "MVC should be clearly negative in the comb, min {}",
        mvc.min()
    );
    assert!(pmvc.min() >= 0.0);
}

#[test]
fn pmvc_matches_mvc_inside_a_convex_cage_and_converges_with_resolution() {
    let cage = convex();
    let points = procedural::points_inside(&cage, 40, 3, 0.05);
    let mut errors = Vec::new();
    for resolution in [16, 32, 64] {
        let mut worst = 0.0f64;
        for &x in &points {
            let (p, m) = (pmvc_f64(&cage, x, resolution), mvc_f64(&cage, x));
            worst = p
                .iter()
                .zip(&m)
                .map(|(a, b)| (a - b).abs())
                .fold(worst, f64::max);
        }
        println!("R={resolution}: max |PMVC − MVC| = {worst:e}");
        errors.push(worst);
    }
    assert!(errors[1] <= 5e-4, "R=32 error {} exceeds 5e-4", errors[1]);
    assert!(
        errors[1] < errors[0] && errors[2] < errors[1],
        "error must shrink as R grows: {errors:?}"
    );
}

#[test]
fn both_methods_interpolate_as_a_point_approaches_a_face() {
    for (name, cage) in [("convex", convex()), ("comb", comb())] {
        let t = 3;
        let [a, b, c] = cage.triangle(t);
        let target = DVec3::new(0.2, 0.3, 0.5);
        let foot = target.x * a + target.y * b + target.z * c;
        let inward = -(b - a).cross(c - a).normalize();
        let mut previous = f64::INFINITY;
        for exponent in 1..=6 {
            let distance = 10f64.powi(-exponent) * cage.diagonal();
            let x = foot + distance * inward;
            for (method, weights) in [("PMVC", pmvc_f64(&cage, x, 32)), ("MVC", mvc_f64(&cage, x))]
            {
                let corners = cage.triangles()[t];
                let error: f64 = (0..cage.vertex_count())
                    .map(|j| {
                        let expected = corners
                            .iter()
                            .zip([target.x, target.y, target.z])
                            .filter(|(&v, _)| v as usize == j)
                            .map(|(_, b)| b)
                            .sum::<f64>();
                        (weights[j] - expected).abs()
                    })
                    .fold(0.0, f64::max);
                if method == "PMVC" {
                    assert!(
                        error <= previous * 1.01 + 1e-12,
                        "{name}: PMVC error grew from {previous} to {error} at {distance}"
                    );
                    previous = error;
                }
                if exponent == 6 {
                    println!("{name} {method}: error at 1e-6 of the diagonal: {error:e}");
                    assert!(
                        error < 1e-3,
                        "{name} {method}: {error} from the barycentrics at distance {distance}"
                    );
                }
            }
        }
    }
}

#[test]
fn points_on_the_surface_get_barycentrics_and_never_nan() {
    let cage = comb();
    let [a, b, c] = cage.triangle(5);
    let on_face = 0.25 * a + 0.25 * b + 0.5 * c;
    let on_edge = 0.5 * a + 0.5 * b;
    let points = vec![
        on_face,
        on_edge,
        a,
        on_face + 1e-13 * DVec3::X,
        on_face - 1e-7 * DVec3::Y,
    ];
    let classes = classify_points(&cage, &points);
    assert!(matches!(classes.classes[0], PointClass::OnSurface { .. }));
    assert!(matches!(classes.classes[1], PointClass::OnSurface { .. }));
    for method in [Method::Mvc, Method::Pmvc] {
        let weights = bind_cpu(
            &points,
            &classes.classes,
            &cage,
            BindOptions {
                method,
                resolution: 32,
                ..Default::default()
            },
            &BindProgress::default(),
        )
        .unwrap();
        assert!(
            weights.values.iter().all(|w| w.is_finite()),
            "{method:?}: non-finite weight"
        );
        let reproduced = weights.apply(cage.positions());
        for (x, p) in points.iter().zip(&reproduced) {
            assert!(
                x.distance(*p) <= 1e-6 * cage.diagonal(),
                "{method:?}: {x} reproduced as {p}"
            );
        }
        let corners = cage.triangles()[5];
        assert!((f64::from(weights.row(0)[corners[2] as usize]) - 0.5).abs() < 1e-6);
    }
}

/// The inside-only evaluation skips triangles that x sees from their outer side; it
/// must agree with the full one up to rounding, also for points just off the surface
/// (at 1e-8 of the diagonal, where the sign of the determinant matters most).
#[test]
fn skipping_triangles_facing_away_from_inside_points_changes_nothing() {
    let table = TexelTable::new(16);
    for (name, cage) in [("convex", convex()), ("comb", comb()), ("star", star())] {
        let mut points = procedural::points_inside(&cage, 200, 11, 1e-3);
        for t in 0..cage.triangles().len() {
            let [a, b, c] = cage.triangle(t);
            let inward = -(b - a).cross(c - a).normalize();
            points.push((a + b + c) / 3.0 + 1e-8 * cage.diagonal() * inward);
        }
        let classes = classify_points(&cage, &points);
        let mut worst = 0.0f64;
        for (x, class) in points.iter().zip(&classes.classes) {
            if *class != PointClass::Inside {
                continue;
            }
            let mut full = vec![0.0; cage.vertex_count()];
            let mut culled = vec![0.0; cage.vertex_count()];
            let enclosed =
                pmvc_ref::pmvc_weights(*x, &cage, &table, &mut full, &mut Default::default());
            let enclosed_culled = pmvc_ref::pmvc_weights_inside(
                *x,
                &cage,
                &table,
                &mut culled,
                &mut Default::default(),
            );
            assert_eq!(enclosed, enclosed_culled, "{name}: at {x}");
            for (f, c) in full.iter().zip(&culled) {
                worst = worst.max((f - c).abs());
            }
        }
        println!("{name}: largest difference {worst:e}");
        assert!(
            worst <= 1e-12,
            "{name}: culling changed a weight by {worst}"
        );
    }
}

/// The library checks a parameter as the command line and sessions do: a
/// resolution past its family's range is refused before anything is allocated.
#[test]
fn the_library_refuses_a_parameter_outside_its_range() {
    let cage = convex();
    let points = [DVec3::ZERO];
    let classes = classify_points(&cage, &points);
    for (method, resolution, grid) in [(Method::Pmvc, 100_000, 64), (Method::Harmonic, 32, 0)] {
        let options = BindOptions {
            resolution,
            grid,
            ..BindOptions::for_method(method)
        };
        let error = bind_cpu(
            &points,
            &classes.classes,
            &cage,
            options,
            &BindProgress::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(error.contains("out of range"), "{method:?}: {error}");
    }
}

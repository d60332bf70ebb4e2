//! What the tests of a family solved point by point (MEC, MLC) share: its row
//! through the entry every bind uses, the promises checked the same way for
//! each (positivity, partition of unity, linear precision, invariance, the
//! comb where MVC go negative), and a BFGS minimiser for the references.

use glam::{DMat3, DQuat, DVec3};
use pmvc::coords::{
    bind_cpu, weights_at, BindOptions, BindProgress, Method, PmvcIntegration, RowScratch, Weights,
};
use pmvc::geometry::procedural_quads::cage_from_polygons;
use pmvc::geometry::{classify_points, procedural, Cage, PointClass};

/// `method`'s weights at an inside point, through the one-row entry every
/// bind uses, in f64.
pub fn row(method: Method, cage: &Cage, x: DVec3) -> Vec<f64> {
    let mut out = vec![f64::NAN; cage.vertex_count()];
    weights_at(
        x,
        PointClass::Inside,
        cage,
        method,
        &PmvcIntegration::of(BindOptions::for_method(method)),
        &mut out,
        &mut RowScratch::default(),
    );
    out
}

/// `|Σ wᵢ (vᵢ − x)|` in cage diagonals, measured here from the weights.
pub fn linear_precision(cage: &Cage, x: DVec3, w: &[f64]) -> f64 {
    let moved: DVec3 = w
        .iter()
        .zip(cage.positions())
        .map(|(w, &v)| *w * (v - x))
        .sum();
    moved.length() / cage.diagonal()
}

pub fn worst_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max)
}

fn smallest(w: &[f64]) -> f64 {
    w.iter().copied().fold(f64::INFINITY, f64::min)
}

/// `cage` with every vertex mapped, its faces triangulated again (a quad's
/// diagonal is chosen from its positions).
pub fn cage_mapped(cage: &Cage, map: &dyn Fn(DVec3) -> DVec3) -> Cage {
    let positions: Vec<DVec3> = cage.positions().iter().map(|&p| map(p)).collect();
    let (mapped, _) =
        cage_from_polygons(&positions, &cage.polygons()).expect("a moved cage is valid");
    assert_eq!(mapped.quads().len(), cage.quads().len());
    mapped
}

/// At 300 points inside each cage: every weight positive, `|Σw − 1| ≤ 1e-12`
/// and the point reproduced to 1e-10 of the diagonal.
pub fn check_positive_sums_to_one_and_reproduces_the_point(
    method: Method,
    cages: Vec<(&'static str, Cage)>,
) {
    for (name, cage) in cages {
        let points = procedural::points_inside(&cage, 300, 9, 1e-4);
        let (mut sum_error, mut position_error, mut min) = (0.0f64, 0.0f64, f64::INFINITY);
        for &x in &points {
            let w = row(method, &cage, x);
            sum_error = sum_error.max((w.iter().sum::<f64>() - 1.0).abs());
            position_error = position_error.max(linear_precision(&cage, x, &w));
            min = min.min(smallest(&w));
        }
        println!(
            "{name}: |Σw − 1| {sum_error:e}, linear precision {position_error:e}, min {min:e}"
        );
        assert!(
            sum_error <= 1e-12,
            "{name}: partition of unity off by {sum_error}"
        );
        assert!(
            position_error <= 1e-10,
            "{name}: linear precision {position_error}"
        );
        assert!(min > 0.0, "{name}: weight {min}");
    }
}

/// A map of the scene, its name, and how far the weights may move under it.
type SceneMap = (&'static str, Box<dyn Fn(DVec3) -> DVec3>, f64);

/// The same weights after a rotation, a scaling by 1000 and a translation to
/// 1e7 from the origin, still positive and reproducing the point to 1e-10.
pub fn check_invariance_under_rotation_scaling_and_a_far_translation(
    method: Method,
    cages: Vec<(&'static str, Cage)>,
) {
    let turn = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 0.9);
    let maps: [SceneMap; 3] = [
        ("rotated", Box::new(move |p| turn * p), 1e-9),
        ("scaled by 1000", Box::new(|p| 1000.0 * p), 1e-9),
        // Positions at 1e7 are rounded to 2e-9: the geometry itself moves that much.
        ("moved to 1e7", Box::new(|p| p + DVec3::splat(1e7)), 1e-7),
    ];
    for (name, cage) in cages {
        let points = procedural::points_inside(&cage, 30, 13, 1e-2);
        for (map_name, map, tolerance) in &maps {
            let moved = cage_mapped(&cage, map);
            let (mut worst, mut precision, mut min) = (0.0f64, 0.0f64, f64::INFINITY);
            for &x in &points {
                let (w, y) = (row(method, &cage, x), map(x));
                let v = row(method, &moved, y);
                worst = worst.max(worst_difference(&w, &v));
                precision = precision.max(linear_precision(&moved, y, &v));
                min = min.min(smallest(&v));
            }
            println!(
                "{name} {map_name}: weights differ by {worst:e}, linear precision {precision:e}"
            );
            assert!(worst <= *tolerance, "{name} {map_name}: {worst}");
            assert!(
                precision <= 1e-10,
                "{name} {map_name}: linear precision {precision}"
            );
            assert!(min > 0.0, "{name} {map_name}: weight {min}");
        }
    }
}

/// `points` classified and bound to `cage` by `method` at its defaults, as
/// every front end binds them (f32 weights).
pub fn bind(cage: &Cage, points: &[DVec3], method: Method) -> Weights {
    let classes = classify_points(cage, points);
    bind_cpu(
        points,
        &classes.classes,
        cage,
        BindOptions::for_method(method),
        &BindProgress::default(),
    )
    .unwrap()
}

/// Where MVC go negative in the comb, `method` stays positive, through the
/// f32 bind.
pub fn check_positive_where_mvc_go_negative(method: Method) {
    let cage = procedural::extrude(&procedural::comb_outline(5, 1.0, 0.25, 4.0), -0.5, 0.5);
    let points: Vec<DVec3> = (1..20)
        .map(|k| DVec3::new(1.75, 1.0 + 0.2 * f64::from(k), 0.0))
        .collect();
    let (mvc, tested) = (
        bind(&cage, &points, Method::Mvc),
        bind(&cage, &points, method),
    );
    println!(
        "comb: MVC min {}, {method:?} min {}",
        mvc.min(),
        tested.min()
    );
    assert!(mvc.min() < -0.01);
    assert!(tested.min() >= 0.0);
}

/// BFGS from `start` with a backtracking line search (which `f` keeps in its
/// domain by answering infinity outside it) until the gradient is at most
/// `tolerance`; the minimiser. `scale` is the first inverse Hessian's size.
pub fn minimise_by_bfgs(
    f: impl Fn(DVec3) -> (f64, DVec3),
    start: DVec3,
    scale: f64,
    tolerance: f64,
) -> DVec3 {
    let mut at = start;
    let (mut value, mut gradient) = f(at);
    let mut inverse = DMat3::IDENTITY * scale;
    for _ in 0..5000 {
        if gradient.length() <= tolerance {
            return at;
        }
        let direction = -(inverse * gradient);
        let mut t = 1.0;
        let (next, next_value, next_gradient) = loop {
            let trial = at + t * direction;
            let (tf, tg) = f(trial);
            // Past the rounding of the value, a smaller gradient decides.
            if tf <= value + 1e-4 * t * gradient.dot(direction)
                || (tf <= value + 1e-14 * value.abs().max(1.0) && tg.length() < gradient.length())
            {
                break (trial, tf, tg);
            }
            t *= 0.5;
            assert!(t > 1e-30, "reference line search failed from {start}");
        };
        let s = next - at;
        let y = next_gradient - gradient;
        let sy = s.dot(y);
        if sy > 0.0 {
            let rho = 1.0 / sy;
            let left = DMat3::IDENTITY - rho * outer(s, y);
            inverse = left * inverse * left.transpose() + rho * outer(s, s);
        }
        (at, value, gradient) = (next, next_value, next_gradient);
    }
    panic!(
        "reference BFGS did not converge: gradient {}",
        gradient.length()
    );
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

//! Local barycentric coordinates: their promises (non-negative, a partition
//! of unity, linear precision at the grid's nodes and away from the cage,
//! interpolation at convex corners) on convex and non-convex cages of
//! triangles and quads, far from the origin, convergence under grid
//! refinement, locality against harmonic coordinates, refused grids. The
//! independent reference is in `lbc_reference.rs`.

use glam::DVec3;
use pmvc::coords::harmonic::HarmonicError;
use pmvc::coords::lbc::{bind_lbc, node_weights, plan, LbcSettings, NodeWeights};
use pmvc::coords::{bind_cpu, BindOptions, BindProgress, Method, Weights};
use pmvc::geometry::procedural_quads::quad_comb;
use pmvc::geometry::{classify_points, procedural, Cage};

fn comb() -> Cage {
    procedural::extrude(&procedural::comb_outline(5, 1.0, 0.25, 4.0), -0.5, 0.5)
}

fn nodes(cage: &Cage, grid: u32) -> NodeWeights {
    let (nodes, stats) =
        node_weights(cage, grid, &LbcSettings::default(), &BindProgress::new(0)).unwrap();
    println!("grid {grid}: {stats:?}");
    assert!(stats.converged, "{stats:?}");
    nodes
}

fn bind(cage: &Cage, points: &[DVec3], grid: u32) -> Weights {
    let classes = classify_points(cage, points);
    let (weights, stats) = bind_lbc(
        points,
        &classes.classes,
        cage,
        grid,
        &BindProgress::new(points.len()),
    )
    .unwrap();
    println!("grid {grid}: {stats:?}");
    assert!(stats.converged, "{stats:?}");
    weights
}

/// Worst |Σw − 1| and |Σ w v − x| (over the diagonal), and the smallest weight,
/// of rows of `columns` weights at `positions`.
fn barycentric_errors(cage: &Cage, positions: &[DVec3], values: &[f64]) -> (f64, f64, f64) {
    let columns = cage.vertex_count();
    let mut worst = (0.0f64, 0.0f64, f64::INFINITY);
    for (row, &x) in values.chunks(columns).zip(positions) {
        let sum: f64 = row.iter().sum();
        let reproduced: DVec3 = row.iter().zip(cage.positions()).map(|(&w, &v)| w * v).sum();
        worst.0 = worst.0.max((sum - 1.0).abs());
        worst.1 = worst.1.max(reproduced.distance(x) / cage.diagonal());
        worst.2 = row.iter().copied().fold(worst.2, f64::min);
    }
    worst
}

fn as_f64(weights: &Weights) -> Vec<f64> {
    weights.values.iter().map(|&w| f64::from(w)).collect()
}

#[test]
fn non_negative_and_barycentric_at_every_node_and_point() {
    let cages = [
        ("cube", procedural::cube_cage(1.0)),
        ("comb", comb()),
        ("quad comb", quad_comb(4, 1.0, 0.3, 3.0, 1.0, 0.4)),
    ];
    for (name, cage) in cages {
        let grid = 12;
        let at_nodes = nodes(&cage, grid);
        let (sum, linear, smallest) =
            barycentric_errors(&cage, &at_nodes.positions, &at_nodes.values);
        println!("{name} nodes: |Σw − 1| {sum:e}, |Σwv − x| {linear:e} of the diagonal, smallest {smallest:e}");
        assert!(smallest >= 0.0, "{name}: {smallest}");
        assert!(sum <= 1e-12 && linear <= 1e-12, "{name}: {sum} {linear}");
        // Points anywhere inside: sampled from nodes, and near the cage from
        // the boundary data of outside corners.
        let points = procedural::points_inside(&cage, 300, 3, 1e-3);
        let weights = bind(&cage, &points, grid);
        let (sum, _, smallest) = barycentric_errors(&cage, &points, &as_f64(&weights));
        println!("{name} points: |Σw − 1| {sum:e}, smallest {smallest:e}");
        assert!(smallest >= 0.0 && sum <= 1e-6, "{name}: {smallest} {sum}");
    }
}

#[test]
fn linear_precision_holds_wherever_the_sampled_cell_is_inside() {
    // A point √3 cells from the cage samples eight nodes, and trilinear
    // interpolation of barycentric nodes is barycentric; nearer the cage an
    // outside corner takes the boundary data of its closest cage point, which
    // reproduces that point, not the corner.
    let cage = procedural::cube_cage(1.0);
    let grid = 12;
    let cell = cage.diagonal() / 3f64.sqrt() / f64::from(grid);
    let deep =
        procedural::points_inside(&cage, 200, 5, 1.01 * 3f64.sqrt() * cell / cage.diagonal());
    let near = procedural::points_inside(&cage, 200, 6, 1e-3);
    let deep_weights = bind(&cage, &deep, grid);
    let near_weights = bind(&cage, &near, grid);
    let (_, deep_error, _) = barycentric_errors(&cage, &deep, &as_f64(&deep_weights));
    let (_, near_error, _) = barycentric_errors(&cage, &near, &as_f64(&near_weights));
    println!("cube grid {grid}: |Σwv − x| {deep_error:e} of the diagonal a cell deep, {near_error:e} anywhere");
    assert!(deep_error <= 1e-6, "{deep_error}");
    assert!(near_error <= 0.5 * cell / cage.diagonal(), "{near_error}");
}

#[test]
fn a_convex_corner_has_weight_one_at_itself_and_close_to_it() {
    // Not by the boundary data alone (total variation lets a weight jump at
    // the cage): the constraints force it at the nodes, since a convex corner
    // is a vertex of the cage's hull (at 0.98 v the weight of v is at least
    // 0.97); the sampling near the cage adds its error (one percent here).
    let cage = procedural::cube_cage(1.0);
    let n = cage.vertex_count();
    let mut points: Vec<DVec3> = cage.positions().to_vec();
    points.extend(cage.positions().iter().map(|&v| v * 0.98));
    let weights = bind(&cage, &points, 12);
    let mut smallest = f32::INFINITY;
    for k in 0..n {
        assert_eq!(weights.row(k)[k], 1.0, "vertex {k} on itself");
        let near = weights.row(n + k)[k];
        smallest = smallest.min(near);
        assert!(near >= 0.9, "vertex {k}: {near} at 1 % of the diagonal");
    }
    println!("cube: smallest weight of a corner at 0.98 of itself {smallest}");
}

fn largest_difference(a: &Weights, b: &Weights) -> f64 {
    a.values
        .iter()
        .zip(&b.values)
        .map(|(&a, &b)| f64::from((a - b).abs()))
        .fold(0.0, f64::max)
}

#[test]
fn refining_the_grid_converges() {
    let cage = comb();
    let points = procedural::points_inside(&cage, 200, 7, 0.05);
    let mut energies = Vec::new();
    let mut weights = Vec::new();
    for grid in [8, 12, 16] {
        let (nodes, stats) =
            node_weights(&cage, grid, &LbcSettings::default(), &BindProgress::new(0)).unwrap();
        // The energy is in cells²: times h², ∫|∇w| in the cage's units.
        energies.push(stats.energy * nodes.cell * nodes.cell);
        weights.push(bind(&cage, &points, grid));
    }
    let (first, second) = (
        largest_difference(&weights[0], &weights[2]),
        largest_difference(&weights[1], &weights[2]),
    );
    println!("comb: total variation {energies:?}; |w8 − w16| {first:e}, |w12 − w16| {second:e}");
    assert!(second < first, "no convergence: {first} then {second}");
    let (a, b) = (energies[1] - energies[0], energies[2] - energies[1]);
    assert!(b.abs() < a.abs(), "energies {energies:?}");
}

#[test]
fn local_where_harmonic_coordinates_are_not() {
    let cage = comb();
    let points = procedural::points_inside(&cage, 300, 9, 0.02);
    let lbc = bind(&cage, &points, 16);
    let options = BindOptions {
        grid: 16,
        ..BindOptions::for_method(Method::Harmonic)
    };
    let classes = options.classify(&cage, &points);
    let harmonic = bind_cpu(
        &points,
        &classes.classes,
        &cage,
        options,
        &BindProgress::new(points.len()),
    )
    .unwrap();
    let mean_above = |weights: &Weights, threshold: f32| {
        weights.values.iter().filter(|&&w| w > threshold).count() as f64 / weights.rows as f64
    };
    for threshold in [1e-3, 1e-2] {
        let (local, spread) = (
            mean_above(&lbc, threshold),
            mean_above(&harmonic, threshold),
        );
        println!(
            "comb grid 16, {} cage vertices: weights above {threshold:e} per point, LBC {local:.1}, HC {spread:.1}",
            cage.vertex_count()
        );
        assert!(local < 0.9 * spread, "LBC {local}, HC {spread}");
    }
}

#[test]
fn far_from_the_origin_the_weights_are_the_same() {
    let cage = comb();
    let points = procedural::points_inside(&cage, 200, 11, 1e-3);
    let offset = DVec3::splat(1e7);
    let moved = cage.with_positions(cage.positions().iter().map(|&p| p + offset).collect());
    let moved_points: Vec<DVec3> = points.iter().map(|&p| p + offset).collect();
    let difference =
        largest_difference(&bind(&cage, &points, 12), &bind(&moved, &moved_points, 12));
    println!("1e7 from the origin: largest difference {difference:e}");
    assert!(difference <= 1e-4, "{difference}");
}

#[test]
fn the_family_binds_through_bind_cpu() {
    let cage = procedural::cube_cage(1.0);
    let points = procedural::points_inside(&cage, 50, 17, 0.05);
    assert_eq!(BindOptions::for_method(Method::Lbc).grid, 32);
    let options = BindOptions {
        grid: 10,
        ..BindOptions::for_method(Method::Lbc)
    };
    let classes = options.classify(&cage, &points);
    let weights = bind_cpu(
        &points,
        &classes.classes,
        &cage,
        options,
        &BindProgress::new(50),
    )
    .unwrap();
    assert_eq!(weights, bind(&cage, &points, 10));
}

#[test]
fn plans_predict_memory_and_refuse_what_does_not_fit() {
    let cage = comb();
    let small = plan(&cage, 16, 1000).unwrap();
    let larger = plan(&cage, 32, 1000).unwrap();
    println!("{small:?}\n{larger:?}");
    assert!(larger.inside_nodes > 6 * small.inside_nodes);
    // At least W, Y and V per node and handle, and B, Z and U per row.
    let columns = cage.vertex_count() as u64;
    let floor = 8 * columns * (3 * larger.inside_nodes as u64 + 3 * larger.rows as u64);
    assert!(larger.predicted_bytes > floor, "{}", larger.predicted_bytes);
    let error = plan(&cage, 2048, 1000).unwrap_err();
    assert!(
        matches!(
            error,
            HarmonicError::GridTooLarge { .. } | HarmonicError::NotEnoughMemory { .. }
        ),
        "{error}"
    );
}

#[test]
fn a_cancelled_bind_stops() {
    let cage = comb();
    let points = procedural::points_inside(&cage, 10, 19, 0.05);
    let classes = classify_points(&cage, &points);
    let progress = BindProgress::new(10);
    progress.cancel();
    let error = bind_lbc(&points, &classes.classes, &cage, 16, &progress).unwrap_err();
    assert!(matches!(error, HarmonicError::Cancelled(_)), "{error}");
}

/// Time and memory of LBC at its default grid on the benchmark scenes (what
/// `pmvc bench` rows measure), for the docs; long, so not run by default.
#[test]
#[ignore]
fn cost_on_the_shared_models() {
    let names = std::env::var("LBC_SCENES").unwrap_or_default();
    for name in procedural::table1_scene_names() {
        if !names.is_empty() && !names.split(',').any(|n| n == *name) {
            continue;
        }
        let scene = procedural::table1_scene(name).unwrap();
        let grid = std::env::var("LBC_GRID")
            .map_or(pmvc::coords::lbc::DEFAULT_GRID, |g| g.parse().unwrap());
        let tolerance = std::env::var("LBC_TOL")
            .map_or(LbcSettings::default().tolerance, |t| t.parse().unwrap());
        let settings = LbcSettings {
            tolerance,
            ..LbcSettings::default()
        };
        let planned = plan(&scene.cage, grid, scene.points.len()).unwrap();
        let start = std::time::Instant::now();
        let points = &scene.points;
        let classes = classify_points(&scene.cage, points);
        let (_, stats) = pmvc::coords::lbc::bind_lbc_with(
            points,
            &classes.classes,
            &scene.cage,
            grid,
            &settings,
            &BindProgress::new(points.len()),
        )
        .unwrap();
        println!(
            "{name}: {} cage vertices, {} points, {planned:?}, {:.1} s, {stats:?}",
            scene.cage.vertex_count(),
            points.len(),
            start.elapsed().as_secs_f64()
        );
    }
}

//! Harmonic coordinates: their defining properties on convex and non-convex cages,
//! convergence under grid refinement, exact and near-exact harmonic functions as
//! independent references, and bad grids.

use glam::DVec3;
use pmvc::coords::harmonic::{bind_harmonic, plan, HarmonicError, SolveStats};
use pmvc::coords::{BindProgress, Weights};
use pmvc::geometry::{classify_points, procedural, Cage, PointClass, TriMesh};

fn comb() -> Cage {
    procedural::extrude(&procedural::comb_outline(5, 1.0, 0.25, 4.0), -0.5, 0.5)
}

fn bind(cage: &Cage, points: &[DVec3], grid: u32) -> (Weights, SolveStats) {
    let classes = classify_points(cage, points);
    bind_harmonic(
        points,
        &classes.classes,
        cage,
        grid,
        &BindProgress::new(points.len()),
    )
    .unwrap()
}

/// Worst |Σλ − 1|, smallest weight, and worst |Σλ c − x| over the cage diagonal.
fn properties(cage: &Cage, points: &[DVec3], weights: &Weights) -> (f64, f32, f64) {
    let reproduced = weights.apply(cage.positions());
    let mut sum_error = 0.0f64;
    let mut position_error = 0.0f64;
    for (i, x) in points.iter().enumerate() {
        let sum: f64 = weights.row(i).iter().map(|&w| f64::from(w)).sum();
        sum_error = sum_error.max((sum - 1.0).abs());
        position_error = position_error.max(reproduced[i].distance(*x));
    }
    (sum_error, weights.min(), position_error / cage.diagonal())
}

#[test]
fn positive_affine_and_linearly_precise_on_convex_and_non_convex_cages() {
    for (name, cage) in [("cube", procedural::cube_cage(1.0)), ("comb", comb())] {
        let points = procedural::points_inside(&cage, 400, 5, 1e-3);
        let mut boundary_errors = Vec::new();
        for grid in [32, 64] {
            let (weights, stats) = bind(&cage, &points, grid);
            let (sum_error, min, position_error) = properties(&cage, &points, &weights);
            println!(
                "{name} grid {grid}: min {min:e}, |Σλ−1| {sum_error:e}, linear precision {position_error:e}, {stats:?}"
            );
            assert!(min >= -1e-6, "{name}: weight {min}");
            assert!(
                sum_error <= 1e-5,
                "{name}: partition of unity off by {sum_error}"
            );
            // Linear functions are exact at the nodes; near the cage a cell corner
            // outside takes the boundary value at its closest point, off by at most
            // a cell diagonal.
            let (lo, hi) = pmvc::geometry::bounds_of(cage.positions());
            let cell = (hi - lo).max_element() / f64::from(grid);
            assert!(
                position_error <= 3f64.sqrt() * cell / cage.diagonal(),
                "{name} grid {grid}: linear precision off by {position_error} of the diagonal"
            );
            boundary_errors.push(position_error);
            // Farther than a cell diagonal from the cage every corner is a node: exact
            // up to the solver's tolerance.
            let deep: Vec<usize> = (0..points.len())
                .filter(|&i| {
                    procedural::distance_to_surface(&cage, points[i]) > 1.01 * 3f64.sqrt() * cell
                })
                .collect();
            let reproduced = weights.apply(cage.positions());
            let deep_error = deep
                .iter()
                .map(|&i| reproduced[i].distance(points[i]))
                .fold(0.0, f64::max)
                / cage.diagonal();
            println!(
                "{name} grid {grid}: {} points deep inside, linear precision {deep_error:e}",
                deep.len()
            );
            assert!(
                grid < 64 || !deep.is_empty(),
                "{name}: no point deep inside"
            );
            assert!(
                deep_error <= 1e-5,
                "{name} grid {grid}: deep inside off by {deep_error}"
            );
        }
        assert!(
            boundary_errors[1] < boundary_errors[0],
            "{boundary_errors:?}"
        );
    }
}

#[test]
fn the_comb_keeps_each_prong_to_itself() {
    // Deep in the second prong, the vertices of the neighbouring prongs' tips have
    // (almost) no influence: what MVC gets wrong.
    let cage = comb();
    let x = DVec3::new(1.75, 4.0, 0.0);
    let (weights, _) = bind(&cage, &[x], 64);
    let row = weights.row(0);
    for (j, &w) in row.iter().enumerate() {
        let c = cage.positions()[j];
        let in_neighbour_prong = c.y > 3.0 && (c.x < 1.1 || (2.4..3.4).contains(&c.x));
        if in_neighbour_prong {
            assert!(w.abs() < 1e-3, "vertex {j} at {c} has weight {w}");
        }
    }
}

#[test]
fn harmonic_boundary_data_gives_the_harmonic_function_inside() {
    // On a finely tessellated sphere the hat interpolation of a harmonic function
    // is close to it, so Σ hᵢ(x) f(vᵢ) must be close to f(x). Independent of the
    // solver: f is known in closed form.
    let cage = procedural::icosphere(1.0, 3);
    type Harmonic = fn(DVec3) -> f64;
    let functions: [(&str, Harmonic); 2] = [
        ("x² − y²", |p| p.x * p.x - p.y * p.y),
        ("xy + z", |p| p.x * p.y + p.z),
    ];
    let points = procedural::points_inside(&cage, 60, 9, 0.2);
    let (weights, _) = bind(&cage, &points, 48);
    for (name, f) in functions {
        let values: Vec<f64> = cage.positions().iter().map(|&v| f(v)).collect();
        let worst = points
            .iter()
            .enumerate()
            .map(|(i, &x)| {
                let interpolated: f64 = weights
                    .row(i)
                    .iter()
                    .zip(&values)
                    .map(|(&w, &v)| f64::from(w) * v)
                    .sum();
                (interpolated - f(x)).abs()
            })
            .fold(0.0, f64::max);
        println!("{name}: max |Σ hᵢ f(vᵢ) − f(x)| = {worst:e}");
        assert!(worst < 1e-2, "{name}: off by {worst}");
    }
}

#[test]
fn refining_the_grid_converges() {
    let cage = comb();
    let points = procedural::points_inside(&cage, 200, 3, 0.05);
    let solutions: Vec<Weights> = [32, 64, 128]
        .map(|grid| bind(&cage, &points, grid).0)
        .into();
    let difference = |a: &Weights, b: &Weights| {
        a.values
            .iter()
            .zip(&b.values)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f32, f32::max)
    };
    let coarse = difference(&solutions[0], &solutions[1]);
    let fine = difference(&solutions[1], &solutions[2]);
    println!("max |h32 − h64| = {coarse:e}, max |h64 − h128| = {fine:e}");
    assert!(fine < coarse, "no convergence: {coarse} then {fine}");
}

#[test]
fn shuffling_the_cage_vertices_permutes_the_columns() {
    let cage = comb();
    let n = cage.vertex_count();
    // A fixed permutation: new index of old vertex j.
    let new_of: Vec<u32> = (0..n as u32).map(|j| (j * 7 + 3) % n as u32).collect();
    let mut positions = vec![DVec3::ZERO; n];
    for (old, &new) in new_of.iter().enumerate() {
        positions[new as usize] = cage.positions()[old];
    }
    let triangles = cage
        .triangles()
        .iter()
        .map(|t| t.map(|k| new_of[k as usize]))
        .collect();
    let (shuffled, _) = Cage::new(TriMesh {
        positions,
        triangles,
        triangle_faces: cage.triangle_faces().to_vec(),
    })
    .unwrap();
    let points = procedural::points_inside(&cage, 100, 4, 1e-3);
    let (original, _) = bind(&cage, &points, 32);
    let (permuted, _) = bind(&shuffled, &points, 32);
    for i in 0..points.len() {
        for (j, &new) in new_of.iter().enumerate() {
            let (a, b) = (original.row(i)[j], permuted.row(i)[new as usize]);
            // Blocks group other columns and stop together, so within the solver's
            // tolerance rather than bit for bit.
            assert!((a - b).abs() < 1e-5, "row {i}, vertex {j}: {a} vs {b}");
        }
    }
}

#[test]
fn points_on_and_outside_the_cage_follow_the_shared_policy() {
    let cage = procedural::cube_cage(1.0);
    let corner = cage.positions()[5];
    let points = [corner, DVec3::new(3.0, 0.2, 0.1)];
    let classes = classify_points(&cage, &points);
    assert!(matches!(classes.classes[0], PointClass::OnSurface { .. }));
    assert_eq!(classes.outside, [1]);
    let (weights, _) = bind(&cage, &points, 16);
    assert!(
        (weights.row(0)[5] - 1.0).abs() < 1e-6,
        "{:?}",
        weights.row(0)
    );
    let reproduced = weights.apply(cage.positions())[1];
    assert!(
        reproduced.distance(points[1]) < 1e-5,
        "MVC reproduces outside points"
    );
}

#[test]
fn bad_grids_are_clear_errors() {
    let cage = procedural::cube_cage(1.0);
    let progress = BindProgress::default();
    let points = [DVec3::ZERO];
    let classes = classify_points(&cage, &points);
    let error = bind_harmonic(&points, &classes.classes, &cage, 0, &progress).unwrap_err();
    assert!(
        matches!(error, HarmonicError::GridTooSmall { grid: 0 }),
        "{error}"
    );
    let error = bind_harmonic(&points, &classes.classes, &cage, 100_000, &progress).unwrap_err();
    assert!(
        matches!(
            error,
            HarmonicError::GridTooLarge { .. } | HarmonicError::NotEnoughMemory { .. }
        ),
        "{error}"
    );
    assert!(error.to_string().contains("smaller --grid"), "{error}");
    // A grid that builds but would not fit names one that does.
    let error = bind_harmonic(&points, &classes.classes, &cage, 600, &progress).unwrap_err();
    let message = error.to_string();
    println!("{message}");
    assert!(
        matches!(error, HarmonicError::NotEnoughMemory { .. }),
        "{message}"
    );
}

#[test]
fn the_plan_counts_inside_nodes_before_solving() {
    let cage = procedural::cube_cage(1.0);
    let small = plan(&cage, 16, 10).unwrap();
    let large = plan(&cage, 32, 10).unwrap();
    println!("{small:?}\n{large:?}");
    // A cube of side 2 at cell 2/16 holds 16³ nodes strictly inside, give or take a layer.
    assert!((15usize.pow(3)..=17usize.pow(3)).contains(&small.inside_nodes));
    assert!(large.inside_nodes > 7 * small.inside_nodes);
    assert!(large.predicted_bytes > small.predicted_bytes);
}

#[test]
fn progress_is_monotone_and_cancel_stops_the_solve() {
    let cage = comb();
    let points = procedural::points_inside(&cage, 300, 2, 1e-3);
    let classes = classify_points(&cage, &points);
    let progress = BindProgress::new(points.len());
    let mut seen = Vec::new();
    std::thread::scope(|scope| {
        let run = scope.spawn(|| bind_harmonic(&points, &classes.classes, &cage, 96, &progress));
        while !run.is_finished() {
            seen.push(progress.done());
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        assert!(run.join().unwrap().is_ok());
    });
    assert!(seen.windows(2).all(|pair| pair[0] <= pair[1]), "{seen:?}");
    assert_eq!(progress.done(), points.len());

    let cancelled = BindProgress::new(points.len());
    std::thread::scope(|scope| {
        let run = scope.spawn(|| bind_harmonic(&points, &classes.classes, &cage, 128, &cancelled));
        std::thread::sleep(std::time::Duration::from_millis(50));
        let asked = std::time::Instant::now();
        cancelled.cancel();
        let result = run.join().unwrap();
        println!("cancel took effect after {:?}", asked.elapsed());
        assert!(matches!(result, Err(HarmonicError::Cancelled(_))));
    });
}

//! Harmonic coordinates on cages with quads: bilinear boundary data on the
//! patches, nodes classified by the patches, and weights that depend on the
//! patches, not on corner order or a split.

use super::grid::{inside_nodes, THETA_MIN};
use super::{bind_harmonic, frame_for, multigrid, right_hand_sides, solve, TOLERANCE};
use crate::coords::{BindProgress, Weights};
use crate::geometry::procedural_quads::{cage_from_polygons, twisted_box};
use crate::geometry::quads::{patch_grid, patch_grid_triangles};
use crate::geometry::{classify_points, procedural, Cage, QuadSplit};
use glam::{DQuat, DVec3};

fn bind(cage: &Cage, points: &[DVec3], grid: u32) -> Weights {
    let classes = classify_points(cage, points);
    let progress = BindProgress::new(points.len());
    bind_harmonic(points, &classes.classes, cage, grid, &progress)
        .unwrap()
        .0
}

/// [`twisted_box`], each quad's corner list turned by `turn(face)` places.
fn twisted_box_turned(turn: impl Fn(usize) -> usize) -> Cage {
    let (height, angle) = (2.0, 0.6);
    let square = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    let mut positions: Vec<DVec3> = square.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
    let top = DQuat::from_rotation_z(angle);
    positions.extend(square.iter().map(|&(x, y)| top * DVec3::new(x, y, height)));
    let faces = [
        [0, 3, 2, 1],
        [4, 5, 6, 7],
        [0, 1, 5, 4],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 0, 4, 7],
    ];
    let polygons: Vec<Vec<u32>> = faces
        .iter()
        .enumerate()
        .map(|(k, face)| (0..4).map(|i| face[(i + turn(k)) % 4]).collect())
        .collect();
    cage_from_polygons(&positions, &polygons).unwrap().0
}

/// A square pyramid on a bent quad: four lone triangles and one patch.
fn pyramid_on_a_bent_quad() -> Cage {
    let positions = [
        DVec3::new(-1.0, -1.0, 0.0),
        DVec3::new(1.0, -1.0, 0.0),
        DVec3::new(1.0, 1.0, 0.4),
        DVec3::new(-1.0, 1.0, 0.0),
        DVec3::new(0.1, 0.05, 1.8),
    ];
    let polygons = vec![
        vec![0, 3, 2, 1],
        vec![0, 1, 4],
        vec![1, 2, 4],
        vec![2, 3, 4],
        vec![3, 0, 4],
    ];
    cage_from_polygons(&positions, &polygons).unwrap().0
}

/// Σ over columns of `row[j] f(cage vertex j)`.
fn interpolate(row: &[f32], cage: &Cage, f: impl Fn(DVec3) -> f64) -> f64 {
    row.iter()
        .zip(cage.positions())
        .map(|(&w, &c)| f64::from(w) * f(c))
        .sum()
}

fn largest_difference(a: &Weights, b: &Weights) -> f32 {
    a.values
        .iter()
        .zip(&b.values)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

/// f32 values and the solver's tolerance, over the cage diagonal.
const ROUNDING: f64 = 2e-6;

/// The most a linear function can be off: a node closer than `THETA_MIN` cells
/// to the cage takes its boundary value as if it were `THETA_MIN` cells away,
/// moving the boundary by up to that much on each axis.
fn clamp_error(cage: &Cage, h: f64) -> f64 {
    3f64.sqrt() * THETA_MIN * h + ROUNDING * cage.diagonal()
}

#[test]
fn bilinear_data_reproduce_linear_functions_at_the_nodes() {
    for (name, cage) in [
        ("twisted box", twisted_box(2.0, 0.6)),
        ("pyramid", pyramid_on_a_bent_quad()),
    ] {
        let grid = 32;
        let multigrid = multigrid(&cage, grid).unwrap();
        let level = &multigrid.levels[0];
        let width = cage.vertex_count();
        let b = right_hand_sides(level, 0, width);
        let progress = BindProgress::default();
        let (x, stats) =
            solve::solve_block(&multigrid, &b, width, TOLERANCE, 200, &progress).unwrap();
        let (mut worst, mut exact) = (0.0f64, 0);
        for (unknown, &node) in level.nodes.iter().enumerate() {
            let at = level.frame.position(level.frame.coordinates(node as usize));
            let row = &x[unknown * width..][..width];
            let reproduced: DVec3 = row
                .iter()
                .zip(cage.positions())
                .map(|(&w, &c)| f64::from(w) * c)
                .sum();
            let error = reproduced.distance(at);
            worst = worst.max(error);
            exact += usize::from(error < ROUNDING * cage.diagonal());
        }
        println!(
            "{name}: {exact} of {} nodes exact, worst {:e} of the diagonal, {stats:?}",
            level.unknowns(),
            worst / cage.diagonal()
        );
        // Exact but for the clamp of arms shorter than THETA_MIN.
        assert!(exact * 100 >= level.unknowns() * 99, "{name}: {exact}");
        assert!(
            worst <= clamp_error(&cage, level.frame.h),
            "{name}: off by {worst}"
        );
    }
}

#[test]
fn bilinear_data_reproduce_linear_functions_at_points() {
    let cage = twisted_box(2.0, 0.6);
    let grid = 48;
    let points = procedural::points_inside(&cage, 300, 7, 0.02);
    let weights = bind(&cage, &points, grid);
    let reproduced = weights.apply(cage.positions());
    let (frame, _) = frame_for(&cage, grid).unwrap();
    let cell_diagonal = 3f64.sqrt() * frame.h;
    let (mut deep, mut near) = (0.0f64, 0.0f64);
    let mut deep_count = 0;
    for (x, y) in points.iter().zip(&reproduced) {
        let error = x.distance(*y);
        // Farther than a cell diagonal from every face, all eight corners are nodes.
        if procedural::distance_to_surface(&cage, *x) > cell_diagonal + 0.2 {
            deep = deep.max(error);
            deep_count += 1;
        } else {
            near = near.max(error);
        }
    }
    println!(
        "{deep_count} points deep inside: {deep:e}; near the surface {near:e}; cell {}",
        frame.h
    );
    assert!(deep_count > 20);
    assert!(
        deep <= clamp_error(&cage, frame.h),
        "deep inside off by {deep}"
    );
    // A corner outside takes the data of its closest point on the cage.
    assert!(near <= cell_diagonal, "near the surface off by {near}");
}

/// xy + yz + zx: harmonic, and bilinear on every face of an axis-aligned box,
/// so the patches' data are exact where split quads' are not.
fn bilinear_on_box_faces(p: DVec3) -> f64 {
    p.x * p.y + p.y * p.z + p.z * p.x
}

fn box_of_quads() -> Cage {
    let (lo, hi) = (DVec3::new(-1.0, -0.5, 0.2), DVec3::new(1.2, 1.5, 1.4));
    let positions: Vec<DVec3> = (0..8)
        .map(|k| {
            DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect();
    let polygons = vec![
        vec![0, 2, 3, 1],
        vec![4, 5, 7, 6],
        vec![0, 1, 5, 4],
        vec![2, 6, 7, 3],
        vec![0, 4, 6, 2],
        vec![1, 3, 7, 5],
    ];
    cage_from_polygons(&positions, &polygons).unwrap().0
}

/// Worst |Σ hᵢ f(vᵢ) − f(x)| over `points`.
fn harmonic_error(cage: &Cage, points: &[DVec3], grid: u32) -> f64 {
    let weights = bind(cage, points, grid);
    points
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            (interpolate(weights.row(i), cage, bilinear_on_box_faces) - bilinear_on_box_faces(x))
                .abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_harmonic_function_bilinear_on_the_faces_is_found_inside() {
    let cage = box_of_quads();
    let points = procedural::points_inside(&cage, 300, 11, 1e-3);
    let errors: Vec<f64> = [16, 32, 64]
        .iter()
        .map(|&grid| harmonic_error(&cage, &points, grid))
        .collect();
    let split = harmonic_error(&cage.split_quads(QuadSplit::Shorter), &points, 64);
    println!("patches: max error at grids 16, 32, 64: {errors:?}; split quads at 64: {split:e}");
    // At the nodes the solution is exact (the function is linear along every grid
    // line); the error is that of points whose cell reaches outside the box.
    assert!(
        errors.windows(2).all(|pair| pair[1] < 0.7 * pair[0]),
        "{errors:?}"
    );
    assert!(errors[2] < 0.02, "{errors:?}");
    assert!(split > 5.0 * errors[2], "split {split}, patches {errors:?}");
}

#[test]
fn turning_a_quads_corner_list_changes_no_weight() {
    let cage = twisted_box_turned(|_| 0);
    let points = procedural::points_inside(&cage, 200, 3, 1e-3);
    let weights = bind(&cage, &points, 32);
    for turn in 1..4 {
        let turned = twisted_box_turned(|face| (face + turn) % 4);
        let difference = largest_difference(&weights, &bind(&turned, &points, 32));
        println!("turned by {turn}: max difference {difference:e}");
        assert!(difference <= 1e-6, "turn {turn}: {difference}");
    }
}

#[test]
fn splitting_the_quads_changes_the_weights() {
    let cage = twisted_box(2.0, 0.6);
    let points = procedural::points_inside(&cage, 200, 5, 1e-3);
    let patches = bind(&cage, &points, 32);
    let shorter = bind(&cage.split_quads(QuadSplit::Shorter), &points, 32);
    let longer = bind(&cage.split_quads(QuadSplit::Longer), &points, 32);
    let between_splits = largest_difference(&shorter, &longer);
    let from_patches = largest_difference(&patches, &shorter);
    println!("shorter vs longer {between_splits:e}, patches vs shorter {from_patches:e}");
    assert!(between_splits > 0.02, "{between_splits}");
    assert!(from_patches > 0.01, "{from_patches}");
}

/// Σ of the signed solid angles of `triangles` seen from `x`, over 4π.
fn winding_number(positions: &[DVec3], triangles: &[[u32; 3]], x: DVec3) -> f64 {
    let mut total = 0.0;
    for t in triangles {
        let [a, b, c] = t.map(|k| positions[k as usize] - x);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let numerator = a.dot(b.cross(c));
        let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        total += 2.0 * numerator.atan2(denominator);
    }
    total / (4.0 * std::f64::consts::PI)
}

/// The cage's surface with its patches finely tessellated.
fn fine_surface(cage: &Cage, steps: usize) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut positions = cage.positions().to_vec();
    let mut triangles: Vec<[u32; 3]> = cage.lone_triangles().map(|t| cage.triangles()[t]).collect();
    for k in 0..cage.quads().len() {
        let base = positions.len() as u32;
        positions.extend(patch_grid(&cage.quad(k), steps));
        triangles.extend(
            patch_grid_triangles(steps)
                .iter()
                .map(|t| t.map(|i| i + base)),
        );
    }
    (positions, triangles)
}

#[test]
fn nodes_between_a_bent_patch_and_its_triangles_follow_the_patch() {
    for (name, cage) in [
        ("twisted box", twisted_box(2.0, 0.6)),
        ("pyramid", pyramid_on_a_bent_quad()),
    ] {
        let (frame, _) = frame_for(&cage, 32).unwrap();
        let (inside, _) = inside_nodes(&cage, &frame);
        let (split_inside, _) = inside_nodes(&cage.split_quads(QuadSplit::Shorter), &frame);
        let (positions, triangles) = fine_surface(&cage, 64);
        let (mut differ_from_split, mut checked) = (0, 0);
        for (index, (&patch, &split)) in inside.iter().zip(&split_inside).enumerate() {
            if patch == split {
                continue;
            }
            differ_from_split += 1;
            let x = frame.position(frame.coordinates(index));
            let winding = winding_number(&positions, &triangles, x);
            // The tessellation is within 1/64² of the bend of the patch.
            if (winding - 0.5).abs() > 0.45 {
                checked += 1;
                assert_eq!(
                    patch,
                    winding > 0.5,
                    "{name}: node {x} has winding {winding}"
                );
            }
        }
        println!(
            "{name}: {differ_from_split} nodes differ from the split cage's, {checked} checked"
        );
        assert!(differ_from_split > 10, "{name}: {differ_from_split}");
        assert!(checked * 10 >= differ_from_split * 9, "{name}: {checked}");
    }
}

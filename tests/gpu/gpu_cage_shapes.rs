//! GPU PMVC binds agree with the CPU on cages that stress the kernel: more
//! triangles than a band's workgroup owns at once, a box whose triangles each span
//! several cube faces, and points close to the surface. Without an adapter each test
//! says it was not run, unless `PMVC_REQUIRE_GPU=1`, which turns a missing adapter
//! into a failure.

use crate::gpu_support;
use glam::DVec3;
use gpu_support::*;
use pmvc::geometry::procedural::{comb_outline, cube_cage, extrude, points_inside, refine_outline};
use pmvc::geometry::{classify_points, Cage, PointClass, TriMesh};

#[test]
fn a_cage_of_more_than_1500_vertices_agrees_with_cpu() {
    let Some(context) = test_context("1500+ vertices") else {
        return;
    };
    // A comb with 1,600 vertices: more triangles per cube face than one chunk of
    // set-ups holds, and teeth hiding one another.
    let outline = refine_outline(&comb_outline(8, 1.0, 0.25, 4.0), 800);
    let cage = extrude(&outline, -0.5, 0.5);
    assert!(
        cage.vertex_count() >= 1500,
        "{} vertices",
        cage.vertex_count()
    );
    let redone = pmvc_agrees(
        "1500+ vertices",
        &context,
        &cage,
        points_inside(&cage, 120, 6, 1e-3),
    );
    assert_eq!(redone, 0);
}

#[test]
fn an_eight_vertex_box_whose_triangles_cover_whole_faces_agrees_with_cpu() {
    let Some(context) = test_context("eight-vertex box") else {
        return;
    };
    // Stretched, so that one triangle spans several cube-map faces from inside.
    let cube = cube_cage(1.0);
    let stretched: Vec<DVec3> = cube
        .positions()
        .iter()
        .map(|p| *p * DVec3::new(4.0, 1.0, 0.5))
        .collect();
    let triangles = cube.triangles().to_vec();
    let mesh = TriMesh {
        positions: stretched,
        triangle_faces: (0..triangles.len() as u32).collect(),
        triangles,
    };
    let (cage, _) = Cage::new(mesh).expect("a box");
    assert_eq!(cage.vertex_count(), 8);
    let mut points = points_inside(&cage, 300, 7, 1e-3);
    points.extend([
        DVec3::ZERO,
        DVec3::new(3.5, 0.0, 0.0),
        DVec3::new(-1.0, 0.9, 0.45),
    ]);
    let redone = pmvc_agrees("eight-vertex box", &context, &cage, points);
    assert_eq!(redone, 0);
}

#[test]
fn points_close_to_the_cage_agree_with_cpu_and_few_go_to_the_cpu() {
    let Some(context) = test_context("close to the cage") else {
        return;
    };
    let cage = comb();
    let diagonal = cage.diagonal();
    // Each triangle's centroid and a point near its first corner, moved inwards by
    // 1e-3 to 1e-6 of the diagonal.
    let mut points = Vec::new();
    for (t, corners) in cage.triangles().iter().enumerate() {
        let [a, b, c] = corners.map(|k| cage.positions()[k as usize]);
        let inward = -(b - a).cross(c - a).normalize();
        let depth = diagonal * [1e-3, 1e-4, 1e-5, 1e-6][t % 4];
        points.push((a + b + c) / 3.0 + depth * inward);
        points.push(0.9 * a + 0.05 * (b + c) + depth * inward);
    }
    let classes = classify_points(&cage, &points).classes;
    let inside = classes.iter().filter(|c| **c == PointClass::Inside).count();
    assert!(
        inside * 10 >= points.len() * 9,
        "{inside} of {} inside",
        points.len()
    );
    let redone = pmvc_agrees("close to the cage", &context, &cage, points);
    // Rays that escape through the nearest triangle's edges send a row to the CPU;
    // most rows must still be the kernel's.
    assert!(
        redone * 20 <= inside,
        "{redone} of {inside} inside rows redone on the CPU"
    );
}

//! The two evaluation schemes against each other and against the brute-force
//! reference where the far-field rule serves most triangles.

use super::near;
use super::reference::brute_force_blocks;
use super::triangle::{Material, TriangleBlocks, TriangleFrame};
use super::*;
use crate::geometry::procedural::{icosphere, points_inside};
use std::time::Instant;

fn difference(a: &TriangleBlocks, b: &TriangleBlocks) -> f64 {
    let entries = |m: DMat3| m.to_cols_array();
    let mut worst: f64 = 0.0;
    for (x, y) in a.vertex.iter().zip(&b.vertex).chain([(&a.face, &b.face)]) {
        for (p, q) in entries(*x).iter().zip(entries(*y)) {
            worst = worst.max((p - q).abs());
        }
    }
    worst
}

#[test]
fn near_and_far_schemes_agree_around_a_triangle() {
    let frame = TriangleFrame::new([
        DVec3::new(0.1, -0.2, 0.3),
        DVec3::new(1.3, 0.1, 0.2),
        DVec3::new(0.4, 0.9, 0.5),
    ]);
    let material = Material::new(0.3);
    let centre = (frame.corners[0] + frame.corners[1] + frame.corners[2]) / 3.0;
    let (n, e1, e2) = (frame.normal, frame.tangent, frame.bitangent);
    let mut points = Vec::new();
    // Above the triangle, beside it, and in its plane outside it (ζ = 0 there,
    // up to the rounding of the in-plane offsets).
    for &height in &[0.4, -0.7, 1.5, 0.0] {
        for &(a, b) in &[(0.0, 0.0), (1.5, 0.2), (-0.9, 0.8), (0.3, -1.4), (2.0, 2.0)] {
            let x = centre + e1 * a + e2 * b + n * height;
            let (offset, _) = crate::geometry::closest_offset_on_triangle(
                x,
                frame.corners[0],
                frame.corners[1],
                frame.corners[2],
            );
            if offset.length() > 0.3 {
                points.push(x);
            }
        }
    }
    let mut worst: f64 = 0.0;
    for &x in &points {
        let relative = frame.corners.map(|c| c - x);
        let polar = near::blocks(&frame, relative, &material);
        let direct = frame.far_field(relative, &material);
        worst = worst.max(difference(&polar, &direct));
    }
    println!(
        "{} points: polar and direct schemes differ by at most {worst:.2e}",
        points.len()
    );
    assert!(points.len() >= 12);
    assert!(worst < 1e-11, "{worst}");
}

#[test]
fn an_icosphere_matches_the_reference_and_keeps_the_identities() {
    let cage = icosphere(1.0, 1);
    let points = [DVec3::new(0.2, -0.1, 0.3), DVec3::new(-0.35, 0.4, -0.25)];
    let blocks = somigliana_blocks(&points, &cage, 0.4).unwrap();
    for (i, &x) in points.iter().enumerate() {
        let (vertex, face) = brute_force_blocks(x, &cage, 0.4, 12, 8);
        let worst = (blocks.vertex_blocks(i).iter().zip(&vertex))
            .chain(blocks.face_blocks(i).iter().zip(&face))
            .map(|(a, b)| {
                (*a - *b)
                    .to_cols_array()
                    .iter()
                    .fold(0.0f64, |m, v| m.max(v.abs()))
            })
            .fold(0.0, f64::max);
        println!("icosphere point {x}: blocks differ from the reference by {worst:.2e}");
        assert!(worst < 1e-10, "{worst}");
    }

    let cage = icosphere(1.0, 2);
    let points = points_inside(&cage, 200, 7, 0.01);
    let started = Instant::now();
    let blocks = somigliana_blocks(&points, &cage, 0.25).unwrap();
    let elapsed = started.elapsed();
    let mut identity: f64 = 0.0;
    let mut reproduction: f64 = 0.0;
    let moved = deform(&blocks, &cage, cage.positions(), 0.0).unwrap();
    for (i, &x) in points.iter().enumerate() {
        let sum: DMat3 = blocks.vertex_blocks(i).iter().copied().sum();
        let entries = (sum - DMat3::IDENTITY).to_cols_array();
        identity = identity.max(entries.iter().fold(0.0f64, |m, v| m.max(v.abs())));
        reproduction = reproduction.max((moved[i] - x).length());
    }
    println!(
        "icosphere of {} triangles, {} points: {:.2?} ({:.1} µs per point and triangle); \
         max |Σ Bᵥ − I| {identity:.2e}, max rest error {reproduction:.2e}",
        cage.triangle_count(),
        points.len(),
        elapsed,
        elapsed.as_secs_f64() * 1e6 / (points.len() * cage.triangle_count()) as f64
    );
    assert!(
        identity < 1e-10 && reproduction < 1e-10,
        "{identity} {reproduction}"
    );
}

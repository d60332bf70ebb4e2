use super::reference::brute_force_blocks;
use super::*;
use crate::geometry::procedural::{cube_cage, extrude};
use glam::DVec2;

/// A non-convex L-shaped prism: the planes y = 1 and x = 1 of its step faces
/// pass through its interior.
pub(super) fn l_cage() -> Cage {
    let outline = [
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 2.0),
        (0.0, 2.0),
    ]
    .map(|(x, y)| DVec2::new(x, y));
    extrude(&outline, 0.0, 1.0)
}

pub(super) fn box_cage() -> Cage {
    let outline =
        [(-1.0, -0.5), (1.0, -0.5), (1.0, 0.5), (-1.0, 0.5)].map(|(x, y)| DVec2::new(x, y));
    extrude(&outline, -0.5, 0.5)
}

fn l_points() -> Vec<DVec3> {
    vec![
        DVec3::new(0.5, 0.5, 0.5),
        DVec3::new(1.7, 0.3, 0.2),
        DVec3::new(0.2, 1.8, 0.9),
        DVec3::new(0.9, 0.9, 0.05),
        DVec3::new(0.5, 1.0, 0.5), // in the plane y = 1 of a step face
        DVec3::new(1.0, 0.5, 0.5), // in the plane x = 1 of the other
        DVec3::new(0.999999, 1.000001, 0.3), // just inside the re-entrant edge
    ]
}

fn max_entry(m: DMat3) -> f64 {
    m.to_cols_array().iter().fold(0.0f64, |a, v| a.max(v.abs()))
}

fn block_sum(blocks: &SomiglianaBlocks, point: usize) -> DMat3 {
    blocks.vertex_blocks(point).iter().copied().sum()
}

/// Σ Bᵥ vᵥ + s Σ F_f n_f for a cage at rest (no fit, no centring).
fn rest_image(blocks: &SomiglianaBlocks, cage: &Cage, point: usize) -> DVec3 {
    let from_vertices: DVec3 = (blocks.vertex_blocks(point).iter())
        .zip(cage.positions())
        .map(|(b, &v)| *b * v)
        .sum();
    let from_faces: DVec3 = (blocks.face_blocks(point).iter())
        .enumerate()
        .map(|(t, b)| {
            let [a, bb, c] = cage.triangle(t);
            *b * (bb - a).cross(c - a).normalize()
        })
        .sum();
    from_vertices + from_faces
}

#[test]
fn vertex_blocks_sum_to_the_identity_inside() {
    for nu in [0.0, 0.3, -0.4] {
        for (name, cage, points) in [
            (
                "cube",
                cube_cage(1.0),
                vec![DVec3::ZERO, DVec3::new(0.9, -0.95, 0.99)],
            ),
            ("L", l_cage(), l_points()),
        ] {
            let blocks = somigliana_blocks(&points, &cage, nu).unwrap();
            let worst = (0..points.len())
                .map(|i| max_entry(block_sum(&blocks, i) - DMat3::IDENTITY))
                .fold(0.0, f64::max);
            println!("{name} ν={nu}: max |Σ Bᵥ − I| = {worst:.2e}");
            assert!(worst < 1e-10, "{name} ν={nu}: {worst}");
        }
    }
}

#[test]
fn rest_cage_reproduces_every_inside_point() {
    for nu in [0.0, 0.45, -0.7] {
        let cage = l_cage();
        let points = l_points();
        let blocks = somigliana_blocks(&points, &cage, nu).unwrap();
        let deformed = deform(&blocks, &cage, cage.positions(), 0.0).unwrap();
        let mut worst: f64 = 0.0;
        for (i, &x) in points.iter().enumerate() {
            worst = worst
                .max((rest_image(&blocks, &cage, i) - x).length())
                .max((deformed[i] - x).length());
        }
        println!(
            "ν={nu}: max rest reproduction error {worst:.2e} (diagonal {:.2})",
            cage.diagonal()
        );
        assert!(worst < 1e-10 * cage.diagonal(), "ν={nu}: {worst}");
    }
}

#[test]
fn similarities_of_the_cage_are_followed() {
    let cage = l_cage();
    let points = l_points();
    let blocks = somigliana_blocks(&points, &cage, 0.25).unwrap();
    let rotation = DMat3::from_axis_angle(DVec3::new(0.3, -1.0, 0.6).normalize(), 1.1);
    let cases = [
        ("rigid", 1.0, rotation, DVec3::new(4.0, -2.0, 1.5)),
        ("uniform scale", 2.5, DMat3::IDENTITY, DVec3::ZERO),
        (
            "similarity",
            0.6,
            rotation.transpose(),
            DVec3::new(-3.0, 0.5, 9.0),
        ),
    ];
    for (name, scale, rotation, translation) in cases {
        let map = |p: DVec3| scale * (rotation * p) + translation;
        let deformed: Vec<DVec3> = cage.positions().iter().map(|&p| map(p)).collect();
        let moved = deform(&blocks, &cage, &deformed, 0.0).unwrap();
        let worst = points
            .iter()
            .zip(&moved)
            .map(|(&x, &y)| (map(x) - y).length())
            .fold(0.0, f64::max);
        println!(
            "{name}: max error {worst:.2e} (diagonal {:.2})",
            cage.diagonal()
        );
        assert!(worst < 1e-8 * cage.diagonal(), "{name}: {worst}");
    }
}

#[test]
fn blocks_match_a_brute_force_reference() {
    let cage = l_cage();
    // Away from the faces (the reference's cells are 1/16 of an edge): points
    // where the polar scheme and the far-field rule both serve some triangles.
    let points = [
        DVec3::new(0.5, 0.5, 0.5),
        DVec3::new(1.6, 0.5, 0.4),
        DVec3::new(0.4, 1.5, 0.7),
    ];
    for nu in [0.0, 0.35] {
        let blocks = somigliana_blocks(&points, &cage, nu).unwrap();
        for (i, &x) in points.iter().enumerate() {
            let (vertex, face) = brute_force_blocks(x, &cage, nu, 16, 8);
            let vertex_error = (blocks.vertex_blocks(i).iter())
                .zip(&vertex)
                .map(|(a, b)| max_entry(*a - *b))
                .fold(0.0, f64::max);
            let face_error = (blocks.face_blocks(i).iter())
                .zip(&face)
                .map(|(a, b)| max_entry(*a - *b))
                .fold(0.0, f64::max);
            let largest = (blocks.vertex_blocks(i).iter())
                .chain(blocks.face_blocks(i))
                .map(|b| max_entry(*b))
                .fold(0.0, f64::max);
            println!(
                "ν={nu} point {x}: vertex blocks differ by {vertex_error:.2e}, face blocks by \
                 {face_error:.2e} (largest entry {largest:.3})"
            );
            assert!(
                vertex_error < 1e-9 && face_error < 1e-9,
                "{vertex_error} {face_error}"
            );
        }
    }
}

#[test]
fn a_point_in_the_plane_of_another_face_deforms_continuously() {
    let cage = l_cage();
    // A bend that is not a similarity: the upper arm of the L sheared along x.
    let deformed: Vec<DVec3> = cage
        .positions()
        .iter()
        .map(|&p| p + DVec3::new(0.3 * p.y * p.y, 0.1 * p.x, 0.05 * p.x * p.y))
        .collect();
    let step = 1e-7;
    for (on_plane, across) in [
        (DVec3::new(0.5, 1.0, 0.5), DVec3::Y),
        (DVec3::new(1.0, 0.5, 0.5), DVec3::X),
        (DVec3::new(0.25, 1.0, 0.75), DVec3::Y),
    ] {
        let points = [on_plane - step * across, on_plane, on_plane + step * across];
        let blocks = somigliana_blocks(&points, &cage, 0.2).unwrap();
        let moved = deform(&blocks, &cage, &deformed, 0.0).unwrap();
        // Linear in the offset: the middle is the mean of its neighbours.
        let kink = (moved[1] - 0.5 * (moved[0] + moved[2])).length();
        let spread = (moved[2] - moved[0]).length();
        let identity_error = (0..3)
            .map(|i| max_entry(block_sum(&blocks, i) - DMat3::IDENTITY))
            .fold(0.0, f64::max);
        let block_jump = (blocks.vertex_blocks(1).iter())
            .zip(blocks.vertex_blocks(0))
            .map(|(a, b)| max_entry(*a - *b))
            .fold(0.0, f64::max);
        println!(
            "{on_plane}: deformed positions ±1e-7 apart differ by {spread:.2e}, mid-point off \
             their mean by {kink:.2e}; largest block change {block_jump:.2e}; |Σ Bᵥ − I| \
             {identity_error:.2e}"
        );
        assert!(spread < 1e-5 && kink < 1e-10, "{spread} {kink}");
        assert!(block_jump < 1e-5, "{block_jump}");
        assert!(identity_error < 1e-10, "{identity_error}");
    }
}

#[test]
fn blocks_rotate_with_the_cage() {
    let cage = l_cage();
    let rotation = DMat3::from_axis_angle(DVec3::new(2.0, 1.0, -1.0).normalize(), 0.9);
    let rotated = cage.with_positions(cage.positions().iter().map(|&p| rotation * p).collect());
    let points = l_points();
    let turned: Vec<DVec3> = points.iter().map(|&p| rotation * p).collect();
    let blocks = somigliana_blocks(&points, &cage, 0.3).unwrap();
    let rotated_blocks = somigliana_blocks(&turned, &rotated, 0.3).unwrap();
    let mut worst: f64 = 0.0;
    for i in 0..points.len() {
        let pairs = (blocks
            .vertex_blocks(i)
            .iter()
            .zip(rotated_blocks.vertex_blocks(i)))
        .chain(
            blocks
                .face_blocks(i)
                .iter()
                .zip(rotated_blocks.face_blocks(i)),
        );
        for (b, rb) in pairs {
            worst = worst.max(max_entry(rotation * *b * rotation.transpose() - *rb));
        }
    }
    println!("max |R B Rᵀ − B(R·)| = {worst:.2e}");
    assert!(worst < 1e-11, "{worst}");
}

#[test]
fn a_cage_far_from_the_origin_gives_the_same_blocks() {
    let cage = l_cage();
    let offset = DVec3::new(1e7, -1e7, 1e7);
    let moved = cage.with_positions(cage.positions().iter().map(|&p| p + offset).collect());
    let points = l_points();
    let shifted: Vec<DVec3> = points.iter().map(|&p| p + offset).collect();
    let blocks = somigliana_blocks(&points, &cage, 0.1).unwrap();
    let far = somigliana_blocks(&shifted, &moved, 0.1).unwrap();
    let mut worst: f64 = 0.0;
    for i in 0..points.len() {
        let pairs = (blocks.vertex_blocks(i).iter().zip(far.vertex_blocks(i)))
            .chain(blocks.face_blocks(i).iter().zip(far.face_blocks(i)));
        for (a, b) in pairs {
            worst = worst.max(max_entry(*a - *b));
        }
    }
    let deformed: Vec<DVec3> = moved.positions().iter().map(|&p| p + DVec3::X).collect();
    let moved_points = deform(&far, &moved, &deformed, 0.0).unwrap();
    let translation_error = shifted
        .iter()
        .zip(&moved_points)
        .map(|(&x, &y)| (y - x - DVec3::X).length())
        .fold(0.0, f64::max);
    println!("at 1e7: max block difference {worst:.2e}, translation error {translation_error:.2e}");
    assert!(worst < 1e-8, "{worst}");
    assert!(translation_error < 1e-8, "{translation_error}");
}

#[test]
fn points_approaching_a_face_keep_the_identities() {
    let cage = cube_cage(1.0);
    let points: Vec<DVec3> = [1e-3, 1e-6, 1e-9, 0.0]
        .iter()
        .map(|gap| DVec3::new(0.3, -0.2, 1.0 - gap))
        .collect();
    let blocks = somigliana_blocks(&points, &cage, 0.25).unwrap();
    for (i, &x) in points.iter().enumerate() {
        let identity = max_entry(block_sum(&blocks, i) - DMat3::IDENTITY);
        let reproduction = (rest_image(&blocks, &cage, i) - x).length();
        println!("{x}: |Σ Bᵥ − I| {identity:.2e}, rest error {reproduction:.2e}");
        assert!(
            identity < 1e-10 && reproduction < 1e-10,
            "{identity} {reproduction}"
        );
    }
}

#[test]
fn stretching_response_is_monotonic_in_the_poisson_ratio() {
    let cage = box_cage();
    // Stretch along x by 1.5 with the sides kept: the probe near a side face
    // moves sideways by an amount that depends on ν alone.
    let deformed: Vec<DVec3> = cage
        .positions()
        .iter()
        .map(|&p| DVec3::new(1.5 * p.x, p.y, p.z))
        .collect();
    let probe = [DVec3::new(0.0, 0.35, 0.1)];
    let ratios = [-0.6, -0.3, 0.0, 0.2, 0.35, 0.45];
    let widths: Vec<f64> = ratios
        .iter()
        .map(|&nu| {
            let blocks = somigliana_blocks(&probe, &cage, nu).unwrap();
            deform(&blocks, &cage, &deformed, 0.0).unwrap()[0].y
        })
        .collect();
    for (nu, y) in ratios.iter().zip(&widths) {
        println!("ν={nu}: probe y {:.6} → {y:.6}", probe[0].y);
    }
    // The fitted dilation s = 4/3 gives the side faces the traction s(3λ + 2μ),
    // more than the stretch's own 3.5λ + 2μ by 0.5λ + 2μ/3: the excess, and so
    // the outward push, grows with λ/μ = 2ν/(1 − 2ν).
    assert!(widths.windows(2).all(|w| w[1] > w[0]), "{widths:?}");
    assert!(
        (widths[0] - widths[widths.len() - 1]).abs() > 1e-3,
        "{widths:?}"
    );
}

#[test]
fn the_poisson_ratio_is_validated() {
    for bad in [-1.0, 0.5, 0.7, -3.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            validate_poisson_ratio(bad),
            Err(SomiglianaError::PoissonRatio { .. })
        ));
    }
    for good in [DEFAULT_POISSON_RATIO, 0.49, -0.99, 0.3] {
        assert_eq!(validate_poisson_ratio(good), Ok(good));
    }
    let cage = cube_cage(1.0);
    assert!(somigliana_blocks(&[DVec3::ZERO], &cage, 0.5).is_err());
}

#[test]
fn deform_checks_its_inputs() {
    let cage = cube_cage(1.0);
    let blocks = somigliana_blocks(&[DVec3::ZERO], &cage, 0.0).unwrap();
    let mut positions = cage.positions().to_vec();
    assert_eq!(
        deform(&blocks, &cage, &positions[1..], 0.0),
        Err(SomiglianaError::PositionCount {
            expected: 8,
            actual: 7
        })
    );
    positions[3].y = f64::NAN;
    assert_eq!(
        deform(&blocks, &cage, &positions, 0.0),
        Err(SomiglianaError::NonFinitePosition { index: 3 })
    );
    let other = l_cage();
    assert!(matches!(
        deform(&blocks, &other, other.positions(), 0.0),
        Err(SomiglianaError::CageMismatch { .. })
    ));
    assert_eq!(
        somigliana_blocks(&[DVec3::ZERO, DVec3::splat(f64::INFINITY)], &cage, 0.0),
        Err(SomiglianaError::NonFinitePoint { index: 1 })
    );
}

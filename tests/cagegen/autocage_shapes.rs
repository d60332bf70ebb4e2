//! Generated cages around procedural shapes whose gaps and volumes are known
//! from their definitions (`common::shapes`): a hand of four fingers, a torus
//! knot, a thin plate and two close blobs. Whether a gap stays open is judged
//! at points midway across it, with this file's own winding number; volume
//! ratios divide by the shape's volume, not by anything the generator measured.

use crate::common;

use common::measure::signed_volume;
use common::shapes::{self, Shape};
use common::winding_number;
use glam::DVec3;
use pmvc::cagegen::{generate_cage, CageOptions, CageStart, GeneratedCage, DEFAULT_CLEARANCE};
use pmvc::geometry::Cage;

fn cage_volume(cage: &Cage) -> f64 {
    signed_volume(cage.positions(), cage.triangles())
}

fn inside(cage: &Cage, p: DVec3) -> bool {
    winding_number(cage.positions(), cage.triangles(), p) > 0.5
}

fn gap_points_inside(shape: &Shape, cage: &Cage) -> Vec<DVec3> {
    shape
        .gap_points
        .iter()
        .copied()
        .filter(|&p| inside(cage, p))
        .collect()
}

/// Generates a cage and checks what every cage must satisfy: every mesh
/// vertex inside, and the volume ratio against the shape's own volume.
/// Returns the cage and its ratio.
fn generate(name: &str, shape: &Shape, target: usize) -> (GeneratedCage, f64) {
    let generated = generate_cage(&shape.mesh, &CageOptions::new(target), &|_| true)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let cage = &generated.cage;
    let outside = shape
        .mesh
        .positions
        .iter()
        .step_by(7)
        .filter(|&&p| !inside(cage, p))
        .count();
    assert_eq!(outside, 0, "{name}: mesh vertices outside the cage");
    let ratio = cage_volume(cage) / shape.volume;
    eprintln!(
        "{name} at N = {target}: {} vertices, volume ratio {ratio:.3}, {} of {} gap points inside; \
         the report: {} of {} open, narrowest open {:?}, widest bridged {:?}, voxels {:.3}",
        cage.vertex_count(),
        gap_points_inside(shape, cage).len(),
        shape.gap_points.len(),
        generated.stats.gaps.open,
        generated.stats.gaps.points,
        generated.stats.gaps.narrowest_open,
        generated.stats.gaps.widest_closed,
        generated.stats.cell_size,
    );
    (generated, ratio)
}

/// The smallest volume ratio any cage standing `clearance` off a tube of
/// `radius` can have along it: the tube's cross-section grows to the radius
/// plus the clearance.
fn tube_ratio_floor(radius: f64, clearance: f64) -> f64 {
    ((radius + clearance) / radius).powi(2)
}

#[test]
fn the_shapes_are_what_the_tests_take_them_for() {
    // The triangles' own volume agrees with the shape's (the chords cut
    // the curved parts a little; the hand's fingers overlap its palm, which the
    // shape's volume counts once and the triangles twice).
    let signed = |shape: &Shape| signed_volume(&shape.mesh.positions, &shape.mesh.triangles);
    let knot = shapes::torus_knot();
    assert!((signed(&knot) / knot.volume - 1.0).abs() < 0.02);
    let plate = shapes::thin_plate();
    assert!((signed(&plate) / plate.volume - 1.0).abs() < 1e-9);
    let blobs = shapes::two_blobs(0.4);
    assert!((signed(&blobs) / blobs.volume - 1.0).abs() < 0.02);
    let hand = shapes::hand(0.42);
    // Each finger's bottom hemisphere and 0.3 of its body lie in the palm.
    let overlap =
        4.0 * (std::f64::consts::PI * 0.25 * 0.3 + 2.0 / 3.0 * std::f64::consts::PI * 0.125);
    assert!(((signed(&hand) - overlap) / hand.volume - 1.0).abs() < 0.02);
    // Gap points are in empty space, at least a tenth of the gap from the mesh.
    for shape in [&knot, &blobs, &hand] {
        assert!(!shape.gap_points.is_empty());
        for &p in &shape.gap_points {
            assert!(winding_number(&shape.mesh.positions, &shape.mesh.triangles, p).abs() < 1e-6);
        }
    }
}

/// Fingers 5 % of the diagonal apart keep their own cage parts at N = 120 and
/// 200: no point midway between two fingers is inside. (Before gaps were kept,
/// 2 of the 21 were inside at N = 120: the cage, widened to reach N, bridged
/// the fingertips.)
#[test]
fn a_hand_keeps_every_gap_between_fingers_open() {
    let hand = shapes::hand(0.42);
    let diagonal = hand.mesh.diagonal();
    assert!((0.42 / diagonal - 0.05).abs() < 0.003);
    for target in [120, 200] {
        let (generated, ratio) = generate("hand, 5 % gaps", &hand, target);
        let bridged = gap_points_inside(&hand, &generated.cage);
        assert!(
            bridged.is_empty(),
            "N = {target}: gap points inside: {bridged:?}"
        );
        assert!(
            generated.stats.target_reached(),
            "N = {target}: {} vertices",
            generated.stats.vertices
        );
        // The report agrees: the gaps it found stay open.
        assert_eq!(
            generated.stats.gaps.closed(),
            0,
            "{:?}",
            generated.stats.gaps
        );
        assert!(generated.stats.gaps.points > 0);
        // Within 1.25 of the hand's volume (measured 1.197 at N = 120 and
        // 1.178 at 200; 1.276 and 1.245 before the final polishing, and
        // 1.44 and 1.40 at the 1/128 clearance of before, when the fingers
        // alone set a floor of 1.28).
        let floor = tube_ratio_floor(0.5, DEFAULT_CLEARANCE * diagonal);
        assert!(
            ratio > floor && ratio <= 1.25,
            "N = {target}: ratio {ratio}, floor {floor}"
        );
    }
}

/// A hand's cage keeps every test point between fingers outside, its report
/// says every gap is open, it reaches N, and its volume ratio is above the
/// fingers' floor at the default clearance and at most `most`.
fn assert_fingers_apart(
    name: &str,
    hand: &Shape,
    (generated, ratio): (&GeneratedCage, f64),
    most: f64,
) {
    let bridged = gap_points_inside(hand, &generated.cage);
    assert!(bridged.is_empty(), "{name}: inside: {bridged:?}");
    let stats = &generated.stats;
    assert_eq!(stats.gaps.closed(), 0, "{name}: {:?}", stats.gaps);
    assert!(stats.target_reached(), "{name}: {}", stats.vertices);
    let floor = tube_ratio_floor(0.5, DEFAULT_CLEARANCE * hand.mesh.diagonal());
    assert!(
        ratio > floor && ratio <= most,
        "{name}: ratio {ratio}, floor {floor}"
    );
}

/// Fingers 3.1 % and 2.07 % of the diagonal apart keep their own cage
/// parts at N = 120 and 200 as well: the voxels are made fine enough to
/// keep such gaps open (a quarter of the gap), and no point midway between
/// two fingers is inside. Before they were, the 3.1 % hand had 6 of these
/// 21 points inside at N = 200 and the 2.07 % hand most of them.
#[test]
fn a_hand_with_fingers_two_percent_apart_keeps_them_apart() {
    for gap in [0.26, 0.168] {
        let hand = shapes::hand(gap);
        let percent = 100.0 * gap / hand.mesh.diagonal();
        for target in [120, 200] {
            let name = format!("hand, {percent:.2} % gaps, N = {target}");
            let (generated, ratio) = generate(&name, &hand, target);
            assert_fingers_apart(&name, &hand, (&generated, ratio), 1.25);
        }
    }
}

/// Below about 120 vertices the simplification cannot keep four fingers
/// apart (the 2.07 % hand bridged every one of its 1,344 gap points at
/// N = 48, and 763 at 100), but a prism over the hand seen along the palm's
/// normal can: its outline keeps the slots between the fingers, and it
/// replaces the cage from the voxels, as the summary says. At N = 40, 48, 64
/// and 100 the hands with fingers 3.1 % and 2.07 % apart keep every test
/// point between fingers outside, the report agrees, and the cage stays
/// within 1.4 of the hand's volume.
#[test]
fn a_hand_below_120_vertices_keeps_its_fingers_apart() {
    for gap in [0.26, 0.168] {
        let hand = shapes::hand(gap);
        let percent = 100.0 * gap / hand.mesh.diagonal();
        for target in [40, 48, 64, 100] {
            let name = format!("hand, {percent:.2} % gaps, N = {target}");
            let (generated, ratio) = generate(&name, &hand, target);
            // Measured 1.28–1.37 against the shapes' volumes: the prism's
            // fingers are near square around round ones.
            assert_fingers_apart(&name, &hand, (&generated, ratio), 1.4);
            let stats = &generated.stats;
            // Where the cage from the voxels bridged them (the 2.07 % hand at
            // every N here), the summary says the start kept them open.
            if gap < 0.2 {
                let lines = pmvc::app::cage_generation::stats_lines(stats, false);
                let started = lines
                    .iter()
                    .find(|l| l.starts_with("started from: the prism"));
                assert!(
                    started.is_some_and(|l| l.contains("keeps open gaps")),
                    "{name}: {lines:?}"
                );
            }
        }
    }
}

/// Fingers 1.2 % apart: the clearance (0.39 % of the diagonal each side)
/// leaves too little between them for any voxels the generator chooses
/// (the finest keep gaps from 1.6 %), and the cage cannot reopen a gap its
/// voxels closed. The summary must say so: every test point found inside is
/// within a gap the report counts as bridged.
#[test]
fn a_hand_whose_gaps_are_bridged_says_so() {
    let hand = shapes::hand(0.1);
    let (generated, ratio) = generate("hand, 1.2 % gaps", &hand, 200);
    let floor = tube_ratio_floor(0.5, DEFAULT_CLEARANCE * hand.mesh.diagonal());
    assert!(
        ratio > floor && ratio <= 1.25,
        "ratio {ratio}, floor {floor}"
    );
    let bridged = gap_points_inside(&hand, &generated.cage);
    let gaps = &generated.stats.gaps;
    assert!(!bridged.is_empty(), "no test point inside, report {gaps:?}");
    assert!(
        gaps.closed() > 0,
        "{} test points inside, report {gaps:?}",
        bridged.len()
    );
    let widest = gaps.widest_closed.expect("a widest bridged gap");
    assert!(widest >= 0.9 * 0.1, "widest bridged gap {widest}");
}

/// A torus knot's strands keep apart, and the cage is a single knotted tube:
/// one part, no point between strands inside.
#[test]
fn a_torus_knot_keeps_its_strands_apart() {
    let knot = shapes::torus_knot();
    let (generated, ratio) = generate("torus knot", &knot, 200);
    assert!(gap_points_inside(&knot, &generated.cage).is_empty());
    assert_eq!(generated.stats.shells, 1);
    let cage = &generated.cage;
    // A closed surface of genus 1: V − E + F = 0.
    let edges = cage.triangles().len() * 3 / 2;
    assert_eq!(
        cage.vertex_count() as i64 - edges as i64 + cage.triangles().len() as i64,
        0
    );
    let floor = tube_ratio_floor(0.25, DEFAULT_CLEARANCE * knot.mesh.diagonal());
    // Measured 1.735, against a floor of 1.30 for any cage at this
    // clearance (1.88 before the final polishing; 2.28 against 1.63 at the
    // 1/128 clearance of before, 2.36 without the final tightening along
    // face normals, 2.48 without tightening when the collapses are stuck
    // either).
    assert!(floor > 1.29, "{floor}");
    assert!(
        ratio >= floor && ratio < 1.8,
        "ratio {ratio}, floor {floor}"
    );
}

/// A plate 1.2 % of its diagonal thick is enclosed with the clearance on both
/// sides, and the cage is no thicker than the clearance and a few voxels.
#[test]
fn a_thin_plate_is_enclosed_and_stays_thin() {
    let plate = shapes::thin_plate();
    let (generated, ratio) = generate("thin plate", &plate, 120);
    let stats = &generated.stats;
    let clearance = DEFAULT_CLEARANCE * plate.mesh.diagonal();
    assert!(stats.min_clearance >= 0.99 * clearance);
    // The cage's thickness in the middle of the plate, measured along z.
    let thickness = |x: f64, y: f64| {
        let (mut lo, mut hi) = (0.0, 0.0);
        while inside(&generated.cage, DVec3::new(x, y, hi)) {
            hi += 0.002;
        }
        while inside(&generated.cage, DVec3::new(x, y, lo)) {
            lo -= 0.002;
        }
        hi - lo
    };
    for (x, y) in [(0.0, 0.0), (1.0, 0.5), (-1.2, -0.7)] {
        let t = thickness(x, y);
        assert!(t >= 0.06 + 2.0 * clearance - 0.004, "({x}, {y}): {t}");
        assert!(
            t <= 0.06 + 2.0 * clearance + 3.0 * stats.cell_size,
            "({x}, {y}): {t}"
        );
    }
    // The plate is 0.06 thick: no cage is thinner than it and two clearances.
    assert!(
        ratio >= (0.06 + 2.0 * clearance) / 0.06 * 0.97 && ratio < 3.0,
        "ratio {ratio}"
    );
}

/// Two blobs 8 % and 2 % of the diagonal apart get two parts (2 %: the
/// voxels are made fine enough to keep the gap open); 1 % apart, closer
/// than the finest voxels chosen to keep a gap can keep (a quarter of the
/// gap, at least 1/256 of the diagonal), they share one, and the report
/// says their gap is bridged.
#[test]
fn two_blobs_apart_and_close() {
    for (gap, name) in [(0.4, "two blobs 8 % apart"), (0.1, "two blobs 2 % apart")] {
        let apart = shapes::two_blobs(gap);
        let (generated, _) = generate(name, &apart, 120);
        assert_eq!(generated.stats.shells, 2, "{name}");
        assert!(
            gap_points_inside(&apart, &generated.cage).is_empty(),
            "{name}"
        );
        assert!(!inside(&generated.cage, DVec3::ZERO), "{name}");
        assert_eq!(generated.stats.gaps.closed(), 0, "{name}");
    }

    let close = shapes::two_blobs(0.05);
    let (generated, _) = generate("two blobs 1 % apart", &close, 120);
    assert_eq!(generated.stats.shells, 1);
    // Where the blobs are closest the gap is bridged; further off the axis,
    // where it widens, it may stay open.
    assert!(inside(&generated.cage, DVec3::ZERO));
    let gaps = &generated.stats.gaps;
    assert!(
        gaps.closed() > 0 && gaps.widest_closed.is_some_and(|w| w >= 0.045),
        "{gaps:?}"
    );
}

/// Gap points are looked for along each face's outward normal, outward being
/// the side that gives the mesh a positive volume: the same blobs turned
/// inside out find the same gaps and keep them open.
#[test]
fn a_mesh_turned_inside_out_finds_the_same_gaps() {
    let apart = shapes::two_blobs(0.4);
    let mut inside_out = apart.clone();
    for t in &mut inside_out.mesh.triangles {
        t.swap(1, 2);
    }
    assert!(signed_volume(&inside_out.mesh.positions, &inside_out.mesh.triangles) < 0.0);
    let (generated, _) = generate("two blobs 8 % apart", &apart, 120);
    let (turned, _) = generate("the same, inside out", &inside_out, 120);
    assert!(generated.stats.gaps.points > 0);
    assert_eq!(turned.stats.gaps.points, generated.stats.gaps.points);
    assert_eq!(turned.stats.shells, 2);
    assert_eq!(turned.stats.gaps.closed(), 0);
}

/// The report lists the gap points the cage bridges, where the mesh is: two
/// blobs 1 % apart, far from the origin (the generator works about the mesh's
/// centre), give points inside the cage, between the blobs.
#[test]
fn the_bridged_gap_points_are_reported_where_the_mesh_is() {
    let offset = DVec3::new(40.0, -15.0, 7.0);
    let mut close = shapes::two_blobs(0.05);
    for p in &mut close.mesh.positions {
        *p += offset;
    }
    let (generated, _) = generate("two blobs 1 % apart, moved", &close, 120);
    let gaps = &generated.stats.gaps;
    assert!(gaps.closed() > 0);
    assert_eq!(gaps.bridged.len(), gaps.closed());
    for &p in &gaps.bridged {
        assert!(inside(&generated.cage, p), "{p} is not inside the cage");
        // Between the blobs (centred at ±1.05 along x): outside both, and
        // near the plane midway.
        let winding = winding_number(&close.mesh.positions, &close.mesh.triangles, p);
        assert!(winding.abs() < 0.5, "{p} is inside the mesh");
        assert!((p.x - offset.x).abs() < 0.5, "{p} is not between the blobs");
    }
}

/// A long block turned 45° about y: its bounding box is three times its
/// volume, but eight vertices can hold it with the clearance on every side,
/// the block grown by the clearance, which the prism along y finds (its
/// outline seen along y is a turned rectangle). The voxels and the bounding
/// box cannot turn their corners to it.
#[test]
fn a_turned_block_gets_a_turned_box_at_eight_vertices() {
    let half = DVec3::new(1.5, 2.0, 0.4);
    let cube = pmvc::geometry::procedural::cube_cage(1.0);
    let fine = pmvc::geometry::subdivide_midpoint(&cube, cube.positions()).unwrap();
    let turn = glam::DQuat::from_rotation_y(std::f64::consts::FRAC_PI_4);
    let positions: Vec<DVec3> = fine
        .cage
        .positions()
        .iter()
        .map(|p| turn * (*p * half) + DVec3::new(10.0, -4.0, 2.0))
        .collect();
    let block = Shape {
        mesh: pmvc::geometry::TriMesh {
            positions,
            triangles: fine.cage.triangles().to_vec(),
            triangle_faces: (0..fine.cage.triangles().len() as u32).collect(),
        },
        volume: 8.0 * half.x * half.y * half.z,
        gap_points: Vec::new(),
    };
    let (generated, ratio) = generate("turned block", &block, 8);
    assert_eq!(generated.cage.vertex_count(), 8);
    // The summary says where the cage came from, and what the voxel size was for.
    assert_eq!(generated.stats.start, CageStart::Prism { axis: 1 });
    let lines = pmvc::app::cage_generation::stats_lines(&generated.stats, false);
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("started from: the prism along y")),
        "{lines:?}"
    );
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("voxel size: ") && l.contains("replaced by the prism along y")),
        "{lines:?}"
    );
    // A prism begins around every part: no distance below which parts may
    // merge is claimed for it.
    assert_eq!(generated.stats.merge_distance(), f64::INFINITY);
    assert!(
        lines.iter().any(|l| l.starts_with(
            "parts of the mesh at any distance may share one part of the cage: the prism along y"
        )),
        "{lines:?}"
    );
    let clearance = DEFAULT_CLEARANCE * block.mesh.diagonal();
    let grown = 2.0 * (half + DVec3::splat(clearance));
    let snug = grown.x * grown.y * grown.z / block.volume;
    // Measured 1.007 times the grown block; 1.84 times without the prisms.
    assert!(
        ratio <= 1.05 * snug,
        "volume ratio {ratio}, grown block {snug}"
    );
}

/// A beam whose cross-section is an L (arms 3 long and 1 wide, area 5),
/// 8 long along x: twelve vertices can hold it as the L grown by the
/// clearance, extruded, which the prism over its traced outline finds. The
/// convex outline cannot go under the L's hull (area 7).
#[test]
fn an_l_beam_gets_an_l_shaped_prism_at_twelve_vertices() {
    let profile = [
        (0.0, 0.0),
        (3.0, 0.0),
        (3.0, 1.0),
        (1.0, 1.0),
        (1.0, 3.0),
        (0.0, 3.0),
    ];
    let (length, offset) = (8.0, DVec3::new(-20.0, 5.0, 7.0));
    let mut positions = Vec::new();
    for x in [0.0, length] {
        positions.extend(profile.iter().map(|&(y, z)| DVec3::new(x, y, z) + offset));
    }
    // Sides as quads split in two; each end as four triangles.
    let mut triangles = Vec::new();
    for i in 0..6u32 {
        let j = (i + 1) % 6;
        triangles.extend([[i, j, j + 6], [i, j + 6, i + 6]]);
    }
    for [a, b, c] in [[0u32, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]] {
        triangles.extend([[a, c, b], [a + 6, b + 6, c + 6]]);
    }
    let coarse = pmvc::geometry::TriMesh {
        positions,
        triangle_faces: (0..triangles.len() as u32).collect(),
        triangles,
    };
    let (mut cage, _) = Cage::new(coarse).expect("the L beam is closed and outward");
    for _ in 0..3 {
        cage = pmvc::geometry::subdivide_midpoint(&cage, cage.positions())
            .unwrap()
            .cage;
    }
    let beam = Shape {
        mesh: pmvc::geometry::TriMesh {
            positions: cage.positions().to_vec(),
            triangles: cage.triangles().to_vec(),
            triangle_faces: (0..cage.triangles().len() as u32).collect(),
        },
        volume: 5.0 * length,
        gap_points: Vec::new(),
    };
    let (generated, ratio) = generate("L beam", &beam, 12);
    assert_eq!(generated.stats.start, CageStart::Prism { axis: 0 });
    let c = DEFAULT_CLEARANCE * beam.mesh.diagonal();
    let grown_l = 2.0 * (3.0 + 2.0 * c) * (1.0 + 2.0 * c) - (1.0 + 2.0 * c).powi(2);
    let snug = grown_l * (length + 2.0 * c) / beam.volume;
    assert!(ratio <= 1.05 * snug, "volume ratio {ratio}, grown L {snug}");
}

//! Automatic cages (`cagegen::generate_cage`) against their documented
//! contract: a valid, closed, edge-manifold cage that strictly encloses every
//! point of the mesh's surface, follows its shape (prongs apart, holes open,
//! separate parts in separate shells), is about the requested size and tight,
//! and whose reported statistics agree with measurements made here.
//!
//! Everything is measured independently of the library: the winding number
//! (van Oosterom–Strackee solid angles), point–triangle distances, volumes,
//! angles and connected components are computed in this file.

use crate::common;

use common::measure::*;

use common::winding_number;
use glam::DVec3;
use pmvc::cagegen::{
    generate_cage, AutoCageError, CageOptions, GeneratedCage, DEFAULT_CELL_SIZE, DEFAULT_CLEARANCE,
};
use pmvc::coords::{cubemap::TexelTable, mvc, pmvc as pmvc_ref};
use pmvc::formats::load_mesh;
use pmvc::geometry::procedural;
use pmvc::geometry::{Cage, TriMesh};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

// Measurements made here, not by the library: `common::measure`.

// ---------------------------------------------------------------- shapes

fn mesh_of(cage: &Cage) -> TriMesh {
    mesh(cage.positions().to_vec(), cage.triangles().to_vec())
}

fn mesh(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> TriMesh {
    let triangle_faces = (0..triangles.len() as u32).collect();
    TriMesh {
        positions,
        triangles,
        triangle_faces,
    }
}

/// Five prongs 1 wide, 0.5 apart, 4 long, on a spine 1 wide, 1 deep.
fn comb() -> TriMesh {
    mesh_of(&procedural::extrude(
        &procedural::comb_outline(5, 1.0, 0.5, 4.0),
        -0.5,
        0.5,
    ))
}

fn torus() -> TriMesh {
    common::torus_mesh()
}

/// Two unit spheres on the x axis whose surfaces are `gap` apart.
fn two_blobs(gap: f64) -> TriMesh {
    common::shapes::two_blobs(gap).mesh
}

/// A unit sphere with its cap above z = 0.7 removed: open, with a hole.
/// An icosphere without its cap above z = 0.7, and without the cap's vertices
/// (no stray points).
fn open_sphere() -> TriMesh {
    let sphere = procedural::icosphere(1.0, 3);
    let kept: Vec<[u32; 3]> = sphere
        .triangles()
        .iter()
        .filter(|t| t.iter().any(|&i| sphere.positions()[i as usize].z < 0.7))
        .copied()
        .collect();
    let mut remap = vec![u32::MAX; sphere.vertex_count()];
    let mut positions = Vec::new();
    for &i in kept.iter().flatten() {
        if remap[i as usize] == u32::MAX {
            remap[i as usize] = positions.len() as u32;
            positions.push(sphere.positions()[i as usize]);
        }
    }
    let triangles = kept.iter().map(|t| t.map(|i| remap[i as usize])).collect();
    mesh(positions, triangles)
}

fn asset(name: &str) -> TriMesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets")
        .join(name);
    load_mesh(&path).expect("bundled asset loads").mesh
}

// ---------------------------------------------------------------- checks

fn generate_with(mesh: &TriMesh, options: CageOptions) -> GeneratedCage {
    generate_cage(mesh, &options, &|_| true)
        .unwrap_or_else(|error| panic!("no cage for {options:?}: {error}"))
}

fn generate(mesh: &TriMesh, target: usize) -> GeneratedCage {
    generate_with(mesh, CageOptions::new(target))
}

/// The checks every generated cage must pass, with `per_triangle` random surface
/// samples on each mesh triangle. Returns the cage's Euler characteristic.
fn check_cage(name: &str, mesh: &TriMesh, per_triangle: usize, generated: &GeneratedCage) -> i64 {
    let (cage, stats) = (&generated.cage, &generated.stats);
    let (positions, triangles) = (cage.positions(), cage.triangles());
    let diagonal = mesh.diagonal();
    eprintln!(
        "{name}: {} vertices (target {}), {} shells, volume ratio {:?}, clearance {:.4} \
         ({:.2} % of diagonal), min angle {:.1}°, {:.2} s",
        stats.vertices,
        stats.target_vertices,
        stats.shells,
        stats.volume_ratio(),
        stats.min_clearance,
        100.0 * stats.min_clearance / diagonal,
        stats.min_angle_degrees,
        stats.seconds
    );

    // Valid again on its own, already outward, every vertex used.
    let (_, report) = Cage::new(mesh_of(cage))
        .unwrap_or_else(|error| panic!("{name}: the generated cage does not validate: {error}"));
    assert!(!report.flipped, "{name}: cage faces inward");
    assert!(report.unreferenced.is_empty(), "{name}: unused vertices");

    // Closed and edge-manifold: every directed edge once, and its reverse once.
    let directed = directed_edges(triangles);
    for (&(a, b), &uses) in &directed {
        assert_eq!(uses, 1, "{name}: edge {a}→{b} used {uses} times");
        assert_eq!(directed.get(&(b, a)), Some(&1), "{name}: open edge {a}–{b}");
    }

    // Reported counts.
    let shells = components(positions.len(), triangles);
    assert_eq!(stats.shells, shells, "{name}: shells");
    assert_eq!(stats.vertices, positions.len(), "{name}: vertices");
    assert_eq!(stats.triangles, triangles.len(), "{name}: triangles");
    assert!((stats.mesh_diagonal - diagonal).abs() <= 1e-9 * diagonal);

    // Every point of the mesh's surface strictly inside: winding number 1.
    let samples = surface_samples(mesh, per_triangle, 17);
    let windings: Vec<f64> = samples.par_iter().map(|&x| cage_winding(cage, x)).collect();
    let outside = windings.iter().filter(|&&w| w <= 0.5).count();
    let worst = (0..samples.len())
        .min_by(|&a, &b| windings[a].total_cmp(&windings[b]))
        .unwrap();
    assert_eq!(
        outside,
        0,
        "{name}: {outside} of {} surface samples outside the cage (worst {:?}: winding {})",
        samples.len(),
        samples[worst],
        windings[worst]
    );
    assert!(
        windings.iter().all(|w| (w - 1.0).abs() < 1e-3),
        "{name}: winding number {} is not about 1",
        windings[worst]
    );
    assert_eq!(stats.outside_vertices, 0, "{name}: outside_vertices");

    // Clearance: brute force over mesh vertices × cage triangles.
    let clearance = mesh
        .positions
        .par_iter()
        .map(|&p| {
            (0..triangles.len())
                .map(|t| triangle_distance(p, cage.triangle(t)))
                .fold(f64::INFINITY, f64::min)
        })
        .reduce(|| f64::INFINITY, f64::min);
    assert!(stats.min_clearance > 0.0, "{name}: no clearance");
    assert!(
        (stats.min_clearance - clearance).abs() <= 1e-4 * clearance + 1e-12 * diagonal,
        "{name}: min_clearance {} but measured {clearance}",
        stats.min_clearance
    );

    // Volumes and angles.
    let volume = signed_volume(positions, triangles);
    assert!(volume > 0.0, "{name}: cage volume {volume}");
    assert!(
        (stats.cage_volume - volume).abs() <= 1e-9 * volume,
        "{name}: cage_volume {} but measured {volume}",
        stats.cage_volume
    );
    if is_closed(mesh) {
        // Its own volume, whichever way its faces point.
        let mesh_volume = signed_volume(&mesh.positions, &mesh.triangles).abs();
        assert!(!stats.mesh_volume_from_voxels, "{name}: closed mesh");
        assert!(
            (stats.mesh_volume - mesh_volume).abs() <= 1e-6 * mesh_volume,
            "{name}: mesh_volume {} but measured {mesh_volume}",
            stats.mesh_volume
        );
    } else {
        assert!(stats.mesh_volume_from_voxels, "{name}: open mesh");
        assert!(stats.mesh_volume > 0.0, "{name}: open mesh has no inside");
    }
    assert!(
        stats.volume_ratio().unwrap() > 1.0,
        "{name}: smaller than the mesh"
    );
    let angle = min_angle_degrees(positions, triangles);
    assert!(angle > 0.0, "{name}: degenerate triangle");
    assert!(
        (stats.min_angle_degrees - angle).abs() <= 1e-4,
        "{name}: min_angle_degrees {} but measured {angle}",
        stats.min_angle_degrees
    );

    let edges = directed.len() as i64 / 2;
    positions.len() as i64 - edges + triangles.len() as i64
}

/// Shapes whose parts must stay apart can need more vertices than asked for;
/// the generator then stops where every further collapse would merge parts or
/// loosen the cage past its limit. It must still have simplified far below the
/// voxel surface.
fn assert_simplified(name: &str, generated: &GeneratedCage) {
    let stats = &generated.stats;
    assert!(
        stats.vertices <= 5 * stats.target_vertices && stats.vertices * 20 < stats.surface_vertices,
        "{name}: {} vertices for a target of {} (voxel surface {})",
        stats.vertices,
        stats.target_vertices,
        stats.surface_vertices
    );
}

fn assert_target(name: &str, generated: &GeneratedCage) {
    let stats = &generated.stats;
    let (vertices, target) = (generated.cage.vertex_count() as f64, stats.target_vertices);
    assert!(
        (vertices - target as f64).abs() <= 0.15 * target as f64 && stats.target_reached(),
        "{name}: {vertices} vertices for a target of {target}"
    );
}

fn assert_outside(name: &str, cage: &Cage, x: DVec3, what: &str) {
    let w = cage_winding(cage, x);
    assert!(w.abs() < 1e-3, "{name}: {what} {x:?} has winding {w}");
}

// ---------------------------------------------------------------- shapes' tests

#[test]
fn comb_prongs_stay_apart_and_the_cage_is_tight() {
    let comb = comb();
    // The finest voxels, asked for: they are never coarsened.
    let options = CageOptions {
        cell_size: Some(DEFAULT_CELL_SIZE),
        ..CageOptions::new(120)
    };
    let generated = generate_with(&comb, options);
    assert_eq!(check_cage("comb", &comb, 4, &generated), 2);
    assert_simplified("comb", &generated);
    // Prongs span x ∈ [1.5k, 1.5k + 1], y ∈ [1, 5]: the gaps' centres.
    for k in 0..4 {
        let gap = DVec3::new(1.5 * k as f64 + 1.25, 3.0, 0.0);
        assert!(winding_number(&comb.positions, &comb.triangles, gap).abs() < 1e-9);
        assert_outside("comb", &generated.cage, gap, "the middle of the gap");
    }
    let ratio = generated.stats.volume_ratio().unwrap();
    assert!(ratio < 3.0, "comb: volume ratio {ratio}");
}

/// A target too small for the prongs to stay apart: the voxel size is chosen
/// coarser until the target is reached, and the stats say which was used and
/// under what distance parts may merge. Asked for, the finest voxels stay.
#[test]
fn a_small_target_is_reached_with_coarser_voxels_chosen_for_it() {
    let comb = comb();
    let diagonal = comb.diagonal();
    let generated = generate(&comb, 16);
    check_cage("comb at 16", &comb, 2, &generated);
    assert_target("comb at 16", &generated);
    let stats = &generated.stats;
    assert!(stats.cell_size_chosen);
    assert!(
        stats.cell_size > 1.5 * DEFAULT_CELL_SIZE * diagonal,
        "voxel size {} of the diagonal",
        stats.cell_size / diagonal
    );
    assert!(stats.merge_distance() >= 3.0 * stats.cell_size);
    // The prongs (0.5 apart) merge, and the summary never claims to keep apart
    // what the cage joined: its merge distance covers their gap and every gap
    // it reports bridged.
    for k in 0..4 {
        let gap = DVec3::new(1.5 * k as f64 + 1.25, 3.0, 0.0);
        assert!(
            cage_winding(&generated.cage, gap) > 0.5,
            "prong gap {k} open"
        );
    }
    assert!(stats.merge_distance() >= 0.5, "{}", stats.merge_distance());
    let widest = stats.gaps.widest_closed.expect("bridged gaps reported");
    assert!(
        widest <= stats.merge_distance(),
        "{widest} > {}",
        stats.merge_distance()
    );
    let asked = generate_with(
        &comb,
        CageOptions {
            cell_size: Some(DEFAULT_CELL_SIZE),
            ..CageOptions::new(16)
        },
    );
    assert!(!asked.stats.cell_size_chosen);
    assert!((asked.stats.cell_size / diagonal - DEFAULT_CELL_SIZE).abs() < 1e-12);
    assert!(asked.stats.vertices > generated.stats.vertices);
}

#[test]
fn torus_keeps_its_hole() {
    let torus = torus();
    assert!(winding_number(&torus.positions, &torus.triangles, DVec3::ZERO).abs() < 1e-9);
    let generated = generate(&torus, 48);
    let euler = check_cage("torus", &torus, 2, &generated);
    assert_eq!(generated.stats.shells, 1);
    assert_eq!(euler, 0, "the torus's cage has genus 1");
    assert_target("torus", &generated);
    assert_outside(
        "torus",
        &generated.cage,
        DVec3::ZERO,
        "the centre of the hole",
    );
    let ratio = generated.stats.volume_ratio().unwrap();
    assert!(ratio < 3.0, "torus: volume ratio {ratio}");
}

#[test]
fn two_blobs_apart_get_two_shells() {
    // Surfaces 6 % of the diagonal apart, voxels of 1 %: further apart than the
    // three voxels under which parts merge.
    let blobs = two_blobs(0.3);
    let gap = 0.3 / blobs.diagonal();
    assert!((0.05..0.07).contains(&gap), "gap {gap}");
    assert!(winding_number(&blobs.positions, &blobs.triangles, DVec3::ZERO).abs() < 1e-9);
    let options = CageOptions {
        cell_size: Some(0.01),
        ..CageOptions::new(40)
    };
    let generated = generate_with(&blobs, options);
    assert_eq!(check_cage("blobs", &blobs, 2, &generated), 4);
    assert_eq!(generated.stats.shells, 2);
    assert_simplified("blobs", &generated);
    assert_outside("blobs", &generated.cage, DVec3::ZERO, "the midpoint");
    let ratio = generated.stats.volume_ratio().unwrap();
    assert!(ratio < 2.5, "blobs: volume ratio {ratio}");
}

#[test]
fn open_sphere_with_a_hole_is_enclosed_and_not_hollow() {
    let open = open_sphere();
    let generated = generate(&open, 32);
    assert_eq!(check_cage("open sphere", &open, 3, &generated), 2);
    assert_eq!(generated.stats.shells, 1);
    assert_target("open sphere", &generated);
    let centre = cage_winding(&generated.cage, DVec3::ZERO);
    assert!((centre - 1.0).abs() < 1e-3, "centre winding {centre}");
    // Its voxelised inside is about the unit ball's volume.
    let volume = generated.stats.mesh_volume;
    assert!((volume / (4.0 / 3.0 * PI) - 1.0).abs() < 0.25, "{volume}");
}

#[test]
fn a_sphere_at_64_vertices_is_tight() {
    let sphere = mesh_of(&procedural::icosphere(1.0, 3));
    let generated = generate(&sphere, 64);
    assert_eq!(check_cage("sphere", &sphere, 2, &generated), 2);
    assert_target("sphere", &generated);
    let ratio = generated.stats.volume_ratio().unwrap();
    assert!(ratio < 2.0, "sphere: volume ratio {ratio}");
}

#[test]
fn a_box_reaches_eight_vertices() {
    let cube = procedural::cube_cage(1.0);
    let fine = pmvc::geometry::subdivide_midpoint(&cube, cube.positions()).unwrap();
    let fine = pmvc::geometry::subdivide_midpoint(&fine.cage, fine.cage.positions()).unwrap();
    let boxed = mesh_of(&fine.cage);
    let generated = generate(&boxed, 8);
    assert_eq!(check_cage("box", &boxed, 2, &generated), 2);
    assert_target("box", &generated);
    // Eight vertices can hold the box with its clearance on every side, a
    // box (2 + 2c)³, and the generator starts from that box as well as from
    // the voxels when the target allows eight vertices. The voxels' own cage
    // had two corners well out: 1.26 times that box before polishing, 1.14
    // after; the box start reaches it.
    let clearance = DEFAULT_CLEARANCE * boxed.diagonal();
    let snug = (2.0 + 2.0 * clearance).powi(3) / 8.0;
    let ratio = generated.stats.volume_ratio().unwrap();
    assert!(
        ratio <= 1.01 * snug,
        "box: volume ratio {ratio}, snug box {snug}"
    );
}

// ---------------------------------------------------------------- progress

#[test]
fn progress_is_monotone_within_0_and_1() {
    let seen = Mutex::new(Vec::new());
    let options = CageOptions::new(32);
    generate_cage(&open_sphere(), &options, &|fraction| {
        seen.lock().unwrap().push(fraction);
        true
    })
    .unwrap();
    let seen = seen.into_inner().unwrap();
    assert!(!seen.is_empty(), "progress never called");
    assert!(seen.iter().all(|f| (0.0..=1.0).contains(f)), "{seen:?}");
    assert!(seen.windows(2).all(|w| w[0] <= w[1]), "{seen:?}");
}

#[test]
fn a_progress_callback_returning_false_cancels() {
    let options = CageOptions::new(48);
    let result = generate_cage(&torus(), &options, &|_| false);
    assert_eq!(result.err(), Some(AutoCageError::Cancelled));
    // Cancelled part-way, at the second report.
    let calls = Mutex::new(0);
    let result = generate_cage(&torus(), &options, &|_| {
        let mut calls = calls.lock().unwrap();
        *calls += 1;
        *calls < 2
    });
    let calls = calls.into_inner().unwrap();
    if calls >= 2 {
        assert_eq!(result.err(), Some(AutoCageError::Cancelled));
    }
}

/// A cancel asked for once the tries are done (during the second starts or
/// the checks at the end) gives no cage: before, the callback's answer was
/// not read after the tries, and a cage came back.
#[test]
fn a_cancel_after_the_tries_gives_no_cage() {
    let options = CageOptions::new(16);
    for last in [0.95, 0.97, 1.0] {
        let result = generate_cage(&torus(), &options, &|fraction| fraction < last);
        assert_eq!(
            result.err(),
            Some(AutoCageError::Cancelled),
            "cancelled from {last}"
        );
    }
}

#[test]
fn the_same_input_gives_the_same_cage() {
    let comb = comb();
    let first = generate(&comb, 64);
    let second = generate(&comb, 64);
    assert_eq!(first.cage.positions(), second.cage.positions());
    assert_eq!(first.cage.triangles(), second.cage.triangles());
}

// ---------------------------------------------------------------- bundled and real data

/// The bundled comb: five fingers 1 wide, 1.4 apart (0.5 between their
/// surfaces), from y = 0.5 to 4.95, on a palm 1 high.
fn bundled_comb_gaps() -> Vec<DVec3> {
    (0..4)
        .map(|k| DVec3::new(1.4 * k as f64 + 1.2, 3.0, 0.0))
        .collect()
}

/// How far the upper halves of the two fingers beside the middle one move, with
/// PMVC and with MVC, when the cage vertices around the middle finger's tip are
/// pulled up 4.5 along it.
fn neighbours_moved(comb: &TriMesh, cage: &Cage) -> (f64, f64) {
    let moved: Vec<usize> = (0..cage.vertex_count())
        .filter(|&j| {
            let p = cage.positions()[j];
            p.y > 4.5 && p.x > 2.6 && p.x < 4.0
        })
        .collect();
    assert!(!moved.is_empty(), "no cage vertex around the middle tip");
    let lift = DVec3::new(0.0, 4.5, 0.0);
    let neighbours: Vec<DVec3> = comb
        .positions
        .iter()
        .filter(|p| p.y > 3.0 && p.y < 4.5)
        .filter(|p| (1.4..2.4).contains(&p.x) || (4.2..5.2).contains(&p.x))
        .step_by(5)
        .copied()
        .collect();
    assert!(neighbours.len() >= 40, "{} points", neighbours.len());
    let table = TexelTable::new(32);
    let displacement = |weights: &[f64]| moved.iter().map(|&j| weights[j] * lift).sum::<DVec3>();
    let (mut pmvc_worst, mut mvc_worst) = (0.0f64, 0.0f64);
    let mut weights = vec![0.0; cage.vertex_count()];
    for &x in &neighbours {
        let enclosed =
            pmvc_ref::pmvc_weights(x, cage, &table, &mut weights, &mut Default::default());
        assert!(enclosed, "{x:?} not enclosed");
        pmvc_worst = pmvc_worst.max(displacement(&weights).length());
        mvc::mvc_weights(x, cage, &mut weights, &mut Default::default());
        mvc_worst = mvc_worst.max(displacement(&weights).length());
    }
    eprintln!("neighbouring fingers move {pmvc_worst:e} with PMVC, {mvc_worst:e} with MVC");
    (pmvc_worst, mvc_worst)
}

/// The measurement below on the hand-made cage: it tells the cases apart.
#[test]
fn the_hand_made_comb_cage_keeps_the_neighbours_still_under_pmvc() {
    let comb = asset("comb_mesh.obj");
    let cage = Cage::new(asset("comb_cage.obj")).unwrap().0;
    for gap in bundled_comb_gaps() {
        assert_outside("hand-made comb cage", &cage, gap, "the middle of the gap");
    }
    let (pmvc_moved, mvc_moved) = neighbours_moved(&comb, &cage);
    assert!(pmvc_moved < 1e-6, "PMVC moves a neighbour by {pmvc_moved}");
    assert!(mvc_moved > 1e-3, "MVC moves the neighbours by {mvc_moved}");
}

/// The bundled comb at 120 vertices, with nothing else asked: the fingers stay
/// apart, and PMVC bound to the cage keep a finger still when the cage around
/// the next finger's tip moves, as with the hand-made cage (MVC move it).
#[test]
fn bundled_comb_fingers_stay_apart() {
    let comb = asset("comb_mesh.obj");
    let generated = generate(&comb, 120);
    assert_target("bundled comb", &generated);
    check_cage("bundled comb", &comb, 1, &generated);
    for gap in bundled_comb_gaps() {
        assert!(winding_number(&comb.positions, &comb.triangles, gap).abs() < 1e-6);
        assert_outside(
            "bundled comb",
            &generated.cage,
            gap,
            "the middle of the gap",
        );
    }
    // The summary promises what it kept: the fingers' 0.5 gaps are wider than
    // its merge distance, and no gap is reported bridged.
    let stats = &generated.stats;
    assert!(stats.merge_distance() < 0.5, "{}", stats.merge_distance());
    assert_eq!(stats.gaps.closed(), 0, "{:?}", stats.gaps);
    let (pmvc_moved, mvc_moved) = neighbours_moved(&comb, &generated.cage);
    assert!(pmvc_moved < 1e-6, "PMVC moves a neighbour by {pmvc_moved}");
    assert!(mvc_moved > 1e-3, "MVC moves the neighbours by {mvc_moved}");
}

/// At the hand-made cage's 40 vertices, and at 54, the fingers stay apart:
/// every gap point is reported open, none of the test's own points between
/// fingers is inside, PMVC keep the next finger still where MVC move it,
/// and the cage encloses less than the hand-made one (a prism over the
/// comb's outline, 0.1 off the mesh). The simplification alone stops at 54
/// vertices with every gap open; 40 is reached by a prism whose outline
/// keeps the slots between the fingers. (Before prisms were tried above 32
/// vertices, the 40-vertex cage came from coarser voxels and bridged 869 of
/// 5,600 gap points; before gap points were placed where gaps open out, it
/// joined two fingertips by a face above a gap and reported every gap open,
/// and PMVC moved a neighbour by 2.08.)
#[test]
fn bundled_comb_fingers_at_the_hand_made_cages_size() {
    let comb = asset("comb_mesh.obj");
    let hand_made = asset("comb_cage.obj");
    let hand_made_volume = signed_volume(&hand_made.positions, &hand_made.triangles);
    for target in [40, 54] {
        let name = format!("bundled comb at {target}");
        let generated = generate(&comb, target);
        assert_target(&name, &generated);
        check_cage(&name, &comb, 1, &generated);
        let gaps = &generated.stats.gaps;
        assert_eq!(gaps.closed(), 0, "{name}: {gaps:?}");
        let covered = bundled_comb_gaps()
            .into_iter()
            .filter(|&gap| {
                winding_number(generated.cage.positions(), generated.cage.triangles(), gap) > 0.5
            })
            .count();
        assert_eq!(covered, 0, "{name}: all open reported, {covered} inside");
        let (pmvc_moved, mvc_moved) = neighbours_moved(&comb, &generated.cage);
        assert!(
            pmvc_moved < 1e-4,
            "{name}: PMVC moves a neighbour by {pmvc_moved}"
        );
        assert!(
            mvc_moved > 0.1,
            "{name}: MVC moves the neighbours by {mvc_moved}"
        );
        let volume = signed_volume(generated.cage.positions(), generated.cage.triangles());
        assert!(
            volume < hand_made_volume,
            "{name}: {volume} against the hand-made cage's {hand_made_volume}"
        );
    }
}

#[test]
fn bundled_scan_is_enclosed_at_the_size_of_its_cage() {
    let scan = asset("scan_mesh.obj");
    let generated = generate(&scan, 162);
    check_cage("scan", &scan, 2, &generated);
    assert_simplified("scan", &generated);
    // Thin ears and trunk: only a sanity bound.
    let ratio = generated.stats.volume_ratio().unwrap();
    assert!(ratio < 4.0, "scan: volume ratio {ratio}");
}

fn qmvc_data() -> Option<PathBuf> {
    let candidates = [
        std::env::var_os("PMVC_QMVC_DATA").map(PathBuf::from),
        Some(Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/qmvc")),
        Some(PathBuf::from("/work/shared/data/qmvc")),
    ];
    candidates.into_iter().flatten().find(|path| path.is_dir())
}

/// The smallest real mesh of ../shared/data/qmvc, when present.
#[test]
fn the_smallest_real_mesh_is_enclosed() {
    let Some(data) = qmvc_data() else {
        eprintln!("not run: ../shared/data/qmvc is missing");
        return;
    };
    let smallest = std::fs::read_dir(&data)
        .unwrap()
        .filter_map(|entry| entry.ok().map(|entry| entry.path()))
        .filter(|path| {
            let name = path.file_name().unwrap().to_string_lossy();
            name.ends_with(".obj") && !name.contains("_Cage")
        })
        .min_by_key(|path| path.metadata().map(|m| m.len()).unwrap_or(u64::MAX));
    let Some(path) = smallest else {
        eprintln!("not run: no mesh in {}", data.display());
        return;
    };
    let mesh = load_mesh(&path).unwrap().mesh;
    let generated = generate(&mesh, 64);
    check_cage(&path.display().to_string(), &mesh, 0, &generated);
    assert_target("real mesh", &generated);
}

//! Automatic cages of the bundled comb and scan and of the shared real meshes:
//! fingers kept apart, neighbours kept still under PMVC, the size of the
//! hand-made cages reached. Measured as in [`super::autocage`].

use super::autocage::*;
use crate::common;
use common::measure::*;
use common::winding_number;
use glam::DVec3;
use pmvc::coords::{cubemap::TexelTable, mvc, pmvc as pmvc_ref};
use pmvc::formats::load_mesh;
use pmvc::geometry::{Cage, TriMesh};
use std::path::{Path, PathBuf};

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

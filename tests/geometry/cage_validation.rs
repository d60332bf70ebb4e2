//! Cage validation against self-intersection and misplaced shells: what the
//! issue's hostile tester found (a cube with a corner pushed through the far
//! faces was accepted as "inward-facing, flipped"), and no false alarm on the
//! real artist cages.

use glam::DVec3;
use pmvc::geometry::{procedural, Cage, CageError, TriMesh};
use std::path::Path;
use std::time::Instant;

fn mesh_of(cage: &Cage) -> TriMesh {
    TriMesh {
        positions: cage.positions().to_vec(),
        triangles: cage.triangles().to_vec(),
        ..Default::default()
    }
}

#[test]
fn a_cube_with_a_corner_pushed_through_the_far_faces_is_refused_naming_two_faces() {
    let cube = procedural::cube_cage(0.5);
    let mut mesh = mesh_of(&cube);
    // Corner 7 is (+½, +½, +½); push it through the faces at x = −½.
    mesh.positions[7] = DVec3::new(-1.0, 0.2, 0.1);
    let error = Cage::new(mesh).expect_err("a self-intersecting cage");
    let CageError::SelfIntersecting { first, second } = error else {
        panic!("{error}");
    };
    assert_ne!(first, second);
    let text = error.to_string();
    assert!(text.contains("crosses itself"), "{text}");
    assert!(
        text.contains(&format!("faces {} and {}", first + 1, second + 1)),
        "{text}"
    );
}

#[test]
fn a_solid_inside_a_solid_is_refused_and_a_cavity_accepted() {
    let outer = procedural::icosphere(2.0, 1);
    let inner = procedural::cube_cage(0.5);
    let combined = |reverse_inner: bool| {
        let mut mesh = mesh_of(&outer);
        let offset = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(inner.positions());
        mesh.triangles.extend(inner.triangles().iter().map(|t| {
            let mut t = t.map(|i| i + offset);
            if reverse_inner {
                t.reverse();
            }
            t
        }));
        mesh
    };
    let error = Cage::new(combined(false)).expect_err("nested solids");
    assert!(matches!(error, CageError::NestedShells { .. }), "{error}");
    assert!(error.to_string().contains("count twice"), "{error}");
    let (cavity, _) = Cage::new(combined(true)).expect("a cavity is a valid cage");
    assert_eq!(cavity.vertex_count(), outer.vertex_count() + 8);
}

#[test]
fn every_procedural_cage_still_validates() {
    let cages = [
        procedural::cube_cage(1.0),
        procedural::icosphere(1.0, 3),
        procedural::uv_sphere(1.0, 12, 24),
        procedural::extrude(&procedural::comb_outline(5, 1.0, 0.25, 4.0), -0.5, 0.5),
        procedural::extrude(&procedural::star_outline(6, 0.4, 1.0), -0.3, 0.3),
    ];
    for cage in cages {
        Cage::new(mesh_of(&cage)).expect("valid");
    }
}

/// The artist cages of ../shared/data/qmvc, when present: all validate. The
/// time of the self-intersection check is printed, not asserted.
#[test]
fn the_shared_artist_cages_validate() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/qmvc");
    let Ok(entries) = std::fs::read_dir(&data) else {
        eprintln!("not run: {} is missing", data.display());
        return;
    };
    let mut names: Vec<_> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.to_string_lossy().ends_with("_Cage.obj"))
        .collect();
    names.sort();
    assert!(!names.is_empty());
    for path in names {
        let started = Instant::now();
        let (cage, _) = pmvc::formats::load_cage(&path).unwrap_or_else(|error| panic!("{error}"));
        eprintln!(
            "{}: {} triangles validated in {:.1} ms",
            path.display(),
            cage.triangle_count(),
            started.elapsed().as_secs_f64() * 1e3
        );
    }
}

//! Automatic cages are bounded and do not depend on where the mesh is: what
//! grows with the clearance, the voxel size or the mesh's surface is predicted
//! and refused with its size and a value that would fit, and the same mesh
//! moved far from the origin gets the same cage, moved.
//!
//! Winding numbers and distances are computed here, relative to the object,
//! independently of the library.

use crate::common;

use common::winding_number;
use glam::DVec3;
use pmvc::cagegen::{generate_cage, plan_cage, AutoCageError, CageOptions};
use pmvc::geometry::procedural::{self, SplitMix64};
use pmvc::geometry::TriMesh;

fn sphere_at(offset: DVec3) -> TriMesh {
    let cage = procedural::icosphere(1.0, 3);
    TriMesh {
        positions: cage.positions().iter().map(|p| *p + offset).collect(),
        triangles: cage.triangles().to_vec(),
        triangle_faces: cage.triangle_faces().to_vec(),
    }
}

/// `count` vertices uniform in a box of side `side`, and `faces` triangles of
/// random distinct vertices: a surface with no structure, whose triangles
/// span the whole box.
pub fn noise_mesh(count: usize, faces: usize, side: f64, seed: u64) -> TriMesh {
    let mut random = SplitMix64(seed);
    let positions = (0..count)
        .map(|_| DVec3::new(random.unit(), random.unit(), random.unit()) * side)
        .collect();
    let mut pick = || (random.next_u64() % count as u64) as u32;
    let triangles: Vec<[u32; 3]> = (0..faces)
        .map(|_| loop {
            let t = [pick(), pick(), pick()];
            if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                break t;
            }
        })
        .collect();
    TriMesh {
        positions,
        triangle_faces: (0..triangles.len() as u32).collect(),
        triangles,
    }
}

/// A clearance of 1e-12 of the diagonal would need trillions of surface
/// samples: it is refused before anything is allocated, with the size and a
/// clearance that fits, and that clearance is accepted.
#[test]
fn a_tiny_clearance_is_refused_with_its_size_and_one_that_fits() {
    let sphere = sphere_at(DVec3::ZERO);
    let options = CageOptions {
        clearance: Some(1e-12),
        ..CageOptions::new(64)
    };
    let error = plan_cage(&sphere, &options).unwrap_err();
    let AutoCageError::TooManySamples { suggested, .. } = &error else {
        panic!("expected the samples to be refused, got {error:?}: {error}");
    };
    let message = error.to_string();
    assert!(message.contains("surface samples"), "{message}");
    assert!(message.contains("iB"), "no size in: {message}");
    assert!(message.contains("clearance of"), "{message}");
    // The same error from the generator itself, before any work.
    let from_generator = generate_cage(&sphere, &options, &|_| true).unwrap_err();
    assert_eq!(from_generator, error);
    // What it suggests is accepted.
    let fitting = CageOptions {
        clearance: Some(*suggested),
        ..options
    };
    plan_cage(&sphere, &fitting).unwrap();
}

/// A voxel size finer than the grid allows is coarsened, and the cage says so.
#[test]
fn a_voxel_size_finer_than_the_grid_allows_is_reported_as_coarsened() {
    let sphere = sphere_at(DVec3::ZERO);
    let options = CageOptions {
        cell_size: Some(1e-3),
        ..CageOptions::new(64)
    };
    let plan = plan_cage(&sphere, &options).unwrap();
    let diagonal = 2.0 * 3f64.sqrt() * sphere.positions.iter().map(|p| p.x).fold(0.0, f64::max);
    assert!(plan.cell_size > 1e-3 * diagonal, "{plan:?}");
    let asked = plan.cell_size_asked.expect("the asked voxel size is kept");
    assert!(
        (asked - 1e-3 * diagonal).abs() <= 1e-12 * diagonal,
        "{plan:?}"
    );
}

/// A wide clearance with fine voxels needs a grid with wide margins: refused
/// with its size and a voxel size that fits, which is accepted.
#[test]
fn a_grid_that_cannot_fit_is_refused_with_a_voxel_size_that_does() {
    let sphere = sphere_at(DVec3::ZERO);
    let options = CageOptions {
        clearance: Some(0.45),
        cell_size: Some(0.002),
        ..CageOptions::new(64)
    };
    let error = plan_cage(&sphere, &options).unwrap_err();
    let AutoCageError::GridTooLarge { suggested, .. } = &error else {
        panic!("expected the grid to be refused, got {error:?}: {error}");
    };
    let message = error.to_string();
    assert!(message.contains("voxel grid"), "{message}");
    assert!(message.contains("voxel size of"), "{message}");
    let fitting = CageOptions {
        cell_size: Some(*suggested),
        ..options
    };
    plan_cage(&sphere, &fitting).unwrap();
}

/// Random triangles across a box: their surface samples at the default
/// clearance would be hundreds of millions of points. Refused at once with the
/// size, and the clearance it suggests is accepted.
#[test]
fn a_noise_mesh_is_refused_with_its_size_or_fits() {
    let noise = noise_mesh(30_000, 60_000, 1.0, 5);
    let error = plan_cage(&noise, &CageOptions::new(64)).unwrap_err();
    let AutoCageError::TooManySamples {
        points, suggested, ..
    } = &error
    else {
        panic!("expected the samples to be refused, got {error:?}");
    };
    assert!(*points > 100_000_000, "{error}");
    let fitting = CageOptions {
        clearance: Some(*suggested),
        ..CageOptions::new(64)
    };
    plan_cage(&noise, &fitting).unwrap();
}

/// The same sphere at growing offsets gets the same cage, moved, with the
/// same guarantees: valid, enclosing, with the clearance reported.
#[test]
fn the_cage_does_not_depend_on_where_the_mesh_is() {
    let reference = generate_cage(&sphere_at(DVec3::ZERO), &CageOptions::new(64), &|_| true)
        .expect("a cage at the origin");
    let diagonal = reference.stats.mesh_diagonal;
    for offset in [1e3, 1e6, 1e7] {
        let shift = DVec3::new(offset, -0.5 * offset, 0.25 * offset);
        let sphere = sphere_at(shift);
        let generated = generate_cage(&sphere, &CageOptions::new(64), &|_| true)
            .unwrap_or_else(|error| panic!("offset {offset}: {error}"));
        let (cage, stats) = (&generated.cage, &generated.stats);
        assert_eq!(
            stats.vertices, reference.stats.vertices,
            "offset {offset}: vertex count"
        );
        let worst = cage
            .positions()
            .iter()
            .zip(reference.cage.positions())
            .map(|(p, q)| ((*p - shift) - *q).length())
            .fold(0.0, f64::max);
        assert!(
            worst <= 1e-6 * diagonal,
            "offset {offset}: a vertex moved {worst} (diagonal {diagonal})"
        );
        for p in &sphere.positions {
            let w = winding_number(cage.positions(), cage.triangles(), *p);
            assert!(
                (w - 1.0).abs() < 1e-6,
                "offset {offset}: winding {w} at {p}"
            );
        }
        assert!(
            (stats.min_clearance - reference.stats.min_clearance).abs() <= 1e-6 * diagonal,
            "offset {offset}: clearance {} against {}",
            stats.min_clearance,
            reference.stats.min_clearance
        );
        let ratio = stats.volume_ratio().unwrap();
        let expected = reference.stats.volume_ratio().unwrap();
        assert!(
            (ratio - expected).abs() <= 1e-6 * expected,
            "offset {offset}: volume ratio {ratio} against {expected}"
        );
    }
}

/// Open sheets stacked close together enclose nothing: the mesh volume the
/// cage is compared with is its winding-number volume, never more than its
/// bounding box.
#[test]
fn stacked_open_sheets_report_no_more_volume_than_their_box() {
    let mut mesh = TriMesh::default();
    let sheets = 6;
    for k in 0..sheets {
        let z = 0.02 * k as f64;
        let base = mesh.positions.len() as u32;
        mesh.positions.extend([
            DVec3::new(0.0, 0.0, z),
            DVec3::new(1.0, 0.0, z),
            DVec3::new(1.0, 1.0, z),
            DVec3::new(0.0, 1.0, z),
        ]);
        mesh.triangles
            .extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    }
    mesh.triangle_faces = (0..mesh.triangles.len() as u32).collect();
    let generated = generate_cage(&mesh, &CageOptions::new(16), &|_| true).unwrap();
    let stats = &generated.stats;
    let box_volume = 1.0 * 1.0 * 0.02 * (sheets - 1) as f64;
    assert!(stats.mesh_volume_from_voxels);
    assert!(
        stats.mesh_volume <= box_volume,
        "mesh volume {} in a box of {box_volume}",
        stats.mesh_volume
    );
}

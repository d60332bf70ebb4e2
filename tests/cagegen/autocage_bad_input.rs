//! Automatic cages refuse what they cannot enclose or were not asked for
//! properly, with an error that says why and with the numbers involved.

use glam::DVec3;
use pmvc::cagegen::{
    generate_cage, AutoCageError, CageOptions, MAX_TARGET_VERTICES, MIN_TARGET_VERTICES,
};
use pmvc::geometry::{procedural, TriMesh};

fn sphere() -> TriMesh {
    let cage = procedural::icosphere(1.0, 2);
    TriMesh {
        positions: cage.positions().to_vec(),
        triangles: cage.triangles().to_vec(),
        triangle_faces: cage.triangle_faces().to_vec(),
    }
}

fn run(mesh: &TriMesh, options: CageOptions) -> AutoCageError {
    match generate_cage(mesh, &options, &|_| true) {
        Ok(generated) => panic!(
            "expected an error for {options:?}, got a cage of {} vertices",
            generated.stats.vertices
        ),
        Err(error) => error,
    }
}

/// A `side` × `side` grid of squares in the plane z = 0, two triangles each.
fn flat_square(side: u32) -> TriMesh {
    let mut mesh = TriMesh::default();
    for j in 0..=side {
        for i in 0..=side {
            mesh.positions.push(DVec3::new(i as f64, j as f64, 0.0));
        }
    }
    let at = |i: u32, j: u32| j * (side + 1) + i;
    for j in 0..side {
        for i in 0..side {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            mesh.triangles.extend([[a, b, c], [a, c, d]]);
        }
    }
    mesh.triangle_faces = (0..mesh.triangles.len() as u32).collect();
    mesh
}

#[test]
fn a_mesh_without_triangles_is_refused() {
    let points = TriMesh {
        positions: sphere().positions,
        ..TriMesh::default()
    };
    let error = run(&points, CageOptions::new(32));
    assert_eq!(error, AutoCageError::NoTriangles);
    assert!(error.to_string().contains("no triangles"), "{error}");
    assert_eq!(
        run(&TriMesh::default(), CageOptions::new(32)),
        AutoCageError::NoTriangles
    );
}

#[test]
fn a_flat_mesh_is_refused() {
    let error = run(&flat_square(4), CageOptions::new(32));
    assert_eq!(error, AutoCageError::Flat);
    assert!(error.to_string().contains("flat"), "{error}");
    // A tilted plane is as flat as an axis-aligned one.
    let mut tilted = flat_square(4);
    for p in &mut tilted.positions {
        *p = DVec3::new(p.x, p.y * 0.6, p.y * 0.8 + 0.3 * p.x);
    }
    assert_eq!(run(&tilted, CageOptions::new(32)), AutoCageError::Flat);
    // So are points on one line, with triangles between them.
    let line = TriMesh {
        positions: (0..6).map(|k| DVec3::splat(k as f64)).collect(),
        triangles: vec![[0, 1, 2], [2, 3, 4], [3, 4, 5]],
        triangle_faces: vec![0, 1, 2],
    };
    assert_eq!(run(&line, CageOptions::new(32)), AutoCageError::Flat);
}

#[test]
fn too_few_vertices_are_refused_with_the_numbers() {
    let error = run(&sphere(), CageOptions::new(7));
    assert_eq!(error, AutoCageError::TooFewVertices { requested: 7 });
    let message = error.to_string();
    assert!(message.contains('7'), "{message}");
    assert!(
        message.contains(&MIN_TARGET_VERTICES.to_string()),
        "{message}"
    );
    assert_eq!(
        run(&sphere(), CageOptions::new(0)),
        AutoCageError::TooFewVertices { requested: 0 }
    );
}

#[test]
fn too_many_vertices_are_refused_with_the_numbers() {
    let mesh = sphere();
    let error = run(&mesh, CageOptions::new(10_000_000));
    assert_eq!(
        error,
        AutoCageError::TooManyVertices {
            requested: 10_000_000,
            mesh_vertices: mesh.positions.len()
        }
    );
    let message = error.to_string();
    for number in [10_000_000, MAX_TARGET_VERTICES, mesh.positions.len()] {
        assert!(message.contains(&number.to_string()), "{message}");
    }
    assert!(matches!(
        run(&mesh, CageOptions::new(MAX_TARGET_VERTICES + 1)),
        AutoCageError::TooManyVertices { .. }
    ));
}

#[test]
fn bad_clearances_and_voxel_sizes_are_refused_with_the_value() {
    let mesh = sphere();
    for value in [0.0, -0.01, 0.5, 2.0, f64::NAN, f64::INFINITY] {
        let options = CageOptions {
            clearance: Some(value),
            ..CageOptions::new(32)
        };
        let error = run(&mesh, options);
        assert!(
            matches!(error, AutoCageError::BadClearance { value: v } if v.to_bits() == value.to_bits()),
            "{value}: {error:?}"
        );
        assert!(error.to_string().contains(&value.to_string()), "{error}");
    }
    for value in [0.0, -0.1, 0.25, 1.0, f64::NAN] {
        let options = CageOptions {
            cell_size: Some(value),
            ..CageOptions::new(32)
        };
        let error = run(&mesh, options);
        assert!(
            matches!(error, AutoCageError::BadCellSize { value: v } if v.to_bits() == value.to_bits()),
            "{value}: {error:?}"
        );
        assert!(error.to_string().contains(&value.to_string()), "{error}");
    }
}

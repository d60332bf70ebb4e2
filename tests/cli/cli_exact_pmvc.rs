//! `pmvc bind --resolution exact`: PMVC with no cube map, as the command line
//! gives them: recorded as "exact" in W.json, equal to MVC in a convex cage,
//! positive, a partition of unity with linear precision in the comb, the cube
//! map converging to them as its resolution grows, quads split with a notice,
//! and the resolution's code (0) refused as a number.

use crate::cli_support;
use crate::common;
use cli_support::*;
use common::*;
use glam::DVec3;
use pmvc::geometry::procedural;
use std::path::Path;

fn read_weights(path: &Path) -> (usize, usize, Vec<f32>) {
    let (shape, values, _) = parse_npy_f32(&std::fs::read(path).unwrap());
    (shape[0], shape[1], values)
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn bind_pmvc(mesh: &Path, cage: &Path, out: &Path, resolution: &str) -> (usize, usize, Vec<f32>) {
    let output = bind(mesh, cage, "pmvc", out, &["--resolution", resolution]);
    assert!(output.status.success(), "{}", stderr(&output));
    read_weights(out)
}

#[test]
fn exact_pmvc_in_a_convex_cage_are_mvc_and_say_exact_in_their_metadata() {
    let dir = tempfile::tempdir().unwrap();
    let cage = procedural::cube_cage(2.0);
    let points = procedural::points_inside(&cage, 60, 3, 1e-2);
    let mesh = write(dir.path(), "mesh.obj", &points_obj(&points));
    let cage_path = write(dir.path(), "cage.obj", &cage_obj(&cage));

    let exact = dir.path().join("exact.npy");
    let (rows, cols, exact_values) = bind_pmvc(&mesh, &cage_path, &exact, "exact");
    assert_eq!((rows, cols), (points.len(), cage.vertex_count()));
    let metadata = read_json(&dir.path().join("exact.json"));
    assert_eq!(metadata["parameters"]["resolution"], "exact", "{metadata}");

    let mvc = dir.path().join("mvc.npy");
    let output = bind(&mesh, &cage_path, "mvc", &mvc, &[]);
    assert!(output.status.success(), "{}", stderr(&output));
    let (_, _, mvc_values) = read_weights(&mvc);
    let worst = exact_values
        .iter()
        .zip(&mvc_values)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    // Both rounded to float32 from values equal to 1e-12.
    assert!(worst <= 2.0 * f32::EPSILON, "exact PMVC − MVC: {worst}");

    // Read back by `pmvc deform --weights`, which checks the metadata.
    let pose: Vec<DVec3> = cage.positions().iter().map(|&p| p * 1.5).collect();
    let pose_path = write(
        dir.path(),
        "pose.obj",
        &triangles_obj(&pose, cage.triangles()),
    );
    let out = dir.path().join("deformed.obj");
    let output = deform(
        &mesh,
        &cage_path,
        &pose_path,
        &out,
        &["--weights", exact.to_str().unwrap()],
    );
    assert!(output.status.success(), "{}", stderr(&output));
    let deformed = obj_vertices(&out);
    for (moved, rest) in deformed.iter().zip(&points) {
        assert!(
            (*moved - *rest * 1.5).length() < 1e-5,
            "{moved} vs {}",
            *rest * 1.5
        );
    }
}

#[test]
fn exact_pmvc_in_the_comb_are_positive_reproduce_points_and_the_cube_map_approaches_them() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, points) = comb_scene(dir.path(), 80);
    let (rows, cols, exact) = bind_pmvc(&mesh, &cage_path, &dir.path().join("exact.npy"), "exact");
    assert_eq!(rows, points.len());
    for (row, &x) in exact.chunks(cols).zip(&points) {
        assert!(row.iter().all(|&w| w >= 0.0), "a negative weight at {x}");
        let sum: f64 = row.iter().map(|&w| f64::from(w)).sum();
        assert!((sum - 1.0).abs() < 1e-6, "row sum {sum} at {x}");
        let reproduced: DVec3 = row
            .iter()
            .zip(cage.positions())
            .map(|(&w, &v)| v * f64::from(w))
            .sum();
        assert!((reproduced - x).length() < 1e-5, "{reproduced} for {x}");
    }
    // The cube map's error against exact falls as its resolution grows (as 1/R:
    // docs/coordinates.md); the comb is where PMVC differ from MVC.
    let mean_error = |resolution: &str| {
        let name = format!("cube{resolution}.npy");
        let (_, _, cube) = bind_pmvc(&mesh, &cage_path, &dir.path().join(name), resolution);
        cube.iter()
            .zip(&exact)
            .map(|(a, b)| f64::from((a - b).abs()))
            .sum::<f64>()
            / cube.len() as f64
    };
    let (coarse, fine) = (mean_error("8"), mean_error("64"));
    assert!(fine < coarse / 4.0, "8²: {coarse}, 64²: {fine}");
    assert!(fine > 0.0, "the cube map is an approximation");
}

#[test]
fn exact_pmvc_take_a_cage_s_quads_as_patches() {
    let dir = tempfile::tempdir().unwrap();
    let cage = pmvc::geometry::procedural_quads::quad_comb(3, 1.0, 0.5, 2.0, 1.0, 0.0);
    assert!(cage.has_quads());
    let points = procedural::points_inside(&cage, 20, 3, 1e-2);
    let mesh = write(dir.path(), "mesh.obj", &points_obj(&points));
    let mut text = points_obj(cage.positions());
    for polygon in cage.polygons() {
        let corners: Vec<String> = polygon.iter().map(|i| (i + 1).to_string()).collect();
        text.push_str(&format!("f {}\n", corners.join(" ")));
    }
    let cage_path = write(dir.path(), "cage.obj", &text);
    let out = dir.path().join("w.npy");
    let output = bind(&mesh, &cage_path, "pmvc", &out, &["--resolution", "exact"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let said = stderr(&output);
    assert!(!said.contains("split"), "{said}");
    let metadata = read_json(&dir.path().join("w.json"));
    let name = metadata["method_name"].as_str().unwrap();
    assert!(!name.contains("split"), "{metadata}");
}

#[test]
fn resolution_zero_is_refused_and_the_message_names_exact() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, _, _) = comb_scene(dir.path(), 4);
    for value in ["0", "fine"] {
        let output = bind(
            &mesh,
            &cage_path,
            "pmvc",
            &dir.path().join("w.npy"),
            &["--resolution", value],
        );
        assert_eq!(output.status.code(), Some(1), "{value}");
        let said = stderr(&output);
        assert!(said.contains("exact"), "{value}: {said}");
    }
    assert!(!dir.path().join("w.npy").exists());
}

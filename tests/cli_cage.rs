//! `pmvc cage` end to end: the cage it writes loads as a valid cage around the
//! mesh, OFF meshes work, outputs are protected as for the other commands, and
//! bad input fails with status 1 and a message naming the file.

mod common;
use common::*;
use pmvc::geometry::{classify_points, load_cage, load_mesh, procedural};
use std::path::{Path, PathBuf};
use std::process::Output;

fn comb_mesh() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/comb_mesh.obj")
}

fn generate(mesh: &Path, vertices: &str, out: &Path) -> Output {
    pmvc(&[
        "cage",
        "--mesh",
        path_str(mesh),
        "--vertices",
        vertices,
        "--out",
        path_str(out),
    ])
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// The cage at `path` is valid and every vertex of `mesh` lies inside it.
fn assert_encloses(path: &Path, mesh: &Path) {
    let (cage, _) = load_cage(path).expect("the written cage loads as a valid cage");
    let mesh = load_mesh(mesh).unwrap();
    let classes = classify_points(&cage, &mesh.mesh.positions);
    assert!(
        classes.outside.is_empty(),
        "{} mesh vertices lie outside the generated cage",
        classes.outside.len()
    );
}

#[test]
fn a_cage_around_the_comb_is_written_and_its_properties_printed() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cage.obj");
    let output = generate(&comb_mesh(), "64", &out);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_encloses(&out, &comb_mesh());
    let text = stdout(&output);
    let (cage, _) = load_cage(&out).unwrap();
    assert!(
        text.contains(&format!("vertices: {} (target 64)", cage.vertex_count())),
        "{text}"
    );
    for heading in [
        "wrote ",
        "shell",
        "minimum clearance: ",
        "% of the mesh diagonal",
        "volume ratio (cage / mesh): ",
        "minimum angle: ",
        "time: ",
    ] {
        assert!(text.contains(heading), "no '{heading}' in: {text}");
    }
    // Reached or not, the summary says which.
    let within = (cage.vertex_count() as f64 - 64.0).abs() <= 0.15 * 64.0;
    assert_eq!(!within, text.contains("target not reached"), "{text}");
}

/// Without a voxel size, the generator chooses one for the target and says so,
/// with the distance under which parts may merge: the comb reaches 8 vertices
/// (a box). A voxel size that is asked for is used as asked, and the finest
/// keeps the fingers apart at the cost of the target.
#[test]
fn the_voxel_size_is_chosen_or_used_as_asked_and_reported() {
    let dir = tempfile::tempdir().unwrap();
    let (chosen, fine) = (dir.path().join("chosen.obj"), dir.path().join("fine.obj"));
    let auto = generate(&comb_mesh(), "8", &chosen);
    assert!(auto.status.success(), "{}", stderr(&auto));
    let text = stdout(&auto);
    assert!(text.contains("chosen for the target"), "{text}");
    assert!(text.contains("may share one part of the cage"), "{text}");
    let asked = pmvc(&[
        "cage",
        "--mesh",
        path_str(&comb_mesh()),
        "--vertices",
        "8",
        "--cell-size",
        "0.0078125",
        "--out",
        path_str(&fine),
    ]);
    assert!(asked.status.success(), "{}", stderr(&asked));
    let text = stdout(&asked);
    assert!(
        text.contains("(0.78% of the mesh diagonal, as asked)"),
        "{text}"
    );
    assert!(text.contains("target not reached"), "{text}");
    let count = |path: &Path| load_cage(path).unwrap().0.vertex_count();
    assert!((7..=9).contains(&count(&chosen)), "{}", count(&chosen));
    assert!(count(&fine) > 20, "{}", count(&fine));
}

#[test]
fn an_off_mesh_gets_a_cage() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = procedural::icosphere(1.0, 2);
    let mut off = format!(
        "OFF\n{} {} 0\n",
        sphere.vertex_count(),
        sphere.triangle_count()
    );
    for p in sphere.positions() {
        off.push_str(&format!("{} {} {}\n", p.x, p.y, p.z));
    }
    for [a, b, c] in sphere.triangles() {
        off.push_str(&format!("3 {a} {b} {c}\n"));
    }
    let mesh = write(dir.path(), "sphere.off", &off);
    let out = dir.path().join("sphere_cage.obj");
    let output = generate(&mesh, "32", &out);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_encloses(&out, &mesh);
    assert!(stdout(&output).contains("(target 32)"));
}

#[test]
fn inputs_are_never_overwritten_and_an_existing_output_survives_a_failure() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("comb.obj");
    std::fs::copy(comb_mesh(), &mesh).unwrap();
    let before = std::fs::read(&mesh).unwrap();
    assert_clean_failure(
        &generate(&mesh, "64", &mesh),
        path_str(&mesh),
        "never overwrites",
    );
    assert_eq!(std::fs::read(&mesh).unwrap(), before);

    let out = write(dir.path(), "old_cage.obj", "# an earlier cage\n");
    let output = generate(&mesh, "3", &out);
    assert_eq!(output.status.code(), Some(1));
    assert_eq!(
        std::fs::read_to_string(&out).unwrap(),
        "# an earlier cage\n"
    );
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
    // A run that succeeds replaces it, as every command's output.
    let output = generate(&mesh, "64", &out);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_encloses(&out, &mesh);
}

#[test]
fn too_few_or_too_many_vertices_fail_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cage.obj");
    let mesh = comb_mesh();
    assert_clean_failure(
        &generate(&mesh, "3", &out),
        "comb_mesh.obj",
        "at least 8 vertices",
    );
    assert_clean_failure(
        &generate(&mesh, "10000000", &out),
        "comb_mesh.obj",
        "more than the 20000",
    );
    assert!(!out.exists());
}

#[test]
fn a_mesh_without_triangles_fails_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let (points, _, _, _) = comb_scene(dir.path(), 50);
    let out = dir.path().join("generated.obj");
    assert_clean_failure(
        &generate(&points, "16", &out),
        path_str(&points),
        "no triangles",
    );
    assert!(!out.exists());
}

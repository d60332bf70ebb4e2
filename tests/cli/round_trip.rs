//! Files that come from other tools and go back to them: material libraries
//! that resolve from where a deformed copy is written, and files of several
//! objects, of which one is picked by name.

use crate::common;
use common::*;

const TILE: &str = "# a tile\nmtllib tile.mtl\no tile\nv -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nvt 0 0\nvt 1 0\nvt 1 1\nusemtl stone\nf 1/1 2/2 3/3\n";

#[test]
fn a_deformed_obj_in_another_folder_names_its_material_library_by_a_path_that_resolves() {
    let dir = tempfile::tempdir().unwrap();
    let models = dir.path().join("models");
    let out_dir = dir.path().join("out");
    std::fs::create_dir_all(&models).unwrap();
    std::fs::create_dir_all(&out_dir).unwrap();
    let cage = write(
        &models,
        "cage.obj",
        &cage_obj(&pmvc::geometry::procedural::cube_cage(1.0)),
    );
    let mesh = write(&models, "tile.obj", TILE);
    write(&models, "tile.mtl", "newmtl stone\nmap_Kd stone.png\n");
    let out = out_dir.join("posed.obj");
    let output = deform_with(&mesh, &cage, &cage, &out, &["--backend", "cpu"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = std::fs::read_to_string(&out).unwrap();
    let line = text.lines().find(|l| l.starts_with("mtllib")).unwrap();
    assert_eq!(line, "mtllib ../models/tile.mtl");
    let named = line.strip_prefix("mtllib ").unwrap();
    assert!(
        out_dir.join(named).is_file(),
        "resolves from the output's folder"
    );
    let said = stderr(&output);
    assert!(
        said.contains("material library tile.mtl is referred to as ../models/tile.mtl"),
        "{said}"
    );

    // Beside the source, the name stays as written and nothing is said.
    let beside = models.join("posed.obj");
    let output = deform_with(&mesh, &cage, &cage, &beside, &["--backend", "cpu"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = std::fs::read_to_string(&beside).unwrap();
    assert!(text.lines().any(|l| l == "mtllib tile.mtl"), "{text}");
    assert!(!stderr(&output).contains("material library"));
}

/// A scene as Blender exports it: the cage and the mesh as objects of one
/// OBJ, the cage scaled by `scale` (an affine pose, reproduced exactly).
fn scene_obj(scale: f64) -> String {
    let cage = pmvc::geometry::procedural::cube_cage(1.0);
    let mut text = String::from("mtllib scene.mtl\no Cage\n");
    for p in cage.positions() {
        text.push_str(&format!(
            "v {} {} {}\n",
            scale * p.x,
            scale * p.y,
            scale * p.z
        ));
    }
    for [a, b, c] in cage.triangles() {
        text.push_str(&format!("f {} {} {}\n", a + 1, b + 1, c + 1));
    }
    text.push_str("o Mesh\nv 0.1 0.1 0.1\nv 0.3 0.1 0.1\nv 0.1 0.3 0.1\nvt 0 0\nvt 1 0\nvt 0 1\n");
    text.push_str("usemtl skin\nf -3/1 -2/2 -1/3\n");
    text
}

#[test]
fn objects_of_one_file_are_named_and_picked_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write(dir.path(), "scene.obj", &scene_obj(1.0));
    let pose = write(dir.path(), "pose.obj", &scene_obj(2.0));
    let out = dir.path().join("posed.obj");
    let output = pmvc(&[
        "deform",
        "--mesh",
        path_str(&scene),
        "--mesh-object",
        "Mesh",
        "--cage",
        path_str(&scene),
        "--cage-object",
        "Cage",
        "--deformed-cage",
        path_str(&pose),
        "--backend",
        "cpu",
        "--out",
        path_str(&out),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    // The copy is the picked object alone, re-indexed, with its material.
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.lines().any(|l| l == "o Mesh"), "{text}");
    assert!(!text.contains("o Cage"), "{text}");
    assert!(text.lines().any(|l| l == "usemtl skin"), "{text}");
    assert!(text.lines().any(|l| l == "f 1/1/1 2/2/2 3/3/3"), "{text}");
    let deformed = pmvc::formats::load_mesh(&out).unwrap().mesh.positions;
    let expected = [[0.2, 0.2, 0.2], [0.6, 0.2, 0.2], [0.2, 0.6, 0.2]];
    assert_eq!(deformed.len(), 3);
    for (p, e) in deformed.iter().zip(expected) {
        assert!(p.distance(glam::DVec3::from_array(e)) < 1e-6, "{p}");
    }

    // Without a name the objects are read together, and a note says so.
    let cage = write(
        dir.path(),
        "cage.obj",
        &cage_obj(&pmvc::geometry::procedural::cube_cage(1.0)),
    );
    let output = pmvc(&[
        "check",
        "--mesh",
        path_str(&scene),
        "--cage",
        path_str(&cage),
    ]);
    let said = stderr(&output);
    assert!(
        said.contains(
            "note: the file has 2 objects: 'Cage', 'Mesh', read together as one mesh; --mesh-object NAME reads one alone"
        ),
        "{said}"
    );
    // A name the file does not have lists those it has.
    let output = pmvc(&[
        "check",
        "--mesh",
        path_str(&scene),
        "--mesh-object",
        "Body",
        "--cage",
        path_str(&cage),
    ]);
    assert!(!output.status.success());
    let said = stderr(&output);
    assert!(
        said.contains(
            "scene.obj: no object is named 'Body'; the file has 2 objects: 'Cage', 'Mesh'"
        ),
        "{said}"
    );
    let output = pmvc(&[
        "check",
        "--mesh",
        path_str(&scene),
        "--mesh-object",
        " ",
        "--cage",
        path_str(&cage),
    ]);
    assert!(!output.status.success());
    assert!(stderr(&output).contains("an object name cannot be empty"));
}

#[test]
fn the_weights_record_which_objects_were_bound() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write(dir.path(), "scene.obj", &scene_obj(1.0));
    let weights = dir.path().join("W.npy");
    let output = pmvc(&[
        "bind",
        "--mesh",
        path_str(&scene),
        "--mesh-object",
        "Mesh",
        "--cage",
        path_str(&scene),
        "--cage-object",
        "Cage",
        "--method",
        "mvc",
        "--backend",
        "cpu",
        "--out",
        path_str(&weights),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let metadata = pmvc::formats::metadata::read_metadata(&dir.path().join("W.json")).unwrap();
    assert_eq!(metadata.mesh.object.as_deref(), Some("Mesh"));
    assert_eq!(metadata.cage.object.as_deref(), Some("Cage"));
    assert_eq!(metadata.mesh.points, 3);
    let text = std::fs::read_to_string(dir.path().join("W.json")).unwrap();
    assert!(text.contains("\"object\": \"Mesh\""), "{text}");
}

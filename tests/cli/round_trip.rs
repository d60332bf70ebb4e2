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
    let output = pmvc(&[
        "deform",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage),
        "--deformed-cage",
        path_str(&cage),
        "--backend",
        "cpu",
        "--out",
        path_str(&out),
    ]);
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
    let output = pmvc(&[
        "deform",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage),
        "--deformed-cage",
        path_str(&cage),
        "--backend",
        "cpu",
        "--out",
        path_str(&beside),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = std::fs::read_to_string(&beside).unwrap();
    assert!(text.lines().any(|l| l == "mtllib tile.mtl"), "{text}");
    assert!(!stderr(&output).contains("material library"));
}

//! The bundled scene files in `assets/` match their generators and are valid.
//! Run with `PMVC_REGENERATE_ASSETS=1` to rewrite them (the scanned mesh is read
//! from the OFF file named by `PMVC_SCAN_SOURCE`, see assets/README.md).

use glam::DVec3;
use pmvc::app::scenes::{comb_cage, comb_mesh, BundledScene};
use pmvc::formats::{load_cage, load_mesh, write_obj_to};
use pmvc::geometry::classify_points;
use pmvc::geometry::procedural::star_cage;
use std::path::Path;

fn assets() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/assets"))
}

/// OBJ text through the product's one OBJ writer.
fn obj_text(positions: &[DVec3], triangles: &[[u32; 3]]) -> String {
    let mut text = Vec::new();
    write_obj_to(&mut text, positions, triangles).unwrap();
    String::from_utf8(text).unwrap()
}

fn regenerate() -> bool {
    std::env::var_os("PMVC_REGENERATE_ASSETS").is_some()
}

#[test]
fn comb_assets_match_the_generator() {
    let mesh = comb_mesh();
    let cage = comb_cage();
    let mesh_text = obj_text(&mesh.positions, &mesh.triangles);
    let cage_text = obj_text(cage.positions(), cage.triangles());
    if regenerate() {
        std::fs::write(assets().join("comb_mesh.obj"), &mesh_text).unwrap();
        std::fs::write(assets().join("comb_cage.obj"), &cage_text).unwrap();
    }
    assert_eq!(
        std::fs::read_to_string(assets().join("comb_mesh.obj")).unwrap(),
        mesh_text
    );
    assert_eq!(
        std::fs::read_to_string(assets().join("comb_cage.obj")).unwrap(),
        cage_text
    );
    assert!(mesh.positions.len() >= 5000, "several thousand vertices");
    let classes = classify_points(&cage, &mesh.positions);
    assert!(
        classes.outside.is_empty(),
        "the comb mesh lies inside its cage"
    );
    load_cage(&assets().join("comb_cage.obj")).expect("the comb cage validates");
}

#[test]
fn scan_assets_are_valid_and_enclosed() {
    if regenerate() {
        if let Some(source) = std::env::var_os("PMVC_SCAN_SOURCE") {
            let file = load_mesh(Path::new(&source)).unwrap();
            let mesh = &file.mesh;
            let cage = star_cage(&mesh.positions, 2, 22.0, 0.06);
            std::fs::write(
                assets().join("scan_mesh.obj"),
                obj_text(&mesh.positions, &mesh.triangles),
            )
            .unwrap();
            std::fs::write(
                assets().join("scan_cage.obj"),
                obj_text(cage.positions(), cage.triangles()),
            )
            .unwrap();
        }
    }
    let mesh = load_mesh(&assets().join("scan_mesh.obj")).expect("scan mesh loads");
    let (cage, _) = load_cage(&assets().join("scan_cage.obj")).expect("scan cage validates");
    let classes = classify_points(&cage, &mesh.mesh.positions);
    assert!(
        classes.outside.is_empty(),
        "{} scan vertices outside",
        classes.outside.len()
    );
    // The embedded copy goes through the same loader: identical to reading the files.
    let (bundled_mesh, bundled_cage) = BundledScene::Scan.build().expect("bundled scan loads");
    assert_eq!(bundled_mesh, mesh.mesh);
    assert_eq!(bundled_cage, cage);
}

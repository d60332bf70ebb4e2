//! Files dropped on the window: a dialog asks what the file is, offering it as a
//! pose when its vertex count matches the cage, and says what each choice does;
//! a mesh and its cage dropped together open as one scene.

use crate::common;

use common::editor::*;
use egui_kittest::kittest::Queryable;
use glam::DVec3;
use pmvc::coords::Method;

#[test]
fn a_dropped_file_with_the_cages_vertex_count_is_offered_as_a_pose() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let dir = tempfile::tempdir().unwrap();
    let cage = harness.state().document().cage().clone();
    let posed: Vec<DVec3> = cage
        .positions()
        .iter()
        .map(|&p| p + DVec3::new(0.0, 0.1 * p.y, 0.0))
        .collect();
    // Named like the dataset's posed cages, which used to replace the rest cage.
    let path = common::write(
        dir.path(),
        "Comb_Cage_Deformed.obj",
        &common::triangles_obj(&posed, cage.triangles()),
    );
    let binds = harness.state().bind_count();
    drop_files(&mut harness, &[path]);
    assert!(harness.state().pending_drop().is_some());
    harness.get_by_label_contains("moves the 40 cage handles");
    harness.get_by_label("Use as pose").click();
    harness.run_steps(3);
    let app = harness.state();
    assert!(app.pending_drop().is_none());
    assert_eq!(app.document().pose(), posed.as_slice());
    assert_eq!(
        app.document().cage().positions(),
        cage.positions(),
        "the rest cage stays"
    );
    assert_eq!(app.bind_count(), binds, "a pose needs no bind");
    // Undo returns to the rest pose.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    let app = harness.state();
    assert_eq!(app.document().pose(), cage.positions());
}

#[test]
fn a_dropped_mesh_opens_as_the_mesh_when_asked_and_reports_outside_vertices() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let directory = tempfile::tempdir().unwrap();
    // Two vertices inside the comb cage's palm, one far outside it.
    let mesh = directory.path().join("dropped.obj");
    std::fs::write(&mesh, "v 1 0.5 0\nv 2 0.5 0\nv 1 0.5 9\nf 1 2 3\n").unwrap();
    drop_files(&mut harness, &[mesh]);
    assert!(
        !harness.state().is_binding(),
        "nothing happens before the choice"
    );
    harness.get_by_label("Open as mesh").click();
    harness.step();
    assert!(harness.state().is_binding(), "the chosen mesh rebinds");
    run_until_bound(&mut harness);
    let app = harness.state();
    assert_eq!(app.document().mesh().positions.len(), 3);
    assert_eq!(app.document().outside(), vec![2]);
    assert_eq!(app.document().weights(Method::Pmvc).unwrap().rows, 3);
}

#[test]
fn a_mesh_and_its_cage_dropped_together_open_as_one_scene() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, points) = common::comb_scene(dir.path(), 50);
    // The cage first, to show the order does not matter; its name says "cage".
    drop_files(&mut harness, &[cage_path, mesh]);
    assert!(harness.state().pending_drop().is_none());
    run_until_bound(&mut harness);
    let app = harness.state();
    assert_eq!(app.document().mesh().positions, points);
    assert_eq!(app.document().cage().vertex_count(), cage.vertex_count());
    assert_eq!(
        app.undo_label().as_deref(),
        Some("open mesh.obj and cage.obj")
    );
}

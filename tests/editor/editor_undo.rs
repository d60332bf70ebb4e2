//! Undo of the actions that replace the scene: opening a cage, subdividing it,
//! switching scenes and using the pose as rest shape come back with Ctrl+Z, with
//! their weights and without binding again, in one order with pose edits.

use crate::common;

use common::editor::*;
use common::{cage_obj, write};
use egui::{Key, Modifiers};
use egui_kittest::Harness;
use glam::DVec3;
use pmvc::app::editor::FileRole;
use pmvc::app::EditorApp;
use pmvc::coords::Method;
use pmvc::geometry::classify_points;

fn press_undo(harness: &mut Harness<'static, EditorApp>) {
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
}

fn press_redo(harness: &mut Harness<'static, EditorApp>) {
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    harness.run_steps(2);
}

/// What identifies a scene state in these tests.
#[derive(Debug, PartialEq)]
struct SceneState {
    mesh_vertices: usize,
    cage: Vec<DVec3>,
    pose: Vec<DVec3>,
}

fn scene_state(app: &EditorApp) -> SceneState {
    SceneState {
        mesh_vertices: app.document().mesh().positions.len(),
        cage: app.document().cage().positions().to_vec(),
        pose: app.document().pose().to_vec(),
    }
}

/// The GPU draws the mesh where the document's weights put it: weights came
/// back with the document, not from a new bind.
fn assert_gpu_matches_document(app: &EditorApp) {
    let gpu = app.read_back_deformed().unwrap().unwrap();
    let cpu = app.document().deformed_positions(app.active_method());
    assert_eq!(gpu.len(), cpu.len());
    let scale = app.document().cage().diagonal() as f32;
    let worst = gpu
        .iter()
        .zip(&cpu)
        .map(|(g, c)| g.distance(c.as_vec3()))
        .fold(0.0, f32::max);
    assert!(worst <= 1e-5 * scale, "GPU and document differ by {worst}");
}

#[test]
fn undo_and_redo_walk_back_through_opened_cages_subdivision_and_scene_switches() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let dir = tempfile::tempdir().unwrap();

    // 0: the comb with one handle moved (a pose edit).
    let handle = 3;
    let moved = harness.state().document().pose()[handle] + DVec3::new(0.0, 0.4, 0.1);
    harness.state_mut().set_handle_position(handle, moved);
    harness.run_steps(2);
    let posed_comb = scene_state(harness.state());

    // 1: a larger cage opened from a file.
    let cage = harness.state().document().cage().clone();
    let centre = cage.positions().iter().sum::<DVec3>() / cage.vertex_count() as f64;
    let larger = cage.with_positions(
        cage.positions()
            .iter()
            .map(|&p| centre + (p - centre) * 1.1)
            .collect(),
    );
    let larger_path = write(dir.path(), "larger_cage.obj", &cage_obj(&larger));
    assert!(harness.state_mut().open_file(FileRole::Cage, &larger_path));
    open_without_saving(&mut harness);
    run_until_bound(&mut harness);
    let opened = scene_state(harness.state());
    assert_eq!(
        harness.state().undo_label().as_deref(),
        Some("open cage larger_cage.obj")
    );

    // 2: that cage subdivided.
    assert!(harness.state_mut().subdivide_cage());
    run_until_bound(&mut harness);
    let subdivided = scene_state(harness.state());
    assert!(subdivided.cage.len() > opened.cage.len());

    // 3: another scene.
    harness
        .state_mut()
        .open_bundled(pmvc::app::scenes::BundledScene::Scan);
    open_without_saving(&mut harness);
    run_until_bound(&mut harness);
    let scan = scene_state(harness.state());
    assert_eq!(scan.mesh_vertices, 2775);

    let binds = harness.state().bind_count();
    for expected in [&subdivided, &opened, &posed_comb] {
        press_undo(&mut harness);
        let app = harness.state();
        assert_eq!(&scene_state(app), expected);
        assert!(app.document().weights(Method::Pmvc).is_some());
        assert!(!app.is_binding(), "undo must not rebind");
        assert_gpu_matches_document(app);
    }
    // The pose edit made before the first replacement is undone last.
    press_undo(&mut harness);
    let app = harness.state();
    assert_eq!(app.document().pose(), app.document().cage().positions());
    assert_eq!(app.undo_label(), None);

    for expected in [&posed_comb, &opened, &subdivided, &scan] {
        press_redo(&mut harness);
        let app = harness.state();
        assert_eq!(&scene_state(app), expected);
        assert_gpu_matches_document(app);
    }
    assert_eq!(harness.state().redo_label(), None);
    assert_eq!(
        harness.state().bind_count(),
        binds,
        "no bind in undo or redo"
    );
    assert_eq!(harness.state().last_error(), None);
}

#[test]
fn a_pose_edit_after_undo_drops_the_scene_redo() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    assert!(harness.state_mut().subdivide_cage());
    run_until_bound(&mut harness);
    press_undo(&mut harness);
    assert_eq!(
        harness.state().redo_label().as_deref(),
        Some("subdivide the cage")
    );
    let moved = harness.state().document().pose()[0] + DVec3::new(0.1, 0.0, 0.0);
    harness.state_mut().set_handle_position(0, moved);
    assert_eq!(harness.state().redo_label(), None);
    press_redo(&mut harness);
    assert_eq!(harness.state().document().pose()[0], moved);
}

#[test]
fn using_the_pose_as_rest_shape_keeps_the_deformed_mesh_inside_and_is_undoable() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let before = scene_state(harness.state());
    // Bend one prong of the comb: every handle above the palm on the left.
    let pose: Vec<DVec3> = harness.state().document().pose().to_vec();
    let left = pose.iter().map(|p| p.x).fold(f64::INFINITY, f64::min);
    for (i, p) in pose.iter().enumerate() {
        if p.x < left + 0.5 && p.y > 1.5 {
            harness
                .state_mut()
                .set_handle_position(i, *p + DVec3::new(-0.6, 0.0, 0.0));
        }
    }
    harness.run_steps(2);
    let app = harness.state();
    let deformed = app.document().deformed_positions(app.active_method());
    let posed_cage = app.document().pose().to_vec();
    assert_ne!(posed_cage, before.cage, "the test bends the cage");

    harness.state_mut().pose_as_rest();
    run_until_bound(&mut harness);
    let app = harness.state();
    assert_eq!(app.document().cage().positions(), posed_cage.as_slice());
    assert_eq!(app.document().pose(), posed_cage.as_slice());
    assert_eq!(app.document().mesh().positions, deformed);
    let outside = classify_points(app.document().cage(), &deformed)
        .outside
        .len();
    assert_eq!(outside, 0, "the deformed mesh lies in the posed cage");
    assert!(app.document().weights(Method::Pmvc).is_some());

    press_undo(&mut harness);
    let app = harness.state();
    assert_eq!(scene_state(app).cage, before.cage);
    assert_eq!(app.document().pose(), posed_cage.as_slice());
    assert_gpu_matches_document(app);
}

/// Saving a pose over the open cage, or exporting over the open mesh (directly or
/// through a link), is refused with a message and both files stay as they were.
#[test]
fn saving_over_the_open_mesh_or_cage_is_refused() {
    let directory = tempfile::tempdir().unwrap();
    let assets = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    let mesh = directory.path().join("mesh.obj");
    let cage = directory.path().join("cage.obj");
    std::fs::copy(assets.join("comb_mesh.obj"), &mesh).unwrap();
    std::fs::copy(assets.join("comb_cage.obj"), &cage).unwrap();
    let link = directory.path().join("latest.obj");
    std::os::unix::fs::symlink(&mesh, &link).unwrap();
    let Some(mut harness) = editor_with(pmvc::app::EditorOptions {
        mesh: Some(mesh.clone()),
        cage: Some(cage.clone()),
        ..Default::default()
    }) else {
        return;
    };
    run_until_bound(&mut harness);
    let before = (std::fs::read(&mesh).unwrap(), std::fs::read(&cage).unwrap());
    let app = harness.state_mut();
    let moved = app.document().pose()[3] + DVec3::new(0.2, 0.0, 0.0);
    app.set_handle_position(3, moved);
    app.save_pose(&cage);
    assert!(app
        .last_error()
        .is_some_and(|e| e.contains("never overwrites")));
    for target in [&mesh, &link] {
        app.export_deformed(target);
        let error = app.last_error().unwrap_or_default().to_owned();
        assert!(
            error.contains("mesh.obj") && error.contains("never overwrites"),
            "{error}"
        );
    }
    assert_eq!(
        (std::fs::read(&mesh).unwrap(), std::fs::read(&cage).unwrap()),
        before
    );
    // Elsewhere, both are written.
    let elsewhere = directory.path().join("deformed.obj");
    app.export_deformed(&elsewhere);
    assert!(elsewhere.exists());
}

#[test]
fn quitting_with_an_unsaved_pose_asks_first() {
    use egui_kittest::kittest::Queryable;
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().set_in_window_file_dialog(true);
    let rest = harness.state().document().pose()[3];
    harness
        .state_mut()
        .set_handle_position(3, rest + DVec3::new(0.0, 0.5, 0.0));

    // Ctrl+Q asks; Cancel keeps the editor and the pose.
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Q);
    harness.run_steps(2);
    assert!(harness.state().is_asking_to_quit());
    harness.get_by_label("Cancel").click();
    harness.run_steps(2);
    assert!(!harness.state().is_asking_to_quit());
    assert!(!harness.state().quit_confirmed());

    // The window's close button asks too.
    close_window(&mut harness);
    assert!(harness.state().is_asking_to_quit());
    assert!(!harness.state().quit_confirmed());

    // Save pose… from the question, in the in-window dialog: saved, then closed.
    harness.get_by_label("Save pose…").click();
    harness.run_steps(2);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("before-quit.obj");
    answer_file_dialog(&mut harness, &path);
    let saved = pmvc::formats::load_mesh(&path).expect("the pose was saved");
    assert_eq!(saved.mesh.positions, harness.state().document().pose());
    assert!(harness.state().quit_confirmed());

    // Quit without saving, in a second editor.
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.get_by_label("File").click();
    harness.run_steps(2);
    harness.get_by_label("Quit (Ctrl+Q)").click();
    harness.run_steps(2);
    assert!(
        harness.state().quit_confirmed(),
        "at rest there is nothing to lose: no question"
    );
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness
        .state_mut()
        .set_handle_position(3, rest + DVec3::new(0.0, 0.5, 0.0));
    close_window(&mut harness);
    harness.get_by_label("Quit without saving").click();
    harness.run_steps(2);
    assert!(harness.state().quit_confirmed());
}

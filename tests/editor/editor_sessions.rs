//! Sessions, named poses and the rest-to-pose blend, through the editor: a
//! session saved and opened again brings back the scene, the poses, the method and
//! the views; an edited cage and a rested mesh survive the trip; a bad session
//! names its file and line and keeps the scene; named poses and the blend are
//! undoable, and export writes the blend shown.

use crate::common;

use common::editor::*;
use egui_kittest::kittest::Queryable;
use glam::DVec3;
use pmvc::app::compare::{Layout, Overlay};
use pmvc::app::recent::RecentEntry;
use pmvc::app::{EditorOptions, FileRole};
use pmvc::coords::Method;
use pmvc::formats::load_mesh;
use std::path::Path;

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The rest cage with `handle` moved by `by`.
fn moved(rest: &[DVec3], handle: usize, by: DVec3) -> Vec<DVec3> {
    let mut pose = rest.to_vec();
    pose[handle] += by;
    pose
}

#[test]
fn a_saved_session_brings_back_the_scene_poses_method_and_views() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = common::comb_scene(dir.path(), 200);
    let Some(mut harness) = editor_with(EditorOptions {
        mesh: Some(mesh.clone()),
        cage: Some(cage.clone()),
        method: Some(Method::Mvc),
        resolution: Some(TEST_RESOLUTION),
        ..Default::default()
    }) else {
        return;
    };
    run_until_bound(&mut harness);
    let rest = harness.state().document().cage().positions().to_vec();
    let lean = moved(&rest, 2, DVec3::new(0.25, 0.5, 0.0));
    let app = harness.state_mut();
    app.set_handle_position(2, lean[2]);
    app.store_named_pose("lean");
    let current = moved(&lean, 5, DVec3::new(0.0, -0.125, 0.375));
    app.set_handle_position(5, current[5]);
    app.view_mut().layout = Layout::SideBySide;
    app.view_mut().overlay = Overlay::Heatmap;
    app.view_mut().heat_vertex = 3;
    let session = dir.path().join("work.session.json");
    assert!(app.save_session(&session), "{:?}", app.last_error());

    // Human-readable, with the files named relative to the session.
    let json = read_json(&session);
    assert_eq!(json["mesh"]["file"], "mesh.obj");
    assert_eq!(json["cage"]["file"], "cage.obj");
    assert_eq!(json["method"], "mvc");
    assert_eq!(json["named_poses"][0]["name"], "lean");
    assert_eq!(json["view"]["layout"], "side_by_side");
    assert!(std::fs::read_to_string(&session).unwrap().lines().count() > 20);

    // Opened by a new editor, from another folder's point of view.
    let Some(mut reopened) = editor_with(EditorOptions {
        session: Some(session.clone()),
        ..Default::default()
    }) else {
        return;
    };
    run_until_bound(&mut reopened);
    let app = reopened.state();
    assert_eq!(app.last_error(), None);
    // Opening started the binds once; a second start would have cancelled them.
    assert!(
        app.document().bound(Method::Mvc).is_some(),
        "bound at start"
    );
    assert!(
        app.document().bound(Method::Pmvc).is_some(),
        "bound at start"
    );
    assert_eq!(app.document().pose(), current.as_slice());
    assert_eq!(app.document().named_poses().len(), 1);
    assert_eq!(app.document().named_poses()[0].positions, lean);
    assert_eq!(app.document().mesh_file().unwrap().path, mesh);
    assert_eq!(app.document().cage_path(), Some(cage.as_path()));
    assert_eq!(app.active_method(), Method::Mvc);
    assert_eq!(app.view().layout, Layout::SideBySide);
    assert_eq!(app.view().overlay, Overlay::Heatmap);
    assert_eq!(app.view().heat_vertex, 3);
    assert_eq!(
        app.recent_files().entries().first(),
        Some(&RecentEntry::Session(session.clone()))
    );
    assert!(!app.pose_is_unsaved(), "the pose is the session's");

    // Opening a session over a scene is undoable.
    let app = harness.state_mut();
    app.open_bundled(pmvc::app::scenes::BundledScene::Comb);
    assert!(app.open_session(&session));
    assert_eq!(app.document().pose(), current.as_slice());
    app.undo();
    assert_eq!(app.document().title(), "Comb of close fingers");
}

#[test]
fn an_edited_cage_and_a_rested_mesh_survive_the_trip() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let dir = tempfile::tempdir().unwrap();
    let rest = harness.state().document().cage().positions().to_vec();
    let app = harness.state_mut();
    app.set_handle_position(7, rest[7] + DVec3::new(0.0, 0.75, 0.0));
    app.pose_as_rest();
    run_until_bound(&mut harness);
    harness.state_mut().subdivide_cage();
    run_until_bound(&mut harness);
    let app = harness.state_mut();
    let session = dir.path().join("rested.session.json");
    assert!(app.save_session(&session), "{:?}", app.last_error());
    let json = read_json(&session);
    // The mesh no longer matches the bundled one: it is written beside the
    // session; the cage is written out in full.
    assert_eq!(json["mesh"]["file"], "rested.rest-mesh.obj");
    assert!(dir.path().join("rested.rest-mesh.obj").is_file());
    let triangles = app.document().cage().triangle_count();
    assert_eq!(
        json["cage"]["inline"]["triangles"]
            .as_array()
            .unwrap()
            .len(),
        triangles
    );

    let expected_mesh = app.document().mesh().positions.clone();
    let expected_cage = app.document().cage().positions().to_vec();
    assert!(app.open_session(&session), "{:?}", app.last_error());
    let document = app.document();
    assert_eq!(document.mesh().positions, expected_mesh);
    assert_eq!(document.cage().positions(), expected_cage.as_slice());
    assert_eq!(document.cage().triangle_count(), triangles);
}

#[test]
fn a_bad_session_names_its_file_and_line_and_keeps_the_scene() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let dir = tempfile::tempdir().unwrap();
    let pose_before = harness.state().document().pose().to_vec();
    let rest = harness.state().document().cage().positions().to_vec();
    let pose_json = |points: &[DVec3]| {
        serde_json::to_string(&points.iter().map(|p| p.to_array()).collect::<Vec<_>>()).unwrap()
    };
    let session = |body: &str| {
        format!(
            "{{\n  \"pmvc_session\": 1,\n  \"title\": \"t\",\n  \"mesh\": {{\"bundled\": \"comb\"}},\n  \"cage\": {{\"bundled\": \"comb\"}},\n{body}\n}}\n"
        )
    };
    let cases = [
        (
            "broken.json",
            session("  \"pose\": [[0, 0, 0],,\n  \"method\": \"pmvc\""),
            "line 6".to_owned(),
        ),
        (
            "short.json",
            session(&format!(
                "  \"pose\": {},\n  \"method\": \"pmvc\"",
                pose_json(&rest[..3])
            )),
            format!(
                "the pose has 3 positions but the cage has {} vertices",
                rest.len()
            ),
        ),
        (
            "method.json",
            session(&format!(
                "  \"pose\": {},\n  \"method\": \"bezier\"",
                pose_json(&rest)
            )),
            "unknown method \"bezier\"".to_owned(),
        ),
        (
            "newer.json",
            session(&format!(
                "  \"pose\": {},\n  \"method\": \"pmvc\"",
                pose_json(&rest)
            ))
            .replace("\"pmvc_session\": 1", "\"pmvc_session\": 2"),
            "a session of format 2".to_owned(),
        ),
        (
            "missing.json",
            session(&format!(
                "  \"pose\": {},\n  \"method\": \"pmvc\"",
                pose_json(&rest)
            ))
            .replace(
                "{\"bundled\": \"comb\"},\n  \"cage\"",
                "{\"file\": \"gone.obj\"},\n  \"cage\"",
            ),
            "the mesh: ".to_owned()
                + &dir.path().join("gone.obj").display().to_string()
                + ": cannot read",
        ),
    ];
    for (name, text, expected) in cases {
        let path = common::write(dir.path(), name, &text);
        let app = harness.state_mut();
        assert!(!app.open_session(&path), "{name} opened");
        let error = app.last_error().unwrap_or_default().to_owned();
        assert!(error.contains(name), "{name}: {error}");
        assert!(error.contains(&expected), "{name}: {error}");
        assert_eq!(app.document().pose(), pose_before.as_slice());
        assert_eq!(app.document().title(), "Comb of close fingers");
    }
    // A well-formed one of the same shape opens: the cases above fail for the
    // reason named, not for the shape of the file.
    let good = session(&format!(
        "  \"pose\": {},\n  \"method\": \"pmvc\"",
        pose_json(&moved(&rest, 0, DVec3::X))
    ));
    let path = common::write(dir.path(), "good.json", &good);
    let app = harness.state_mut();
    assert!(app.open_session(&path), "{:?}", app.last_error());
    assert_eq!(app.document().pose()[0], rest[0] + DVec3::X);
}

#[test]
fn named_poses_and_the_blend_are_undoable_and_export_writes_the_blend() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let rest = harness.state().document().cage().positions().to_vec();
    let target = moved(&rest, 12, DVec3::new(0.5, 1.0, 0.0));
    harness.state_mut().set_handle_position(12, target[12]);
    harness.run_steps(2);

    // Store it from the panel.
    harness.get_by_label("Store pose").click();
    harness.run_steps(2);
    assert_eq!(harness.state().document().named_poses().len(), 1);
    assert_eq!(harness.state().document().named_poses()[0].name, "pose 1");

    // Half way: every handle half way between rest and the pose.
    let app = harness.state_mut();
    app.set_pose_blend(0.5);
    let half = app.document().pose().to_vec();
    assert!((half[12] - (rest[12] + DVec3::new(0.25, 0.5, 0.0))).length() < 1e-12);
    assert_eq!(half[0], rest[0]);
    assert_eq!(app.pose_blend_amount(), 0.5);
    let dir = tempfile::tempdir().unwrap();
    let exported = dir.path().join("half.obj");
    assert!(app.export_deformed(&exported));
    let expected = app.document().deformed_positions(app.active_method());
    let written = load_mesh(&exported).unwrap().mesh.positions;
    let at_rest = &app.document().mesh().positions;
    let moved_vertices = written
        .iter()
        .zip(at_rest)
        .filter(|(w, r)| (**w - **r).length() > 1e-3)
        .count();
    assert!(
        moved_vertices > 0,
        "the export is the blend, not the rest mesh"
    );
    assert!(written
        .iter()
        .zip(&expected)
        .all(|(w, e)| (*w - *e).length() < 1e-9));

    // Back to 100%: the pose exactly, and both steps undo.
    app.set_pose_blend(1.0);
    assert_eq!(app.document().pose(), target.as_slice());
    assert_eq!(app.undo_label().as_deref(), Some("blend the pose to 100%"));
    app.undo();
    assert_eq!(app.document().pose(), half.as_slice());
    app.undo();
    assert_eq!(app.document().pose(), target.as_slice());

    // Apply brings the named pose back; Delete is undoable.
    app.reset_pose();
    harness.run_steps(2);
    // The side panel is taller than the window: the buttons are pressed as a
    // screen reader would, wherever they are scrolled.
    harness.get_by_label("Apply").click_accesskit();
    harness.run_steps(2);
    assert_eq!(harness.state().document().pose(), target.as_slice());
    harness.get_by_label("Delete").click_accesskit();
    harness.run_steps(2);
    let app = harness.state_mut();
    assert!(app.document().named_poses().is_empty());
    assert_eq!(app.undo_label().as_deref(), Some("delete pose pose 1"));
    app.undo();
    assert_eq!(app.document().named_poses().len(), 1);
    assert_eq!(app.document().pose(), target.as_slice());
}

#[test]
fn options_beside_a_session_win_and_a_vanished_recent_file_leaves_the_list() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = common::comb_scene(dir.path(), 100);
    let Some(mut harness) = editor() else { return };
    let app = harness.state_mut();
    assert!(app.open_file(FileRole::Cage, &cage));
    app.view_mut().heat_vertex = 5;
    app.view_mut().overlay = Overlay::Heatmap;
    let session = dir.path().join("s.json");
    assert!(app.save_session(&session));

    let mut options = EditorOptions {
        session: Some(session.clone()),
        ..Default::default()
    };
    options.view.layout = Layout::Difference;
    let Some(reopened) = editor_with(options) else {
        return;
    };
    let app = reopened.state();
    assert_eq!(app.last_error(), None);
    assert_eq!(
        app.view().layout,
        Layout::Difference,
        "the command line wins"
    );
    assert_eq!(app.view().heat_vertex, 5, "the rest comes from the session");
    assert_eq!(app.view().overlay, Overlay::Heatmap);
    // The comb mesh stayed bundled; only the cage came from a file.
    assert_eq!(read_json(&session)["mesh"]["bundled"], "comb");

    let app = harness.state_mut();
    let entry = RecentEntry::Scene {
        mesh: mesh.clone(),
        cage: cage.clone(),
        mesh_object: None,
        cage_object: None,
    };
    assert!(app.open_recent(&entry));
    assert_eq!(app.recent_files().entries().first(), Some(&entry));
    std::fs::remove_file(&mesh).unwrap();
    assert!(!app.open_recent(&entry));
    assert!(!app.recent_files().entries().contains(&entry));
}

#[test]
fn ctrl_s_asks_once_with_the_name_ready_to_type_over_then_saves_in_place() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().set_in_window_file_dialog(true);
    let dir = tempfile::tempdir().unwrap();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    harness.run_steps(3);
    assert_eq!(
        harness.state().open_file_dialog(),
        Some(pmvc::app::ui::file_dialog::FileAction::SaveSession)
    );
    // Typing replaces the selected "scene" and keeps ".session.json".
    let typed = dir.path().join("work");
    harness
        .get_by_label("File name:")
        .type_text(typed.to_str().unwrap());
    harness.step();
    harness.key_press(egui::Key::Enter);
    harness.run_steps(2);
    let saved = dir.path().join("work.session.json");
    assert!(saved.is_file(), "{:?}", harness.state().last_error());
    assert_eq!(harness.state().open_file_dialog(), None);

    // The second Ctrl+S writes there without asking.
    let rest = harness.state().document().cage().positions().to_vec();
    harness
        .state_mut()
        .set_handle_position(0, rest[0] + DVec3::new(0.0, -0.5, 0.0));
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    harness.run_steps(3);
    assert_eq!(harness.state().open_file_dialog(), None);
    let json = read_json(&saved);
    assert_eq!(json["pose"][0][1], rest[0].y - 0.5);
}

/// Ctrl+S as a user presses it, with the pointer over the first view.
fn press_save(harness: &mut egui_kittest::Harness<'static, pmvc::app::EditorApp>) {
    let (_, rect) = harness.state().pane_rects()[0];
    harness.hover_at(rect.left_top() + egui::vec2(60.0, 120.0));
    harness.run_steps(2);
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    harness.run_steps(2);
}

#[test]
fn save_after_opening_another_scene_asks_for_a_name_from_its_mesh_and_keeps_the_old_session() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = common::comb_scene(dir.path(), 200);
    let Some(mut harness) = editor_on_files(&mesh, &cage) else {
        return;
    };
    harness.state_mut().set_in_window_file_dialog(true);
    let session = dir.path().join("first.session.json");
    assert!(harness.state_mut().save_session(&session));
    let saved = std::fs::read_to_string(&session).unwrap();

    // An edit of the same scene stays that session: Ctrl+S writes it at once.
    assert!(harness.state_mut().subdivide_cage());
    run_until_bound(&mut harness);
    press_save(&mut harness);
    assert_eq!(harness.state().open_file_dialog(), None);
    let resaved = std::fs::read_to_string(&session).unwrap();
    assert_ne!(
        resaved, saved,
        "the subdivided cage is saved in the session"
    );

    // Another scene: Save asks, offering the new mesh's name.
    let other_mesh = dir.path().join("hydrant.obj");
    let other_cage = dir.path().join("hydrant_cage.obj");
    std::fs::copy(&mesh, &other_mesh).unwrap();
    std::fs::copy(&cage, &other_cage).unwrap();
    assert!(harness.state_mut().open_pair(&other_mesh, &other_cage));
    run_until_bound(&mut harness);
    let rest = harness.state().document().pose()[3];
    harness
        .state_mut()
        .set_handle_position(3, rest + DVec3::new(0.0, 0.25, 0.0));
    press_save(&mut harness);
    assert_eq!(
        harness.state().open_file_dialog(),
        Some(pmvc::app::ui::file_dialog::FileAction::SaveSession)
    );
    assert_eq!(
        harness.state().file_dialog_name(),
        Some("hydrant.session.json")
    );
    assert_eq!(
        std::fs::read_to_string(&session).unwrap(),
        resaved,
        "the first scene's session is left as it was"
    );
}

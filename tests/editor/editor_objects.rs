//! Files of several objects (an OBJ's `o` objects, as Blender exports a
//! scene): a notice names them, `pmvc edit --mesh-object` picks one, the side
//! panel offers the others, and a session and File > Recent remember which
//! was read.

use crate::common;

use common::editor::*;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use glam::DVec3;
use pmvc::app::recent::RecentEntry;
use pmvc::app::{EditorApp, EditorOptions};

/// A quad box cage and two triangles, as one OBJ of three objects.
const SCENE: &str = "o Cage\n\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n\
o First\nv 0.2 0.2 0.2\nv 0.4 0.2 0.2\nv 0.2 0.4 0.2\nf -3 -2 -1\n\
o Second\nv 0.6 0.6 0.6\nv 0.8 0.6 0.6\nv 0.6 0.8 0.6\nv 0.7 0.7 0.8\nf -4 -3 -2\nf -4 -2 -1\n";

fn notices(harness: &Harness<'static, EditorApp>) -> Vec<String> {
    harness
        .state()
        .notices()
        .all()
        .iter()
        .map(|n| n.text.clone())
        .collect()
}

fn first_vertex(harness: &Harness<'static, EditorApp>) -> DVec3 {
    harness.state().document().mesh().positions[0]
}

#[test]
fn a_file_of_several_objects_opens_with_a_notice_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let cage = common::write(
        dir.path(),
        "cage.obj",
        &common::cage_obj(&pmvc::geometry::procedural::cube_cage(1.0)),
    );
    let mesh = common::write(
        dir.path(),
        "scene.obj",
        "o First\nv 0 0 0\nv 0.2 0 0\nv 0 0.2 0\nf 1 2 3\n\
         o Second\nv 0 0 0.2\nv 0.2 0 0.2\nv 0 0.2 0.2\nf 4 5 6\n",
    );
    let Some(mut harness) = editor_with(EditorOptions {
        mesh: Some(mesh),
        cage: Some(cage),
        ..Default::default()
    }) else {
        return;
    };
    harness.run_steps(2);
    assert_eq!(harness.state().document().mesh().positions.len(), 6);
    let notices = notices(&harness);
    assert!(
        notices.iter().any(|n| n.ends_with(
            "scene.obj: the file has 2 objects: 'First', 'Second', read together as one mesh; \
             choose another in the side panel"
        )),
        "{notices:?}"
    );
    // The side panel offers them, the default selected.
    let choice = harness.get_by_label("Mesh object");
    assert_eq!(choice.value().as_deref(), Some("(all objects together)"));
    assert!(harness.query_by_label("Cage object").is_none());
}

#[test]
fn objects_are_chosen_by_name_in_the_side_panel_undone_and_kept_by_sessions() {
    let dir = tempfile::tempdir().unwrap();
    let scene = common::write(dir.path(), "scene.obj", SCENE);
    // `pmvc edit scene.obj scene.obj --mesh-object Second --cage-object Cage`
    let Some(mut harness) = editor_with(EditorOptions {
        mesh: Some(scene.clone()),
        cage: Some(scene.clone()),
        mesh_object: Some("Second".into()),
        cage_object: Some("Cage".into()),
        resolution: Some(TEST_RESOLUTION),
        ..Default::default()
    }) else {
        return;
    };
    harness.run_steps(2);
    let document = harness.state().document();
    assert_eq!(document.mesh().positions.len(), 4, "Second alone");
    assert_eq!(document.cage().vertex_count(), 8, "the box alone");
    assert_eq!(document.cage().quads().len(), 6, "its quads kept");
    assert_eq!(first_vertex(&harness), DVec3::new(0.6, 0.6, 0.6));
    let notices = notices(&harness);
    assert!(
        !notices.iter().any(|n| n.contains("the file has")),
        "named objects need no notice: {notices:?}"
    );
    assert_eq!(
        harness.get_by_label("Mesh object").value().as_deref(),
        Some("Second")
    );
    assert_eq!(
        harness.get_by_label("Cage object").value().as_deref(),
        Some("Cage")
    );

    // Choose First from the combo box, as a user does.
    harness.get_by_label("Mesh object").click();
    harness.run_steps(2);
    harness.get_by_label("First").click();
    harness.run_steps(3);
    assert_eq!(harness.state().document().mesh().positions.len(), 3);
    assert_eq!(first_vertex(&harness), DVec3::new(0.2, 0.2, 0.2));
    assert_eq!(
        harness.get_by_label("Mesh object").value().as_deref(),
        Some("First")
    );
    // One undo step brings Second back.
    harness.state_mut().undo();
    harness.run_steps(2);
    assert_eq!(first_vertex(&harness), DVec3::new(0.6, 0.6, 0.6));
    harness.state_mut().redo();
    harness.run_steps(2);
    assert_eq!(first_vertex(&harness), DVec3::new(0.2, 0.2, 0.2));

    // File > Recent names the objects read and reads them again by name.
    let recent = harness.state().recent_files().entries().to_vec();
    let labels: Vec<String> = recent.iter().map(RecentEntry::label).collect();
    assert_eq!(
        labels[..2],
        [
            "mesh scene.obj (First)",
            "scene.obj (Second) in scene.obj (Cage)"
        ]
    );
    assert!(harness.state_mut().open_recent(&recent[1]));
    harness.run_steps(2);
    assert_eq!(first_vertex(&harness), DVec3::new(0.6, 0.6, 0.6));
    assert_eq!(harness.state().document().cage().quads().len(), 6);
    assert!(harness.state_mut().open_recent(&recent[0]));
    harness.run_steps(2);
    assert_eq!(first_vertex(&harness), DVec3::new(0.2, 0.2, 0.2));

    // A session names the objects it read, and reads them again.
    let session = dir.path().join("scene.pmvc.json");
    assert!(
        harness.state_mut().save_session(&session),
        "{:?}",
        harness.state().last_error()
    );
    let text = std::fs::read_to_string(&session).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(json["mesh_object"], "First", "{text}");
    assert_eq!(json["cage_object"], "Cage", "{text}");
    assert_eq!(
        json["cage"]["file"], "scene.obj",
        "the cage by its file: {text}"
    );
    let Some(mut reopened) = editor_with(EditorOptions {
        session: Some(session),
        resolution: Some(TEST_RESOLUTION),
        ..Default::default()
    }) else {
        return;
    };
    reopened.run_steps(2);
    assert_eq!(reopened.state().document().mesh().positions.len(), 3);
    assert_eq!(first_vertex(&reopened), DVec3::new(0.2, 0.2, 0.2));
    assert_eq!(reopened.state().document().cage().quads().len(), 6);
    assert_eq!(
        reopened.get_by_label("Cage object").value().as_deref(),
        Some("Cage")
    );
}

#[test]
fn a_name_the_file_does_not_have_keeps_the_scene_and_lists_the_names() {
    let dir = tempfile::tempdir().unwrap();
    let scene = common::write(dir.path(), "scene.obj", SCENE);
    let Some(mut harness) = editor_with(EditorOptions {
        mesh: Some(scene.clone()),
        cage: Some(scene),
        mesh_object: Some("Third".into()),
        cage_object: Some("Cage".into()),
        resolution: Some(TEST_RESOLUTION),
        ..Default::default()
    }) else {
        return;
    };
    harness.run_steps(2);
    let error = harness.state().last_error().unwrap_or_default().to_owned();
    assert!(
        error.contains(
            "no object is named 'Third'; the file has 3 objects: 'Cage', 'First', 'Second'"
        ),
        "{error}"
    );
    assert_eq!(
        harness.state().document().title(),
        "Comb of close fingers",
        "the bundled scene stays"
    );
}

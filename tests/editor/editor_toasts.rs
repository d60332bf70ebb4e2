//! Errors and results show where the user is looking: as toasts over the
//! viewport, whatever the side panel holds, at a laptop's 1280 × 800.

use crate::common;

use common::editor::*;
use egui_kittest::kittest::Queryable;
use pmvc::app::EditorOptions;

#[test]
fn an_error_from_a_dropped_file_shows_over_the_viewport_at_1280_by_800() {
    let Some(state) = render_state() else { return };
    let mut harness = editor_sized(
        state,
        EditorOptions::default(),
        egui::vec2(1280.0, 800.0),
        0.25,
    );
    run_until_bound(&mut harness);
    let dir = tempfile::tempdir().unwrap();
    let notes = dir.path().join("notes.txt");
    std::fs::write(&notes, "not a mesh").unwrap();
    drop_files(&mut harness, &[notes]);
    harness.run_steps(2);
    let error = harness.state().last_error().expect("an error").to_owned();
    assert!(error.contains("notes.txt"), "{error}");

    let window = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1280.0, 800.0));
    let side = harness.get_by_label_contains("mesh vertices,").rect();
    let toast = harness
        .query_all_by_label_contains(&error)
        .map(|node| node.rect())
        .find(|rect| rect.max.x < side.min.x)
        .expect("the error is drawn left of the side panel, over the viewport");
    assert!(
        window.contains_rect(toast),
        "the toast is inside the window: {toast:?}"
    );

    // Dismissed, it leaves the viewport and the panel's list alike.
    let dismiss = harness
        .query_all_by_label("x")
        .find(|node| node.rect().max.x < side.min.x)
        .expect("the toast's dismiss button");
    dismiss.click();
    harness.run_steps(2);
    assert!(harness.query_all_by_label_contains(&error).next().is_none());
}

#[test]
fn a_dropped_session_opens_as_a_session() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("comb.session.json");
    harness
        .state_mut()
        .queue_action(pmvc::app::actions::Action::StoreNamedPose("kept".into()));
    harness.run_steps(2);
    assert!(harness.state_mut().save_session(&path));
    // A new editor, the file dropped on it.
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    drop_files(&mut harness, &[path]);
    harness.run_steps(2);
    assert_eq!(harness.state().last_error(), None);
    let named = harness.state().document().named_poses();
    assert_eq!(named.len(), 1, "the session's named pose came with it");
    assert_eq!(named[0].name, "kept");
}

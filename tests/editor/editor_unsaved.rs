//! Work that cannot be lost: quitting, closing the window and opening another
//! scene ask first whenever the session holds something that is on no disk (the
//! pose, named poses, an edited cage), and offer Save session… beside Discard
//! and Cancel.

use crate::common;

use common::editor::*;
use egui::{Key, Modifiers};
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use pmvc::app::actions::Action;
use pmvc::app::scenes::BundledScene;
use pmvc::app::ui::unsaved_dialog::Question;
use pmvc::app::EditorApp;

fn press_quit(harness: &mut Harness<'static, EditorApp>) {
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Q);
    harness.run_steps(2);
}

fn store_named_pose(harness: &mut Harness<'static, EditorApp>, name: &str) {
    harness
        .state_mut()
        .queue_action(Action::StoreNamedPose(name.into()));
    harness.run_steps(2);
    assert!(harness
        .state()
        .document()
        .named_poses()
        .iter()
        .any(|p| p.name == name));
}

#[test]
fn a_new_named_pose_at_rest_asks_before_quitting_and_save_session_keeps_it() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().set_in_window_file_dialog(true);
    // Stored at rest: the pose itself is saved, the named pose is not.
    store_named_pose(&mut harness, "wave");
    let unsaved = harness.state().unsaved();
    assert!(!unsaved.pose && unsaved.named_poses, "{unsaved:?}");

    press_quit(&mut harness);
    assert!(
        harness.state().is_asking_to_quit(),
        "the named pose would be lost"
    );
    assert!(!harness.state().quit_confirmed());
    harness.get_by_label_contains("the named poses");
    assert!(
        harness.query_by_label("Save pose…").is_none(),
        "a pose file would not keep the named pose"
    );

    harness.get_by_label("Save session…").click();
    harness.run_steps(2);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("waving.session.json");
    answer_file_dialog(&mut harness, &path);
    assert!(harness.state().quit_confirmed(), "saved, then quit");
    let text = std::fs::read_to_string(&path).expect("the session was written");
    assert!(
        text.contains("\"wave\""),
        "the named pose is in the session"
    );
}

#[test]
fn an_edited_cage_asks_before_quitting_and_cancel_keeps_everything() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().queue_action(Action::SubdivideCage);
    harness.run_steps(2);
    run_until_bound(&mut harness);
    let unsaved = harness.state().unsaved();
    assert!(unsaved.cage && !unsaved.pose, "{unsaved:?}");
    let vertices = harness.state().document().cage().vertex_count();

    close_window(&mut harness);
    assert!(harness.state().is_asking_to_quit());
    harness.get_by_label_contains("the edited or generated cage");
    harness.get_by_label("Cancel").click();
    harness.run_steps(2);
    assert!(!harness.state().is_asking_to_quit());
    assert!(!harness.state().quit_confirmed());
    assert_eq!(harness.state().document().cage().vertex_count(), vertices);

    // Undo brings back the cage on disk: nothing to lose, no question.
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert!(!harness.state().unsaved().any());
    press_quit(&mut harness);
    assert!(harness.state().quit_confirmed());
}

#[test]
fn opening_another_scene_asks_and_the_scene_waits_for_the_answer() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    store_named_pose(&mut harness, "kept");
    let title = harness.state().document().title().to_owned();

    harness.state_mut().open_bundled(BundledScene::Scan);
    harness.run_steps(2);
    assert!(
        matches!(harness.state().unsaved_question(), Some(Question::Open(_))),
        "{:?}",
        harness.state().unsaved_question()
    );
    assert_eq!(harness.state().document().title(), title, "not yet opened");
    harness.get_by_label("Cancel").click();
    harness.run_steps(2);
    assert_eq!(harness.state().document().title(), title, "cancelled");
    assert_eq!(harness.state().document().named_poses().len(), 1);

    harness.state_mut().open_bundled(BundledScene::Scan);
    harness.run_steps(2);
    harness.get_by_label("Open without saving").click();
    harness.run_steps(2);
    assert_ne!(harness.state().document().title(), title, "opened");
    assert!(
        !harness.state().unsaved().any(),
        "a scene just opened has nothing unsaved"
    );
}

#[test]
fn save_session_from_the_open_question_writes_where_the_session_came_from_then_opens() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("comb.session.json");
    assert!(harness.state_mut().save_session(&path));
    let saved = std::fs::read_to_string(&path).unwrap();
    store_named_pose(&mut harness, "later");

    harness.state_mut().open_bundled(BundledScene::Scan);
    harness.run_steps(2);
    harness.get_by_label("Save session…").click();
    harness.run_steps(2);
    assert_eq!(
        harness.state().open_file_dialog(),
        None,
        "the session has a file: no dialog"
    );
    let written = std::fs::read_to_string(&path).unwrap();
    assert_ne!(written, saved);
    assert!(written.contains("\"later\""));
    assert_eq!(
        harness.state().document().bundled(),
        Some(BundledScene::Scan),
        "then the scene opened"
    );
}

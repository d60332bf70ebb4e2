//! Autosave and recovery: unsaved work goes to a recovery file; an editor that
//! ends without a clean exit (a crash, simulated here by dropping it) leaves the
//! file, and the next editor offers it back.

use crate::common;

use common::editor::*;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use pmvc::app::actions::Action;
use pmvc::app::{EditorApp, EditorOptions};
use std::path::Path;

fn editor_recovering_in(dir: &Path) -> Option<Harness<'static, EditorApp>> {
    let mut harness = editor_with(EditorOptions {
        recovery_dir: Some(dir.to_owned()),
        ..Default::default()
    })?;
    run_until_bound(&mut harness);
    Some(harness)
}

fn recovery_files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.ends_with(".session.json"))
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

#[test]
fn work_left_by_an_editor_that_crashed_is_offered_and_restored_as_unsaved() {
    let dir = tempfile::tempdir().unwrap();
    let Some(mut harness) = editor_recovering_in(dir.path()) else {
        return;
    };
    assert!(!harness.state().is_offering_recovery(), "nothing was left");
    let rest = harness.state().document().pose()[3];
    let moved = rest + glam::DVec3::new(0.0, 0.5, 0.0);
    harness.state_mut().set_handle_position(3, moved);
    harness
        .state_mut()
        .queue_action(Action::StoreNamedPose("raised".into()));
    harness.run_steps(2);
    harness.state_mut().autosave().expect("autosaved");
    let written = harness.state().recovery_file().unwrap().to_owned();
    assert!(written.exists());
    drop(harness); // the crash: no quit, no clean exit

    let Some(mut harness) = editor_recovering_in(dir.path()) else {
        return;
    };
    assert!(harness.state().is_offering_recovery());
    harness.get_by_label("Restore").click();
    harness.run_steps(2);
    let app = harness.state();
    assert_eq!(app.document().pose()[3], moved, "the pose came back");
    assert_eq!(app.document().named_poses()[0].name, "raised");
    let unsaved = app.unsaved();
    assert!(unsaved.pose && unsaved.named_poses, "{unsaved:?}");
    assert_eq!(
        app.session_path(),
        None,
        "Save session asks for a name, not the recovery file's"
    );
    assert!(
        !written.exists(),
        "the old file went once this editor's was written"
    );
    let own = app.recovery_file().unwrap().file_name().unwrap();
    assert_eq!(recovery_files(dir.path()), [own.to_string_lossy()]);

    // Saved, nothing is unsaved: the recovery file goes.
    let session = dir.path().join("kept").join("work.session.json");
    std::fs::create_dir(session.parent().unwrap()).unwrap();
    assert!(harness.state_mut().save_session(&session));
    harness.run_steps(2);
    assert!(recovery_files(dir.path()).is_empty());
}

#[test]
fn discarded_recovery_is_deleted_and_not_now_keeps_it_for_the_next_start() {
    let dir = tempfile::tempdir().unwrap();
    let Some(mut harness) = editor_recovering_in(dir.path()) else {
        return;
    };
    harness
        .state_mut()
        .queue_action(Action::StoreNamedPose("kept".into()));
    harness.run_steps(2);
    harness.state_mut().autosave().unwrap();
    drop(harness);

    let Some(mut harness) = editor_recovering_in(dir.path()) else {
        return;
    };
    harness.get_by_label("Not now").click();
    harness.run_steps(2);
    assert!(!harness.state().is_offering_recovery());
    assert_eq!(recovery_files(dir.path()).len(), 1, "kept");
    drop(harness);

    let Some(mut harness) = editor_recovering_in(dir.path()) else {
        return;
    };
    assert!(harness.state().is_offering_recovery(), "offered again");
    harness.get_by_label("Discard").click();
    harness.run_steps(2);
    assert!(recovery_files(dir.path()).is_empty());
    assert!(harness.state().document().named_poses().is_empty());
}

#[test]
fn quitting_without_saving_lets_the_autosave_go() {
    let dir = tempfile::tempdir().unwrap();
    let Some(mut harness) = editor_recovering_in(dir.path()) else {
        return;
    };
    harness
        .state_mut()
        .queue_action(Action::StoreNamedPose("dropped".into()));
    harness.run_steps(2);
    harness.state_mut().autosave().unwrap();
    assert_eq!(recovery_files(dir.path()).len(), 1);
    close_window(&mut harness);
    harness.get_by_label("Quit without saving").click();
    harness.run_steps(2);
    assert!(harness.state().quit_confirmed());
    assert!(recovery_files(dir.path()).is_empty());
}

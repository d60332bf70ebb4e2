//! The editor's model: one undo log for pose edits and whole-scene replacements,
//! and gestures (a drag, G/R/S, a numeric drag, the blend slider) that end when
//! the document is replaced, so undo never brings back a pose of another cage.

mod common;

use common::editor::*;
use egui::{Key, Modifiers, Pos2};
use egui_kittest::Harness;
use pmvc::app::{EditorApp, TransformKind};

/// Put the pointer in the first view, away from the handles.
fn hover_view(harness: &mut Harness<'static, EditorApp>) -> Pos2 {
    let (_, rect) = harness.state().pane_rects()[0];
    let at = rect.left_top() + egui::vec2(60.0, 120.0);
    harness.hover_at(at);
    harness.run_steps(2);
    at
}

fn press(harness: &mut Harness<'static, EditorApp>, key: Key) {
    harness.key_press(key);
    harness.run_steps(2);
}

fn press_undo(harness: &mut Harness<'static, EditorApp>) {
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
}

/// The pose has one position per cage vertex.
fn assert_pose_fits_cage(app: &EditorApp) {
    assert_eq!(
        app.document().pose().len(),
        app.document().cage().vertex_count(),
        "pose length against the cage's vertex count"
    );
}

#[test]
fn a_move_under_way_when_the_cage_is_subdivided_leaves_nothing_to_undo_of_the_old_cage() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let start = harness.state().document().pose().to_vec();
    let rest_cage = harness.state().document().cage().positions().to_vec();
    harness.state_mut().select_only([3]);
    let at = hover_view(&mut harness);
    press(&mut harness, Key::G);
    for k in 1..=3 {
        harness.hover_at(at + egui::vec2(10.0 * k as f32, -6.0 * k as f32));
        harness.step();
    }
    assert_eq!(
        harness.state().transform_under_way(),
        Some(TransformKind::Grab)
    );
    assert!(harness.state_mut().subdivide_cage());
    harness.run_steps(2);
    assert_pose_fits_cage(harness.state());
    press(&mut harness, Key::Enter);
    assert_pose_fits_cage(harness.state());
    press_undo(&mut harness);
    let app = harness.state();
    assert_pose_fits_cage(app);
    // The move ended with the old document: undo returns to it as it was before G.
    assert_eq!(app.document().cage().positions(), rest_cage.as_slice());
    assert_eq!(app.document().pose(), start.as_slice());
}

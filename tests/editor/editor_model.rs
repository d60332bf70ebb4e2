//! The editor's model: one undo log for pose edits and whole-scene replacements,
//! and gestures (a drag, G/R/S, a numeric drag, the blend slider) that end when
//! the document is replaced, so undo never brings back a pose of another cage;
//! and one walk through a mixed history, undone to the start and redone to the end.

use crate::common;

use common::editor::*;
use common::{cage_obj, write};
use egui::accesskit::Role;
use egui::{Event, Key, Modifiers, PointerButton, Pos2};
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use glam::DVec3;
use pmvc::app::compare::ViewSettings;
use pmvc::app::{EditorApp, FileRole, TransformKind};
use pmvc::coords::Method;

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

/// Press the primary button at `from` and move the pointer to `to`, holding it.
fn press_and_move(harness: &mut Harness<'static, EditorApp>, from: Pos2, to: Pos2) {
    harness.hover_at(from);
    harness.run_steps(2);
    harness.event(Event::PointerButton {
        pos: from,
        button: PointerButton::Primary,
        pressed: true,
        modifiers: Modifiers::NONE,
    });
    harness.step();
    for k in 1..=6 {
        harness.hover_at(from + (to - from) * (k as f32 / 6.0));
        harness.step();
    }
}

fn release(harness: &mut Harness<'static, EditorApp>, at: Pos2) {
    harness.event(Event::PointerButton {
        pos: at,
        button: PointerButton::Primary,
        pressed: false,
        modifiers: Modifiers::NONE,
    });
    harness.run_steps(2);
}

/// With a gesture under way (the pose differs from `start`), subdivide the cage,
/// give the gesture's widget a selection again (`reselect`), end the gesture at
/// `release_at`, then undo: the comb comes back exactly as before the gesture.
fn replace_mid_gesture_then_undo(
    harness: &mut Harness<'static, EditorApp>,
    start: &[DVec3],
    reselect: &[usize],
    release_at: Pos2,
) {
    let rest_cage = harness.state().document().cage().positions().to_vec();
    assert_ne!(
        harness.state().document().pose(),
        start,
        "the gesture moves the pose"
    );
    assert!(harness.state_mut().subdivide_cage());
    harness.run_steps(2);
    harness.state_mut().select_only(reselect.iter().copied());
    harness.run_steps(2);
    release(harness, release_at);
    assert_pose_fits_cage(harness.state());
    assert_eq!(
        harness.state().undo_label().as_deref(),
        Some("subdivide the cage"),
        "the gesture ended with its document"
    );
    press_undo(harness);
    let app = harness.state();
    assert_pose_fits_cage(app);
    assert_eq!(app.document().cage().positions(), rest_cage.as_slice());
    assert_eq!(app.document().pose(), start);
}

#[test]
fn a_handle_drag_under_way_ends_with_its_document() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let (handle, at) = isolated_handle(&harness);
    click(&mut harness, at);
    let start = harness.state().document().pose().to_vec();
    let to = at + egui::vec2(60.0, -30.0);
    press_and_move(&mut harness, at, to);
    replace_mid_gesture_then_undo(&mut harness, &start, &[handle], to);
}

#[test]
fn a_numeric_drag_under_way_ends_with_its_document() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().select_only([3]);
    harness.run_steps(2);
    let start = harness.state().document().pose().to_vec();
    let field = harness.get_by_label("x").rect().center();
    let to = field + egui::vec2(40.0, 0.0);
    press_and_move(&mut harness, field, to);
    replace_mid_gesture_then_undo(&mut harness, &start, &[3], to);
}

#[test]
fn a_blend_slider_drag_under_way_ends_with_its_document() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let moved = harness.state().document().pose()[3] + DVec3::new(0.0, 0.4, 0.1);
    harness.state_mut().set_handle_position(3, moved);
    harness.run_steps(2);
    let start = harness.state().document().pose().to_vec();
    let slider = harness.get_by_role_and_label(Role::Slider, "pose").rect();
    let from = slider.right_center() - egui::vec2(4.0, 0.0);
    let to = slider.center();
    press_and_move(&mut harness, from, to);
    replace_mid_gesture_then_undo(&mut harness, &start, &[], to);
    // Before the blend, the handle's move is still one step back.
    press_undo(&mut harness);
    let app = harness.state();
    assert_eq!(app.document().pose(), app.document().cage().positions());
}

#[test]
fn a_transform_under_way_ends_with_its_document() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().select_only([10, 11]);
    let start = harness.state().document().pose().to_vec();
    let at = hover_view(&mut harness);
    press(&mut harness, Key::R);
    for k in 1..=3 {
        harness.hover_at(at + egui::vec2(0.0, 15.0 * k as f32));
        harness.step();
    }
    assert_eq!(
        harness.state().transform_under_way(),
        Some(TransformKind::Rotate)
    );
    let rest_cage = harness.state().document().cage().positions().to_vec();
    assert!(harness.state_mut().subdivide_cage());
    harness.run_steps(2);
    harness.state_mut().select_only([10, 11]);
    // A click would have confirmed the rotation; it is over with its document.
    assert_eq!(harness.state().transform_under_way(), None);
    press(&mut harness, Key::Enter);
    assert_eq!(
        harness.state().undo_label().as_deref(),
        Some("subdivide the cage")
    );
    press_undo(&mut harness);
    let app = harness.state();
    assert_pose_fits_cage(app);
    assert_eq!(app.document().cage().positions(), rest_cage.as_slice());
    assert_eq!(app.document().pose(), start.as_slice());
}

/// What the mixed-history walk checks at each step.
#[derive(Debug, PartialEq)]
struct Checkpoint {
    pose: Vec<DVec3>,
    selection: Vec<usize>,
    cage: Vec<DVec3>,
    view: ViewSettings,
    method: Method,
}

fn checkpoint(app: &EditorApp) -> Checkpoint {
    Checkpoint {
        pose: app.document().pose().to_vec(),
        selection: app.document().selection().iter().copied().collect(),
        cage: app.document().cage().positions().to_vec(),
        view: *app.view(),
        method: app.active_method(),
    }
}

fn press_redo(harness: &mut Harness<'static, EditorApp>) {
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    harness.run_steps(2);
}

#[test]
fn undo_walks_a_mixed_history_back_to_the_start_and_redo_forward_to_the_end() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let dir = tempfile::tempdir().unwrap();
    // Each checkpoint is taken just before the next action (its selection made):
    // undoing an action comes back to the checkpoint before it, redoing it to the
    // one after.
    let mut checkpoints = Vec::new();
    let (handle, at) = isolated_handle(&harness);
    click(&mut harness, at);
    checkpoints.push(checkpoint(harness.state()));

    // 1: a handle dragged.
    drag(
        &mut harness,
        at,
        at + egui::vec2(60.0, -30.0),
        Modifiers::NONE,
    );
    assert_eq!(harness.state().undo_label().as_deref(), Some("pose edit"));
    assert!(harness.state().document().selection().contains(&handle));
    // A session of this scene with other view settings, opened at step 5.
    let session = dir.path().join("posed.pmvc.json");
    let shown = *harness.state().view();
    harness.state_mut().view_mut().wireframe = !shown.wireframe;
    harness.state_mut().view_mut().smooth_shading = !shown.smooth_shading;
    assert!(harness.state_mut().save_session(&session));
    *harness.state_mut().view_mut() = shown;
    harness.run_steps(2);
    checkpoints.push(checkpoint(harness.state()));

    // 2: a larger cage opened from a file.
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
    run_until_bound(&mut harness);
    harness.state_mut().select_only([10, 11, 12]);
    harness.run_steps(2);
    checkpoints.push(checkpoint(harness.state()));

    // 3: those handles rotated 90° about Z.
    hover_view(&mut harness);
    press(&mut harness, Key::R);
    press(&mut harness, Key::Z);
    harness.event(Event::Text("90".into()));
    harness.run_steps(2);
    press(&mut harness, Key::Enter);
    assert_eq!(
        harness.state().undo_label().as_deref(),
        Some("rotate handles")
    );
    checkpoints.push(checkpoint(harness.state()));

    // 4: the cage subdivided.
    assert!(harness.state_mut().subdivide_cage());
    run_until_bound(&mut harness);
    checkpoints.push(checkpoint(harness.state()));

    // 5: the session opened, with its view settings.
    assert!(harness.state_mut().open_session(&session));
    open_without_saving(&mut harness);
    run_until_bound(&mut harness);
    assert_eq!(harness.state().view().wireframe, !shown.wireframe);
    checkpoints.push(checkpoint(harness.state()));

    // 6: the pose blended half way from rest.
    harness.state_mut().set_pose_blend(0.5);
    harness.run_steps(2);
    checkpoints.push(checkpoint(harness.state()));

    for (i, pair) in checkpoints.windows(2).enumerate() {
        assert_ne!(pair[0], pair[1], "action {} changed nothing", i + 1);
    }
    for (step, expected) in checkpoints.iter().enumerate().rev().skip(1) {
        press_undo(&mut harness);
        assert_eq!(&checkpoint(harness.state()), expected, "undo to {step}");
        assert_pose_fits_cage(harness.state());
    }
    assert_eq!(harness.state().undo_label(), None);
    for (step, expected) in checkpoints.iter().enumerate().skip(1) {
        press_redo(&mut harness);
        assert_eq!(&checkpoint(harness.state()), expected, "redo to {step}");
        assert_pose_fits_cage(harness.state());
    }
    assert_eq!(harness.state().redo_label(), None);
    assert_eq!(harness.state().last_error(), None);
}

//! Shortcuts matched with the modifiers each key was pressed with: Ctrl+S is
//! only Save and S only Scale, Ctrl+O only Open session and O only soft
//! selection, whatever else arrives in the same frame (a quick tap brings the
//! modifier's press, the key and the modifier's release together). Every entry
//! of the table is tried with and without each modifier.

use crate::common;

use common::editor::*;
use egui::{Event, Key, Modifiers, RawInput};
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use pmvc::app::shortcuts::{pressed, Keys, Scope, Shortcut, SHORTCUTS};
use pmvc::app::ui::file_dialog::FileAction;
use pmvc::app::EditorApp;

/// Put the pointer in the first view, away from the handles.
fn hover_view(harness: &mut Harness<'static, EditorApp>) {
    let (_, rect) = harness.state().pane_rects()[0];
    harness.hover_at(rect.left_top() + egui::vec2(60.0, 120.0));
    harness.run_steps(2);
}

/// A quick tap of `key` with `modifiers`, as X11 delivers it to one frame:
/// the modifiers pressed, the key down and up, the modifiers released.
fn tap(harness: &mut Harness<'static, EditorApp>, modifiers: Modifiers, key: Key) {
    for event in tap_events(modifiers, key) {
        harness.event(event);
    }
    harness.run_steps(2);
}

fn tap_events(modifiers: Modifiers, key: Key) -> Vec<Event> {
    let key_event = |pressed| Event::Key {
        key,
        physical_key: None,
        pressed,
        repeat: false,
        modifiers,
    };
    vec![
        Event::ModifiersChanged(modifiers),
        key_event(true),
        key_event(false),
        Event::ModifiersChanged(Modifiers::NONE),
    ]
}

#[test]
fn ctrl_s_saves_and_does_not_also_scale() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().set_in_window_file_dialog(true);
    harness.state_mut().select_only([10, 11]);
    hover_view(&mut harness);
    let pose = harness.state().document().pose().to_vec();
    tap(&mut harness, Modifiers::COMMAND, Key::S);
    assert_eq!(
        harness.state().transform_under_way(),
        None,
        "Ctrl+S began a transform"
    );
    assert_eq!(
        harness.state().open_file_dialog(),
        Some(FileAction::SaveSession)
    );
    assert_eq!(harness.state().document().pose(), pose.as_slice());
}

#[test]
fn ctrl_o_opens_a_session_and_does_not_toggle_soft_selection() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().set_in_window_file_dialog(true);
    hover_view(&mut harness);
    let soft = harness.state().pose_tool_settings().soft_selection;
    tap(&mut harness, Modifiers::COMMAND, Key::O);
    assert_eq!(
        harness.state().pose_tool_settings().soft_selection,
        soft,
        "Ctrl+O toggled soft selection"
    );
    assert_eq!(
        harness.state().open_file_dialog(),
        Some(FileAction::OpenSession)
    );
}

#[test]
fn plain_s_still_scales_and_o_still_toggles_soft_selection() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().select_only([10, 11]);
    hover_view(&mut harness);
    harness.key_press(Key::S);
    harness.run_steps(2);
    assert!(harness.state().transform_under_way().is_some());
    harness.key_press(Key::Escape);
    harness.run_steps(2);
    let soft = harness.state().pose_tool_settings().soft_selection;
    harness.key_press(Key::O);
    harness.run_steps(2);
    assert_ne!(harness.state().pose_tool_settings().soft_selection, soft);
}

/// Which shortcuts of `scope` one frame with `key` pressed, held with
/// `modifiers` the way a quick tap arrives (the modifiers pressed, the key, the
/// modifiers released, all in the frame), gives.
fn fired(scope: Scope, modifiers: Modifiers, key: Key) -> Vec<Shortcut> {
    let ctx = egui::Context::default();
    let input = RawInput {
        events: tap_events(modifiers, key),
        ..RawInput::default()
    };
    let mut found = Vec::new();
    let _ = ctx.run_ui(input, |ui| found = pressed(ui.ctx(), scope));
    found
}

const TRIED: [Modifiers; 6] = [
    Modifiers::NONE,
    Modifiers::COMMAND,
    Modifiers::SHIFT,
    Modifiers::ALT,
    Modifiers {
        shift: true,
        ..Modifiers::COMMAND
    },
    Modifiers {
        alt: true,
        ..Modifiers::COMMAND
    },
];

#[test]
fn every_entry_fires_with_its_own_modifiers_and_no_others() {
    let mut wrong = Vec::new();
    for (keys, scope, shortcut) in SHORTCUTS {
        for modifiers in TRIED {
            let (key, expected) = match *keys {
                Keys::With(own, key) => (key, own == modifiers),
                Keys::Plain(key) => (key, modifiers.is_none()),
                Keys::Any(key) => (key, true),
            };
            let found = fired(*scope, modifiers, key);
            // One key press is one shortcut of its scope at most.
            if found.contains(shortcut) != expected || found.len() > 1 {
                wrong.push(format!("{} with {modifiers:?}: {found:?}", keys.label()));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn help_shortcuts_lists_every_entry_of_the_table() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.get_by_label("Help").click();
    harness.run();
    harness.get_by_label("Shortcuts").click();
    harness.run();
    for (keys, _, shortcut) in SHORTCUTS {
        let label = keys.label();
        assert!(
            harness.query_all_by_label(&label).next().is_some(),
            "{label} is not listed"
        );
        assert!(
            harness
                .query_all_by_label(shortcut.describe())
                .next()
                .is_some(),
            "{} is not listed",
            shortcut.describe()
        );
    }
}

#[test]
fn blenders_selection_keys_select_all_none_and_the_inverse() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    hover_view(&mut harness);
    let handles = harness.state().document().pose().len();
    tap(&mut harness, Modifiers::NONE, Key::A);
    assert_eq!(harness.state().document().selection().len(), handles);
    tap(&mut harness, Modifiers::ALT, Key::A);
    assert!(harness.state().document().selection().is_empty());
    harness.state_mut().select_only([0, 3]);
    tap(&mut harness, Modifiers::COMMAND, Key::I);
    let selection = harness.state().document().selection();
    assert_eq!(selection.len(), handles - 2);
    assert!(!selection.contains(&0) && !selection.contains(&3));
}

#[test]
fn number_keys_look_from_the_front_right_top_and_with_ctrl_the_opposite_sides() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    hover_view(&mut harness);
    let before = harness.state().camera();
    let cases = [
        (Modifiers::NONE, Key::Num1, (0.0, 0.0)),
        (Modifiers::COMMAND, Key::Num1, (std::f32::consts::PI, 0.0)),
        (
            Modifiers::NONE,
            Key::Num3,
            (std::f32::consts::FRAC_PI_2, 0.0),
        ),
        (
            Modifiers::COMMAND,
            Key::Num3,
            (-std::f32::consts::FRAC_PI_2, 0.0),
        ),
        (Modifiers::NONE, Key::Num7, (0.0, 89f32.to_radians())),
        (Modifiers::COMMAND, Key::Num7, (0.0, -89f32.to_radians())),
    ];
    for (modifiers, key, (yaw, pitch)) in cases {
        tap(&mut harness, modifiers, key);
        let camera = harness.state().camera();
        assert!(
            (camera.yaw - yaw).abs() < 1e-6 && (camera.pitch - pitch).abs() < 1e-6,
            "{modifiers:?}+{key:?}: yaw {} pitch {}",
            camera.yaw,
            camera.pitch
        );
        assert_eq!(camera.target, before.target, "the target stays");
        assert_eq!(camera.distance, before.distance, "the distance stays");
    }
}

#[test]
fn alt_drag_orbits_even_when_it_starts_on_a_handle() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let (handle, at) = isolated_handle(&harness);
    let pose = harness.state().document().pose().to_vec();
    let camera = harness.state().camera();
    drag(
        &mut harness,
        at,
        at + egui::vec2(80.0, 30.0),
        Modifiers::ALT,
    );
    assert_eq!(
        harness.state().document().pose(),
        pose.as_slice(),
        "handle {handle} did not move"
    );
    assert_ne!(harness.state().camera().yaw, camera.yaw, "the view orbited");
    // Without Alt a drag from the handle, where it now is, moves it.
    let at = harness.state().handle_screen_position(handle).unwrap();
    drag(
        &mut harness,
        at,
        at + egui::vec2(0.0, -30.0),
        Modifiers::NONE,
    );
    assert_ne!(harness.state().document().pose(), pose.as_slice());
}

#[test]
fn numpad_5_switches_every_view_to_parallel_and_back_and_handles_still_pick() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    hover_view(&mut harness);
    assert!(!harness.state().camera().orthographic);
    tap(&mut harness, Modifiers::NONE, Key::Num5);
    let panes = harness.state().pane_rects().len();
    for pane in 0..panes {
        assert!(harness.state().camera_of(pane).orthographic, "view {pane}");
    }
    // A handle is picked where the parallel view draws it.
    let (handle, at) = isolated_handle(&harness);
    click(&mut harness, at);
    let selection = harness.state().document().selection();
    assert_eq!(selection.iter().copied().collect::<Vec<_>>(), [handle]);

    hover_view(&mut harness);
    tap(&mut harness, Modifiers::NONE, Key::Num5);
    assert!(
        !harness.state().camera().orthographic,
        "back to perspective"
    );
}

#[test]
fn the_period_key_frames_the_selection_as_f_does() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().select_only([0, 1]);
    hover_view(&mut harness);
    tap(&mut harness, Modifiers::NONE, Key::F);
    let framed_by_f = harness.state().camera();
    tap(&mut harness, Modifiers::NONE, Key::Home);
    assert_ne!(harness.state().camera().target, framed_by_f.target);
    tap(&mut harness, Modifiers::NONE, Key::Period);
    let framed = harness.state().camera();
    assert_eq!(framed.target, framed_by_f.target);
    assert_eq!(framed.distance, framed_by_f.distance);
}

//! The keyboard shortcuts, as Blender binds them: one table from keys to
//! actions, and the one place that runs them. A transform under way (G, R, S)
//! steers with its own keys (`viewport/modal.rs`) until it ends.

use super::editor::EditorApp;
use super::ui::file_dialog::FileAction;
use super::viewport::TransformKind;
use egui::{Key, KeyboardShortcut, Modifiers};

/// What a shortcut does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Action {
    Quit,
    BeginTransform(TransformKind),
    Redo,
    Undo,
    Deselect,
    FrameSelection,
    FrameAll,
    NextMethod,
    ToggleCage,
    ToggleSoftSelection,
    SaveSessionAs,
    SaveSession,
    OpenSession,
}

/// How a shortcut's keys are pressed.
#[derive(Clone, Copy)]
enum Keys {
    /// With these modifiers (consumed, so a longer shortcut listed first wins).
    With(Modifiers, Key),
    /// Alone, with no modifier held.
    Plain(Key),
    /// With any modifiers.
    Any(Key),
}

/// When a shortcut's keys are live.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Scope {
    /// Always, even over a dialog.
    Always,
    /// Not while a dialog or a text field has the keyboard, nor during a transform
    /// (whose own keys these are then).
    Viewport,
    /// Not while a dialog or a text field has the keyboard; the first of these
    /// pressed runs.
    Files,
}

const COMMAND: Modifiers = Modifiers::COMMAND;
const COMMAND_SHIFT: Modifiers = Modifiers {
    shift: true,
    ..Modifiers::COMMAND
};

/// Every shortcut, in the order they are checked.
const SHORTCUTS: &[(Keys, Scope, Action)] = &[
    (Keys::With(COMMAND, Key::Q), Scope::Always, Action::Quit),
    (
        Keys::Plain(Key::G),
        Scope::Viewport,
        Action::BeginTransform(TransformKind::Grab),
    ),
    (
        Keys::Plain(Key::R),
        Scope::Viewport,
        Action::BeginTransform(TransformKind::Rotate),
    ),
    (
        Keys::Plain(Key::S),
        Scope::Viewport,
        Action::BeginTransform(TransformKind::Scale),
    ),
    (
        Keys::With(COMMAND_SHIFT, Key::Z),
        Scope::Viewport,
        Action::Redo,
    ),
    (Keys::With(COMMAND, Key::Y), Scope::Viewport, Action::Redo),
    (Keys::With(COMMAND, Key::Z), Scope::Viewport, Action::Undo),
    (Keys::Any(Key::Escape), Scope::Viewport, Action::Deselect),
    (Keys::Plain(Key::F), Scope::Viewport, Action::FrameSelection),
    (Keys::Plain(Key::M), Scope::Viewport, Action::NextMethod),
    (Keys::Any(Key::Home), Scope::Viewport, Action::FrameAll),
    (Keys::Plain(Key::H), Scope::Viewport, Action::ToggleCage),
    (
        Keys::Plain(Key::O),
        Scope::Viewport,
        Action::ToggleSoftSelection,
    ),
    (
        Keys::With(COMMAND_SHIFT, Key::S),
        Scope::Files,
        Action::SaveSessionAs,
    ),
    (
        Keys::With(COMMAND, Key::S),
        Scope::Files,
        Action::SaveSession,
    ),
    (
        Keys::With(COMMAND, Key::O),
        Scope::Files,
        Action::OpenSession,
    ),
];

/// The actions of `scope` whose keys were pressed this frame, in table order.
fn pressed(ctx: &egui::Context, scope: Scope) -> Vec<Action> {
    let mut actions: Vec<Action> = Vec::new();
    for &(keys, _, action) in SHORTCUTS.iter().filter(|(_, s, _)| *s == scope) {
        let hit = ctx.input_mut(|i| match keys {
            Keys::With(modifiers, key) => {
                i.consume_shortcut(&KeyboardShortcut::new(modifiers, key))
            }
            Keys::Plain(key) => i.key_pressed(key) && i.modifiers.is_none(),
            Keys::Any(key) => i.key_pressed(key),
        });
        if hit && !actions.contains(&action) {
            actions.push(action);
        }
    }
    actions
}

impl EditorApp {
    /// Run this frame's shortcuts.
    pub(super) fn run_shortcuts(&mut self, ctx: &egui::Context) {
        for action in pressed(ctx, Scope::Always) {
            self.run_action(ctx, action);
        }
        // A dialog's fields and keys are its own; M or F typed into a path must
        // not switch the method or move the camera.
        let keyboard_taken =
            |app: &Self| ctx.egui_wants_keyboard_input() || app.modal_dialog_open();
        if keyboard_taken(self) {
            return;
        }
        if !self.steer_transform(ctx) {
            for action in pressed(ctx, Scope::Viewport) {
                if let Action::BeginTransform(kind) = action {
                    if self.begin_transform_at_pointer(ctx, kind) {
                        break;
                    }
                    continue;
                }
                self.run_action(ctx, action);
            }
        }
        if keyboard_taken(self) {
            return;
        }
        if let Some(&action) = pressed(ctx, Scope::Files).first() {
            self.run_action(ctx, action);
        }
    }

    fn run_action(&mut self, ctx: &egui::Context, action: Action) {
        match action {
            Action::Quit => self.actions.push(super::actions::Action::Quit),
            Action::BeginTransform(kind) => {
                self.begin_transform_at_pointer(ctx, kind);
            }
            Action::Redo => self.redo(),
            Action::Undo => self.undo(),
            Action::Deselect => self.select_only([]),
            Action::FrameSelection => self.frame_selection(),
            Action::FrameAll => self.frame_scene(),
            Action::NextMethod => self.toggle_method(),
            Action::ToggleCage => self.view.show_cage = !self.view.show_cage,
            Action::ToggleSoftSelection => {
                self.pose_tools.soft_selection = !self.pose_tools.soft_selection;
            }
            Action::SaveSessionAs => self.ask_for_file(FileAction::SaveSession),
            Action::SaveSession => self.save_session_again(),
            Action::OpenSession => self.ask_for_file(FileAction::OpenSession),
        }
    }
}

//! The keyboard shortcuts, as Blender binds them: one table from keys to
//! what they do, each an [`Action`] the editor's one runner carries out
//! (`editor/frame.rs` reads them each frame). A transform under way (G, R, S)
//! steers with its own keys (`viewport/modal.rs`) until it ends.

use super::actions::Action;
use super::model::{Command, Selection};
use super::ui::file_dialog::FileAction;
use super::viewport::TransformKind;
use egui::{Key, KeyboardShortcut, Modifiers};

/// What a shortcut does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shortcut {
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
pub enum Scope {
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
const SHORTCUTS: &[(Keys, Scope, Shortcut)] = &[
    (Keys::With(COMMAND, Key::Q), Scope::Always, Shortcut::Quit),
    (
        Keys::Plain(Key::G),
        Scope::Viewport,
        Shortcut::BeginTransform(TransformKind::Grab),
    ),
    (
        Keys::Plain(Key::R),
        Scope::Viewport,
        Shortcut::BeginTransform(TransformKind::Rotate),
    ),
    (
        Keys::Plain(Key::S),
        Scope::Viewport,
        Shortcut::BeginTransform(TransformKind::Scale),
    ),
    (
        Keys::With(COMMAND_SHIFT, Key::Z),
        Scope::Viewport,
        Shortcut::Redo,
    ),
    (Keys::With(COMMAND, Key::Y), Scope::Viewport, Shortcut::Redo),
    (Keys::With(COMMAND, Key::Z), Scope::Viewport, Shortcut::Undo),
    (Keys::Any(Key::Escape), Scope::Viewport, Shortcut::Deselect),
    (
        Keys::Plain(Key::F),
        Scope::Viewport,
        Shortcut::FrameSelection,
    ),
    (Keys::Plain(Key::M), Scope::Viewport, Shortcut::NextMethod),
    (Keys::Any(Key::Home), Scope::Viewport, Shortcut::FrameAll),
    (Keys::Plain(Key::H), Scope::Viewport, Shortcut::ToggleCage),
    (
        Keys::Plain(Key::O),
        Scope::Viewport,
        Shortcut::ToggleSoftSelection,
    ),
    (
        Keys::With(COMMAND_SHIFT, Key::S),
        Scope::Files,
        Shortcut::SaveSessionAs,
    ),
    (
        Keys::With(COMMAND, Key::S),
        Scope::Files,
        Shortcut::SaveSession,
    ),
    (
        Keys::With(COMMAND, Key::O),
        Scope::Files,
        Shortcut::OpenSession,
    ),
];

/// The actions of `scope` whose keys were pressed this frame, in table order.
pub fn pressed(ctx: &egui::Context, scope: Scope) -> Vec<Shortcut> {
    let mut actions: Vec<Shortcut> = Vec::new();
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

impl Shortcut {
    /// The action the runner carries out; a transform begins in the viewport
    /// instead (it needs the pointer's view).
    pub fn action(self) -> Option<Action> {
        Some(match self {
            Shortcut::Quit => Action::Quit,
            Shortcut::BeginTransform(_) => return None,
            Shortcut::Redo => Action::Redo,
            Shortcut::Undo => Action::Undo,
            Shortcut::Deselect => Action::Apply(Command::Select(Selection::only([]))),
            Shortcut::FrameSelection => Action::FrameSelection,
            Shortcut::FrameAll => Action::FrameAll,
            Shortcut::NextMethod => Action::NextMethod,
            Shortcut::ToggleCage => Action::ToggleCage,
            Shortcut::ToggleSoftSelection => Action::ToggleSoftSelection,
            Shortcut::SaveSessionAs => Action::AskForFile(FileAction::SaveSession),
            Shortcut::SaveSession => Action::SaveSessionAgain,
            Shortcut::OpenSession => Action::AskForFile(FileAction::OpenSession),
        })
    }
}

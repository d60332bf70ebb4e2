//! The keyboard shortcuts, as Blender binds them: one table from keys to
//! what they do, each an [`Action`] the editor's one runner carries out
//! (`editor/frame.rs` reads them each frame). A transform under way (G, R, S)
//! steers with its own keys (`viewport/modal.rs`) until it ends.

use super::actions::{Action, FileAction, ViewSide};
use super::commands::{Command, Selection};
use super::viewport::TransformKind;
use egui::{Key, Modifiers};

/// What a shortcut does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shortcut {
    Quit,
    BeginTransform(TransformKind),
    Redo,
    Undo,
    Deselect,
    SelectAll,
    InvertSelection,
    /// Look at the scene from one side (Blender's numpad views).
    ViewFrom(ViewSide),
    /// Parallel or perspective view (numpad 5).
    ToggleOrthographic,
    FrameSelection,
    FrameAll,
    NextMethod,
    ToggleCage,
    ToggleSoftSelection,
    SaveSessionAs,
    SaveSession,
    OpenSession,
}

// What Help > Shortcuts says of each side.
impl ViewSide {
    fn describe(self) -> &'static str {
        match self {
            ViewSide::Front => "View from the front (+z)",
            ViewSide::Back => "View from the back (−z)",
            ViewSide::Right => "View from the right (+x)",
            ViewSide::Left => "View from the left (−x)",
            ViewSide::Top => "View from the top (+y)",
            ViewSide::Bottom => "View from below (−y)",
        }
    }
}

/// How a shortcut's keys are pressed.
#[derive(Clone, Copy, Debug)]
pub enum Keys {
    /// With exactly these modifiers (the press is consumed).
    With(Modifiers, Key),
    /// Alone, with no modifier held.
    Plain(Key),
    /// With any modifiers.
    Any(Key),
}

/// When a shortcut's keys are live.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
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
const ALT: Modifiers = Modifiers::ALT;
const COMMAND_SHIFT: Modifiers = Modifiers {
    shift: true,
    ..Modifiers::COMMAND
};

/// Every shortcut, in the order they are checked.
pub const SHORTCUTS: &[(Keys, Scope, Shortcut)] = &[
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
    (Keys::Plain(Key::A), Scope::Viewport, Shortcut::SelectAll),
    (Keys::With(ALT, Key::A), Scope::Viewport, Shortcut::Deselect),
    (
        Keys::With(COMMAND, Key::I),
        Scope::Viewport,
        Shortcut::InvertSelection,
    ),
    (
        Keys::Plain(Key::Num1),
        Scope::Viewport,
        Shortcut::ViewFrom(ViewSide::Front),
    ),
    (
        Keys::With(COMMAND, Key::Num1),
        Scope::Viewport,
        Shortcut::ViewFrom(ViewSide::Back),
    ),
    (
        Keys::Plain(Key::Num3),
        Scope::Viewport,
        Shortcut::ViewFrom(ViewSide::Right),
    ),
    (
        Keys::With(COMMAND, Key::Num3),
        Scope::Viewport,
        Shortcut::ViewFrom(ViewSide::Left),
    ),
    (
        Keys::Plain(Key::Num7),
        Scope::Viewport,
        Shortcut::ViewFrom(ViewSide::Top),
    ),
    (
        Keys::With(COMMAND, Key::Num7),
        Scope::Viewport,
        Shortcut::ViewFrom(ViewSide::Bottom),
    ),
    (
        Keys::Plain(Key::Num5),
        Scope::Viewport,
        Shortcut::ToggleOrthographic,
    ),
    (
        Keys::Plain(Key::F),
        Scope::Viewport,
        Shortcut::FrameSelection,
    ),
    (
        Keys::Plain(Key::Period),
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

/// The shortcuts of `scope` whose keys were pressed this frame, in table order.
/// Each key press is matched with the modifiers it was pressed with, exactly:
/// not with the modifiers held at the end of the frame, which a quick tap has
/// already released, so that Ctrl+S is never also S.
pub fn pressed(ctx: &egui::Context, scope: Scope) -> Vec<Shortcut> {
    let mut found: Vec<Shortcut> = Vec::new();
    for &(keys, _, shortcut) in SHORTCUTS.iter().filter(|(_, s, _)| *s == scope) {
        let hit = ctx.input_mut(|i| match keys {
            // Consumed, so that no other entry or widget sees the press again.
            Keys::With(wanted, key) => take_press(&mut i.events, key, Some(wanted)),
            Keys::Plain(key) => pressed_with(&i.events, key, Some(Modifiers::NONE)),
            Keys::Any(key) => pressed_with(&i.events, key, None),
        });
        if hit && !found.contains(&shortcut) {
            found.push(shortcut);
        }
    }
    found
}

/// Whether `event` presses `key` with exactly `modifiers` (any, for `None`).
fn presses(event: &egui::Event, key: Key, modifiers: Option<Modifiers>) -> bool {
    matches!(
        event,
        egui::Event::Key { key: pressed, pressed: true, modifiers: held, .. }
            if *pressed == key && modifiers.is_none_or(|wanted| held.matches_exact(wanted))
    )
}

fn pressed_with(events: &[egui::Event], key: Key, modifiers: Option<Modifiers>) -> bool {
    events.iter().any(|event| presses(event, key, modifiers))
}

/// Remove the presses of `key` with exactly `modifiers`; true when there was one.
fn take_press(events: &mut Vec<egui::Event>, key: Key, modifiers: Option<Modifiers>) -> bool {
    let before = events.len();
    events.retain(|event| !presses(event, key, modifiers));
    events.len() < before
}

impl Scope {
    /// When its keys work, for Help > Shortcuts.
    pub fn describe(self) -> &'static str {
        match self {
            Scope::Always => "always",
            Scope::Viewport => "not in a text field or dialog, nor during a transform",
            Scope::Files => "not in a text field or dialog",
        }
    }
}

impl Keys {
    /// The keys as a person reads them: "Ctrl+Shift+Z", "G", "Esc".
    pub fn label(self) -> String {
        let (modifiers, key) = match self {
            Keys::With(modifiers, key) => (modifiers, key),
            Keys::Plain(key) | Keys::Any(key) => (Modifiers::NONE, key),
        };
        let mut parts = Vec::new();
        if modifiers.command || modifiers.ctrl || modifiers.mac_cmd {
            parts.push("Ctrl");
        }
        if modifiers.alt {
            parts.push("Alt");
        }
        if modifiers.shift {
            parts.push("Shift");
        }
        parts.push(key.name());
        parts.join("+")
    }
}

impl Shortcut {
    /// What it does, for Help > Shortcuts.
    pub fn describe(self) -> &'static str {
        match self {
            Shortcut::Quit => "Quit (asks first when the pose is unsaved)",
            Shortcut::BeginTransform(TransformKind::Grab) => "Move the selected handles",
            Shortcut::BeginTransform(TransformKind::Rotate) => "Rotate the selected handles",
            Shortcut::BeginTransform(TransformKind::Scale) => "Scale the selected handles",
            Shortcut::Redo => "Redo",
            Shortcut::Undo => "Undo",
            Shortcut::Deselect => "Deselect every handle",
            Shortcut::SelectAll => "Select every handle",
            Shortcut::InvertSelection => "Invert the selection",
            Shortcut::ViewFrom(side) => side.describe(),
            Shortcut::ToggleOrthographic => "Parallel (orthographic) or perspective view",
            Shortcut::FrameSelection => "Frame the selection",
            Shortcut::FrameAll => "Frame the whole scene",
            Shortcut::NextMethod => "Show the next family",
            Shortcut::ToggleCage => "Show or hide the cage and its handles",
            Shortcut::ToggleSoftSelection => "Soft selection on or off",
            Shortcut::SaveSessionAs => "Save the session as…",
            Shortcut::SaveSession => "Save the session",
            Shortcut::OpenSession => "Open a session…",
        }
    }

    /// The action the runner carries out; a transform begins in the viewport
    /// instead (it needs the pointer's view).
    pub fn action(self) -> Option<Action> {
        Some(match self {
            Shortcut::Quit => Action::Quit,
            Shortcut::BeginTransform(_) => return None,
            Shortcut::Redo => Action::Redo,
            Shortcut::Undo => Action::Undo,
            Shortcut::Deselect => Action::Apply(Command::Select(Selection::only([]))),
            Shortcut::SelectAll => Action::SelectAll,
            Shortcut::InvertSelection => Action::InvertSelection,
            Shortcut::ViewFrom(side) => Action::ViewFrom(side),
            Shortcut::ToggleOrthographic => Action::ToggleOrthographic,
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

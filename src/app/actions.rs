//! What panels ask the editor to do, as values, and the one runner that does it
//! after the panels have drawn each frame (egui's demo app returns its commands
//! the same way). Actions do the I/O; what changes the document goes on to the
//! model as a [`Command`].

use super::editor::{EditorApp, FileRole};
use super::model::Command;
use super::ui::file_dialog::FileAction;
use super::ui::notices::Notices;
use glam::DVec3;
use std::path::PathBuf;

/// Something a panel or a shortcut asks for.
#[derive(Debug)]
pub enum Action {
    /// File > Quit, Ctrl+Q: close now when nothing would be lost, else ask.
    Quit,
    /// Close the window: the user confirmed quitting.
    CloseWindow,
    /// Open the file dialog for `FileAction`.
    AskForFile(FileAction),
    /// Open a file as the mesh or the cage.
    Open(FileRole, PathBuf),
    /// Open a mesh and its cage together.
    OpenPair { mesh: PathBuf, cage: PathBuf },
    /// Use the vertices read from `path` as the cage's pose.
    TakePose { path: PathBuf, pose: Vec<DVec3> },
    /// Report an error to the user.
    Error(String),
    /// Remove the notice at this index of the list.
    DismissNotice(usize),
    /// Change the model.
    Apply(Command),
}

impl EditorApp {
    /// Run the actions the panels and shortcuts queued this frame, in order.
    pub(super) fn run_actions(&mut self, ctx: &egui::Context) {
        let mut ran = false;
        // An action may queue more (none does yet): run until none is left.
        while !self.actions.is_empty() {
            for action in std::mem::take(&mut self.actions) {
                self.run_queued(ctx, action);
                ran = true;
            }
        }
        if ran {
            // What the actions changed shows in the next frame, without waiting
            // for input.
            ctx.request_repaint();
        }
    }

    fn run_queued(&mut self, ctx: &egui::Context, action: Action) {
        match action {
            Action::Quit => {
                if self.quit.request(self.model.pose_unsaved()) {
                    ctx.send_viewport_cmd(egui::ViewportCommand::Close);
                }
            }
            Action::CloseWindow => ctx.send_viewport_cmd(egui::ViewportCommand::Close),
            Action::AskForFile(file_action) => self.ask_for_file(file_action),
            Action::Open(role, path) => {
                self.open_file(role, &path);
            }
            Action::OpenPair { mesh, cage } => {
                self.open_pair(&mesh, &cage);
            }
            Action::TakePose { path, pose } => {
                self.take_pose_file(&path, pose);
            }
            Action::Error(text) => self.error(text),
            Action::DismissNotice(index) => self.notices.dismiss(index),
            Action::Apply(command) => {
                self.apply(command);
            }
        }
    }

    /// Queue `action` for the end of the next frame, as a panel would.
    pub fn queue_action(&mut self, action: Action) {
        self.actions.push(action);
    }

    // ---- thin wrappers over the panels' state, for the tests ---------------------

    /// The pose differs from the rest pose and from the last one saved or loaded.
    pub fn pose_is_unsaved(&self) -> bool {
        self.model.pose_unsaved()
    }

    /// The current pose is on disk (saved, loaded or bundled): quitting keeps it.
    pub(super) fn mark_pose_saved(&mut self) {
        self.apply(Command::MarkSaved);
    }

    pub fn notices(&self) -> &Notices {
        &self.notices
    }

    pub fn notices_mut(&mut self) -> &mut Notices {
        &mut self.notices
    }

    /// The latest error, if any (for tests and the status bar).
    pub fn last_error(&self) -> Option<&str> {
        self.notices.last_error()
    }

    /// The quit question is shown.
    pub fn is_asking_to_quit(&self) -> bool {
        self.quit.is_asking()
    }

    /// The window was told to close.
    pub fn quit_confirmed(&self) -> bool {
        self.quit.confirmed()
    }

    /// The dropped file waiting for a choice, if any.
    pub fn pending_drop(&self) -> Option<&super::ui::drop_dialog::DroppedFile> {
        self.drop_dialog.pending()
    }

    /// Average frame interval over the recent frames, in seconds.
    pub fn average_frame_time(&self) -> Option<f32> {
        self.statistics.frames().average()
    }
}

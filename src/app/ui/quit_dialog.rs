//! Quitting with an unsaved pose asks first, as Blender and Maya do: save it,
//! quit without it, or go back. A pose counts as saved when it is the rest pose or
//! the last one saved or loaded.

use crate::app::editor::EditorApp;
use crate::app::model::Command;
use crate::app::ui::file_dialog::FileAction;

/// Where quitting stands.
#[derive(Clone, Debug, Default)]
pub struct QuitState {
    /// The question is shown.
    asking: bool,
    /// The user chose to quit; the window may close.
    confirmed: bool,
    /// "Save pose…" was chosen in the question: quit once the pose is saved.
    after_save: bool,
    /// Close at the next frame (a save asked for by the question succeeded).
    close_next_frame: bool,
}

impl EditorApp {
    /// The pose differs from the rest pose and from the last one saved or loaded.
    pub fn pose_is_unsaved(&self) -> bool {
        self.model.pose_unsaved()
    }

    /// The current pose is on disk (saved, loaded or bundled): quitting keeps it.
    pub(in crate::app) fn mark_pose_saved(&mut self) {
        self.apply(Command::MarkSaved);
    }

    /// The quit question is shown.
    pub fn is_asking_to_quit(&self) -> bool {
        self.quit.asking
    }

    /// The window was told to close.
    pub fn quit_confirmed(&self) -> bool {
        self.quit.confirmed
    }

    /// File > Quit, Ctrl+Q, or the window's close button: close now when nothing
    /// would be lost, else ask.
    pub fn request_quit(&mut self, ctx: &egui::Context) {
        if self.quit.confirmed || !self.pose_is_unsaved() {
            self.quit.confirmed = true;
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        } else {
            self.quit.asking = true;
        }
    }

    /// A close asked for by the window system waits for the question's answer.
    pub(in crate::app) fn intercept_close(&mut self, ctx: &egui::Context) {
        // A scripted run (`--screenshot`) ends on its own; its pose (`--drag`) is
        // not work to keep.
        if ctx.input(|i| i.viewport().close_requested())
            && self.screenshot.is_none()
            && !self.quit.confirmed
            && self.pose_is_unsaved()
        {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.quit.asking = true;
        }
    }

    /// A pose save asked for from the question ended: quit if it was written
    /// (`save_pose` has moved the save point).
    pub(in crate::app) fn pose_save_finished(&mut self, saved: bool) {
        if std::mem::take(&mut self.quit.after_save) && saved {
            self.quit.confirmed = true;
            self.quit.close_next_frame = true;
        }
    }

    /// The question, while it is shown.
    pub(in crate::app) fn quit_dialog(&mut self, ctx: &egui::Context) {
        if std::mem::take(&mut self.quit.close_next_frame) {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
        if !self.quit.asking {
            return;
        }
        let mut answer = None;
        egui::Window::new("Quit with an unsaved pose?")
            .collapsible(false)
            .resizable(false)
            .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
            .show(ctx, |ui| {
                ui.label("The cage's pose differs from the rest pose and from the last pose saved or loaded.");
                ui.horizontal(|ui| {
                    if ui.button("Save pose…").clicked() {
                        answer = Some(QuitAnswer::Save);
                    }
                    if ui.button("Quit without saving").clicked() {
                        answer = Some(QuitAnswer::Discard);
                    }
                    if ui.button("Cancel").clicked() {
                        answer = Some(QuitAnswer::Cancel);
                    }
                });
            });
        if ctx.input(|i| i.key_pressed(egui::Key::Escape)) {
            answer = Some(QuitAnswer::Cancel);
        }
        match answer {
            Some(QuitAnswer::Save) => {
                self.quit.asking = false;
                self.quit.after_save = true;
                self.ask_for_file(FileAction::SavePose);
            }
            Some(QuitAnswer::Discard) => {
                self.quit.asking = false;
                self.quit.confirmed = true;
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
            Some(QuitAnswer::Cancel) => self.quit.asking = false,
            None => {}
        }
    }
}

enum QuitAnswer {
    Save,
    Discard,
    Cancel,
}

//! Quitting with an unsaved pose asks first, as Blender and Maya do: save it,
//! quit without it, or go back. A pose counts as saved when it is the rest pose or
//! the last one saved or loaded.

use crate::app::actions::Action;
use crate::app::ctx::PanelContext;
use crate::app::ui::file_dialog::FileAction;

/// The quit question and where quitting stands.
#[derive(Clone, Debug, Default)]
pub struct QuitDialog {
    /// The question is shown.
    asking: bool,
    /// The user chose to quit; the window may close.
    confirmed: bool,
    /// "Save pose…" was chosen in the question: quit once the pose is saved.
    after_save: bool,
    /// Close at the next frame (a save asked for by the question succeeded).
    close_next_frame: bool,
}

impl QuitDialog {
    /// The question is shown.
    pub fn is_asking(&self) -> bool {
        self.asking
    }

    /// The window was told to close.
    pub fn confirmed(&self) -> bool {
        self.confirmed
    }

    /// File > Quit, Ctrl+Q, or the window's close button: true when the window
    /// may close now (nothing would be lost), else the question is shown.
    pub fn request(&mut self, pose_unsaved: bool) -> bool {
        if self.confirmed || !pose_unsaved {
            self.confirmed = true;
        } else {
            self.asking = true;
        }
        self.confirmed
    }

    /// A close asked for by the window system waits for the question's answer. A
    /// scripted run (`--screenshot`) ends on its own; its pose (`--drag`) is not
    /// work to keep.
    pub fn intercept_close(&mut self, ctx: &egui::Context, scripted: bool, pose_unsaved: bool) {
        if ctx.input(|i| i.viewport().close_requested())
            && !scripted
            && !self.confirmed
            && pose_unsaved
        {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.asking = true;
        }
    }

    /// A pose save ended: quit if it was asked for by the question and written.
    pub fn pose_save_finished(&mut self, saved: bool) {
        if std::mem::take(&mut self.after_save) && saved {
            self.confirmed = true;
            self.close_next_frame = true;
        }
    }

    /// The question, while it is shown. It sends `AskForFile(SavePose)` for
    /// Save pose… and `CloseWindow` for quitting; it sees nothing else.
    pub fn ui(&mut self, ctx: &egui::Context, context: &mut PanelContext) {
        if std::mem::take(&mut self.close_next_frame) {
            context.send(Action::CloseWindow);
        }
        if !self.asking {
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
                self.asking = false;
                self.after_save = true;
                context.send(Action::AskForFile(FileAction::SavePose));
            }
            Some(QuitAnswer::Discard) => {
                self.asking = false;
                self.confirmed = true;
                context.send(Action::CloseWindow);
            }
            Some(QuitAnswer::Cancel) => self.asking = false,
            None => {}
        }
    }
}

enum QuitAnswer {
    Save,
    Discard,
    Cancel,
}

//! Quitting, closing the window or opening another scene with unsaved work asks
//! first, as Blender and Maya do: save the session, quit (or open) without it,
//! or go back. The question names what would be lost: the pose, the named
//! poses, a generated or edited cage, a rest mesh made from a pose.
//!
//! The dialog only asks. What waits for the answer (quitting, the scene read
//! from disk) is the editor's, which the answer's action resumes or drops.

use crate::app::actions::Action;
pub use crate::app::actions::UnsavedAnswer;
use crate::app::ctx::PanelContext;
use crate::app::model::Unsaved;

/// What waits for the answer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Question {
    Quit,
    /// Opening another scene, by what the editor's notice calls it.
    Open(String),
}

#[derive(Clone, Debug, Default)]
pub struct UnsavedDialog {
    /// The question shown, with what was unsaved when it was asked.
    asking: Option<(Question, Unsaved)>,
    /// The user chose to quit (or nothing was unsaved): the window may close.
    confirmed: bool,
}

impl UnsavedDialog {
    pub fn is_asking(&self) -> bool {
        self.asking.is_some()
    }

    /// The question shown, if one is.
    pub fn question(&self) -> Option<&Question> {
        self.asking.as_ref().map(|(question, _)| question)
    }

    /// The window was told to close.
    pub fn confirmed(&self) -> bool {
        self.confirmed
    }

    /// Quitting goes ahead: the window may close without asking again.
    pub fn confirm_quit(&mut self) {
        self.confirmed = true;
        self.asking = None;
    }

    /// Show `question` about `unsaved` work.
    pub fn ask(&mut self, question: Question, unsaved: Unsaved) {
        self.asking = Some((question, unsaved));
    }

    /// File > Quit, Ctrl+Q: true when the window may close now (nothing would be
    /// lost, or quitting was confirmed), else the question is shown.
    pub fn request_quit(&mut self, unsaved: Unsaved) -> bool {
        if !self.confirmed && unsaved.any() {
            self.ask(Question::Quit, unsaved);
        } else {
            self.confirm_quit();
        }
        self.confirmed
    }

    /// A close asked for by the window system waits for the answer; true when
    /// it was held. A scripted run (`--screenshot`) ends on its own; its pose
    /// (`--drag`) is not work to keep. `unsaved` is asked only for a close.
    pub fn intercept_close(
        &mut self,
        ctx: &egui::Context,
        scripted: bool,
        unsaved: impl FnOnce() -> Unsaved,
    ) -> bool {
        if !ctx.input(|i| i.viewport().close_requested()) || scripted || self.confirmed {
            return false;
        }
        let unsaved = unsaved();
        if unsaved.any() {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.ask(Question::Quit, unsaved);
        }
        unsaved.any()
    }

    /// The question, while it is shown. Every button sends
    /// `Action::Unsaved(answer)`; it sees nothing else.
    pub fn ui(&mut self, ctx: &egui::Context, context: &mut PanelContext) {
        let Some((question, unsaved)) = &self.asking else {
            return;
        };
        let (title, go_on) = match question {
            Question::Quit => (
                "Save changes before quitting?".to_owned(),
                "Quit without saving",
            ),
            Question::Open(what) => (
                format!("Save changes before opening {what}?"),
                "Open without saving",
            ),
        };
        let mut answer = None;
        egui::Window::new(title)
            .collapsible(false)
            .resizable(false)
            .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
            .show(ctx, |ui| {
                ui.label(format!("Not saved: {}.", unsaved.items().join(", ")));
                if !unsaved.only_pose() {
                    ui.label("A session keeps them all; a pose file keeps only the pose.");
                }
                ui.horizontal(|ui| {
                    if ui.button("Save session…").clicked() {
                        answer = Some(UnsavedAnswer::SaveSession);
                    }
                    if unsaved.only_pose() && ui.button("Save pose…").clicked() {
                        answer = Some(UnsavedAnswer::SavePose);
                    }
                    if ui.button(go_on).clicked() {
                        answer = Some(UnsavedAnswer::Discard);
                    }
                    if ui.button("Cancel").clicked() {
                        answer = Some(UnsavedAnswer::Cancel);
                    }
                });
            });
        if ctx.input(|i| i.key_pressed(egui::Key::Escape)) {
            answer = Some(UnsavedAnswer::Cancel);
        }
        if let Some(answer) = answer {
            self.asking = None;
            context.send(Action::Unsaved(answer));
        }
    }
}

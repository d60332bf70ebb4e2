//! What quitting and opening another scene wait for: the unsaved-work
//! question and its answers, autosave, and recovery of work an editor left
//! behind.

use super::{EditorApp, Waiting};
use crate::app::actions::{Action, FileAction, RecoverAnswer, UnsavedAnswer};
use crate::app::commands::Command;
use crate::app::files::{self, SceneChange};
use crate::app::ui::unsaved_dialog::Question;
use std::path::Path;

impl EditorApp {
    /// Open another scene, or edit this one: another scene waits for the
    /// answer to "Save changes?" when work would be lost. True when the change
    /// was read and checked (it may still wait).
    pub(super) fn change_scene(&mut self, change: Result<SceneChange, String>) -> bool {
        let change = match change {
            Ok(change) => change,
            Err(error) => {
                self.error(error);
                return false;
            }
        };
        let unsaved = self.model.unsaved();
        if !change.same_session && unsaved.any() {
            let what = change.replacement.document.title().to_owned();
            self.panels.unsaved.ask(Question::Open(what), unsaved);
            self.files.waiting = Some(Waiting::Open(Box::new(change)));
            return true;
        }
        self.apply_scene_change(change);
        true
    }

    /// The answer to "Save changes before quitting (or opening)?".
    pub(super) fn answer_unsaved(&mut self, answer: UnsavedAnswer) {
        match answer {
            UnsavedAnswer::Cancel => self.files.waiting = None,
            UnsavedAnswer::Discard => self.go_on(),
            UnsavedAnswer::SaveSession => match self.files.session_path.clone() {
                Some(path) => {
                    if self.save_session_now(&path) {
                        self.go_on_after_save();
                    } else {
                        self.files.waiting = None;
                    }
                }
                None => self.ask_for_file_now(FileAction::SaveSession),
            },
            UnsavedAnswer::SavePose => self.ask_for_file_now(FileAction::SavePose),
        }
    }

    /// A save finished: what waited goes on, unless work is still unsaved (a
    /// pose file keeps only the pose), when the question comes back.
    pub(super) fn go_on_after_save(&mut self) {
        let Some(waiting) = self.files.waiting.take() else {
            return;
        };
        let unsaved = self.model.unsaved();
        if unsaved.any() {
            let question = match &waiting {
                Waiting::Quit => Question::Quit,
                Waiting::Open(change) => Question::Open(change.replacement.document.title().into()),
            };
            self.panels.unsaved.ask(question, unsaved);
            self.files.waiting = Some(waiting);
            return;
        }
        self.files.waiting = Some(waiting);
        self.go_on();
    }

    /// The answer about a recovery file left behind.
    pub(super) fn recover(&mut self, path: &Path, answer: RecoverAnswer) {
        match answer {
            RecoverAnswer::Later => {}
            RecoverAnswer::Discard => {
                crate::app::recovery::discard(path);
                self.info(format!(
                    "discarded the autosaved work {}",
                    crate::formats::shown_path(path)
                ));
            }
            RecoverAnswer::Restore => {
                let change = files::open_session(path).map(|mut change| {
                    // Not a session of the user's: Save session asks for a name.
                    change.session = None;
                    change.recent = None;
                    change
                });
                if !self.change_scene(change) {
                    return;
                }
                self.apply(Command::MarkRecovered);
                self.files.session_path = None;
                // This editor's own autosave holds it before the old file goes.
                if self.autosave_now().is_ok() {
                    crate::app::recovery::discard(path);
                }
                self.info("restored the autosaved work: File > Save session… keeps it");
            }
        }
    }

    /// Carry out what waited for the question: quit, or open the scene.
    fn go_on(&mut self) {
        match self.files.waiting.take() {
            Some(Waiting::Quit) => {
                self.panels.unsaved.confirm_quit();
                self.actions.push(Action::CloseWindow);
            }
            Some(Waiting::Open(change)) => self.apply_scene_change(*change),
            None => {}
        }
    }

    /// Autosave unsaved work when it is due; let the file go once nothing is
    /// unsaved.
    pub(super) fn autosave_when_due(&mut self, ctx: &egui::Context) {
        let Some(recovery) = &mut self.files.recovery else {
            return;
        };
        if !self.model.unsaved().any() {
            recovery.remove();
            return;
        }
        let now = ctx.input(|i| i.time);
        match recovery.due_in(now, self.model.document()) {
            None => {}
            Some(wait) if wait > 0.0 => {
                ctx.request_repaint_after(std::time::Duration::from_secs_f64(wait));
            }
            Some(_) => {
                if let Err(error) = self.autosave_now() {
                    self.error(error);
                }
            }
        }
    }

    /// Write the session to the recovery file now.
    pub(super) fn autosave_now(&mut self) -> Result<(), String> {
        let settings = self.session_settings();
        let Some(recovery) = &mut self.files.recovery else {
            return Err("this run keeps no recovery file".into());
        };
        let now = self.run.clock;
        recovery.write(now, self.model.document(), &settings)
    }
}

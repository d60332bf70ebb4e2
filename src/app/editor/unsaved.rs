//! Files and unsaved work: opening, saving and exporting (each refusing to
//! write over what the scene was read from) and the file dialogs' answers;
//! what quitting and opening another scene wait for: the unsaved-work
//! question and its answers, autosave, and recovery of work an editor left
//! behind.

use super::{EditorApp, Waiting};
use crate::app::actions::{Action, FileAction, FileRole, RecoverAnswer, UnsavedAnswer};
use crate::app::commands::Command;
use crate::app::files::{self, SceneChange};
use crate::app::recent::RecentEntry;
use crate::app::session::SessionSettings;
use crate::app::ui::file_dialog::DialogAnswer;
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

impl EditorApp {
    /// `positions` read from `path` as the pose, once checked; the pose is
    /// then on disk.
    pub(super) fn take_pose(
        &mut self,
        path: &Path,
        checked: Result<Vec<glam::DVec3>, String>,
    ) -> bool {
        match checked {
            Ok(pose) => {
                self.apply(Command::edit_pose(pose));
                self.apply(Command::MarkSaved);
                self.info(format!("loaded pose {}", crate::formats::shown_path(path)));
                true
            }
            Err(error) => {
                self.error(error);
                false
            }
        }
    }

    // ---- files ----------------------------------------------------------------------

    pub(super) fn open_file_now(&mut self, role: FileRole, path: &Path) -> bool {
        self.open_object_now(role, path, None)
    }

    /// Object `object` of the file at `path` as the mesh or the cage.
    pub(super) fn open_object_now(
        &mut self,
        role: FileRole,
        path: &Path,
        object: Option<&str>,
    ) -> bool {
        let change = files::open_file(role, path, object, self.model.document());
        self.change_scene(change)
    }

    /// Another object of the current mesh's or cage's file in its place.
    pub(super) fn reopen_object_now(&mut self, role: FileRole, object: Option<&str>) -> bool {
        let document = self.model.document();
        let path = match role {
            FileRole::Mesh => document.mesh_file().map(|file| file.path.clone()),
            FileRole::Cage => document.cage_path().map(Path::to_path_buf),
        };
        match path {
            Some(path) => self.open_object_now(role, &path, object),
            None => {
                self.error("this scene was not read from a file with objects to choose from");
                false
            }
        }
    }

    pub(super) fn open_pair_now(
        &mut self,
        mesh: &Path,
        cage: &Path,
        objects: files::ObjectNames,
    ) -> bool {
        self.change_scene(files::open_pair(mesh, cage, objects))
    }

    pub(super) fn open_session_now(&mut self, path: &Path) -> bool {
        self.change_scene(files::open_session(path))
    }

    pub(super) fn open_recent_now(&mut self, entry: &RecentEntry) -> bool {
        let opened = match entry {
            RecentEntry::Session(path) => self.open_session_now(path),
            RecentEntry::Scene {
                mesh,
                cage,
                mesh_object,
                cage_object,
            } => {
                let objects = files::ObjectNames {
                    mesh: mesh_object.as_deref(),
                    cage: cage_object.as_deref(),
                };
                self.open_pair_now(mesh, cage, objects)
            }
            RecentEntry::Mesh(path) => self.open_file_now(FileRole::Mesh, path),
            RecentEntry::Cage(path) => self.open_file_now(FileRole::Cage, path),
            RecentEntry::MeshObject { path, object } => {
                self.open_object_now(FileRole::Mesh, path, Some(object))
            }
            RecentEntry::CageObject { path, object } => {
                self.open_object_now(FileRole::Cage, path, Some(object))
            }
        };
        if !opened {
            self.files.recent.forget(entry);
        }
        opened
    }

    pub(super) fn load_pose_now(&mut self, path: &Path) -> bool {
        let checked = files::read_pose(path, self.model.document());
        self.take_pose(path, checked)
    }

    /// Whether `path` may be written by anything but Save session: never the
    /// session file the scene came from (the mesh and cage are refused by the
    /// writers in `files`).
    fn refuse_overwriting_session(&mut self, path: &Path) -> bool {
        let session = self.files.session_path.as_deref();
        match files::refuse_overwriting_inputs(path, self.model.document(), session) {
            Ok(()) => false,
            Err(error) => {
                self.error(error);
                true
            }
        }
    }

    pub(super) fn save_pose_now(&mut self, path: &Path) -> bool {
        if self.refuse_overwriting_session(path) {
            return false;
        }
        let saved = self.report(files::save_pose(path, self.model.document()));
        if saved {
            self.apply(Command::MarkSaved);
        }
        saved
    }

    pub(super) fn save_cage_now(&mut self, path: &Path) -> bool {
        if self.refuse_overwriting_session(path) {
            return false;
        }
        self.report(files::save_cage(path, self.model.document()))
    }

    /// What a session keeps besides the document.
    pub(super) fn session_settings(&self) -> SessionSettings {
        SessionSettings {
            bind_options: self.binding.options,
            view: self.views.settings,
            cameras: self.views.viewport.camera_list(),
        }
    }

    pub(super) fn save_session_now(&mut self, path: &Path) -> bool {
        let settings = self.session_settings();
        let saved = self.report(files::save_session(path, self.model.document(), &settings));
        if saved {
            self.apply(Command::MarkSessionSaved);
            self.files.session_path = Some(path.to_owned());
            self.files
                .recent
                .remember(RecentEntry::Session(path.to_owned()));
        }
        saved
    }

    pub(super) fn export_deformed_now(&mut self, path: &Path) -> bool {
        if self.refuse_overwriting_session(path) {
            return false;
        }
        let method = self.binding.active_method();
        self.report(files::export_deformed(path, self.model.document(), method))
    }

    pub(super) fn export_gltf_now(&mut self, path: &Path, base: files::GltfBase) -> bool {
        if self.refuse_overwriting_session(path) {
            return false;
        }
        let (document, method) = (self.model.document(), self.binding.active_method());
        let exported = files::export_gltf(path, document, method, base);
        self.report(exported)
    }

    pub(super) fn export_coloured_mesh_now(&mut self, path: &Path) -> bool {
        if self.refuse_overwriting_session(path) {
            return false;
        }
        let wanted = self.wanted_methods_now();
        let exported = self
            .views
            .export_coloured_mesh(path, self.model.document(), &wanted);
        self.report(exported)
    }

    pub(super) fn save_image_now(&mut self, path: &Path) -> bool {
        if self.refuse_overwriting_session(path) {
            return false;
        }
        self.files.image_request.ask(path);
        true
    }

    /// Ask for a file for `action` and carry it out: the system's dialog when it
    /// works, else the in-window one (which answers in a later frame).
    pub(super) fn ask_for_file_now(&mut self, action: FileAction) {
        let name = match action {
            FileAction::SaveSession => Some(files::session_name(self.model.document())),
            FileAction::SaveCage => Some(files::cage_name(self.model.document())),
            _ => None,
        };
        match self.panels.file_dialogs.ask(action, name) {
            DialogAnswer::Chosen(path) => {
                self.finish_file_action(action, &path);
            }
            DialogAnswer::Cancelled => self.file_action_cancelled(action),
            DialogAnswer::InWindow { fell_back } => {
                if fell_back {
                    self.info(
                        "the system's file dialog did not open (no desktop portal?): using the \
                         in-window dialog (File > In-window file dialog)",
                    );
                }
            }
        }
    }

    /// Carry out `action` on `path`; true when it succeeded.
    pub(super) fn finish_file_action(&mut self, action: FileAction, path: &Path) -> bool {
        self.panels.file_dialogs.remember_folder(path);
        let done = match action {
            FileAction::OpenMesh => self.open_file_now(FileRole::Mesh, path),
            FileAction::OpenCage => self.open_file_now(FileRole::Cage, path),
            FileAction::LoadPose => self.load_pose_now(path),
            FileAction::SavePose => self.save_pose_now(path),
            FileAction::SaveCage => self.save_cage_now(path),
            FileAction::ExportMesh => self.export_deformed_now(path),
            FileAction::OpenSession => self.open_session_now(path),
            FileAction::SaveSession => self.save_session_now(path),
            FileAction::SaveImage => self.save_image_now(path),
            FileAction::ExportColouredMesh => self.export_coloured_mesh_now(path),
            FileAction::ExportGltf => self.export_gltf_now(path, files::GltfBase::Rest),
            FileAction::ExportGltfPosedBase => self.export_gltf_now(path, files::GltfBase::Pose),
        };
        if matches!(action, FileAction::SavePose | FileAction::SaveSession) {
            if done {
                self.go_on_after_save();
            } else if !self.panels.file_dialogs.is_open() {
                // The system's dialog is gone with the error: the user answers
                // again when quitting or opening again.
                self.files.waiting = None;
            }
        }
        done
    }

    pub(super) fn file_action_cancelled(&mut self, action: FileAction) {
        if matches!(action, FileAction::SavePose | FileAction::SaveSession) {
            self.files.waiting = None;
        }
    }

    /// The in-window dialog's file: carried out, the dialog closes; failed, it
    /// stays and says why, so another file can be chosen.
    pub(super) fn in_window_answer(&mut self, action: FileAction, path: &Path) {
        let notices_before = self.panels.notices.all().len();
        let done = self.finish_file_action(action, path);
        let failed = (!done).then(|| {
            let notices = self.panels.notices.all();
            (notices.get(notices_before..))
                .and_then(|new| new.iter().rev().find(|n| n.is_error))
                .map_or_else(|| "failed".into(), |n| n.text.clone())
        });
        self.panels.file_dialogs.answered(failed);
    }

    // ---- the Generate cage window -----------------------------------------------------
}

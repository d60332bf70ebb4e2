//! The editor's model: everything undoable — the document, the one undo log, the
//! gesture under way and the save point. It changes only through
//! [`Model::apply`], the single caller of the document's mutators: lengths are
//! checked there, undo steps are made there, and replacing the document ends any
//! gesture, so no step of one cage can be undone onto another.

pub mod document;
mod save_point;
mod undo_log;

use super::commands::{GestureKind, Selection, SessionView, POSE_EDIT};
use document::{Changes, Document};
use glam::DVec3;
use save_point::SessionMark;
pub use save_point::Unsaved;
use std::sync::Arc;
use undo_log::{Step, UndoLog};

// Commands are defined below the model, in `commands.rs`, so that what sends
// them need not depend on the model; `model::{Command, Model}` still names both.
pub use super::commands::Command;

#[derive(Debug)]
struct Gesture {
    kind: GestureKind,
    start_pose: Vec<DVec3>,
}

/// A whole document came back from the undo log.
#[derive(Debug)]
pub struct Swapped {
    /// What was undone or redone ("open cage.obj").
    pub action: String,
    /// The mesh stayed (a cage edit): the cameras need not frame it again.
    pub same_mesh: bool,
    /// The view settings to show with it, when the step kept them.
    pub view: Option<SessionView>,
}

/// What applying a command did.
#[derive(Debug, PartialEq)]
pub enum Outcome {
    Unchanged,
    Changed,
    /// Refused, with why (a pose of another length, a name in use).
    Refused(String),
}

/// The result of [`Model::apply`]: the outcome, and the document swapped in by
/// undo or redo, which the views and the GPU copy must follow.
#[derive(Debug)]
pub struct Applied {
    pub outcome: Outcome,
    pub swapped: Option<Swapped>,
}

impl Applied {
    fn of(outcome: Outcome) -> Self {
        Self {
            outcome,
            swapped: None,
        }
    }

    pub fn changed(&self) -> bool {
        self.outcome == Outcome::Changed
    }
}

#[derive(Debug)]
pub struct Model {
    document: Document,
    log: UndoLog,
    gesture: Option<Gesture>,
    /// The pose last saved (a session or a pose file), or opened as saved.
    saved_pose: Vec<DVec3>,
    /// `None` after recovery: no session holds this work.
    session_mark: Option<SessionMark>,
}

impl Model {
    pub fn new(document: Document) -> Self {
        Self {
            session_mark: Some(SessionMark::of(&document)),
            document,
            log: UndoLog::default(),
            gesture: None,
            saved_pose: Vec::new(),
        }
    }

    pub fn document(&self) -> &Document {
        &self.document
    }

    /// The pose a gesture of `kind` under way started from.
    pub fn gesture_start(&self, kind: GestureKind) -> Option<&[DVec3]> {
        (self.gesture.as_ref())
            .filter(|g| g.kind == kind)
            .map(|g| g.start_pose.as_slice())
    }

    pub fn gesture_under_way(&self) -> Option<GestureKind> {
        self.gesture.as_ref().map(|g| g.kind)
    }

    /// What Undo would reverse, for its menu entry.
    pub fn undo_label(&self) -> Option<&str> {
        self.log.undo_action()
    }

    pub fn redo_label(&self) -> Option<&str> {
        self.log.redo_action()
    }

    /// The pose differs from the rest pose and from the one last saved.
    pub fn pose_unsaved(&self) -> bool {
        let pose = self.document.pose();
        pose != self.document.cage().positions() && pose != self.saved_pose.as_slice()
    }

    /// What quitting or opening another scene would lose now.
    pub fn unsaved(&self) -> Unsaved {
        Unsaved::of(
            &self.document,
            self.session_mark.as_ref(),
            self.pose_unsaved(),
        )
    }

    /// What changed since the last call, for the GPU copy and the caches.
    pub fn take_changes(&mut self) -> Changes {
        self.document.take_changes()
    }

    pub fn apply(&mut self, command: Command) -> Applied {
        match command {
            Command::EditPose { pose, action } => Applied::of(self.edit_pose(pose, &action)),
            Command::BeginGesture(kind) => {
                self.end_gesture(POSE_EDIT);
                self.gesture = Some(Gesture {
                    kind,
                    start_pose: self.document.pose().to_vec(),
                });
                Applied::of(Outcome::Changed)
            }
            Command::PreviewGesture(pose) => Applied::of(self.preview(pose)),
            Command::EndGesture { action } => Applied::of(self.end_gesture(&action)),
            Command::CancelGesture => Applied::of(self.cancel_gesture()),
            Command::Select(selection) => {
                match selection {
                    Selection::Only(handles) => self.document.select_only(handles),
                    Selection::More(handles) => self.document.select_more(handles),
                    Selection::Toggle(handle) => self.document.toggle_selected(handle),
                }
                Applied::of(Outcome::Changed)
            }
            Command::StoreNamedPose(name) => {
                self.record_pose_step(&format!("store pose {name}"));
                self.document.store_named_pose(&name);
                Applied::of(Outcome::Changed)
            }
            Command::DeleteNamedPose(index) => {
                let Some(name) = self
                    .document
                    .named_poses()
                    .get(index)
                    .map(|n| n.name.clone())
                else {
                    return Applied::of(Outcome::Unchanged);
                };
                self.record_pose_step(&format!("delete pose {name}"));
                self.document.delete_named_pose(index);
                Applied::of(Outcome::Changed)
            }
            Command::RenameNamedPose { index, name } => Applied::of(self.rename(index, &name)),
            Command::SetPoseTime { index, time } => Applied::of(self.set_pose_time(index, time)),
            Command::InstallWeights { id, set, outside } => {
                Applied::of(if self.document.install_weights(id, set, outside) {
                    Outcome::Changed
                } else {
                    Outcome::Unchanged
                })
            }
            Command::ReplaceDocument {
                document,
                action,
                view,
            } => {
                self.cancel_gesture();
                let before = std::mem::replace(&mut self.document, *document);
                self.log.record(Step::Scene {
                    document: Box::new(before),
                    view,
                    action,
                });
                Applied::of(Outcome::Changed)
            }
            Command::SetDeformParameter { parameter, value } => {
                Applied::of(self.set_deform_value(parameter, value))
            }
            Command::InstallDocument(document) => {
                self.gesture = None;
                self.document = *document;
                self.session_mark = Some(SessionMark::of(&self.document));
                self.log.clear();
                Applied::of(Outcome::Changed)
            }
            Command::ForgetHistory => {
                self.log.clear();
                Applied::of(Outcome::Changed)
            }
            Command::Undo(view) => self.step_back_or_forth(true, view),
            Command::Redo(view) => self.step_back_or_forth(false, view),
            Command::MarkSaved => {
                self.saved_pose = self.document.pose().to_vec();
                Applied::of(Outcome::Changed)
            }
            Command::MarkSessionSaved => {
                self.saved_pose = self.document.pose().to_vec();
                self.session_mark = Some(SessionMark::of(&self.document));
                Applied::of(Outcome::Changed)
            }
            Command::MarkRecovered => {
                self.saved_pose.clear();
                self.session_mark = None;
                Applied::of(Outcome::Changed)
            }
        }
    }

    /// Why `pose` cannot be the document's, if it cannot.
    fn refuse_length(&self, pose: &[DVec3]) -> Option<Outcome> {
        let count = self.document.pose().len();
        (pose.len() != count).then(|| {
            Outcome::Refused(format!(
                "a pose of {} positions for a cage of {count} vertices",
                pose.len()
            ))
        })
    }

    fn edit_pose(&mut self, pose: Vec<DVec3>, action: &str) -> Outcome {
        if let Some(refused) = self.refuse_length(&pose) {
            return refused;
        }
        if pose == self.document.pose() {
            return Outcome::Unchanged;
        }
        self.record_pose_step(action);
        self.document.set_pose(pose);
        Outcome::Changed
    }

    fn preview(&mut self, pose: Vec<DVec3>) -> Outcome {
        if self.gesture.is_none() {
            return Outcome::Refused("no gesture under way".into());
        }
        if let Some(refused) = self.refuse_length(&pose) {
            return refused;
        }
        if pose == self.document.pose() {
            return Outcome::Unchanged;
        }
        self.document.set_pose(pose);
        Outcome::Changed
    }

    fn end_gesture(&mut self, action: &str) -> Outcome {
        let Some(gesture) = self.gesture.take() else {
            return Outcome::Unchanged;
        };
        if gesture.start_pose == self.document.pose() {
            return Outcome::Unchanged;
        }
        let named_poses = self.document.named_poses_shared();
        self.record(Step::Pose {
            pose: gesture.start_pose,
            named_poses,
            action: action.into(),
        });
        Outcome::Changed
    }

    fn cancel_gesture(&mut self) -> Outcome {
        let Some(gesture) = self.gesture.take() else {
            return Outcome::Unchanged;
        };
        if gesture.start_pose == self.document.pose() {
            return Outcome::Unchanged;
        }
        self.document.set_pose(gesture.start_pose);
        Outcome::Changed
    }

    /// A deformation setting, checked by its spec, as one undo step that
    /// brings back the document as it was (its weights are shared, not copied).
    fn set_deform_value(&mut self, parameter: crate::coords::Parameter, value: u32) -> Outcome {
        let spec = parameter.spec();
        let value = match spec.validate(value.into()) {
            Ok(value) => value,
            Err(error) => return Outcome::Refused(error.to_string()),
        };
        if self.document.deform_value(parameter) == value {
            return Outcome::Unchanged;
        }
        self.cancel_gesture();
        let mut next = self.document.clone();
        next.set_deform_value(parameter, value);
        let before = std::mem::replace(&mut self.document, next);
        self.log.record(Step::Scene {
            document: Box::new(before),
            view: None,
            action: format!("{} {}", spec.label, spec.text(value)),
        });
        Outcome::Changed
    }

    fn rename(&mut self, index: usize, name: &str) -> Outcome {
        let named = self.document.named_poses();
        if named
            .iter()
            .enumerate()
            .any(|(i, n)| i != index && n.name == name)
        {
            return Outcome::Refused(format!("a pose is already called \"{name}\""));
        }
        let Some(old) = named.get(index).map(|n| n.name.clone()) else {
            return Outcome::Refused(format!("no stored pose {}", index + 1));
        };
        if old == name {
            return Outcome::Unchanged;
        }
        self.record_pose_step(&format!("rename pose {old} to {name}"));
        self.document.rename_named_pose(index, name);
        Outcome::Changed
    }

    fn set_pose_time(&mut self, index: usize, time: Option<f64>) -> Outcome {
        let named = self.document.named_poses();
        let Some(pose) = named.get(index) else {
            return Outcome::Refused(format!("no stored pose {}", index + 1));
        };
        if pose.time == time {
            return Outcome::Unchanged;
        }
        let name = pose.name.clone();
        if let Some(seconds) = time {
            if let Err(why) = crate::app::timeline::check_key_time(seconds) {
                return Outcome::Refused(why);
            }
            if let Some(other) = named
                .iter()
                .enumerate()
                .find(|(i, n)| *i != index && n.time == Some(seconds))
            {
                return Outcome::Refused(format!("\"{}\" is already at {seconds} s", other.1.name));
            }
        }
        let action = match time {
            Some(seconds) => format!("place pose {name} at {seconds} s"),
            None => format!("take pose {name} off the timeline"),
        };
        self.record_pose_step(&action);
        self.document.set_named_pose_time(index, time);
        Outcome::Changed
    }

    /// Record the pose and named poses now, which `action` is about to change.
    fn record_pose_step(&mut self, action: &str) {
        self.record(Step::Pose {
            pose: self.document.pose().to_vec(),
            named_poses: self.document.named_poses_shared(),
            action: action.into(),
        });
    }

    fn record(&mut self, step: Step) {
        self.log.record(step);
        self.document.count_edit();
    }

    /// Undo (`back`) or redo the last step; `view` is what is shown now.
    fn step_back_or_forth(&mut self, back: bool, view: SessionView) -> Applied {
        self.cancel_gesture();
        let step = if back {
            self.log.take_undo()
        } else {
            self.log.take_redo()
        };
        let Some(step) = step else {
            return Applied::of(Outcome::Unchanged);
        };
        let (reverse, applied) = match step {
            Step::Pose {
                pose,
                named_poses,
                action,
            } => {
                if let Some(refused) = self.refuse_length(&pose) {
                    // Cannot happen while steps are made here; refused all the same.
                    return Applied::of(refused);
                }
                let reverse = Step::Pose {
                    pose: self.document.pose().to_vec(),
                    named_poses: self.document.named_poses_shared(),
                    action,
                };
                self.document.restore_poses(pose, named_poses);
                (reverse, Applied::of(Outcome::Changed))
            }
            Step::Scene {
                document,
                view: kept_view,
                action,
            } => {
                let same_mesh = Arc::ptr_eq(document.mesh(), self.document.mesh());
                let mut after = std::mem::replace(&mut self.document, *document);
                after.mark_all_changed();
                self.document.mark_all_changed();
                let reverse = Step::Scene {
                    document: Box::new(after),
                    view: kept_view.map(|_| view),
                    action: action.clone(),
                };
                let applied = Applied {
                    outcome: Outcome::Changed,
                    swapped: Some(Swapped {
                        action,
                        same_mesh,
                        view: kept_view,
                    }),
                };
                (reverse, applied)
            }
        };
        if back {
            self.log.push_redo(reverse);
        } else {
            self.log.push_undo(reverse);
        }
        applied
    }
}

#[cfg(test)]
mod tests;

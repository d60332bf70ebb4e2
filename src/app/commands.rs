//! Every change of the model, as values, and what one carries: panels, the
//! viewport and the editor's runner build them, and `Model::apply` is the one
//! place that carries them out. A leaf: it imports nothing of the editor, so
//! whatever sends commands depends on this file and not on the model.

use super::compare::ViewSettings;
use super::document::{Document, WeightSet};
use crate::coords::BindOptions;
use crate::render::{OrbitCamera, SceneOrigin, MAX_VIEWS};
use glam::DVec3;
use std::collections::BTreeSet;
use std::sync::Arc;

/// What undo calls a plain pose change.
pub const POSE_EDIT: &str = "pose edit";

/// One pose change that is previewed while it lasts and is one undo step when it
/// ends: a handle drag, a G/R/S transform, a drag on a position field, a drag of
/// the blend slider.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GestureKind {
    Drag,
    Transform,
    NumericDrag,
    Blend,
    /// The timeline playing or scrubbed.
    Playback,
}

/// The view settings a session sets beside its document: undoing the opening
/// of a session brings back the ones it replaced.
#[derive(Clone, Copy, Debug)]
pub struct SessionView {
    pub bind_options: BindOptions,
    pub view: ViewSettings,
    pub cameras: ViewCameras,
}

/// Every view's camera, with the scene origin they are relative to, kept
/// across a change of document.
#[derive(Clone, Copy, Debug)]
pub struct ViewCameras {
    pub(super) origin: SceneOrigin,
    pub(super) cameras: [OrbitCamera; MAX_VIEWS],
}

/// A change of the selection.
#[derive(Clone, Debug)]
pub enum Selection {
    Only(BTreeSet<usize>),
    More(Vec<usize>),
    Toggle(usize),
}

impl Selection {
    pub fn only(handles: impl IntoIterator<Item = usize>) -> Self {
        Selection::Only(handles.into_iter().collect())
    }
}

/// Every change of the model.
#[derive(Debug)]
pub enum Command {
    /// Change the pose as one undo step called `action`.
    EditPose {
        pose: Vec<DVec3>,
        action: String,
    },
    /// Start a gesture from the current pose (ending one under way first).
    BeginGesture(GestureKind),
    /// Show `pose` while the gesture lasts; no undo step.
    PreviewGesture(Vec<DVec3>),
    /// The gesture ends as one undo step called `action` (none if the pose is
    /// back where it started).
    EndGesture {
        action: String,
    },
    /// The gesture ends with the pose it started from.
    CancelGesture,
    Select(Selection),
    StoreNamedPose(String),
    DeleteNamedPose(usize),
    RenameNamedPose {
        index: usize,
        name: String,
    },
    /// Place a named pose on the timeline at a time (seconds), or take it off.
    SetPoseTime {
        index: usize,
        time: Option<f64>,
    },
    /// A bind's weights, if they fit the document's mesh and cage.
    InstallWeights {
        id: crate::coords::WeightsId,
        set: WeightSet,
        outside: Arc<[u32]>,
    },
    /// Replace the whole document by `action` ("open cage.obj"), as one undo
    /// step; `view` is the view settings it replaces, when it replaces them.
    ReplaceDocument {
        document: Box<Document>,
        action: String,
        view: Option<SessionView>,
    },
    /// Deform with `value` for the deformation setting `parameter`
    /// (Somigliana's bulging), checked by its spec, as one undo step.
    SetDeformParameter {
        parameter: crate::coords::Parameter,
        value: u32,
    },
    /// Make `document` current with nothing to undo (the start-up scene).
    InstallDocument(Box<Document>),
    /// Forget every step (what start-up opened is where editing begins).
    ForgetHistory,
    /// Undo or redo, given the view settings now, which a scene step keeps for
    /// the way back.
    Undo(SessionView),
    Redo(SessionView),
    /// The current pose is saved (the quit dialog compares against it).
    MarkSaved,
    /// The whole document is on disk: a session was saved or opened, or a scene
    /// was opened from its files. The pose is saved too.
    MarkSessionSaved,
    /// The document came from a recovery file: nothing of it counts as saved
    /// but the files it names.
    MarkRecovered,
}

impl Command {
    /// A plain pose change as one undo step.
    pub fn edit_pose(pose: Vec<DVec3>) -> Self {
        Command::EditPose {
            pose,
            action: POSE_EDIT.into(),
        }
    }
}

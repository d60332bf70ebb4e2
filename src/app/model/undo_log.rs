//! The one undo log: pose edits and whole-scene replacements in the order they
//! were made. A pose step keeps the pose and the named poses it changed; a scene
//! step keeps the whole document it replaced (with its weights and selection)
//! and, when the replacement changed them, the view settings beside it.

use super::document::{Document, NamedPose};
use crate::app::commands::SessionView;
use glam::DVec3;
use std::sync::Arc;

/// What one step brings back, and what undo calls it ("move handles").
#[derive(Debug)]
pub(super) enum Step {
    Pose {
        pose: Vec<DVec3>,
        named_poses: Arc<Vec<NamedPose>>,
        action: String,
    },
    Scene {
        document: Box<Document>,
        view: Option<SessionView>,
        action: String,
    },
}

impl Step {
    pub(super) fn action(&self) -> &str {
        match self {
            Step::Pose { action, .. } | Step::Scene { action, .. } => action,
        }
    }

    fn is_scene(&self) -> bool {
        matches!(self, Step::Scene { .. })
    }
}

/// Steps kept for undo; older ones are dropped.
const STEP_LIMIT: usize = 200;
/// Scene steps kept: each holds a document with its weights.
const SCENE_STEP_LIMIT: usize = 8;

#[derive(Debug, Default)]
pub(super) struct UndoLog {
    undo: Vec<Step>,
    redo: Vec<Step>,
}

impl UndoLog {
    /// A new edit: undo can reverse it, and what was undone before is gone.
    pub(super) fn record(&mut self, step: Step) {
        self.undo.push(step);
        self.redo.clear();
        // Dropped from the oldest end only: a pose step belongs to the document
        // that the scene steps after it replaced, so none may be skipped.
        while self.undo.len() > STEP_LIMIT
            || self.undo.iter().filter(|s| s.is_scene()).count() > SCENE_STEP_LIMIT
        {
            self.undo.remove(0);
        }
    }

    pub(super) fn take_undo(&mut self) -> Option<Step> {
        self.undo.pop()
    }

    pub(super) fn take_redo(&mut self) -> Option<Step> {
        self.redo.pop()
    }

    /// The step that reverses an undo (or a redo) just made.
    pub(super) fn push_redo(&mut self, step: Step) {
        self.redo.push(step);
    }

    pub(super) fn push_undo(&mut self, step: Step) {
        self.undo.push(step);
    }

    pub(super) fn undo_action(&self) -> Option<&str> {
        self.undo.last().map(Step::action)
    }

    pub(super) fn redo_action(&self) -> Option<&str> {
        self.redo.last().map(Step::action)
    }

    pub(super) fn clear(&mut self) {
        self.undo.clear();
        self.redo.clear();
    }
}

//! Undo of the actions that replace the whole document: opening a mesh or a cage,
//! switching scenes, subdividing the cage and resting the cage in its pose. Pose
//! edits have their own history inside the document; together they make one
//! undo order, because a replaced document keeps its pose history.

use super::document::Document;

/// A document some action replaced, and what that action was ("open cage.obj").
#[derive(Debug)]
struct Replaced {
    document: Document,
    action: String,
}

/// Documents kept for undo; a replaced document holds its weights, so older
/// ones are dropped.
const SCENE_HISTORY_LIMIT: usize = 8;

#[derive(Debug, Default)]
pub struct SceneHistory {
    undo: Vec<Replaced>,
    redo: Vec<Replaced>,
    /// The current document's pose-edit count when it was swapped in by undo or
    /// redo: a new pose edit after that makes the scene redo stale.
    edits_at_swap: Option<u64>,
}

impl SceneHistory {
    /// Remember `before`, which `action` is replacing. Redo is forgotten, as after
    /// any new edit, and so is `before`'s own pose redo.
    pub fn record(&mut self, mut before: Document, action: String) {
        before.forget_redo();
        self.undo.push(Replaced {
            document: before,
            action,
        });
        if self.undo.len() > SCENE_HISTORY_LIMIT {
            self.undo.remove(0);
        }
        self.redo.clear();
        self.edits_at_swap = None;
    }

    /// What undo would reverse, if it is a replacement.
    pub fn undo_action(&self) -> Option<&str> {
        self.undo.last().map(|r| r.action.as_str())
    }

    /// What redo would repeat, if it is a replacement and still valid for
    /// `current` (no pose edit since the swap).
    pub fn redo_action(&self, current: &Document) -> Option<&str> {
        if self
            .edits_at_swap
            .is_some_and(|edits| edits != current.edits())
        {
            return None;
        }
        self.redo.last().map(|r| r.action.as_str())
    }

    /// Swap `current` for the document the last replacement removed; `current`
    /// moves to redo. Returns the action undone.
    pub fn undo(&mut self, current: &mut Document) -> Option<String> {
        let Replaced { document, action } = self.undo.pop()?;
        let after = std::mem::replace(current, document);
        self.redo.push(Replaced {
            document: after,
            action: action.clone(),
        });
        self.edits_at_swap = Some(current.edits());
        Some(action)
    }

    /// Swap `current` for the document the last undo put aside. Returns the
    /// action redone.
    pub fn redo(&mut self, current: &mut Document) -> Option<String> {
        self.redo_action(current)?;
        let Replaced { document, action } = self.redo.pop()?;
        let before = std::mem::replace(current, document);
        self.undo.push(Replaced {
            document: before,
            action: action.clone(),
        });
        self.edits_at_swap = Some(current.edits());
        Some(action)
    }

    pub fn clear(&mut self) {
        *self = Self::default();
    }
}

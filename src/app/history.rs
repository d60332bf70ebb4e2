//! Undo and redo of poses.

#[cfg(test)]
use glam::DVec3;

/// Undo and redo stacks of whole states (a pose and the named poses: cages are
/// small, so snapshots are cheap and make every edit trivially reversible).
#[derive(Clone, Debug)]
pub struct History<T> {
    undo: Vec<T>,
    redo: Vec<T>,
}

/// The document's history: poses with the named poses beside them.
pub type PoseHistory = History<super::document::PoseSnapshot>;

impl<T> Default for History<T> {
    fn default() -> Self {
        Self {
            undo: Vec::new(),
            redo: Vec::new(),
        }
    }
}

/// Poses kept for undo; older ones are dropped.
const HISTORY_LIMIT: usize = 200;

impl<T: Clone + PartialEq> History<T> {
    /// Remember `before`, the state an edit is about to change.
    pub fn record(&mut self, before: T) {
        if self.undo.last() == Some(&before) {
            return;
        }
        self.undo.push(before);
        if self.undo.len() > HISTORY_LIMIT {
            self.undo.remove(0);
        }
        self.redo.clear();
    }

    /// The state to go back to, given the current one.
    pub fn undo(&mut self, current: T) -> Option<T> {
        let previous = self.undo.pop()?;
        self.redo.push(current);
        Some(previous)
    }

    pub fn redo(&mut self, current: T) -> Option<T> {
        let next = self.redo.pop()?;
        self.undo.push(current);
        Some(next)
    }

    /// The state undo would return to.
    pub fn last(&self) -> Option<&T> {
        self.undo.last()
    }

    /// The state redo would return to.
    pub fn next(&self) -> Option<&T> {
        self.redo.last()
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    pub fn clear(&mut self) {
        self.undo.clear();
        self.redo.clear();
    }

    /// Forget the poses undo has put aside, as a new edit would.
    pub fn clear_redo(&mut self) {
        self.redo.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn undo_then_redo_returns_to_each_pose() {
        let a = vec![DVec3::ZERO];
        let b = vec![DVec3::X];
        let mut history = History::default();
        history.record(a.clone());
        assert_eq!(history.undo(b.clone()), Some(a.clone()));
        assert_eq!(history.redo(a), Some(b));
        assert!(history.can_undo());
    }
}

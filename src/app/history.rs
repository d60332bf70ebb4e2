//! Undo and redo of poses.

use glam::DVec3;

/// Undo and redo stacks of whole poses (cages are small, so snapshots are cheap
/// and make every edit trivially reversible).
#[derive(Clone, Debug, Default)]
pub struct PoseHistory {
    undo: Vec<Vec<DVec3>>,
    redo: Vec<Vec<DVec3>>,
}

/// Poses kept for undo; older ones are dropped.
const HISTORY_LIMIT: usize = 200;

impl PoseHistory {
    /// Remember `before`, the pose an edit is about to change.
    pub fn record(&mut self, before: Vec<DVec3>) {
        if self.undo.last() == Some(&before) {
            return;
        }
        self.undo.push(before);
        if self.undo.len() > HISTORY_LIMIT {
            self.undo.remove(0);
        }
        self.redo.clear();
    }

    /// The pose to go back to, given the current one.
    pub fn undo(&mut self, current: &[DVec3]) -> Option<Vec<DVec3>> {
        let previous = self.undo.pop()?;
        self.redo.push(current.to_vec());
        Some(previous)
    }

    pub fn redo(&mut self, current: &[DVec3]) -> Option<Vec<DVec3>> {
        let next = self.redo.pop()?;
        self.undo.push(current.to_vec());
        Some(next)
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
        let mut history = PoseHistory::default();
        history.record(a.clone());
        assert_eq!(history.undo(&b), Some(a.clone()));
        assert_eq!(history.redo(&a), Some(b));
        assert!(history.can_undo());
    }
}

//! What the editor edits: a mesh bound to a cage, the cage's current pose, the
//! weights of each method once its bind has finished, and the undo history of poses.

use crate::coords::{BindOptions, Method, WeightQuality, Weights};
use crate::geometry::{Cage, MeshFile, TriMesh};
use glam::DVec3;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

/// A mesh, its cage and the cage's pose.
#[derive(Clone, Debug)]
pub struct Scene {
    pub title: String,
    pub mesh: Arc<TriMesh>,
    /// The file the mesh came from: exports keep its faces, groups and materials.
    pub mesh_file: Option<MeshFile>,
    /// The cage at rest, as bound.
    pub cage: Arc<Cage>,
    pub cage_path: Option<PathBuf>,
    /// The deformed cage: one position per cage vertex.
    pub pose: Vec<DVec3>,
    /// Per method ([`Scene::bound`]): its weights once its bind has finished.
    bound: [Option<Bound>; 2],
    /// Mesh vertices outside the cage, known once bound.
    pub outside: Vec<u32>,
}

/// One method's weights for the scene's mesh and cage, and how they were made.
#[derive(Clone, Debug)]
pub struct Bound {
    pub weights: Arc<Weights>,
    pub options: BindOptions,
    pub bind_time: Duration,
    /// Where the bind ran ("CPU" or the GPU's description).
    pub device: String,
    pub quality: WeightQuality,
}

fn method_slot(method: Method) -> usize {
    match method {
        Method::Mvc => 0,
        Method::Pmvc => 1,
    }
}

impl Scene {
    pub fn new(title: impl Into<String>, mesh: TriMesh, cage: Cage) -> Self {
        Self {
            title: title.into(),
            pose: cage.positions.clone(),
            mesh: Arc::new(mesh),
            mesh_file: None,
            cage: Arc::new(cage),
            cage_path: None,
            bound: [None, None],
            outside: Vec::new(),
        }
    }

    /// `method`'s weights and their bind, once bound.
    pub fn bound(&self, method: Method) -> Option<&Bound> {
        self.bound[method_slot(method)].as_ref()
    }

    /// `method`'s weights, once bound.
    pub fn weights(&self, method: Method) -> Option<&Arc<Weights>> {
        self.bound(method).map(|bound| &bound.weights)
    }

    pub fn set_bound(&mut self, method: Method, bound: Bound) {
        self.bound[method_slot(method)] = Some(bound);
    }

    /// The mesh deformed with `method` on the CPU (for export), or the rest mesh
    /// before that method is bound.
    pub fn deformed_positions(&self, method: Method) -> Vec<DVec3> {
        match self.weights(method) {
            Some(weights) => weights.apply(&self.pose),
            None => self.mesh.positions.clone(),
        }
    }

    /// Centre and radius of a sphere around the mesh and the posed cage.
    pub fn bounding_sphere(&self) -> (DVec3, f64) {
        let points: Vec<DVec3> = self
            .mesh
            .positions
            .iter()
            .chain(&self.pose)
            .copied()
            .collect();
        let (lo, hi) = crate::geometry::bounds_of(&points);
        ((lo + hi) / 2.0, ((hi - lo).length() / 2.0).max(1e-6))
    }
}

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

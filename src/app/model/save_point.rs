//! The save points the unsaved-work question compares against: what the last
//! session save (or the opening of a scene) left on disk, and what would be
//! lost now.

use super::document::{Document, NamedPose};
use crate::geometry::{Cage, TriMesh};
use std::sync::Arc;

/// What the last session save, or the opening of a scene, left on disk: the
/// mesh and cage (by identity: every edit makes new ones) and the named poses.
#[derive(Debug)]
pub(super) struct SessionMark {
    mesh: Arc<TriMesh>,
    cage: Arc<Cage>,
    named_poses: Arc<Vec<NamedPose>>,
}

impl SessionMark {
    pub(super) fn of(document: &Document) -> Self {
        Self {
            mesh: Arc::clone(document.mesh()),
            cage: Arc::clone(document.cage()),
            named_poses: document.named_poses_shared(),
        }
    }
}

/// What quitting or opening another scene would lose.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Unsaved {
    /// The pose differs from the rest pose and from the one last saved.
    pub pose: bool,
    /// Named poses were stored, renamed or deleted since the session was saved.
    pub named_poses: bool,
    /// The rest cage is not on disk (generated, subdivided, rested in a pose).
    pub cage: bool,
    /// The rest mesh is not on disk (Use pose as rest shape).
    pub mesh: bool,
}

impl Unsaved {
    pub fn any(&self) -> bool {
        self.pose || self.named_poses || self.cage || self.mesh
    }

    /// Only the pose: a pose file keeps everything.
    pub fn only_pose(&self) -> bool {
        self.pose && !(self.named_poses || self.cage || self.mesh)
    }

    /// What would be lost, in words ("the pose", "the named poses").
    pub fn items(&self) -> Vec<&'static str> {
        let mut items = Vec::new();
        if self.pose {
            items.push("the pose");
        }
        if self.named_poses {
            items.push("the named poses");
        }
        if self.cage {
            items.push("the edited or generated cage");
        }
        if self.mesh {
            items.push("the rest mesh made from a pose");
        }
        items
    }
}

impl Unsaved {
    /// What `document` would lose, against `mark` (`None` after recovery: no
    /// session holds it), with the pose's own save point already compared.
    pub(super) fn of(document: &Document, mark: Option<&SessionMark>, pose: bool) -> Self {
        let named = document.named_poses_shared();
        let (named_poses, cage, mesh) = match mark {
            Some(mark) => (
                !Arc::ptr_eq(&named, &mark.named_poses) && *named != *mark.named_poses,
                !Arc::ptr_eq(document.cage(), &mark.cage),
                !Arc::ptr_eq(document.mesh(), &mark.mesh),
            ),
            // Recovered: bundled files are still bundled, and named files on disk.
            None => {
                let generated = document.bundled().is_none();
                (!named.is_empty(), generated, generated)
            }
        };
        Unsaved {
            pose,
            named_poses,
            cage: cage && document.cage_path().is_none(),
            mesh: mesh && document.mesh_file().is_none(),
        }
    }
}

//! What the editor edits: a mesh bound to a cage, the cage's pose, the selected
//! handles, the named poses and each method's weights once bound.
//!
//! The fields are private and the mutators are the model's alone
//! ([`super::Model::apply`]). Every mutator records what it changed in
//! [`Changes`], which the editor takes once per frame to update the GPU, and
//! bumps a revision that the CPU caches compare against, so no code can change the
//! pose or the weights without the GPU copy and the caches learning about it.

use crate::app::scenes::BundledScene;
use crate::coords::{BindOptions, Method, Parameter, Twin, WeightQuality, Weights, WeightsId};
use crate::formats::{FileObjects, MeshFile};
use crate::geometry::{Cage, TriMesh};
use glam::DVec3;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

/// One method's weights for the document's mesh and cage, and how they were made.
#[derive(Clone, Debug)]
pub struct WeightSet {
    pub weights: Arc<Weights>,
    pub options: BindOptions,
    pub bind_time: Duration,
    /// Where the bind ran ("CPU" or the GPU's description).
    pub device: String,
    pub quality: WeightQuality,
}

/// What changed since the editor last took the changes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Changes {
    /// A new mesh or cage: every GPU buffer must be rebuilt.
    pub scene: bool,
    pub pose: bool,
    pub selection: bool,
    /// Methods whose weights arrived.
    pub weights: BTreeSet<WeightsId>,
}

/// A pose kept under a name, to come back to or to blend towards.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedPose {
    pub name: String,
    pub positions: Vec<DVec3>,
    /// Where the timeline plays it, in seconds; `None` when it is not on it.
    pub time: Option<f64>,
}

/// A mesh, its cage, the pose and the weights.
#[derive(Clone, Debug)]
pub struct Document {
    title: String,
    mesh: Arc<TriMesh>,
    /// The file the mesh came from: exports keep its faces, groups and materials.
    mesh_file: Option<MeshFile>,
    /// The cage at rest, as bound.
    cage: Arc<Cage>,
    cage_path: Option<PathBuf>,
    /// Which object of the cage file is the cage, and the file's others.
    cage_objects: FileObjects,
    /// The deformed cage: one position per cage vertex.
    pose: Vec<DVec3>,
    selection: BTreeSet<usize>,
    weight_sets: BTreeMap<Method, WeightSet>,
    /// Each family's twin (quads split, or its reference parameter), for the
    /// difference view that shows what that changes.
    twin_sets: BTreeMap<Method, (Twin, WeightSet)>,
    /// Mesh vertices outside the cage, ascending; known once classified.
    outside: Arc<[u32]>,
    changes: Changes,
    /// Bumped by every pose change, so caches of deformed positions can tell.
    pose_revision: u64,
    /// Pose edits recorded for undo (not undo or redo themselves).
    edits: u64,
    /// Poses kept under a name (sessions save them).
    named_poses: Arc<Vec<NamedPose>>,
    /// The bundled scene this document's mesh and cage are, when they are one.
    bundled: Option<BundledScene>,
    /// Settings read when weights deform a pose (Somigliana's bulging), those
    /// set (a session's, or chosen in the side panel); the others are at their
    /// defaults. Part of what the document shows and exports, not of the weights.
    deform_values: BTreeMap<Parameter, u32>,
}

impl Document {
    pub fn new(title: impl Into<String>, mesh: TriMesh, cage: Cage) -> Self {
        Self {
            title: title.into(),
            pose: cage.positions().to_vec(),
            mesh: Arc::new(mesh),
            mesh_file: None,
            cage: Arc::new(cage),
            cage_path: None,
            cage_objects: FileObjects::default(),
            selection: BTreeSet::new(),
            weight_sets: BTreeMap::new(),
            twin_sets: BTreeMap::new(),
            outside: Arc::from([]),
            changes: Changes {
                scene: true,
                pose: true,
                selection: true,
                weights: BTreeSet::new(),
            },
            pose_revision: 0,
            edits: 0,
            named_poses: Arc::new(Vec::new()),
            bundled: None,
            deform_values: BTreeMap::new(),
        }
    }

    /// The same document with these deformation settings (a session being
    /// opened), each checked by its spec; a refused one keeps its default.
    pub fn with_deform_values(
        mut self,
        values: impl IntoIterator<Item = (Parameter, u32)>,
    ) -> Self {
        for (parameter, value) in values {
            if parameter.validate(value.into()).is_ok() {
                self.deform_values.insert(parameter, value);
            }
        }
        self
    }

    /// The value of deformation setting `parameter` (its default if not set).
    pub fn deform_value(&self, parameter: Parameter) -> u32 {
        (self.deform_values.get(&parameter)).map_or(parameter.spec().default, |&v| v)
    }

    /// The settings set on this document (the others are at their defaults).
    pub fn deform_values(&self) -> Vec<(Parameter, u32)> {
        self.deform_values.iter().map(|(&p, &v)| (p, v)).collect()
    }

    /// `bound` (the options weights were bound with) with this document's
    /// deformation settings: how those weights move the mesh here.
    pub fn deform_options(&self, bound: BindOptions) -> BindOptions {
        let mut options = bound;
        for (&parameter, &value) in &self.deform_values {
            options.set(parameter, value);
        }
        options
    }

    /// The same document, marked as the bundled scene `scene`.
    pub fn bundled_as(mut self, scene: BundledScene) -> Self {
        self.bundled = Some(scene);
        self
    }

    /// The same document posed as `pose` and with `named_poses`, none of it an undo
    /// step (a session being opened). Poses of the wrong length are left out.
    pub fn with_poses(mut self, pose: Vec<DVec3>, named_poses: Vec<NamedPose>) -> Self {
        let count = self.pose.len();
        if pose.len() == count {
            self.pose = pose;
        }
        self.named_poses = Arc::new(
            named_poses
                .into_iter()
                .filter(|named| named.positions.len() == count)
                .collect(),
        );
        self
    }

    /// The same document with the file paths it was loaded from.
    pub fn with_files(mut self, mesh_file: Option<MeshFile>, cage_path: Option<PathBuf>) -> Self {
        self.mesh_file = mesh_file;
        self.cage_path = cage_path;
        self
    }

    /// The same document, its cage object `objects` of the cage file.
    pub fn with_cage_objects(mut self, objects: FileObjects) -> Self {
        self.cage_objects = objects;
        self
    }

    /// The same mesh with another rest cage, posed as `pose`; weights, selection
    /// and history start afresh, since they belong to the old cage.
    pub fn with_cage(&self, cage: Cage, cage_path: Option<PathBuf>, pose: Vec<DVec3>) -> Self {
        let mut document = Document::new(self.title.clone(), (*self.mesh).clone(), cage);
        document.mesh_file = self.mesh_file.clone();
        document.bundled = self.bundled;
        document.cage_path = cage_path;
        if pose.len() == document.pose.len() {
            document.pose = pose;
        }
        document
    }

    pub fn title(&self) -> &str {
        &self.title
    }

    pub fn mesh(&self) -> &Arc<TriMesh> {
        &self.mesh
    }

    pub fn mesh_file(&self) -> Option<&MeshFile> {
        self.mesh_file.as_ref()
    }

    /// The cage at rest.
    pub fn cage(&self) -> &Arc<Cage> {
        &self.cage
    }

    pub fn cage_path(&self) -> Option<&Path> {
        self.cage_path.as_deref()
    }

    /// Which object of the cage file is the cage ([`FileObjects::read`]).
    pub fn cage_objects(&self) -> &FileObjects {
        &self.cage_objects
    }

    pub fn pose(&self) -> &[DVec3] {
        &self.pose
    }

    pub fn pose_revision(&self) -> u64 {
        self.pose_revision
    }

    pub fn selection(&self) -> &BTreeSet<usize> {
        &self.selection
    }

    pub fn outside(&self) -> &[u32] {
        &self.outside
    }

    /// The bundled scene this is, if it is one and unchanged.
    pub fn bundled(&self) -> Option<BundledScene> {
        self.bundled
    }

    pub fn named_poses(&self) -> &[NamedPose] {
        &self.named_poses
    }

    /// `method`'s weights and their bind, once bound.
    pub fn bound(&self, method: Method) -> Option<&WeightSet> {
        self.weight_sets.get(&method)
    }

    /// The weights `id`: a family's, or its twin's when bound along that split.
    pub fn bound_id(&self, id: WeightsId) -> Option<&WeightSet> {
        match id.twin {
            None => self.weight_sets.get(&id.method),
            Some(twin) => (self.twin_sets.get(&id.method))
                .filter(|(held, _)| *held == twin)
                .map(|(_, set)| set),
        }
    }

    /// What ψ column `k` of `method`'s weights multiplies, as bound (a
    /// triangle's normal, or on QGC a quad's corner normal); `None` for a
    /// family with no ψ, one not bound, or past the last column.
    pub fn face_column(
        &self,
        method: Method,
        k: usize,
    ) -> Option<crate::coords::green::FaceColumn> {
        let set = self.bound(method)?;
        if set.options.columns(&self.cage) == method.vertex_columns(&self.cage) {
            return None;
        }
        crate::coords::green::face_column(&set.options.cage_to_bind(&self.cage), k)
    }

    /// `method`'s weights, once bound.
    pub fn weights(&self, method: Method) -> Option<&Arc<Weights>> {
        self.bound(method).map(|set| &set.weights)
    }

    /// The methods bound so far, in [`Method::ALL`] order.
    pub fn bound_methods(&self) -> impl Iterator<Item = Method> + '_ {
        self.weight_sets.keys().copied()
    }

    /// The mesh deformed with `method` on the CPU in f64 (for export), or the
    /// rest mesh before that method is bound. Displacement form: exact at rest.
    pub fn deformed_positions(&self, method: Method) -> Vec<DVec3> {
        self.deformed_positions_at(method, &self.pose)
    }

    /// The mesh deformed by `method` with the cage posed as `pose` (one
    /// position per cage vertex), or at rest when the method is not bound.
    pub fn deformed_positions_at(&self, method: Method, pose: &[DVec3]) -> Vec<DVec3> {
        match self.bound(method) {
            Some(set) => {
                // On the cage the set was bound on: Green's columns differ with
                // the quads as patches (QGC) or split.
                let moves = (self.deform_options(set.options)).column_moves(&self.cage, pose);
                set.weights.apply_moves(&self.mesh.positions, &moves)
            }
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

    /// Pose edits recorded so far; undo and redo do not count.
    pub fn edits(&self) -> u64 {
        self.edits
    }

    /// Everything is new to the GPU copy: the document is coming back from the
    /// scene history.
    pub(in crate::app::model) fn mark_all_changed(&mut self) {
        self.changes = Changes {
            scene: true,
            pose: true,
            selection: true,
            weights: (self.weight_sets.keys().map(|&m| WeightsId::of(m)))
                .chain(
                    self.twin_sets
                        .iter()
                        .map(|(&m, &(twin, _))| WeightsId::twin(m, twin)),
                )
                .collect(),
        };
    }

    /// What changed since the last call; the editor applies it to the GPU.
    pub(in crate::app::model) fn take_changes(&mut self) -> Changes {
        std::mem::take(&mut self.changes)
    }

    // ---- pose -----------------------------------------------------------------

    /// Show `pose`, whose length the model has checked.
    pub(in crate::app::model) fn set_pose(&mut self, pose: Vec<DVec3>) {
        if pose != self.pose {
            self.pose = pose;
            self.pose_changed();
        }
    }

    /// Bring back a pose and the named poses beside it (undo, redo).
    pub(in crate::app::model) fn restore_poses(
        &mut self,
        pose: Vec<DVec3>,
        named_poses: Arc<Vec<NamedPose>>,
    ) {
        self.named_poses = named_poses;
        self.set_pose(pose);
    }

    /// The named poses, shared with the undo step that keeps them.
    pub(in crate::app::model) fn named_poses_shared(&self) -> Arc<Vec<NamedPose>> {
        Arc::clone(&self.named_poses)
    }

    /// One more pose edit was recorded for undo.
    pub(in crate::app::model) fn count_edit(&mut self) {
        self.edits += 1;
    }

    // ---- named poses ----------------------------------------------------------

    /// Keep the current pose as `name` (replacing a pose of that name).
    pub(in crate::app::model) fn store_named_pose(&mut self, name: &str) {
        let mut named = (*self.named_poses).clone();
        match named.iter_mut().find(|n| n.name == name) {
            // Stored again: the pose changes, its place on the timeline stays.
            Some(existing) => existing.positions = self.pose.clone(),
            None => named.push(NamedPose {
                name: name.to_owned(),
                positions: self.pose.clone(),
                time: None,
            }),
        }
        self.named_poses = Arc::new(named);
    }

    /// Forget the named pose at `index`.
    pub(in crate::app::model) fn delete_named_pose(&mut self, index: usize) {
        let mut named = (*self.named_poses).clone();
        if index < named.len() {
            named.remove(index);
            self.named_poses = Arc::new(named);
        }
    }

    /// Place the named pose at `index` on the timeline at `time`, or take it off.
    pub(in crate::app::model) fn set_named_pose_time(&mut self, index: usize, time: Option<f64>) {
        let mut named = (*self.named_poses).clone();
        if let Some(pose) = named.get_mut(index) {
            pose.time = time;
            self.named_poses = Arc::new(named);
        }
    }

    /// Rename the named pose at `index` (the model checks the name is free).
    pub(in crate::app::model) fn rename_named_pose(&mut self, index: usize, name: &str) {
        let mut named = (*self.named_poses).clone();
        if let Some(pose) = named.get_mut(index) {
            pose.name = name.to_owned();
            self.named_poses = Arc::new(named);
        }
    }

    /// Deform with `value` for `parameter` (checked by the model): every
    /// deformed position changes, as after a pose change.
    pub(in crate::app::model) fn set_deform_value(&mut self, parameter: Parameter, value: u32) {
        if self.deform_value(parameter) != value {
            self.deform_values.insert(parameter, value);
            self.pose_changed();
        }
    }

    fn pose_changed(&mut self) {
        self.changes.pose = true;
        self.pose_revision += 1;
    }

    // ---- selection ------------------------------------------------------------

    pub(in crate::app::model) fn select_only(&mut self, handles: impl IntoIterator<Item = usize>) {
        let count = self.pose.len();
        let selection: BTreeSet<usize> = handles.into_iter().filter(|&h| h < count).collect();
        if selection != self.selection {
            self.selection = selection;
            self.changes.selection = true;
        }
    }

    /// Add `handles` to the selection.
    pub(in crate::app::model) fn select_more(&mut self, handles: impl IntoIterator<Item = usize>) {
        let mut selection = self.selection.clone();
        selection.extend(handles);
        self.select_only(selection);
    }

    /// Select `handle` if it is not selected, else deselect it.
    pub(in crate::app::model) fn toggle_selected(&mut self, handle: usize) {
        let mut selection = self.selection.clone();
        if !selection.remove(&handle) {
            selection.insert(handle);
        }
        self.select_only(selection);
    }

    // ---- weights --------------------------------------------------------------

    /// Install `method`'s weights, if they fit this document's mesh and cage
    /// (a bind for a scene that has since been replaced does not).
    pub(in crate::app::model) fn install_weights(
        &mut self,
        id: WeightsId,
        set: WeightSet,
        outside: Arc<[u32]>,
    ) -> bool {
        let fits = set.weights.rows == self.mesh.positions.len()
            && set.weights.cols == set.options.columns(&self.cage)
            && id.twin.is_none_or(|twin| twin.matches(&set.options));
        if fits {
            match id.twin {
                None => {
                    self.weight_sets.insert(id.method, set);
                    // A twin is bound only to be compared with: the vertices
                    // outside are those of the cage as the setting binds it.
                    self.outside = outside;
                }
                Some(twin) => {
                    self.twin_sets.insert(id.method, (twin, set));
                }
            };
            self.changes.weights.insert(id);
        }
        fits
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::procedural::cube_cage;

    fn document() -> Document {
        let mesh = TriMesh {
            positions: vec![DVec3::ZERO],
            ..TriMesh::default()
        };
        let mut document = Document::new("test", mesh, cube_cage(1.0));
        document.take_changes();
        document
    }

    #[test]
    fn weights_of_another_shape_are_refused() {
        let mut document = document();
        let set = |rows, cols| WeightSet {
            weights: Arc::new(Weights::zeros(rows, cols)),
            options: BindOptions::default(),
            bind_time: Duration::ZERO,
            device: "CPU".into(),
            quality: WeightQuality::default(),
        };
        let pmvc = WeightsId::of(Method::Pmvc);
        assert!(!document.install_weights(pmvc, set(2, 8), Arc::from([])));
        assert!(document.bound(Method::Pmvc).is_none());
        assert!(document.install_weights(pmvc, set(1, 8), Arc::from([])));
        assert!(document.take_changes().weights.contains(&pmvc));
    }

    #[test]
    fn selection_ignores_handles_the_cage_does_not_have() {
        let mut document = document();
        document.select_only([1, 99]);
        assert_eq!(
            document.selection().iter().copied().collect::<Vec<_>>(),
            [1]
        );
        document.toggle_selected(1);
        assert!(document.selection().is_empty());
    }
}

//! File actions: opening meshes, cages and bundled scenes, poses, export, and
//! dropped files. A file that fails to load or validate changes nothing.

use super::cage_generation::cage_reaches;
use super::document::Document;
use super::editor::{Cameras, EditorApp, FileRole, Replacement};
use super::model::Command;
use super::recent::RecentEntry;
use super::scenes::BundledScene;
use super::session::{self, SessionSettings};
use super::ui::file_dialog::FileAction;
use crate::geometry::shown_path;
use crate::geometry::{
    load_cage, load_mesh, refuse_same_file, write_deformed_mesh, write_mesh_with_normals,
    write_obj, TriMesh,
};
use std::path::Path;

pub(super) fn file_title(path: &Path) -> String {
    path.file_name()
        .map_or_else(|| "mesh".into(), |n| n.to_string_lossy().into_owned())
}

impl EditorApp {
    /// File > Recent, most recent first.
    pub fn recent_files(&self) -> &super::recent::RecentFiles {
        &self.recent
    }

    fn remember(&mut self, entry: RecentEntry) {
        self.recent.remember(entry);
    }

    /// Open a File > Recent entry; one that no longer opens leaves the list.
    pub fn open_recent(&mut self, entry: &RecentEntry) -> bool {
        let opened = match entry {
            RecentEntry::Session(path) => self.open_session(path),
            RecentEntry::Scene { mesh, cage } => self.open_pair(mesh, cage),
            RecentEntry::Mesh(path) => self.open_file(FileRole::Mesh, path),
            RecentEntry::Cage(path) => self.open_file(FileRole::Cage, path),
        };
        if !opened {
            self.recent.forget(entry);
        }
        opened
    }

    /// Open a session: its mesh, cage, poses, method, parameters and views. On
    /// any failure the current scene stays; opening can be undone.
    pub fn open_session(&mut self, path: &Path) -> bool {
        let opened = match session::open_session(path) {
            Ok(opened) => opened,
            Err(error) => {
                self.error(error.to_string());
                return false;
            }
        };
        for note in opened.notes {
            self.info(note);
        }
        let settings = opened.settings;
        self.replace_document_then_bind(Replacement {
            document: opened.document,
            action: format!("open session {}", file_title(path)),
            cameras: Cameras::Session(settings.cameras),
            settings: Some((settings.bind_options, settings.view)),
        });
        self.session_path = Some(path.to_owned());
        self.remember(RecentEntry::Session(path.to_owned()));
        self.info(format!("opened session {}", shown_path(path)));
        true
    }

    /// What `pmvc edit --session` was told beside the session wins over it.
    pub(super) fn command_line_over_session(&mut self, options: &super::EditorOptions) {
        self.view = session::view_with_overrides(self.view, options.view);
        if let Some(method) = options.method {
            self.bind_options.method = method;
        }
        for refused in super::binding::with_asked_parameters(&mut self.bind_options, options) {
            self.error(refused);
        }
    }

    /// Save the session to `path`; true when it was written.
    pub fn save_session(&mut self, path: &Path) -> bool {
        if !self.refuse_overwriting_open_files(path) {
            return false;
        }
        let settings = SessionSettings {
            bind_options: self.bind_options,
            view: self.view,
            cameras: self.viewport.camera_list(),
        };
        match session::save_session(path, self.model.document(), &settings) {
            Ok(()) => {
                self.mark_pose_saved();
                self.session_path = Some(path.to_owned());
                self.remember(RecentEntry::Session(path.to_owned()));
                self.info(format!("saved session {}", shown_path(path)));
                true
            }
            Err(error) => {
                self.error(error.to_string());
                false
            }
        }
    }

    /// File > Save session: where it was last saved or opened, else ask.
    pub fn save_session_again(&mut self) {
        match self.session_path.clone() {
            Some(path) => {
                self.save_session(&path);
            }
            None => self.ask_for_file(FileAction::SaveSession),
        }
    }

    /// Open a mesh and cage together and bind them; on any failure the current
    /// scene stays.
    pub(super) fn open_pair(&mut self, mesh_path: &Path, cage_path: &Path) -> bool {
        let mesh = match load_mesh(mesh_path) {
            Ok(mesh) => mesh,
            Err(error) => {
                self.error(error.to_string());
                return false;
            }
        };
        let (cage, report) = match load_cage(cage_path) {
            Ok(cage) => cage,
            Err(error) => {
                self.error(error.to_string());
                return false;
            }
        };
        for message in report.messages() {
            self.info(message);
        }
        let document = Document::new(file_title(mesh_path), mesh.mesh.clone(), cage)
            .with_files(Some(mesh), Some(cage_path.to_owned()));
        let action = format!(
            "open {} and {}",
            file_title(mesh_path),
            file_title(cage_path)
        );
        self.replace_document_then_bind(Replacement::framed(document, action));
        self.remember(RecentEntry::Scene {
            mesh: mesh_path.to_owned(),
            cage: cage_path.to_owned(),
        });
        true
    }

    /// Replace the mesh (keeping the cage) or the cage (keeping the mesh), then
    /// rebind. A file that fails to load or validate changes nothing.
    pub fn open_file(&mut self, role: FileRole, path: &Path) -> bool {
        let document = match role {
            FileRole::Mesh => match load_mesh(path) {
                // A cage that holds none of the mesh is replaced by a box, and
                // the Generate cage window offers a real one.
                Ok(file) if !cage_reaches(self.model.document().cage(), &file.mesh) => {
                    let opened = self.open_mesh_in_box(path, file);
                    if opened {
                        self.remember(RecentEntry::Mesh(path.to_owned()));
                    }
                    return opened;
                }
                Ok(file) => Document::new(
                    file_title(path),
                    file.mesh.clone(),
                    (**self.model.document().cage()).clone(),
                )
                .with_files(
                    Some(file),
                    self.model.document().cage_path().map(Into::into),
                ),
                Err(error) => {
                    self.error(error.to_string());
                    return false;
                }
            },
            FileRole::Cage => match load_cage(path) {
                Ok((cage, report)) => {
                    for message in report.messages() {
                        self.info(message);
                    }
                    let rest = cage.positions().to_vec();
                    self.model
                        .document()
                        .with_cage(cage, Some(path.to_owned()), rest)
                }
                Err(error) => {
                    self.error(error.to_string());
                    return false;
                }
            },
        };
        let role_name = match role {
            FileRole::Mesh => "mesh",
            FileRole::Cage => "cage",
        };
        let action = format!("open {role_name} {}", file_title(path));
        self.replace_document_then_bind(Replacement::framed(document, action));
        self.remember(match role {
            FileRole::Mesh => RecentEntry::Mesh(path.to_owned()),
            FileRole::Cage => RecentEntry::Cage(path.to_owned()),
        });
        self.info(format!("opened {}", shown_path(path)));
        true
    }

    /// Open a bundled scene; if it cannot be loaded the current scene stays.
    pub fn open_bundled(&mut self, bundled: BundledScene) {
        match bundled.build() {
            Ok((mesh, cage)) => {
                let action = format!("open the {} scene", bundled.title());
                let document = Document::new(bundled.title(), mesh, cage).bundled_as(bundled);
                self.replace_document_then_bind(Replacement::framed(document, action));
            }
            Err(error) => self.error(error.to_string()),
        }
    }

    /// Load a pose: a cage-shaped OBJ/OFF with one vertex per cage vertex.
    pub fn load_pose(&mut self, path: &Path) -> bool {
        match load_mesh(path) {
            Ok(file) => self.take_pose_file(path, file.mesh.positions),
            Err(error) => {
                self.error(error.to_string());
                false
            }
        }
    }

    /// The positions of a pose file (opened or dropped) as the pose, when they
    /// are one per cage vertex and within the reach a session may hold, so that
    /// what is saved can be opened again.
    pub(super) fn take_pose_file(&mut self, path: &Path, positions: Vec<glam::DVec3>) -> bool {
        let cage_vertices = self.model.document().pose().len();
        if positions.len() != cage_vertices {
            self.error(format!(
                "{}: the pose has {} vertices but the cage has {cage_vertices}",
                shown_path(path),
                positions.len(),
            ));
            return false;
        }
        let reach = super::session_checks::Reach::of(self.model.document().cage().positions());
        if let Some((number, distance)) = reach.first_beyond(&positions) {
            let problem = reach.describe(number, distance);
            self.error(format!("{}: {problem}", shown_path(path)));
            return false;
        }
        self.apply(Command::edit_pose(positions));
        self.mark_pose_saved();
        self.info(format!("loaded pose {}", shown_path(path)));
        true
    }

    /// Write the pose as a cage-shaped OBJ; true when it was written.
    pub fn save_pose(&mut self, path: &Path) -> bool {
        if !self.refuse_overwriting_open_files(path) {
            return false;
        }
        let cage = self.model.document().cage();
        let posed = TriMesh {
            positions: self.model.document().pose().to_vec(),
            triangles: cage.triangles().to_vec(),
            triangle_faces: cage.triangle_faces().to_vec(),
        };
        match write_obj(path, &posed) {
            Ok(()) => {
                self.mark_pose_saved();
                self.info(format!("saved pose {}", shown_path(path)));
                true
            }
            Err(error) => {
                self.error(error.to_string());
                false
            }
        }
    }

    /// False, with an error, when `path` is (or links to) the open mesh or cage:
    /// saving a pose over the rest cage, or a deformed mesh over its source, would
    /// lose the scene's input.
    pub(super) fn refuse_overwriting_open_files(&mut self, path: &Path) -> bool {
        let mut inputs = Vec::new();
        inputs.extend(
            self.model
                .document()
                .mesh_file()
                .map(|file| file.path.as_path()),
        );
        inputs.extend(self.model.document().cage_path());
        match refuse_same_file(path, &inputs) {
            Ok(()) => true,
            Err(error) => {
                self.error(error.to_string());
                false
            }
        }
    }

    /// Write the mesh deformed with the active method; true when it was written.
    pub fn export_deformed(&mut self, path: &Path) -> bool {
        if !self.refuse_overwriting_open_files(path) {
            return false;
        }
        let positions = self
            .model
            .document()
            .deformed_positions(self.active_method());
        let result = match self.model.document().mesh_file() {
            Some(file) => write_deformed_mesh(file, &positions, path),
            None => {
                write_mesh_with_normals(path, &positions, &self.model.document().mesh().triangles)
            }
        };
        self.report_export(result, path)
    }

    /// Say what an export wrote, or why it failed; true when it was written.
    pub(super) fn report_export(
        &mut self,
        result: Result<(), crate::geometry::WriteError>,
        path: &Path,
    ) -> bool {
        match result {
            Ok(()) => {
                self.info(format!("exported {}", shown_path(path)));
                true
            }
            Err(error) => {
                self.error(error.to_string());
                false
            }
        }
    }

    /// Make the current pose the rest shape: the mesh takes the shape the active
    /// method gives it, the cage rests in its pose, and both are bound afresh.
    /// Undo returns to the previous rest shape and its weights.
    pub fn pose_as_rest(&mut self) {
        let method = self.active_method();
        if self.model.document().bound(method).is_none() {
            self.error(format!(
                "cannot use the pose as rest shape before {method} is bound: the mesh would not follow the cage"
            ));
            return;
        }
        let mesh = TriMesh {
            positions: self.model.document().deformed_positions(method),
            ..(**self.model.document().mesh()).clone()
        };
        let cage = self
            .model
            .document()
            .cage()
            .with_positions(self.model.document().pose().to_vec());
        let document = Document::new(self.model.document().title(), mesh, cage).with_files(
            self.model.document().mesh_file().cloned(),
            self.model.document().cage_path().map(Into::into),
        );
        self.replace_document_then_bind(Replacement::in_place(document, "use pose as rest shape"));
        self.info(format!(
            "the mesh now rests as {method} deformed it, in the posed cage; rebinding"
        ));
    }
}

//! What to do with a file dropped on the window: a dialog that offers a pose when
//! the vertex count matches the cage, the cage and the mesh otherwise, each with
//! what it will do. A file's name does not decide: the dataset's
//! `*_Cage_Deformed.obj` is a pose, not a new rest cage.

use crate::app::actions::{Action, FileRole};
use crate::app::ctx::PanelContext;
use crate::formats::{load_mesh, MeshFile};
use std::path::PathBuf;

/// A session file (`*.json`, as File > Save session writes them): dropped, it
/// opens as a session.
fn is_session(path: &std::path::Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
}

/// A dropped file, read, waiting for the user's choice.
pub struct DroppedFile {
    pub path: PathBuf,
    file: MeshFile,
}

impl DroppedFile {
    pub fn vertex_count(&self) -> usize {
        self.file.mesh.positions.len()
    }
}

/// The choices the dialog offers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DropChoice {
    Pose,
    Cage,
    Mesh,
    Cancel,
}

/// The dialog for a dropped file, and the file waiting for the user's choice.
#[derive(Default)]
pub struct DropDialog {
    pending: Option<DroppedFile>,
}

impl DropDialog {
    /// The dropped file waiting for a choice, if any.
    pub fn pending(&self) -> Option<&DroppedFile> {
        self.pending.as_ref()
    }

    pub fn is_open(&self) -> bool {
        self.pending.is_some()
    }

    /// Read the files dropped this frame. Two files, one named like a cage, open
    /// together as mesh and cage; a single file waits for the dialog.
    pub fn take_dropped_files(&mut self, ctx: &egui::Context, context: &mut PanelContext) {
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_owned())
                .filter(|p| !p.as_os_str().is_empty())
                .collect()
        });
        match dropped.as_slice() {
            [] => {}
            [path] if is_session(path) => context.send(Action::OpenSession(path.clone())),
            [path] => match load_mesh(path) {
                Ok(file) => {
                    self.pending = Some(DroppedFile {
                        path: path.clone(),
                        file,
                    })
                }
                Err(error) => context.send(Action::Error(error.to_string())),
            },
            [first, second] => {
                let named_cage = |p: &PathBuf| p.to_string_lossy().to_lowercase().contains("cage");
                let (mesh, cage) = if named_cage(first) {
                    (second, first)
                } else {
                    (first, second)
                };
                context.send(Action::OpenPair {
                    mesh: mesh.clone(),
                    cage: cage.clone(),
                });
            }
            _ => context.send(Action::Error(format!(
                "{} files dropped: drop one file, or a mesh and its cage",
                dropped.len()
            ))),
        }
    }

    /// The dialog for a dropped file, while one waits. It reads the cage's vertex
    /// count, and sends `TakePose` or `Open` for the choice made.
    pub fn ui(&mut self, ctx: &egui::Context, context: &mut PanelContext) {
        let Some(dropped) = &self.pending else { return };
        let name = dropped.path.file_name().map_or_else(
            || dropped.path.display().to_string(),
            |n| n.to_string_lossy().into(),
        );
        let vertices = dropped.vertex_count();
        let cage_vertices = context.document().pose().len();
        let mut choice = None;
        egui::Window::new("Open dropped file")
            .collapsible(false)
            .resizable(false)
            .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
            .show(ctx, |ui| {
                ui.label(format!("{name}: {vertices} vertices"));
                ui.separator();
                let mut offer = |ui: &mut egui::Ui, enabled: bool, label: &str, what: String, pick| {
                    ui.horizontal(|ui| {
                        if ui.add_enabled(enabled, egui::Button::new(label)).clicked() {
                            choice = Some(pick);
                        }
                        ui.label(what);
                    });
                };
                let pose_fits = vertices == cage_vertices;
                let pose_text = if pose_fits {
                    format!("moves the {cage_vertices} cage handles to its vertices; the mesh follows (Ctrl+Z undoes it)")
                } else {
                    format!("needs {cage_vertices} vertices, one per cage vertex")
                };
                offer(ui, pose_fits, "Use as pose", pose_text, DropChoice::Pose);
                offer(
                    ui,
                    true,
                    "Open as cage",
                    "replaces the rest cage, keeps the mesh, and binds again (Ctrl+Z returns)".into(),
                    DropChoice::Cage,
                );
                offer(
                    ui,
                    true,
                    "Open as mesh",
                    "replaces the mesh, keeps the cage, and binds again (Ctrl+Z returns)".into(),
                    DropChoice::Mesh,
                );
                if ui.button("Cancel").clicked() {
                    choice = Some(DropChoice::Cancel);
                }
            });
        if let Some(choice) = choice {
            self.resolve(choice, context);
        }
    }

    /// Close the dialog, asking for what `choice` does with the waiting file.
    pub fn resolve(&mut self, choice: DropChoice, context: &mut PanelContext) {
        let Some(dropped) = self.pending.take() else {
            return;
        };
        let action = match choice {
            DropChoice::Pose => Action::TakePose {
                path: dropped.path,
                pose: dropped.file.mesh.positions,
            },
            DropChoice::Cage => Action::Open(FileRole::Cage, dropped.path),
            DropChoice::Mesh => Action::Open(FileRole::Mesh, dropped.path),
            DropChoice::Cancel => return,
        };
        context.send(action);
    }
}

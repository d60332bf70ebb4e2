//! Recent files and sessions, kept across runs in eframe's storage. A mesh opened
//! with its cage is one entry, reopened as a pair; an object read by name from
//! a file of several is reopened by that name.

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Entries kept in File > Recent.
pub const RECENT_LIMIT: usize = 10;

/// The key of the list in eframe's storage.
pub const STORAGE_KEY: &str = "pmvc_recent_files";

/// Something the File menu can open again.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RecentEntry {
    Session(PathBuf),
    /// A mesh and its cage, opened together; each the object of its file
    /// named here, or the file's default (lists of earlier editors have none).
    Scene {
        mesh: PathBuf,
        cage: PathBuf,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        mesh_object: Option<String>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        cage_object: Option<String>,
    },
    Mesh(PathBuf),
    Cage(PathBuf),
    /// One object of a file of several, read by its name as the mesh.
    MeshObject {
        path: PathBuf,
        object: String,
    },
    /// One object of a file of several, read by its name as the cage.
    CageObject {
        path: PathBuf,
        object: String,
    },
}

/// A file's name, and the object read from it when one was named.
fn name_and_object(path: &Path, object: Option<&str>) -> String {
    match object {
        Some(object) => format!("{} ({object})", name(path)),
        None => name(path),
    }
}

fn name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into(),
    )
}

impl RecentEntry {
    /// The menu line: what it is and the file names.
    pub fn label(&self) -> String {
        match self {
            RecentEntry::Session(path) => format!("session {}", name(path)),
            RecentEntry::Scene {
                mesh,
                cage,
                mesh_object,
                cage_object,
            } => format!(
                "{} in {}",
                name_and_object(mesh, mesh_object.as_deref()),
                name_and_object(cage, cage_object.as_deref())
            ),
            RecentEntry::Mesh(path) => format!("mesh {}", name(path)),
            RecentEntry::Cage(path) => format!("cage {}", name(path)),
            RecentEntry::MeshObject { path, object } => {
                format!("mesh {}", name_and_object(path, Some(object)))
            }
            RecentEntry::CageObject { path, object } => {
                format!("cage {}", name_and_object(path, Some(object)))
            }
        }
    }

    /// The full paths, for the menu line's tooltip.
    pub fn paths(&self) -> String {
        match self {
            RecentEntry::Scene { mesh, cage, .. } => {
                format!("{}\n{}", mesh.display(), cage.display())
            }
            RecentEntry::Session(path)
            | RecentEntry::Mesh(path)
            | RecentEntry::Cage(path)
            | RecentEntry::MeshObject { path, .. }
            | RecentEntry::CageObject { path, .. } => path.display().to_string(),
        }
    }
}

/// The most recent first, no duplicates, at most [`RECENT_LIMIT`].
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RecentFiles {
    entries: Vec<RecentEntry>,
}

/// Paths are kept absolute, so they still open after the editor is started
/// from another folder.
fn absolute(path: &Path) -> PathBuf {
    std::path::absolute(path).unwrap_or_else(|_| path.to_owned())
}

impl RecentFiles {
    pub fn entries(&self) -> &[RecentEntry] {
        &self.entries
    }

    pub fn remember(&mut self, entry: RecentEntry) {
        let entry = match entry {
            RecentEntry::Session(p) => RecentEntry::Session(absolute(&p)),
            RecentEntry::Scene {
                mesh,
                cage,
                mesh_object,
                cage_object,
            } => RecentEntry::Scene {
                mesh: absolute(&mesh),
                cage: absolute(&cage),
                mesh_object,
                cage_object,
            },
            RecentEntry::Mesh(p) => RecentEntry::Mesh(absolute(&p)),
            RecentEntry::Cage(p) => RecentEntry::Cage(absolute(&p)),
            RecentEntry::MeshObject { path, object } => RecentEntry::MeshObject {
                path: absolute(&path),
                object,
            },
            RecentEntry::CageObject { path, object } => RecentEntry::CageObject {
                path: absolute(&path),
                object,
            },
        };
        self.entries.retain(|e| *e != entry);
        self.entries.insert(0, entry);
        self.entries.truncate(RECENT_LIMIT);
    }

    /// Drop an entry that no longer opens.
    pub fn forget(&mut self, entry: &RecentEntry) {
        self.entries.retain(|e| e != entry);
    }

    /// The list kept by an earlier run; empty when there is none or it cannot be
    /// read (a list from a newer editor, say), which only costs the list.
    pub fn load(storage: &dyn eframe::Storage) -> Self {
        eframe::get_value(storage, STORAGE_KEY).unwrap_or_default()
    }

    pub fn save(&self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, STORAGE_KEY, self);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    #[derive(Default)]
    struct MemoryStorage(HashMap<String, String>);

    impl eframe::Storage for MemoryStorage {
        fn get_string(&self, key: &str) -> Option<String> {
            self.0.get(key).cloned()
        }
        fn set_string(&mut self, key: &str, value: String) {
            self.0.insert(key.into(), value);
        }
        fn remove_string(&mut self, key: &str) {
            self.0.remove(key);
        }
        fn flush(&mut self) {}
    }

    #[test]
    fn the_list_survives_a_restart_most_recent_first_without_duplicates() {
        let mut recent = RecentFiles::default();
        let ogre = || RecentEntry::Scene {
            mesh: "/data/ogre.obj".into(),
            cage: "/data/ogre_cage.obj".into(),
            mesh_object: None,
            cage_object: None,
        };
        recent.remember(ogre());
        recent.remember(RecentEntry::Session("/work/pose.session.json".into()));
        recent.remember(ogre());
        let mut storage = MemoryStorage::default();
        recent.save(&mut storage);
        let restored = RecentFiles::load(&storage);
        assert_eq!(restored, recent);
        assert_eq!(restored.entries().len(), 2);
        assert_eq!(restored.entries()[0].label(), "ogre.obj in ogre_cage.obj");
    }

    #[test]
    fn the_list_keeps_the_newest_entries_only() {
        let mut recent = RecentFiles::default();
        for i in 0..RECENT_LIMIT + 3 {
            recent.remember(RecentEntry::Mesh(format!("/m/{i}.obj").into()));
        }
        assert_eq!(recent.entries().len(), RECENT_LIMIT);
        let newest = format!("/m/{}.obj", RECENT_LIMIT + 2);
        assert_eq!(recent.entries()[0], RecentEntry::Mesh(newest.into()));
    }

    /// Objects read by name are kept by name; a list an earlier editor kept,
    /// whose scenes have no objects, still reads.
    #[test]
    fn objects_read_by_name_are_remembered_and_older_lists_still_read() {
        let mut recent = RecentFiles::default();
        recent.remember(RecentEntry::Scene {
            mesh: "/data/scene.glb".into(),
            cage: "/data/scene.glb".into(),
            mesh_object: Some("Second".into()),
            cage_object: Some("Cage".into()),
        });
        recent.remember(RecentEntry::CageObject {
            path: "/data/cages.obj".into(),
            object: "Hand".into(),
        });
        let mut storage = MemoryStorage::default();
        recent.save(&mut storage);
        let restored = RecentFiles::load(&storage);
        assert_eq!(restored, recent);
        let labels: Vec<String> = restored.entries().iter().map(RecentEntry::label).collect();
        assert_eq!(
            labels,
            [
                "cage cages.obj (Hand)",
                "scene.glb (Second) in scene.glb (Cage)"
            ]
        );

        let mut earlier = MemoryStorage::default();
        let scene_without_objects = RecentFiles {
            entries: vec![RecentEntry::Scene {
                mesh: "/data/ogre.obj".into(),
                cage: "/data/ogre_cage.obj".into(),
                mesh_object: None,
                cage_object: None,
            }],
        };
        scene_without_objects.save(&mut earlier);
        let text = eframe::Storage::get_string(&earlier, STORAGE_KEY).unwrap();
        assert!(!text.contains("object"), "{text}");
        assert_eq!(RecentFiles::load(&earlier), scene_without_objects);
    }

    #[test]
    fn an_unreadable_list_is_an_empty_one() {
        let mut storage = MemoryStorage::default();
        eframe::Storage::set_string(&mut storage, STORAGE_KEY, "not ron at all (".into());
        assert!(RecentFiles::load(&storage).entries().is_empty());
    }
}

//! Recent files and sessions, kept across runs in eframe's storage. A mesh opened
//! with its cage is one entry, reopened as a pair.

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
    /// A mesh and its cage, opened together.
    Scene {
        mesh: PathBuf,
        cage: PathBuf,
    },
    Mesh(PathBuf),
    Cage(PathBuf),
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
            RecentEntry::Scene { mesh, cage } => format!("{} in {}", name(mesh), name(cage)),
            RecentEntry::Mesh(path) => format!("mesh {}", name(path)),
            RecentEntry::Cage(path) => format!("cage {}", name(path)),
        }
    }

    /// The full paths, for the menu line's tooltip.
    pub fn paths(&self) -> String {
        match self {
            RecentEntry::Scene { mesh, cage } => {
                format!("{}\n{}", mesh.display(), cage.display())
            }
            RecentEntry::Session(path) | RecentEntry::Mesh(path) | RecentEntry::Cage(path) => {
                path.display().to_string()
            }
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
            RecentEntry::Scene { mesh, cage } => RecentEntry::Scene {
                mesh: absolute(&mesh),
                cage: absolute(&cage),
            },
            RecentEntry::Mesh(p) => RecentEntry::Mesh(absolute(&p)),
            RecentEntry::Cage(p) => RecentEntry::Cage(absolute(&p)),
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
        recent.remember(RecentEntry::Scene {
            mesh: "/data/ogre.obj".into(),
            cage: "/data/ogre_cage.obj".into(),
        });
        recent.remember(RecentEntry::Session("/work/pose.session.json".into()));
        recent.remember(RecentEntry::Scene {
            mesh: "/data/ogre.obj".into(),
            cage: "/data/ogre_cage.obj".into(),
        });
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

    #[test]
    fn an_unreadable_list_is_an_empty_one() {
        let mut storage = MemoryStorage::default();
        eframe::Storage::set_string(&mut storage, STORAGE_KEY, "not ron at all (".into());
        assert!(RecentFiles::load(&storage).entries().is_empty());
    }
}

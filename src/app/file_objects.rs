//! Which object of a file of several the editor reads, as notices and File >
//! Recent name it.

use super::actions::FileRole;
use super::recent::RecentEntry;
use crate::formats::shown_path;
use std::path::Path;

/// Which object of the mesh file and of the cage file to read (`pmvc edit
/// --mesh-object`, the side panel's choice); `None`: the file's default.
#[derive(Clone, Copy, Debug, Default)]
pub struct ObjectNames<'a> {
    pub mesh: Option<&'a str>,
    pub cage: Option<&'a str>,
}

/// A file's note of which of its objects was read, as a notice naming it,
/// with where to choose another.
pub(super) fn object_note(path: &Path, note: Option<String>) -> Vec<String> {
    note.map(|note| {
        format!(
            "{}: {note}; choose another in the side panel",
            shown_path(path)
        )
    })
    .into_iter()
    .collect()
}

/// File > Recent's entry for object `object` of `path` (the file's default
/// where `None`) read as the mesh or the cage.
pub(super) fn recent_file(role: FileRole, path: &Path, object: Option<&str>) -> RecentEntry {
    let path = path.to_owned();
    match (role, object.map(String::from)) {
        (FileRole::Mesh, None) => RecentEntry::Mesh(path),
        (FileRole::Cage, None) => RecentEntry::Cage(path),
        (FileRole::Mesh, Some(object)) => RecentEntry::MeshObject { path, object },
        (FileRole::Cage, Some(object)) => RecentEntry::CageObject { path, object },
    }
}

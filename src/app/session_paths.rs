//! The folder a session's relative paths are read from: beside the file,
//! following a link as editors do.

use crate::formats::shown_path;
use std::path::{Path, PathBuf};

pub(super) fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_owned(),
        _ => PathBuf::from("."),
    }
}

/// The folder a session's relative paths are read from: beside the file it
/// is, following a link as editors do, with a note when that is not the
/// link's folder.
pub(super) fn session_folder(path: &Path, note: &mut impl FnMut(String)) -> PathBuf {
    let linked = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    if !linked {
        return folder_of(path);
    }
    match std::fs::canonicalize(path) {
        Ok(target) => {
            let folder = folder_of(&target);
            if std::fs::canonicalize(folder_of(path)).ok().as_ref() != Some(&folder) {
                note(format!(
                    "a link to {}: its files are read from {}",
                    shown_path(&target),
                    shown_path(&folder)
                ));
            }
            folder
        }
        Err(_) => folder_of(path),
    }
}

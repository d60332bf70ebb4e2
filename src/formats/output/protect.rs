//! Which existing files an output may replace.
//!
//! Replacing goes through a rename, which needs only the folder's permission, so
//! a file its user may not write would otherwise be replaced silently, where `cp`
//! or a shell's `>>` stop with "Permission denied". The rule:
//!
//! - the kernel's check for writing as the effective user must pass (what
//!   `test -w` asks, access control lists included), and
//! - the file must have a write permission bit for someone: the kernel lets root
//!   write any file, so a file made read-only (`chmod a-w`) is refused for root too.

use crate::formats::shown_path;
use crate::formats::WriteError;
use std::path::Path;

/// Refuse to replace `target` (an existing regular file, links followed) when
/// its user may not write it; `path` is the name the user gave.
pub(super) fn refuse_protected(path: &Path, target: &Path) -> Result<(), WriteError> {
    let Ok(metadata) = std::fs::metadata(target) else {
        return Ok(()); // a new file replaces nothing
    };
    if !metadata.is_file() {
        return Ok(());
    }
    match protection(path, target, &metadata) {
        None => Ok(()),
        Some(reason) => Err(WriteError {
            path: path.to_owned(),
            source: std::io::Error::new(std::io::ErrorKind::PermissionDenied, reason),
        }),
    }
}

/// " (the file it links to, X)" when `path` is a link to `target`.
fn linked(path: &Path, target: &Path) -> String {
    if path == target {
        String::new()
    } else {
        format!(" (the file it links to, {})", shown_path(target))
    }
}

#[cfg(unix)]
fn protection(path: &Path, target: &Path, metadata: &std::fs::Metadata) -> Option<String> {
    use rustix::fs::{accessat, Access, AtFlags, CWD};
    use std::os::unix::fs::MetadataExt;
    let mode = metadata.mode() & 0o7777;
    if mode & 0o222 == 0 {
        return Some(format!(
            "it is read-only{} (mode {mode:04o}), and pmvc does not replace a read-only file; make it writable (chmod u+w) or choose another output",
            linked(path, target)
        ));
    }
    match accessat(CWD, target, Access::WRITE_OK, AtFlags::EACCESS) {
        Err(rustix::io::Errno::ACCESS | rustix::io::Errno::PERM) => Some(format!(
            "you may not write it{} (mode {mode:04o}, owner uid {}), and pmvc does not replace a file you may not write; choose another output",
            linked(path, target),
            metadata.uid()
        )),
        Err(rustix::io::Errno::ROFS) => Some("it is on a read-only file system".to_owned()),
        // Anything else is for creating the temporary file to report.
        _ => None,
    }
}

#[cfg(not(unix))]
fn protection(path: &Path, target: &Path, metadata: &std::fs::Metadata) -> Option<String> {
    metadata.permissions().readonly().then(|| {
        format!(
            "it is read-only{}, and pmvc does not replace a read-only file; make it writable or choose another output",
            linked(path, target)
        )
    })
}

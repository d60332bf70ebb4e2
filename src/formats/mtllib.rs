//! A deformed OBJ written to another folder than its source keeps its
//! materials: each `mtllib` file is referred to by a path that resolves from
//! the output's folder, relative where the two folders share a root and
//! absolute otherwise. The library is referred to, not copied, so that the
//! texture paths inside it, which are relative to its own folder, still
//! resolve.

use std::fmt;
use std::path::{Component, Path, PathBuf};

/// A material library of the source that a deformed copy refers to by
/// another path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MovedLibrary {
    /// The name as the source's `mtllib` line gives it.
    pub source: String,
    /// The path the copy's `mtllib` line gives instead.
    pub written: String,
    /// Whether the library is there; the reference is rewritten either way,
    /// so that it names what the source named.
    pub found: bool,
}

impl fmt::Display for MovedLibrary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "its material library {} is referred to as {}, which resolves from the output's folder (not copied)",
            self.source, self.written
        )?;
        if !self.found {
            write!(f, "; it was not beside the source either")?;
        }
        Ok(())
    }
}

/// Rewrites `mtllib` lines of an OBJ read from one folder for a copy in another.
pub(super) struct LibraryPaths {
    /// The source's folder, absolute.
    from: PathBuf,
    /// The output's folder, absolute.
    to: PathBuf,
}

impl LibraryPaths {
    /// `None` when `source` and `output` are in the same folder: the names
    /// resolve as they are.
    pub(super) fn new(source: &Path, output: &Path) -> Option<Self> {
        let from = folder_of(source);
        let to = folder_of(output);
        (from != to).then_some(Self { from, to })
    }

    /// The line for `names` (what follows `mtllib`), and the libraries it
    /// now names by another path. Absolute names and names whose new path is
    /// not text are kept as written.
    pub(super) fn rewrite(&self, names: &str) -> (String, Vec<MovedLibrary>) {
        let names = names.trim();
        // One name with spaces (as some exporters write), or several.
        let split: Vec<&str> = if self.from.join(names).is_file() {
            vec![names]
        } else {
            names.split_whitespace().collect()
        };
        let mut moved = Vec::new();
        let written: Vec<String> = split
            .iter()
            .map(|&name| {
                if Path::new(name).is_absolute() {
                    return name.to_owned();
                }
                let target = normalized(&self.from.join(name));
                let new = relative_path(&self.to, &target).unwrap_or_else(|| target.clone());
                let Some(new) = new.to_str().map(|s| s.replace('\\', "/")) else {
                    return name.to_owned();
                };
                moved.push(MovedLibrary {
                    source: name.to_owned(),
                    written: new.clone(),
                    found: target.is_file(),
                });
                new
            })
            .collect();
        (format!("mtllib {}", written.join(" ")), moved)
    }
}

/// The folder holding `path`, absolute, with links resolved where it exists
/// (a `..` then walks the folders the system walks).
fn folder_of(path: &Path) -> PathBuf {
    let folder = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    folder
        .canonicalize()
        .or_else(|_| std::path::absolute(folder))
        .map(|f| normalized(&f))
        .unwrap_or_else(|_| folder.to_owned())
}

/// `path` with `.` left out and each `..` taking the folder before it.
fn normalized(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for component in path.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            other => out.push(other),
        }
    }
    out
}

/// `target` relative to the folder `from` (both absolute and normalized),
/// or `None` where they have different roots (another drive).
fn relative_path(from: &Path, target: &Path) -> Option<PathBuf> {
    let from: Vec<Component> = from.components().collect();
    let target: Vec<Component> = target.components().collect();
    if from.first() != target.first() {
        return None;
    }
    let shared = from.iter().zip(&target).take_while(|(a, b)| a == b).count();
    let mut relative = PathBuf::new();
    for _ in shared..from.len() {
        relative.push("..");
    }
    for component in &target[shared..] {
        relative.push(component);
    }
    Some(relative)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_library_beside_the_source_is_named_from_the_outputs_folder() {
        let dir = tempfile::tempdir().unwrap();
        let models = dir.path().join("models");
        let out = dir.path().join("out/posed");
        std::fs::create_dir_all(&models).unwrap();
        std::fs::create_dir_all(&out).unwrap();
        std::fs::write(models.join("tile.mtl"), "newmtl stone\n").unwrap();
        let paths = LibraryPaths::new(&models.join("tile.obj"), &out.join("tile.obj")).unwrap();
        let (line, moved) = paths.rewrite("tile.mtl");
        assert_eq!(line, "mtllib ../../models/tile.mtl");
        assert_eq!(moved.len(), 1);
        assert!(moved[0].found);
        assert!(out.join("../../models/tile.mtl").is_file());
    }

    #[test]
    fn the_same_folder_keeps_the_names_and_absolute_names_stay() {
        let dir = tempfile::tempdir().unwrap();
        let here = dir.path().join("a.obj");
        assert!(LibraryPaths::new(&here, &dir.path().join("b.obj")).is_none());
        let other = dir.path().join("other");
        std::fs::create_dir(&other).unwrap();
        let paths = LibraryPaths::new(&here, &other.join("b.obj")).unwrap();
        let absolute = dir.path().join("abs.mtl");
        let absolute = absolute.to_str().unwrap();
        let (line, moved) = paths.rewrite(&format!("{absolute} m.mtl"));
        assert_eq!(line, format!("mtllib {absolute} ../m.mtl"));
        assert_eq!(moved.len(), 1);
        assert!(!moved[0].found);
        assert!(moved[0].to_string().contains("not beside the source"));
    }

    #[test]
    fn relative_paths_climb_to_the_shared_folder() {
        let rel = relative_path(Path::new("/a/b/c"), Path::new("/a/d/e.mtl")).unwrap();
        assert_eq!(rel, Path::new("../../d/e.mtl"));
        assert_eq!(normalized(Path::new("/a/./b/../c")), Path::new("/a/c"));
    }
}

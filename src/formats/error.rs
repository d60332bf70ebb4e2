//! Errors for reading and writing files. Every variant names the file and the
//! offending line, face or vertex, so that the message alone is enough to find
//! the problem.

use crate::geometry::CageError;
use std::path::PathBuf;

/// A mesh file could not be read. Lines, faces and vertices in the messages and
/// fields count from 1 in file order, as OBJ and the user do; indices are as written.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    #[error("{path}: cannot read: {source}", path = shown_path(path))]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: the file is empty", path = shown_path(path))]
    Empty { path: PathBuf },
    #[error("{path}: not a text mesh file (binary data near byte {offset})", path = shown_path(path))]
    Binary { path: PathBuf, offset: usize },
    #[error("{path}: unknown mesh format (expected a .obj, .off, .glb or .gltf file, or a .npy point set)", path = shown_path(path))]
    UnknownFormat { path: PathBuf },
    #[error("{path}:{line}: {message}", path = shown_path(path))]
    Parse {
        path: PathBuf,
        line: usize,
        message: String,
    },
    #[error("{path}: the file has no vertices", path = shown_path(path))]
    NoVertices { path: PathBuf },
    #[error("{path}:{line}: vertex {vertex} has a non-finite coordinate", path = shown_path(path))]
    NonFinite {
        path: PathBuf,
        line: usize,
        vertex: usize,
    },
    #[error(
        "{path}:{line}: face {face} refers to vertex {index}, but the file has {count} vertices",
        path = shown_path(path)
    )]
    IndexOutOfRange {
        path: PathBuf,
        line: usize,
        face: usize,
        index: i64,
        count: usize,
    },
    #[error("{path}: {message}", path = shown_path(path))]
    Obj { path: PathBuf, message: String },
    /// A `.npy` point set that is not an (n, 3) array of finite floats.
    #[error("{path}: {message}", path = shown_path(path))]
    Npy { path: PathBuf, message: String },
    /// A glTF file that cannot be read: the message names the element
    /// (`accessor 3: …`) and what is wrong with it.
    #[error("{path}: {message}", path = shown_path(path))]
    Gltf { path: PathBuf, message: String },
    #[error("{path}: {count} vertices is more than the {limit} this tool supports", path = shown_path(path))]
    TooLarge {
        path: PathBuf,
        count: usize,
        limit: usize,
    },
    /// The object asked for by name is not one of the file's.
    #[error("{path}: {source}", path = shown_path(path))]
    Object { path: PathBuf, source: ObjectError },
}

/// An object asked for by name (`--mesh-object`, `object=`) that the file
/// cannot give.
#[derive(Debug, thiserror::Error)]
pub enum ObjectError {
    #[error("no object is named '{name}'; the file has {}", object_list(names))]
    NotFound { name: String, names: Vec<String> },
    #[error(
        "{count} objects are named '{name}', so which one is meant is unclear; the file has {}",
        object_list(names)
    )]
    Ambiguous {
        name: String,
        count: usize,
        names: Vec<String>,
    },
    #[error("{format} files hold one unnamed object, so there is no object '{name}' to read")]
    Unnamed { name: String, format: &'static str },
}

/// Object names as messages list them: quoted, the first twenty, then how
/// many more.
pub fn object_list(names: &[String]) -> String {
    const SHOWN: usize = 20;
    if names.is_empty() {
        return "no named objects".to_owned();
    }
    let quoted: Vec<String> = names.iter().take(SHOWN).map(|n| format!("'{n}'")).collect();
    let more = names.len().saturating_sub(SHOWN);
    let list = quoted.join(", ");
    match (names.len(), more) {
        (1, _) => format!("one object, {list}"),
        (count, 0) => format!("{count} objects: {list}"),
        (count, more) => format!("{count} objects: {list} and {more} more"),
    }
}

/// A cage file could not be read, or was read but is not a valid cage.
#[derive(Debug, thiserror::Error)]
pub enum CageLoadError {
    #[error(transparent)]
    Load(#[from] LoadError),
    #[error("{path}: {source}", path = shown_path(path))]
    Invalid { path: PathBuf, source: CageError },
}

/// An output file could not be written. Any existing file at `path` is untouched.
#[derive(Debug, thiserror::Error)]
#[error("{path}: cannot write: {source}", path = shown_path(path))]
pub struct WriteError {
    pub path: PathBuf,
    pub source: std::io::Error,
}

/// A file name as a one-line message shows it: as it is when it prints on one
/// line, quoted with escapes when it holds a control character (a newline would
/// split the message) or starts or ends with a space.
pub fn shown_path(path: &std::path::Path) -> String {
    let text = path.to_string_lossy();
    let plain = !text.chars().any(char::is_control)
        && !text.starts_with(char::is_whitespace)
        && !text.ends_with(char::is_whitespace);
    if plain {
        text.into_owned()
    } else {
        format!("{text:?}")
    }
}

#[cfg(test)]
mod tests {
    use super::shown_path;
    use std::path::Path;

    #[test]
    fn names_that_would_break_a_line_are_quoted() {
        assert_eq!(shown_path(Path::new("dir/mesh.obj")), "dir/mesh.obj");
        assert_eq!(shown_path(Path::new("a\nb.obj")), "\"a\\nb.obj\"");
        assert_eq!(shown_path(Path::new("trailing ")), "\"trailing \"");
    }
}

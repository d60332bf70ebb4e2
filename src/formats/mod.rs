//! Every file pmvc reads or writes: meshes and cages (OBJ, OFF, glTF 2.0, `.npy`
//! point sets), coloured PLY, weights (`.npy`, Green's `.npz`) with their
//! metadata and class masks, and outputs that are written whole or not at all.
//! Readers predict their memory through `budget` before they allocate and name
//! the file, the 1-based line or element, and what is wrong.
//!
//! Imports `geometry`, `coords` (the families that weights files describe) and
//! `budget`; never wgpu or egui.

mod error;
pub mod gltf;
mod io;
pub mod metadata;
mod mtllib;
pub mod npy;
pub mod npz;
mod obj;
mod off;
mod output;
mod ply;

pub use crate::budget::human_bytes;
pub use error::{object_list, shown_path, CageLoadError, LoadError, ObjectError, WriteError};
pub use io::{
    cage_from_file, check_object_name, load_cage, load_cage_object, load_mesh, load_mesh_object,
    parse_mesh, write_cage_and_pose, write_deformed_mesh, write_mesh_with_normals, write_obj,
    write_obj_to, write_polygons_obj_to, CageObjects,
};
pub use mtllib::MovedLibrary;
pub use npy::points::write_points_npy;
pub use output::{
    extension_warning, refuse_same_file, refuse_unwritable, remove_unfinished_outputs,
    resolve_output, write_atomically, OutputSet, OutputTarget, PendingOutput, WriteSeek,
};
pub use ply::{colour_byte, write_coloured_ply};

use crate::geometry::TriMesh;
use std::path::PathBuf;

/// The file format a mesh was read from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    Obj,
    Off,
    /// An (n, 3) float32 or float64 NumPy array: a point set.
    Npy,
    /// glTF 2.0, binary (`.glb`) or JSON (`.gltf`): one mesh of it ([`gltf`]).
    Gltf,
}

/// A mesh as read from a file, with what is needed to write it back deformed.
#[derive(Clone, Debug)]
pub struct MeshFile {
    pub path: PathBuf,
    pub format: MeshFormat,
    pub mesh: TriMesh,
    /// The original text of an OBJ file: a deformed copy keeps its faces, texture
    /// coordinates, groups and materials by rewriting only the `v` lines. For a
    /// glTF file, OBJ text written from its mesh (positions, texture coordinates,
    /// primitives as groups), which is what was parsed.
    pub obj_text: Option<String>,
    /// For a glTF mesh, the world transform of the node it was read through,
    /// already applied to `mesh.positions`: a glTF export puts it back on its
    /// node. `None` for other formats and for the identity.
    pub node_transform: Option<glam::DMat4>,
    /// Where the file has several objects and none was asked for, which was
    /// read ("the file has 3 objects: …; …"), for the caller to say.
    pub object_note: Option<String>,
    /// Which of the file's named objects this is, and what the others are.
    pub objects: FileObjects,
}

/// The named objects of a file (an OBJ's `o` objects, a glTF's nodes and
/// meshes), so that a caller can offer the others and record which was read.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FileObjects {
    /// The object read by name; `None` for the file's default (an OBJ's
    /// objects together, a glTF's first mesh).
    pub read: Option<String>,
    /// Every object of the file when it has two or more; empty otherwise.
    pub names: Vec<String>,
}

impl FileObjects {
    /// Whether the file has other objects to choose from.
    pub fn has_choice(&self) -> bool {
        self.names.len() > 1
    }
}

/// What `path` is when it is not a regular file ("a named pipe", "a device",
/// "a folder"), for messages; `None` for a regular file or one that cannot be
/// looked at (its reader then says why). Opening a named pipe for reading
/// waits for a writer, so readers that need a file ask this before opening.
pub fn not_a_regular_file(path: &std::path::Path) -> Option<&'static str> {
    let kind = std::fs::metadata(path).ok()?.file_type();
    if kind.is_file() {
        return None;
    }
    if kind.is_dir() {
        return Some("a folder");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return Some("a named pipe");
        }
        if kind.is_socket() {
            return Some("a socket");
        }
        if kind.is_char_device() || kind.is_block_device() {
            return Some("a device");
        }
    }
    Some("not a regular file")
}

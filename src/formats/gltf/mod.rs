//! glTF 2.0: a deformed mesh and its poses out to other tools as blend shapes
//! ([`write_gltf`]), and glTF meshes in ([`load_gltf`], which
//! [`super::load_mesh`] calls for `.glb` and `.gltf`).
//!
//! # Writing
//!
//! ```ignore
//! use pmvc::formats::gltf::{write_gltf, AnimationKey, GltfPose, GltfScene};
//! let poses = [GltfPose { name: "wave", positions: &wave }];
//! let keys = AnimationKey::evenly(poses.len(), 2.0);
//! write_gltf(path, &GltfScene { mesh: &file, base: &deformed, poses: &poses, animation: Some(&keys) })?;
//! ```
//!
//! - `path` ending in `.gltf` gets JSON with the binary buffer inside it as a
//!   base64 `data:` URI; any other name (`.glb`) gets binary glTF. The buffer is
//!   embedded rather than written as a `.bin` beside the JSON so that an export
//!   is one file, replaced whole by the rules of [`super::output`] (a temporary
//!   file renamed over it), with no second name to collide with or leave behind.
//!   Base64 makes it a third larger than a `.glb`, which suits large meshes.
//! - One mesh with one node and one scene. The base shape is `base`; each pose
//!   is a morph target, with POSITION and NORMAL deltas from the base, named
//!   after the pose in `mesh.extras.targetNames` (what Blender reads as shape key
//!   names, and three.js as `morphTargetDictionary`). Every target weight is 0
//!   in the mesh.
//! - Normals are recomputed from each shape ([`crate::geometry::vertex_normals`]),
//!   as the OBJ export does. Texture coordinates come from the OBJ's `vt` corners
//!   (or a glTF read by [`load_gltf`]) as TEXCOORD_0, with v flipped
//!   (`v_gltf = 1 − v_obj`: glTF's origin is the image's top left). The OBJ's
//!   groups (`g`/`o`, and `usemtl`, which becomes a material of that name with
//!   default values) become primitives of the mesh, each named in its
//!   `extras.name`.
//! - glTF holds one normal and one texture coordinate per vertex, where OBJ
//!   gives them per face corner: a vertex is written once per primitive and per
//!   distinct texture coordinate at its corners, as OBJ converters do. The
//!   targets use the same split. Vertices in no triangle are left out; a mesh
//!   with no triangles is written as points.
//! - A mesh read from glTF keeps the transform of the node it was read through
//!   ([`MeshFile::node_transform`]): the node written has it (as translation,
//!   rotation and scale) and the positions are in its frame, so that an
//!   import lands where the original was; where the source mirrors, the
//!   triangles keep its winding. A transform that is no translation, rotation
//!   and scale (a shear) is baked into the positions instead.
//! - Positions are f32. A mesh far from its node's origin is written relative
//!   to a point near its centre (the centre rounded to a multiple of the power
//!   of two at or above the bounding box's diagonal, so 0 for a mesh around
//!   the origin), added to the node's translation, so the f32 values keep
//!   their precision; deltas are taken in f64 before rounding.
//! - An animation, when asked for, is one `weights` channel with LINEAR
//!   interpolation: at each [`AnimationKey`] its pose's weight is 1 and every
//!   other 0 (all 0 for the base), so a player blends linearly between
//!   neighbouring keys. [`AnimationKey::evenly`] places the base at 0 s and the
//!   poses evenly after it, the last at the end.
//! - Sizes are predicted and checked against the memory available before the
//!   buffers are made ([`crate::budget::check_memory`]).
//!
//! # Reading
//!
//! [`load_gltf`] reads one mesh of a `.glb` or `.gltf` (the first, or one picked
//! by index or name: [`MeshPick`]) into the [`MeshFile`] the OBJ reader makes:
//! every primitive's triangles (strips and fans are cut into triangles; points
//! primitives add their vertices alone), its positions moved by the world
//! transform of the first node (lowest index) that draws the mesh, with its
//! parents' (winding reversed where that transform mirrors), and texture
//! coordinates and primitives as OBJ `vt` corners and groups. The file's text
//! for the writers ([`MeshFile::obj_text`]) is OBJ written from the glTF, so an
//! OBJ or glTF export of an imported mesh keeps its texture coordinates and
//! groups. Vertices at exactly the same position are welded into one (glTF
//! splits a vertex where its normals or texture coordinates differ, which OBJ
//! keeps per corner): a closed glTF surface reads as closed, so a cage may be
//! glTF too, and welded vertices would have had the same weights and moved
//! together anyway. Skins, morph targets and other meshes of the file are not
//! read. Buffers come from the GLB's binary chunk, base64 `data:` URIs, or
//! regular files in the glTF's folder or below it, never from elsewhere (nor
//! from a named pipe or a device). What the glTF says is checked, not
//! trusted: its nodes must form a forest (no node its own ancestor, none with
//! two parents), a TRIANGLES primitive must have whole triangles, every bound
//! and size is checked, and the memory its JSON takes once parsed is predicted
//! from the JSON's values before it is parsed. An error names the file and the
//! element (`accessor 3: …`, `node 2 …`, `buffer 0 ("data.bin"): …`).

mod buffers;
mod frame;
mod hierarchy;
mod json_size;
mod layout;
mod objects;
mod read;
mod write;

#[cfg(test)]
mod fuzz_mutations;
#[cfg(test)]
mod fuzz_tests;
#[cfg(test)]
mod json_size_tests;
#[cfg(test)]
mod node_tests;
#[cfg(test)]
mod refusal_tests;
#[cfg(test)]
mod tests;

pub use read::{load_gltf, parse_gltf};
pub use write::write_gltf;

use super::error::{shown_path, WriteError};
use super::MeshFile;
use crate::budget::TooLarge;
use glam::DVec3;
use std::path::{Path, PathBuf};

/// What [`write_gltf`] writes.
#[derive(Clone, Copy, Debug)]
pub struct GltfScene<'a> {
    /// The mesh as read: its triangles and, for an OBJ or a glTF, its texture
    /// coordinates and groups.
    pub mesh: &'a MeshFile,
    /// The base shape: one position per mesh vertex, in file order (the
    /// deformed mesh, or the rest positions).
    pub base: &'a [DVec3],
    /// Morph targets, in order: one position per mesh vertex each.
    pub poses: &'a [GltfPose<'a>],
    /// Keys of an animation through the poses; `None` for no animation.
    pub animation: Option<&'a [AnimationKey]>,
}

/// A morph target: its name and the mesh's positions in that pose.
#[derive(Clone, Copy, Debug)]
pub struct GltfPose<'a> {
    pub name: &'a str,
    pub positions: &'a [DVec3],
}

/// A key of the animation: at `seconds`, the shape is pose `pose` (an index
/// into [`GltfScene::poses`]) or, for `None`, the base.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnimationKey {
    pub seconds: f32,
    pub pose: Option<usize>,
}

impl AnimationKey {
    /// The base at 0 s, then each of `poses` poses in order, evenly over
    /// `seconds`: pose k (from 0) at `seconds · (k + 1) / poses`.
    pub fn evenly(poses: usize, seconds: f32) -> Vec<AnimationKey> {
        let mut keys = vec![AnimationKey {
            seconds: 0.0,
            pose: None,
        }];
        keys.extend((0..poses).map(|k| AnimationKey {
            seconds: (f64::from(seconds) * (k + 1) as f64 / poses as f64) as f32,
            pose: Some(k),
        }));
        keys
    }
}

/// Which mesh of a glTF file [`load_gltf`] reads.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum MeshPick {
    /// `meshes[0]`.
    #[default]
    First,
    /// `meshes[i]`, from 0.
    Index(usize),
    /// The first mesh of this name.
    Name(String),
    /// The object of this name ([`objects`]): the node's transform is the
    /// one that moves it; an error lists the names where none or several
    /// have it.
    Object(String),
}

/// Whether `path` names a glTF file: `.glb` or `.gltf`, in any case.
pub fn is_gltf_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("glb") || e.eq_ignore_ascii_case("gltf"))
}

/// A glTF export failed. Nothing was written at the path.
#[derive(Debug, thiserror::Error)]
pub enum GltfWriteError {
    /// What was asked for cannot be written (a pose of the wrong size, keys out
    /// of order).
    #[error("{path}: {message}", path = shown_path(path))]
    Invalid { path: PathBuf, message: String },
    /// The buffers would not fit in memory, or in a `.glb`.
    #[error("{path}: {source}", path = shown_path(path))]
    TooLarge { path: PathBuf, source: TooLarge },
    #[error(transparent)]
    Write(#[from] WriteError),
}

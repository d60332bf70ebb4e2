//! Reading mesh and cage files, and writing meshes by the rules of
//! [`super::write_atomically`].

use super::error::{CageLoadError, WriteError};
use super::mtllib::{LibraryPaths, MovedLibrary};
use super::npy::points::read_points_npy;
use super::obj::MAX_VERTICES;
use super::output::write_atomically;
use super::{obj, off, LoadError, MeshFile, MeshFormat};
use crate::budget::human_bytes;
use crate::budget::{available_memory, bytes_for, check_memory, read_limited_text};
use crate::geometry::vertex_normals;
use crate::geometry::{polygons_of, Cage, CageReport, TriMesh};
use glam::DVec3;
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;

/// The largest mesh or cage file read (4 GiB): room for the 16.7 million
/// vertices an OBJ file may have, with their faces.
pub const MESH_FILE_LIMIT: u64 = 4 << 30;

/// The format of `path`, by its extension (case-insensitive).
fn format_of(path: &Path) -> Result<MeshFormat, LoadError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("obj") => Ok(MeshFormat::Obj),
        Some("off") => Ok(MeshFormat::Off),
        Some("npy") => Ok(MeshFormat::Npy),
        Some("glb" | "gltf") => Ok(MeshFormat::Gltf),
        _ => Err(LoadError::UnknownFormat {
            path: path.to_owned(),
        }),
    }
}

/// Memory parsing `text` takes at its peak, the text included, predicted from
/// its vertex lines and face corners. Measured peaks (VmHWM) stayed under it:
/// 29 bytes per byte of text for 9-gons of one-digit indices, 17 for
/// `f 1 2 3` lines, 7.2 for `v 0 0 0` lines, 6.3 for a million vertices with two
/// million triangles, 5.6 for the shared scanned meshes; 3.9 for OFF.
fn parse_memory(format: MeshFormat, text: &[u8]) -> u64 {
    // Counted on every core, in pieces cut after a line end.
    let pieces_bytes = (1 << 20).max(text.len() / (4 * rayon::current_num_threads()));
    let mut pieces = Vec::new();
    let mut rest = text;
    while rest.len() > pieces_bytes {
        let Some(end) = rest[pieces_bytes..].iter().position(|&b| b == b'\n') else {
            break;
        };
        let (piece, after) = rest.split_at(pieces_bytes + end + 1);
        pieces.push(piece);
        rest = after;
    }
    pieces.push(rest);
    let (lines, tokens, vertices, corners) =
        pieces.par_iter().map(|piece| count_lines(piece)).reduce(
            || (0, 0, 0, 0),
            |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2, a.3 + b.3),
        );
    let text = text.len() as u64;
    let total = match format {
        // Set for the reader through tobj (the text and its copy; per vertex
        // f64 and f32 positions and a line in the copy; per corner 24 bytes of
        // indices, the triangles and their faces) and kept: the direct reader
        // holds less (each piece's positions and triangles, then all of them:
        // 48 bytes per vertex, 32 per triangle, the text once).
        MeshFormat::Obj => [
            bytes_for(text, 2),
            bytes_for(vertices, 64),
            bytes_for(corners, 60),
        ],
        // Per line at most one position; per number at most a triangle's share.
        MeshFormat::Off => [text, bytes_for(lines, 24), bytes_for(tokens, 8)],
        // Binary: never parsed as text.
        MeshFormat::Npy | MeshFormat::Gltf => [text, 0, 0],
    };
    total.into_iter().fold(0, u64::saturating_add)
}

/// Lines, words, `v` lines and `f` corners in `text`.
fn count_lines(text: &[u8]) -> (u64, u64, u64, u64) {
    let (mut lines, mut tokens, mut vertices, mut corners) = (0u64, 0u64, 0u64, 0u64);
    for line in text.split(|&b| b == b'\n' || b == b'\r') {
        let mut words = line
            .split(|b| b.is_ascii_whitespace())
            .filter(|word| !word.is_empty());
        let Some(first) = words.next() else { continue };
        let rest = words.count() as u64;
        lines += 1;
        tokens += 1 + rest;
        match first {
            b"v" => vertices += 1,
            b"f" => corners += rest,
            _ => {}
        }
    }
    (lines, tokens, vertices, corners)
}

/// Read an OBJ or OFF file, a `.npy` point set, or the first mesh of a glTF file
/// (`.glb` or `.gltf`, read by [`super::gltf::load_gltf`]), chosen by extension,
/// case-insensitive, refusing what would not fit in memory before allocating
/// it: a regular file by its size (its text and a copy) before it is read, then
/// every file by what its text holds ([`parse_memory`]) before it is parsed. A
/// device or pipe, which has no size, is read up to [`MESH_FILE_LIMIT`] or half
/// the memory available, and no further than a NUL byte. A `.npy` is read by
/// [`super::points_npy`]'s rules: an (n, 3) array of finite float32 or float64.
pub fn load_mesh(path: &Path) -> Result<MeshFile, LoadError> {
    load_mesh_object(path, None)
}

/// The one check of an object name asked for (`--mesh-object`, `object=`):
/// some text, as every name the readers list is.
pub fn check_object_name(name: &str) -> Result<&str, String> {
    if name.trim().is_empty() {
        return Err("an object name cannot be empty".to_owned());
    }
    Ok(name)
}

/// [`load_mesh`], reading object `object` of a file with several: a glTF's
/// node or mesh of that name ([`super::gltf::MeshPick::Object`]), an OBJ's
/// `o` object (its faces and the vertices they use, re-indexed in file
/// order; see [`super::obj`]). Without a name an OBJ's objects are read
/// together and a glTF's first mesh alone, and [`MeshFile::object_note`]
/// says so where the file has several. OFF and `.npy` files have no named
/// objects, so a name is an error there.
pub fn load_mesh_object(path: &Path, object: Option<&str>) -> Result<MeshFile, LoadError> {
    let format = format_of(path)?;
    let unnamed = |format: &'static str| match object {
        Some(name) => Err(LoadError::Object {
            path: path.to_owned(),
            source: super::ObjectError::Unnamed {
                name: name.to_owned(),
                format,
            },
        }),
        None => Ok(()),
    };
    match format {
        MeshFormat::Npy => {
            unnamed(".npy")?;
            return read_points_npy(path, MAX_VERTICES);
        }
        MeshFormat::Gltf => {
            let pick = match object {
                Some(name) => super::gltf::MeshPick::Object(name.to_owned()),
                None => super::gltf::MeshPick::First,
            };
            return super::gltf::load_gltf(path, &pick);
        }
        MeshFormat::Off => unnamed("OFF")?,
        MeshFormat::Obj => {}
    }
    let io_error = |source| LoadError::Io {
        path: path.to_owned(),
        source,
    };
    let refused = |error: crate::budget::TooLarge| {
        io_error(std::io::Error::new(
            std::io::ErrorKind::OutOfMemory,
            error.to_string(),
        ))
    };
    let metadata = std::fs::metadata(path).map_err(io_error)?;
    let limit = if metadata.is_file() {
        let size = metadata.len();
        // Past the limit, reading refuses it by name.
        if size <= MESH_FILE_LIMIT {
            check_memory(
                || format!("reading its {} and a copy", human_bytes(size)),
                bytes_for(size, 2),
            )
            .map_err(refused)?;
        }
        MESH_FILE_LIMIT
    } else {
        available_memory().map_or(MESH_FILE_LIMIT, |available| {
            (available / 2).min(MESH_FILE_LIMIT)
        })
    };
    let bytes = read_limited_text(path, limit).map_err(io_error)?;
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(LoadError::Empty {
            path: path.to_owned(),
        });
    }
    // `contains` finds a byte with memchr; most files have none to place.
    let binary_at = if bytes.contains(&0) {
        bytes.iter().position(|&b| b == 0)
    } else {
        None
    };
    if binary_at.is_none() {
        let size = bytes.len() as u64;
        let needed = parse_memory(format, &bytes).saturating_sub(size);
        check_memory(
            || format!("parsing its {} of text", human_bytes(size)),
            needed,
        )
        .map_err(refused)?;
    }
    let text = match (binary_at, String::from_utf8(bytes)) {
        (None, Ok(text)) => text,
        (Some(offset), _) => {
            return Err(LoadError::Binary {
                path: path.to_owned(),
                offset,
            })
        }
        (None, Err(error)) => {
            return Err(LoadError::Binary {
                path: path.to_owned(),
                offset: error.utf8_error().valid_up_to(),
            })
        }
    };
    let file = parse_mesh(path, text)?;
    match format {
        MeshFormat::Obj => obj::pick_object(path, file, object),
        _ => Ok(file),
    }
}

/// Parse the text of an OBJ, OFF or `.gltf` file named `path` (the format chosen
/// by its extension); `path` is only used for the format and for messages. The one entry
/// for mesh text, used by [`load_mesh`] and by the editor's bundled scenes.
pub fn parse_mesh(path: &Path, text: String) -> Result<MeshFile, LoadError> {
    // A byte-order mark would hide the first line's keyword; old-Mac files end
    // lines with CR alone, which `str::lines` does not split on.
    let mut text = text;
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    let text = if text.contains('\r') {
        text.replace("\r\n", "\n").replace('\r', "\n")
    } else {
        text
    };
    match format_of(path)? {
        MeshFormat::Obj => obj::parse_obj(path, text),
        MeshFormat::Off => off::parse_off(path, &text),
        MeshFormat::Npy => Err(LoadError::Npy {
            path: path.to_owned(),
            message: "a .npy point set is binary; read it with load_mesh".to_owned(),
        }),
        MeshFormat::Gltf => {
            super::gltf::parse_gltf(path, text.as_bytes(), &super::gltf::MeshPick::First)
        }
    }
}

/// Read a cage file and validate it (see [`Cage::new`]).
pub fn load_cage(path: &Path) -> Result<(Cage, CageReport), CageLoadError> {
    cage_from_file(path, load_mesh(path)?)
}

/// What a cage file said about its objects besides the cage.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CageObjects {
    /// Which object was read, where none was asked for and the file has several.
    pub note: Option<String>,
    pub objects: super::FileObjects,
}

/// [`load_cage`] of object `object` ([`load_mesh_object`]), and which of the
/// file's objects was read.
pub fn load_cage_object(
    path: &Path,
    object: Option<&str>,
) -> Result<(Cage, CageReport, CageObjects), CageLoadError> {
    let mut file = load_mesh_object(path, object)?;
    let objects = CageObjects {
        note: file.object_note.take(),
        objects: std::mem::take(&mut file.objects),
    };
    let (cage, report) = cage_from_file(path, file)?;
    Ok((cage, report, objects))
}

/// Validate a mesh read from `path` as a cage; errors name the file.
pub fn cage_from_file(path: &Path, file: MeshFile) -> Result<(Cage, CageReport), CageLoadError> {
    Cage::new(file.mesh).map_err(|source| CageLoadError::Invalid {
        path: path.to_owned(),
        source,
    })
}

/// Write a triangle mesh as OBJ.
pub fn write_obj(path: &Path, mesh: &TriMesh) -> Result<(), WriteError> {
    write_atomically(path, |out| {
        write_obj_to(out, &mesh.positions, &mesh.triangles)
    })
}

/// The one OBJ writer: a comment, `v` lines, then 1-based triangular `f` lines.
pub fn write_obj_to(
    out: &mut dyn Write,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> std::io::Result<()> {
    writeln!(out, "# written by pmvc")?;
    for p in positions {
        write_vertex(out, *p)?;
    }
    for [a, b, c] in triangles {
        writeln!(out, "f {} {} {}", a + 1, b + 1, c + 1)?;
    }
    Ok(())
}

/// [`write_obj_to`] with polygons (triangles and quads) as faces.
pub fn write_polygons_obj_to(
    out: &mut dyn Write,
    positions: &[DVec3],
    polygons: &[Vec<u32>],
) -> std::io::Result<()> {
    writeln!(out, "# written by pmvc")?;
    for p in positions {
        write_vertex(out, *p)?;
    }
    for polygon in polygons {
        write!(out, "f")?;
        for corner in polygon {
            write!(out, " {}", corner + 1)?;
        }
        writeln!(out)?;
    }
    Ok(())
}

/// Write a cage as the artist made it and its pose beside it: `rest_path` gets
/// the rest positions and `posed_path` the pose, both with the polygons the
/// cage was read with (quads stay quads), replaced together or not at all.
pub fn write_cage_and_pose(
    rest_path: &Path,
    posed_path: &Path,
    cage: &TriMesh,
    pose: &[DVec3],
) -> Result<(), WriteError> {
    let faces = polygons_of(cage);
    let outputs = super::OutputSet::create(&[rest_path, posed_path])?;
    outputs.finish(|index, out| {
        let positions = if index == 0 {
            &cage.positions[..]
        } else {
            pose
        };
        writeln!(out, "# written by pmvc")?;
        for p in positions {
            write_vertex(out, *p)?;
        }
        for face in &faces {
            write!(out, "f")?;
            for corner in face {
                write!(out, " {}", corner + 1)?;
            }
            writeln!(out)?;
        }
        Ok(())
    })
}

/// Write `file` with its vertices moved to `positions` (one per `v` line, in order).
///
/// An OBJ source keeps everything but its vertex positions and normals: faces,
/// texture coordinates, groups, materials and comments are copied. Normals are
/// recomputed from the deformed positions ([`vertex_normals`], one `vn` per
/// vertex, written before the first face under a comment that says so), and
/// every face corner refers to its vertex's normal. Comments that speak of
/// normals (MeshLab's "# 39028 vertices, 0 vertices normals") would then be
/// wrong, so they are left out. Written to another folder than the source's,
/// `mtllib` lines name their libraries by paths that resolve from there
/// ([`super::mtllib`]): what comes back says which, for the caller to tell.
pub fn write_deformed_mesh(
    file: &MeshFile,
    positions: &[DVec3],
    path: &Path,
) -> Result<Vec<MovedLibrary>, WriteError> {
    assert_eq!(
        positions.len(),
        file.mesh.positions.len(),
        "one position per mesh vertex"
    );
    let libraries = LibraryPaths::new(&file.path, path);
    let mut moved = Vec::new();
    match (&file.format, &file.obj_text) {
        // A glTF's text is OBJ written from it.
        (MeshFormat::Obj | MeshFormat::Gltf, Some(text)) => write_atomically(path, |out| {
            let normals = vertex_normals(positions, &file.mesh.triangles);
            let mut next_vertex = positions.iter();
            // `v` lines so far: a negative index counts back from there.
            let mut vertices_so_far: i64 = 0;
            let mut normals_written = false;
            for line in text.lines() {
                let mut tokens = line.split_whitespace();
                match tokens.next() {
                    Some("v") => {
                        vertices_so_far += 1;
                        write_vertex(
                            out,
                            *next_vertex.next().expect("vertex count checked on load"),
                        )?
                    }
                    // Stale after the deformation: recomputed below.
                    Some("vn") => {}
                    Some("mtllib") if libraries.is_some() => {
                        let names = line.trim_start()["mtllib".len()..].trim();
                        let paths = libraries.as_ref().expect("checked by the guard");
                        let (line, libraries) = paths.rewrite(names);
                        moved.extend(libraries);
                        writeln!(out, "{line}")?
                    }
                    Some(first) if first.starts_with('#') && speaks_of_normals(line) => {}
                    Some("f") => {
                        if !normals_written {
                            write_normals(out, &normals)?;
                            normals_written = true;
                        }
                        write!(out, "f")?;
                        for corner in tokens {
                            let mut parts = corner.split('/');
                            let vertex = parts.next().unwrap_or("");
                            let texcoord = parts.next().filter(|t| !t.is_empty());
                            // The normal of a corner is its vertex's: same index.
                            let normal = match vertex.parse::<i64>() {
                                Ok(index) if index < 0 => (vertices_so_far + 1 + index).to_string(),
                                _ => vertex.to_owned(),
                            };
                            match texcoord {
                                Some(texcoord) => write!(out, " {vertex}/{texcoord}/{normal}")?,
                                None => write!(out, " {vertex}//{normal}")?,
                            }
                        }
                        writeln!(out)?;
                    }
                    _ => writeln!(out, "{line}")?,
                }
            }
            Ok(())
        })?,
        _ => write_mesh_with_normals(path, positions, &file.mesh.triangles)?,
    }
    Ok(moved)
}

/// Write an OBJ of `positions` and `triangles` with recomputed vertex normals
/// (a mesh that came from no OBJ file, such as an OFF file or a bundled scene).
pub fn write_mesh_with_normals(
    path: &Path,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> Result<(), WriteError> {
    write_atomically(path, |out| {
        writeln!(out, "# written by pmvc")?;
        for p in positions {
            write_vertex(out, *p)?;
        }
        if !triangles.is_empty() {
            write_normals(out, &vertex_normals(positions, triangles))?;
        }
        for [a, b, c] in triangles {
            let [a, b, c] = [a + 1, b + 1, c + 1];
            writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}")?;
        }
        Ok(())
    })
}

/// A comment about the source's normals, which a deformation recomputes.
fn speaks_of_normals(comment: &str) -> bool {
    comment.to_ascii_lowercase().contains("normal")
}

/// `vn` lines, one per vertex, in vertex order, under a comment saying what they are.
fn write_normals(out: &mut dyn Write, normals: &[DVec3]) -> std::io::Result<()> {
    writeln!(
        out,
        "# {} vertex normals, recomputed by pmvc from the deformed positions",
        normals.len()
    )?;
    for n in normals {
        writeln!(
            out,
            "vn {} {} {}",
            RoundTrip(n.x),
            RoundTrip(n.y),
            RoundTrip(n.z)
        )?;
    }
    Ok(())
}

fn write_vertex(out: &mut dyn Write, p: DVec3) -> std::io::Result<()> {
    writeln!(
        out,
        "v {} {} {}",
        RoundTrip(p.x),
        RoundTrip(p.y),
        RoundTrip(p.z)
    )
}

/// The shortest decimal that reads back as the same f64 (0.1 stays "0.1"), with
/// an exponent for very large or small magnitudes so that no value takes
/// hundreds of digits.
pub(super) struct RoundTrip(pub f64);

impl std::fmt::Display for RoundTrip {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let magnitude = self.0.abs();
        if magnitude != 0.0 && !(1e-5..1e16).contains(&magnitude) {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

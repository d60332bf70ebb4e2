//! [`load_gltf`]: one mesh of a glTF file, as the OBJ reader would have read
//! it (see the module documentation).

use super::super::io::{RoundTrip, MESH_FILE_LIMIT};
use super::super::obj::{parse_obj, MAX_VERTICES};
use super::buffers::{split_glb, Buffers};
use super::hierarchy::check_hierarchy;
use super::json_size::JsonSize;
use super::objects::{default_note, objects, pick_object};
use super::MeshPick;
use crate::budget::human_bytes;
use crate::budget::{available_memory, bytes_for, check_memory, read_limited};
use crate::formats::{LoadError, MeshFile, MeshFormat};
use glam::{DMat4, DQuat, DVec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

/// Memory reading a mesh takes per vertex and per index: the elements as read,
/// the welded positions and their map, the OBJ text written from them and what
/// parsing that text holds.
const BYTES_PER_VERTEX: u64 = 250;
const BYTES_PER_INDEX: u64 = 100;

/// Read mesh `pick` of the glTF file `path` (`.glb` or `.gltf`), refusing what
/// would not fit in memory before it is read: a regular file by its size, a
/// device or pipe up to [`MESH_FILE_LIMIT`] or half the memory available.
pub fn load_gltf(path: &Path, pick: &MeshPick) -> Result<MeshFile, LoadError> {
    let io_error = |source| LoadError::Io {
        path: path.to_owned(),
        source,
    };
    let metadata = std::fs::metadata(path).map_err(io_error)?;
    let limit = if metadata.is_file() {
        let size = metadata.len();
        if size <= MESH_FILE_LIMIT {
            check_memory(|| format!("reading its {}", human_bytes(size)), size)
                .map_err(|e| out_of_memory(path, e))?;
        }
        MESH_FILE_LIMIT
    } else {
        available_memory().map_or(MESH_FILE_LIMIT, |available| {
            (available / 2).min(MESH_FILE_LIMIT)
        })
    };
    let bytes = read_limited(path, limit).map_err(io_error)?;
    parse_gltf(path, &bytes, pick)
}

fn out_of_memory(path: &Path, error: crate::budget::TooLarge) -> LoadError {
    LoadError::Io {
        path: path.to_owned(),
        source: std::io::Error::new(std::io::ErrorKind::OutOfMemory, error.to_string()),
    }
}

/// [`load_gltf`] for a file's bytes: binary glTF or its JSON, whatever the
/// name; `path` names the file in messages, and its folder is where external
/// buffers are looked for.
pub fn parse_gltf(path: &Path, bytes: &[u8], pick: &MeshPick) -> Result<MeshFile, LoadError> {
    let fail = |message: String| LoadError::Gltf {
        path: path.to_owned(),
        message,
    };
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(LoadError::Empty {
            path: path.to_owned(),
        });
    }
    let (json, bin) = if bytes.starts_with(b"glTF") {
        split_glb(bytes).map_err(fail)?
    } else {
        (bytes, None)
    };
    // What serde will keep, refused before it allocates any of it.
    let size = JsonSize::of(json);
    check_memory(|| size.describe(), size.bytes).map_err(|e| out_of_memory(path, e))?;
    let root: gltf::json::Root = gltf::json::deserialize::from_slice(json)
        .map_err(|e| fail(format!("not glTF JSON: {e}")))?;
    if !root.asset.version.starts_with("2.") {
        return Err(fail(format!(
            "glTF version {}; only 2.x is read",
            root.asset.version
        )));
    }
    let document = validated(root).map_err(fail)?;
    let (mesh, node) = match pick {
        MeshPick::Object(name) => {
            let object = pick_object(&document, name).map_err(|source| LoadError::Object {
                path: path.to_owned(),
                source,
            })?;
            (object.mesh, object.node)
        }
        _ => (picked(&document, pick).map_err(fail)?, None),
    };
    let transform = world_transform(&document, mesh.index(), node);
    let text = obj_text(path, &document, &mesh, transform, bin).map_err(|e| match e {
        Refused::Invalid(message) => fail(message),
        Refused::Memory(e) => out_of_memory(path, e),
        Refused::TooManyVertices(count) => LoadError::TooLarge {
            path: path.to_owned(),
            count,
            limit: MAX_VERTICES,
        },
    })?;
    let mut file = parse_obj(path, text)?;
    file.format = MeshFormat::Gltf;
    file.node_transform = (transform != DMat4::IDENTITY).then_some(transform);
    if *pick == MeshPick::First {
        file.object_note = default_note(&document, mesh.index());
    }
    let names: Vec<String> = objects(&document).into_iter().map(|o| o.name).collect();
    file.objects = crate::formats::FileObjects {
        read: match pick {
            MeshPick::Object(name) | MeshPick::Name(name) => Some(name.clone()),
            MeshPick::First | MeshPick::Index(_) => None,
        },
        names: if names.len() > 1 { names } else { Vec::new() },
    };
    Ok(file)
}

/// The document, checked by gltf-json's rules (every index in range, every
/// enumeration known, required extensions supported) but one: POSITION's `min`
/// and `max`, which the specification requires but nothing here reads, and
/// some exporters leave out. Its nodes must form a forest, which gltf-json
/// does not check. Problems are reported as one line, the first three with
/// where they are.
fn validated(root: gltf::json::Root) -> Result<gltf::Document, String> {
    use gltf::json::validation::{Error, Validate};
    check_hierarchy(&root.nodes)?;
    // gltf-json 1.4 looks a POSITION accessor up without a bound check when
    // it checks its min and max: out of range, it would panic.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(index) = primitive
                .attributes
                .values()
                .find(|index| index.value() >= root.accessors.len())
            {
                return Err(format!(
                    "meshes[{m}].primitives[{p}].attributes: accessor {} does not exist (the file has {})",
                    index.value(),
                    root.accessors.len()
                ));
            }
        }
    }
    // Only the problems shown are kept (with their paths, which are text):
    // a file may have as many as it has indices.
    let mut problems = Vec::new();
    let mut more = 0usize;
    root.validate(&root, gltf::json::Path::new, &mut |path, error| {
        if error == Error::Missing {
            let path = path();
            let bound = ["[\"POSITION\"].min", "[\"POSITION\"].max"]
                .iter()
                .any(|end| path.as_str().ends_with(end));
            if bound {
                return;
            }
        }
        if problems.len() < 3 {
            problems.push((path(), error));
        } else {
            more += 1;
        }
    });
    if problems.is_empty() {
        return Ok(gltf::Document::from_json_without_validation(root));
    }
    let mut text = String::from("invalid glTF: ");
    for (k, (at, problem)) in problems.iter().enumerate() {
        if k > 0 {
            text.push_str("; ");
        }
        let _ = write!(text, "{at}: {}", problem.to_string().to_lowercase());
    }
    if more > 0 {
        let _ = write!(text, "; and {more} more");
    }
    Err(text)
}

fn picked<'a>(document: &'a gltf::Document, pick: &MeshPick) -> Result<gltf::Mesh<'a>, String> {
    let count = document.meshes().len();
    let found = match pick {
        MeshPick::First | MeshPick::Object(_) => document.meshes().next(),
        MeshPick::Index(index) => document.meshes().nth(*index),
        MeshPick::Name(name) => document.meshes().find(|m| m.name() == Some(name.as_str())),
    };
    found.ok_or_else(|| match pick {
        _ if count == 0 => "the file has no meshes".to_owned(),
        MeshPick::First | MeshPick::Object(_) => "the file has no meshes".to_owned(),
        MeshPick::Index(index) => {
            format!("the file has {count} meshes, so there is no mesh {index} (they count from 0)")
        }
        MeshPick::Name(name) => {
            let names: Vec<String> = document
                .meshes()
                .map(|m| format!("'{}'", m.name().unwrap_or("")))
                .collect();
            format!(
                "no mesh is named '{name}'; the file has {}",
                names.join(", ")
            )
        }
    })
}

/// Why a mesh was not read.
enum Refused {
    Invalid(String),
    Memory(crate::budget::TooLarge),
    TooManyVertices(usize),
}

impl From<String> for Refused {
    fn from(message: String) -> Self {
        Refused::Invalid(message)
    }
}

/// A node's own transform, in f64.
fn local_transform(node: &gltf::Node) -> DMat4 {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            DMat4::from_cols_array_2d(&matrix.map(|column| column.map(f64::from)))
        }
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let rotation = DQuat::from_array(rotation.map(f64::from));
            let length = rotation.length();
            let rotation = if length.is_normal() {
                rotation / length
            } else {
                DQuat::IDENTITY
            };
            DMat4::from_scale_rotation_translation(
                DVec3::from_array(scale.map(f64::from)),
                rotation,
                DVec3::from_array(translation.map(f64::from)),
            )
        }
    }
}

/// The world transform of `node`, or else of the first node (lowest index)
/// that draws `mesh`, its parents' included; the identity where no node does.
fn world_transform(document: &gltf::Document, mesh: usize, node: Option<usize>) -> DMat4 {
    let nodes: Vec<gltf::Node> = document.nodes().collect();
    let mut parents = vec![None; nodes.len()];
    for node in &nodes {
        for child in node.children() {
            parents[child.index()].get_or_insert(node.index());
        }
    }
    let Some(first) = node.and_then(|n| nodes.get(n)).or_else(|| {
        nodes
            .iter()
            .find(|n| n.mesh().is_some_and(|m| m.index() == mesh))
    }) else {
        return DMat4::IDENTITY;
    };
    let mut transform = local_transform(first);
    let mut at = first.index();
    // The hierarchy is a forest (`check_hierarchy`): the walk reaches a root
    // within as many steps as there are nodes.
    for _ in 0..nodes.len() {
        let Some(parent) = parents[at] else { break };
        transform = local_transform(&nodes[parent]) * transform;
        at = parent;
    }
    transform
}

/// A name for an OBJ line: control characters (a newline would start another
/// line) as spaces, trimmed.
fn one_line(name: &str) -> String {
    name.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect::<String>()
        .trim()
        .to_owned()
}

/// The `name` in a primitive's extras, as the writer puts it there.
fn extras_name(extras: &gltf::json::Extras) -> Option<String> {
    let value: serde_json::Value = serde_json::from_str(extras.as_ref()?.get()).ok()?;
    Some(one_line(value.get("name")?.as_str()?)).filter(|n| !n.is_empty())
}

/// One primitive as read: its positions, texture coordinates and triangles.
struct Read {
    positions: Vec<[f32; 3]>,
    uvs: Option<Vec<[f32; 2]>>,
    triangles: Vec<[u32; 3]>,
}

fn f32_at(bytes: &[u8], at: usize) -> f32 {
    f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// A texture coordinate component of `data_type`, normalized as glTF says.
fn uv_component(data_type: DataType, bytes: &[u8], at: usize) -> f32 {
    match data_type {
        DataType::U8 => f32::from(bytes[at]) / 255.0,
        DataType::U16 => f32::from(u16::from_le_bytes([bytes[at], bytes[at + 1]])) / 65535.0,
        _ => f32_at(bytes, at),
    }
}

fn read_primitive(
    buffers: &mut Buffers,
    primitive: &gltf::Primitive,
    at: &dyn Fn(String) -> String,
) -> Result<Read, String> {
    let Some(position) = primitive.get(&gltf::Semantic::Positions) else {
        return Err(at("it has no POSITION attribute".to_owned()));
    };
    let index = position.index();
    if (position.data_type(), position.dimensions()) != (DataType::F32, Dimensions::Vec3) {
        return Err(format!(
            "accessor {index}: POSITION must be float VEC3, but it is {:?} {:?}",
            position.data_type(),
            position.dimensions()
        ));
    }
    if primitive.mode() == Mode::Triangles {
        match primitive.indices() {
            Some(indices) if indices.count() % 3 != 0 => {
                return Err(at(format!(
                    "accessor {} holds {} indices, not a multiple of 3 as TRIANGLES needs",
                    indices.index(),
                    indices.count()
                )))
            }
            None if position.count() % 3 != 0 => {
                return Err(at(format!(
                    "accessor {index} (POSITION) holds {} vertices and there are no indices, \
                     but TRIANGLES needs a multiple of 3",
                    position.count()
                )))
            }
            _ => {}
        }
    }
    let positions = buffers.read(&position, |b| [0, 4, 8].map(|at| f32_at(b, at)))?;
    if let Some(k) = positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(format!(
            "accessor {index}: position {k} has a non-finite coordinate"
        ));
    }
    let uvs = match primitive.get(&gltf::Semantic::TexCoords(0)) {
        None => None,
        Some(uv) => {
            let data_type = uv.data_type();
            let readable = match data_type {
                DataType::F32 => true,
                DataType::U8 | DataType::U16 => uv.normalized(),
                _ => false,
            };
            if !readable || uv.dimensions() != Dimensions::Vec2 {
                return Err(format!(
                    "accessor {}: TEXCOORD_0 must be float, or normalized unsigned byte or short, VEC2; it is {data_type:?} {:?}",
                    uv.index(),
                    uv.dimensions()
                ));
            }
            if uv.count() != positions.len() {
                return Err(format!(
                    "accessor {}: TEXCOORD_0 has {} elements, but POSITION (accessor {index}) has {}",
                    uv.index(),
                    uv.count(),
                    positions.len()
                ));
            }
            let size = data_type.size();
            Some(buffers.read(&uv, |b| [0, size].map(|at| uv_component(data_type, b, at)))?)
        }
    };
    let indices: Vec<u32> = match primitive.indices() {
        None => (0..positions.len() as u32).collect(),
        Some(indices) => {
            let data_type = indices.data_type();
            let read = match data_type {
                DataType::U8 => buffers.read(&indices, |b| u32::from(b[0]))?,
                DataType::U16 => {
                    buffers.read(&indices, |b| u32::from(u16::from_le_bytes([b[0], b[1]])))?
                }
                DataType::U32 => {
                    buffers.read(&indices, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))?
                }
                _ => {
                    return Err(format!(
                    "accessor {}: indices must be unsigned byte, short or int, not {data_type:?}",
                    indices.index()
                ))
                }
            };
            if let Some(k) = read.iter().position(|&i| i as usize >= positions.len()) {
                return Err(format!(
                    "accessor {}: index {} (element {k}) is past the primitive's {} vertices",
                    indices.index(),
                    read[k],
                    positions.len()
                ));
            }
            read
        }
    };
    let triangles = match primitive.mode() {
        Mode::Triangles => indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
        Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
            .map(|k| {
                let [a, b, c] = [indices[k], indices[k + 1], indices[k + 2]];
                if k % 2 == 0 {
                    [a, b, c]
                } else {
                    [b, a, c]
                }
            })
            .collect(),
        Mode::TriangleFan => (1..indices.len().saturating_sub(1))
            .map(|k| [indices[0], indices[k], indices[k + 1]])
            .collect(),
        Mode::Points => Vec::new(),
        lines => {
            return Err(at(format!(
                "{lines:?} primitives are not read, only triangles and points"
            )))
        }
    };
    Ok(Read {
        positions,
        uvs,
        triangles,
    })
}

/// The mesh as OBJ text: its positions moved by their node's transform and
/// welded where equal, each primitive's texture coordinates as `vt` lines, and
/// its triangles as a group (named when there are several primitives, or
/// the writer named it) with its material.
fn obj_text(
    path: &Path,
    document: &gltf::Document,
    mesh: &gltf::Mesh,
    transform: DMat4,
    bin: Option<&[u8]>,
) -> Result<String, Refused> {
    let mesh_index = mesh.index();
    let primitives: Vec<gltf::Primitive> = mesh.primitives().collect();
    if primitives.is_empty() {
        return Err(format!("mesh {mesh_index} has no primitives").into());
    }
    let (mut vertices, mut corners) = (0u64, 0u64);
    for primitive in &primitives {
        if let Some(position) = primitive.get(&gltf::Semantic::Positions) {
            vertices = vertices.saturating_add(position.count() as u64);
        }
        corners = corners.saturating_add(primitive.indices().map_or(0, |i| i.count() as u64));
    }
    check_memory(
        || format!("mesh {mesh_index} ({vertices} vertices, {corners} indices)"),
        bytes_for(vertices, BYTES_PER_VERTEX).saturating_add(bytes_for(corners, BYTES_PER_INDEX)),
    )
    .map_err(Refused::Memory)?;
    let mirrored = transform.determinant() < 0.0;
    let mut buffers = Buffers::new(path, document, bin);
    let mut welded: HashMap<[u64; 3], u32> = HashMap::new();
    let (mut v_lines, mut vt_lines, mut f_lines) = (String::new(), String::new(), String::new());
    let mut uv_count = 0usize;
    for (p, primitive) in primitives.iter().enumerate() {
        let at = |message: String| format!("mesh {mesh_index} primitive {p}: {message}");
        let read = read_primitive(&mut buffers, primitive, &at)?;
        let mut ids = Vec::with_capacity(read.positions.len());
        for position in &read.positions {
            let moved = transform.transform_point3(DVec3::from_array(position.map(f64::from)));
            if !moved.is_finite() {
                return Err(
                    at("its node's transform moves a vertex to infinity".to_owned()).into(),
                );
            }
            // -0.0 and 0.0 are one position.
            let key = (moved + DVec3::ZERO).to_array().map(f64::to_bits);
            let next = welded.len() as u32;
            let id = *welded.entry(key).or_insert_with(|| {
                let _ = writeln!(
                    v_lines,
                    "v {} {} {}",
                    RoundTrip(moved.x),
                    RoundTrip(moved.y),
                    RoundTrip(moved.z)
                );
                next
            });
            if welded.len() > MAX_VERTICES {
                return Err(Refused::TooManyVertices(welded.len()));
            }
            ids.push(id + 1);
        }
        let first_uv = uv_count + 1;
        if let Some(uvs) = &read.uvs {
            for [u, v] in uvs {
                let _ = writeln!(
                    vt_lines,
                    "vt {} {}",
                    RoundTrip(f64::from(*u)),
                    RoundTrip(1.0 - f64::from(*v))
                );
            }
            uv_count += uvs.len();
        }
        if read.triangles.is_empty() {
            continue;
        }
        let name = extras_name(primitive.extras())
            .or_else(|| (primitives.len() > 1).then(|| format!("primitive_{p}")));
        if let Some(name) = name {
            let _ = writeln!(f_lines, "g {name}");
        }
        let material = primitive.material();
        if let Some(index) = material.index() {
            let name = material.name().map(one_line).filter(|n| !n.is_empty());
            let name = name.unwrap_or_else(|| format!("material_{index}"));
            let _ = writeln!(f_lines, "usemtl {name}");
        }
        for triangle in &read.triangles {
            let mut corners = *triangle;
            if mirrored {
                corners.swap(1, 2);
            }
            f_lines.push('f');
            for corner in corners {
                let vertex = ids[corner as usize];
                match read.uvs {
                    Some(_) => {
                        let _ = write!(f_lines, " {vertex}/{}", first_uv + corner as usize);
                    }
                    None => {
                        let _ = write!(f_lines, " {vertex}");
                    }
                }
            }
            f_lines.push('\n');
        }
    }
    let name = mesh.name().map(one_line).unwrap_or_default();
    let mut text = format!(
        "# converted by pmvc from glTF mesh {mesh_index} '{name}': positions welded where equal\n"
    );
    text.reserve_exact(v_lines.len() + vt_lines.len() + f_lines.len());
    text.push_str(&v_lines);
    drop(v_lines);
    text.push_str(&vt_lines);
    drop(vt_lines);
    text.push_str(&f_lines);
    Ok(text)
}

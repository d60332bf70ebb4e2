//! A bounded, seeded, structure-aware fuzz of the glTF reader: valid `.glb`
//! and `.gltf` files (written by [`write_gltf`], and a hand-made scene with a
//! node hierarchy, two meshes, indexed, strip and point primitives, texture
//! coordinates and an embedded or external buffer) changed where it matters:
//! node hierarchies (children added, removed, a node its own child, cycles,
//! two parents, out of range), accessors' count, byteOffset, componentType,
//! type and bufferView (huge declared counts included), buffer views' and
//! buffers' lengths, offsets and strides, buffers' URIs, primitives' modes
//! and attributes, node transforms, JSON nested deep in `extras`, `min` and
//! unknown members, many strings, and the GLB container (its lengths, its
//! chunks, the binary chunk cut short). Every case must end in a mesh that is
//! what a mesh must be or in a clean one-line error, without a panic and
//! within a time bound; a case that declares more than memory holds must be
//! refused by a prediction (an allocation that size would blow the bound).

use super::buffers::split_glb;
use super::json_size::JsonSize;
use super::*;
use crate::formats::{parse_mesh, LoadError};
use serde_json::{json, Value};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

const CASES: usize = 6000;

/// The longest a case may take, in the debug build: an allocation of
/// gigabytes or a wait would take longer.
const CASE_LIMIT: Duration = Duration::from_secs(5);

/// xorshift64*: seeded, so that a failure names a case that can be replayed.
struct Random(u64);

impl Random {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    fn chance(&mut self, percent: usize) -> bool {
        self.below(100) < percent
    }

    fn pick<T: Clone>(&mut self, from: &[T]) -> T {
        from[self.below(from.len())].clone()
    }
}

/// Counts and offsets, from small to past any memory.
fn number(random: &mut Random) -> Value {
    const NUMBERS: [u64; 20] = [
        0,
        1,
        2,
        3,
        4,
        5,
        6,
        7,
        12,
        36,
        255,
        65_535,
        1 << 31,
        (1 << 32) - 1,
        1 << 32,
        (1 << 32) + 3,
        1 << 40,
        (1 << 53) + 1,
        1 << 62,
        u64::MAX,
    ];
    match random.below(12) {
        0 => json!(-1),
        1 => json!(1.5),
        2 => json!("3"),
        _ => json!(random.pick(&NUMBERS)),
    }
}

/// Text put in place of a placeholder string after the JSON is written:
/// nesting serde_json's own writer would recurse through.
const DEEP: &str = "\"@deep@\"";

fn deep(random: &mut Random) -> String {
    let depth = random.pick(&[2usize, 64, 126, 127, 128, 129, 200, 5_000, 50_000]);
    let (open, close) = if random.chance(50) {
        ("[", "]")
    } else {
        ("{\"a\":", "}")
    };
    let mut text = String::with_capacity(depth * 6);
    for _ in 0..depth {
        text.push_str(open);
    }
    text.push('0');
    for _ in 0..depth {
        text.push_str(close);
    }
    text
}

/// One file to start from.
#[derive(Clone)]
struct Base {
    name: &'static str,
    json: Value,
    /// The binary chunk of a `.glb`; `None` for a `.gltf`.
    bin: Option<Vec<u8>>,
}

/// A quad's corners (f32 VEC3), their texture coordinates (normalized u16
/// VEC2), its triangles' indices (u16) and a strip's (u8): 80 bytes.
fn scene_buffer() -> Vec<u8> {
    let corners = [0f32, 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.];
    let mut bytes: Vec<u8> = corners.iter().flat_map(|c| c.to_le_bytes()).collect();
    for uv in [0u16, 0, 65535, 0, 65535, 65535, 0, 65535] {
        bytes.extend(uv.to_le_bytes());
    }
    for index in [0u16, 1, 2, 0, 2, 3] {
        bytes.extend(index.to_le_bytes());
    }
    bytes.extend([0u8, 1, 3, 2]);
    bytes
}

fn scene(buffer: Value) -> Value {
    json!({
        "asset": {"version": "2.0", "generator": "fuzz"},
        "scene": 0,
        "scenes": [{"nodes": [0, 4]}],
        "nodes": [
            {"name": "root", "children": [1, 2]},
            {"translation": [1, 2, 3]},
            {"children": [3], "scale": [2, 2, 2]},
            {"mesh": 0, "rotation": [0, 0, 0.70710677, 0.70710677]},
            {"mesh": 1, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1]}
        ],
        "meshes": [
            {"name": "quad", "primitives": [
                {"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "mode": 4,
                 "extras": {"name": "front"}},
                {"attributes": {"POSITION": 0}, "indices": 3, "mode": 5}
            ]},
            {"name": "points", "primitives": [{"attributes": {"POSITION": 0}, "mode": 0}]}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "normalized": true, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
            {"bufferView": 3, "componentType": 5121, "count": 4, "type": "SCALAR"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteLength": 48, "byteStride": 12},
            {"buffer": 0, "byteOffset": 48, "byteLength": 16},
            {"buffer": 0, "byteOffset": 64, "byteLength": 12},
            {"buffer": 0, "byteOffset": 76, "byteLength": 4}
        ],
        "buffers": [buffer]
    })
}

fn data_uri(bytes: &[u8]) -> String {
    use base64::Engine as _;
    format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

/// The files the cases start from; `folder` gets the external buffer
/// (`data.bin`), and, on Unix, a named pipe (`pipe.bin`).
fn bases(folder: &Path) -> Vec<Base> {
    let file = parse_mesh(
        Path::new("square.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         g first\nusemtl red\nf 1/1 2/2 3/3\ng second\nf 1/1 3/3 4/4\n"
            .to_owned(),
    )
    .unwrap();
    let lifted: Vec<DVec3> = file.mesh.positions.iter().map(|p| *p + DVec3::Z).collect();
    let poses = [GltfPose {
        name: "lifted",
        positions: &lifted,
    }];
    let keys = AnimationKey::evenly(1, 1.0);
    let written = GltfScene {
        mesh: &file,
        base: &file.mesh.positions,
        poses: &poses,
        animation: Some(&keys),
    };
    let mut bases = Vec::new();
    for name in ["written.glb", "written.gltf"] {
        let path = folder.join(name);
        write_gltf(&path, &written).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let (json, bin) = if name.ends_with(".glb") {
            let (json, bin) = split_glb(&bytes).unwrap();
            (json.to_vec(), Some(bin.unwrap().to_vec()))
        } else {
            (bytes, None)
        };
        bases.push(Base {
            name,
            json: serde_json::from_slice(&json).unwrap(),
            bin,
        });
    }
    let buffer = scene_buffer();
    std::fs::write(folder.join("data.bin"), &buffer).unwrap();
    std::fs::create_dir_all(folder.join("folder.bin")).unwrap();
    #[cfg(unix)]
    let _ = std::process::Command::new("mkfifo")
        .arg(folder.join("pipe.bin"))
        .status();
    let length = buffer.len();
    bases.push(Base {
        name: "embedded.gltf",
        json: scene(json!({"byteLength": length, "uri": data_uri(&buffer)})),
        bin: None,
    });
    bases.push(Base {
        name: "external.gltf",
        json: scene(json!({"byteLength": length, "uri": "data.bin"})),
        bin: None,
    });
    bases.push(Base {
        name: "scene.glb",
        json: scene(json!({"byteLength": length})),
        bin: Some(buffer),
    });
    bases
}

/// The elements of `json[key]`, if it is a non-empty array.
fn elements<'a>(json: &'a mut Value, key: &str) -> Option<&'a mut Vec<Value>> {
    json.get_mut(key)?.as_array_mut().filter(|a| !a.is_empty())
}

/// One element of `json[key]`, picked at random.
fn element<'a>(json: &'a mut Value, key: &str, random: &mut Random) -> Option<&'a mut Value> {
    let list = elements(json, key)?;
    let at = random.below(list.len());
    list.get_mut(at)
}

fn length(json: &Value, key: &str) -> usize {
    json.get(key).and_then(Value::as_array).map_or(0, Vec::len)
}

/// An index into `json[key]`: mostly in range, sometimes just past it or far.
fn index(json: &Value, key: &str, random: &mut Random) -> Value {
    let count = length(json, key);
    match random.below(10) {
        0 => json!(count),
        1 => json!(count + 7),
        2 => json!(u32::MAX),
        3 => json!(-1),
        _ => json!(random.below(count.max(1))),
    }
}

fn set(target: Option<&mut Value>, key: &str, value: Value) {
    if let Some(Value::Object(object)) = target {
        object.insert(key.to_owned(), value);
    }
}

fn remove(target: Option<&mut Value>, key: &str) {
    if let Some(Value::Object(object)) = target {
        object.remove(key);
    }
}

/// The node hierarchy: children added (the node itself, its parent, an
/// ancestor, a node that has a parent already, one out of range, twice),
/// removed, or a long chain or cycle through many new nodes.
fn mutate_nodes(json: &mut Value, random: &mut Random) {
    let count = length(json, "nodes");
    if count == 0 {
        return;
    }
    let node = random.below(count);
    let parent_of = |json: &Value, child: usize| {
        json["nodes"].as_array().and_then(|nodes| {
            nodes.iter().position(|n| {
                n["children"]
                    .as_array()
                    .is_some_and(|c| c.iter().any(|i| i.as_u64() == Some(child as u64)))
            })
        })
    };
    let child = match random.below(8) {
        0 => json!(node),
        1 => json!(parent_of(json, node).unwrap_or(node)),
        2 => {
            // The root of its tree: a longer cycle.
            let mut at = node;
            for _ in 0..count {
                match parent_of(json, at) {
                    Some(parent) => at = parent,
                    None => break,
                }
            }
            json!(at)
        }
        3 => index(json, "nodes", random),
        4 => {
            remove(json["nodes"].get_mut(node), "children");
            return;
        }
        5 => {
            // A chain of new nodes below `node`, the last maybe back to one
            // of them.
            let extra = random.pick(&[10usize, 200, 2000]);
            let nodes = json["nodes"].as_array_mut().unwrap();
            let first = nodes.len();
            for k in 0..extra {
                let children = if k + 1 < extra {
                    json!([first + k + 1])
                } else if random.chance(50) {
                    json!([first + random.below(extra)])
                } else {
                    json!([])
                };
                nodes.push(json!({"children": children, "scale": [1, 1, 1]}));
            }
            json!(first)
        }
        6 => json!(random.below(count)),
        _ => {
            set(json["nodes"].get_mut(node), "children", json!("none"));
            return;
        }
    };
    let target = &mut json["nodes"][node];
    match target.get_mut("children").and_then(Value::as_array_mut) {
        Some(children) => {
            if random.chance(30) {
                if let Some(first) = children.first().cloned() {
                    children.push(first);
                }
            }
            children.push(child);
        }
        None => set(Some(target), "children", json!([child])),
    }
}

fn mutate_node_fields(json: &mut Value, random: &mut Random) {
    let meshes = length(json, "meshes");
    let mesh = index(json, "meshes", random);
    let Some(node) = element(json, "nodes", random) else {
        return;
    };
    match random.below(7) {
        0 => set(Some(node), "mesh", mesh),
        1 => set(Some(node), "scale", json!([0, 0, 0])),
        2 => set(Some(node), "scale", json!([-1, 1, 1e39])),
        3 => set(Some(node), "rotation", json!([0, 0, 0, 0])),
        4 => set(Some(node), "matrix", json!([1, 2, 3])),
        5 => set(Some(node), "translation", json!([1e38, -1e38, 3.4e38])),
        _ => set(Some(node), "mesh", json!(random.below(meshes.max(1)))),
    }
}

fn mutate_accessor(json: &mut Value, random: &mut Random) {
    let view = index(json, "bufferViews", random);
    let Some(accessor) = element(json, "accessors", random) else {
        return;
    };
    match random.below(11) {
        0 | 1 => {
            let count = number(random);
            set(Some(accessor), "count", count);
        }
        2 => {
            let offset = number(random);
            set(Some(accessor), "byteOffset", offset);
        }
        3 => {
            let kind = random.pick(&[5120, 5121, 5122, 5123, 5125, 5126, 0, 5124, 9999]);
            set(Some(accessor), "componentType", json!(kind));
        }
        4 => {
            let kind = random.pick(&[
                "SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4", "X",
            ]);
            set(Some(accessor), "type", json!(kind));
        }
        5 => set(Some(accessor), "bufferView", view),
        6 => remove(Some(accessor), "bufferView"),
        7 => set(Some(accessor), "normalized", json!(random.chance(50))),
        8 => set(
            Some(accessor),
            "sparse",
            json!({"count": 1, "indices": {"bufferView": 0, "componentType": 5123},
                   "values": {"bufferView": 0}}),
        ),
        9 => set(Some(accessor), "min", json!(DEEP.trim_matches('"'))),
        _ => set(Some(accessor), "max", json!([[], {}, null, "x", [1, [2]]])),
    }
}

fn mutate_view(json: &mut Value, random: &mut Random) {
    let buffer = index(json, "buffers", random);
    let Some(view) = element(json, "bufferViews", random) else {
        return;
    };
    let value = number(random);
    match random.below(5) {
        0 => set(Some(view), "byteLength", value),
        1 => set(Some(view), "byteOffset", value),
        2 => {
            let stride = random.pick(&[0, 1, 3, 4, 5, 12, 252, 256, u32::MAX as u64]);
            set(Some(view), "byteStride", json!(stride));
        }
        3 => set(Some(view), "buffer", buffer),
        _ => remove(Some(view), "byteStride"),
    }
}

fn mutate_buffer(json: &mut Value, random: &mut Random) {
    let Some(buffer) = element(json, "buffers", random) else {
        return;
    };
    if random.chance(50) {
        let length = number(random);
        set(Some(buffer), "byteLength", length);
        return;
    }
    let uri = random.pick(&[
        "data.bin",
        "missing.bin",
        "../data.bin",
        "./data.bin",
        "%64ata.bin",
        "%ZZ",
        "folder.bin",
        "pipe.bin",
        "/etc/passwd",
        "",
        "data:application/octet-stream;base64,AAAA",
        "data:application/octet-stream;base64,!!!",
        "data:text/plain,abc",
        "data:",
    ]);
    if random.chance(10) {
        remove(Some(buffer), "uri");
    } else {
        set(Some(buffer), "uri", json!(uri));
    }
    if random.chance(50) {
        // Nothing to read: what a named pipe's size says.
        set(Some(buffer), "byteLength", json!(0));
    }
}

fn mutate_primitive(json: &mut Value, random: &mut Random) {
    let accessor = index(json, "accessors", random);
    let Some(mesh) = element(json, "meshes", random) else {
        return;
    };
    if random.chance(10) {
        set(Some(mesh), "primitives", json!([]));
        return;
    }
    let Some(primitive) = element(mesh, "primitives", random) else {
        return;
    };
    match random.below(7) {
        0 => set(Some(primitive), "mode", json!(random.below(8))),
        1 => set(Some(primitive), "indices", accessor),
        2 => remove(Some(primitive), "indices"),
        3 => set(primitive.get_mut("attributes"), "POSITION", accessor),
        4 => set(primitive.get_mut("attributes"), "TEXCOORD_0", accessor),
        5 => remove(primitive.get_mut("attributes"), "POSITION"),
        _ => set(
            Some(primitive),
            "targets",
            json!([{"POSITION": accessor}, {"NORMAL": 0}]),
        ),
    }
}

/// JSON nested deep where it is kept as text (`extras`), ignored (an unknown
/// member) or parsed (`min`); many strings; an unknown required extension.
fn mutate_document(json: &mut Value, random: &mut Random) {
    let placeholder = json!(DEEP.trim_matches('"'));
    match random.below(7) {
        0 => set(element(json, "nodes", random), "extras", placeholder),
        6 => {
            let primitive = element(json, "meshes", random)
                .and_then(|mesh| element(mesh, "primitives", random));
            set(primitive, "extras", placeholder);
        }
        1 => set(Some(json), "extras", placeholder),
        2 => set(element(json, "meshes", random), "unknown", placeholder),
        3 => set(element(json, "accessors", random), "min", placeholder),
        4 => {
            let count = random.pick(&[10usize, 1000, 20_000]);
            set(Some(json), "extensionsUsed", json!(vec![""; count]));
        }
        _ => set(Some(json), "extensionsRequired", json!(["KHR_unknown"])),
    }
}

/// A `.glb` of `json` and `bin`, its chunks padded to 4 bytes.
fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let mut json = json.to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut chunks = Vec::new();
    chunks.extend((json.len() as u32).to_le_bytes());
    chunks.extend(b"JSON");
    chunks.extend(&json);
    if let Some(bin) = bin {
        let mut bin = bin.to_vec();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        chunks.extend((bin.len() as u32).to_le_bytes());
        chunks.extend(b"BIN\0");
        chunks.extend(&bin);
    }
    let mut bytes = b"glTF".to_vec();
    bytes.extend(2u32.to_le_bytes());
    bytes.extend((12 + chunks.len() as u32).to_le_bytes());
    bytes.extend(chunks);
    bytes
}

/// The container changed: the binary chunk cut short or dropped, a length
/// changed, the chunks' kinds or order changed.
fn mutate_container(bytes: &mut Vec<u8>, json_length: usize, random: &mut Random) {
    let word = |bytes: &mut Vec<u8>, at: usize, value: u32| {
        if bytes.len() >= at + 4 {
            bytes[at..at + 4].copy_from_slice(&value.to_le_bytes());
        }
    };
    let bin_header = 20 + json_length.next_multiple_of(4);
    match random.below(7) {
        0 => {
            // Cut inside the binary chunk, the header's total kept right.
            let cut = bin_header + random.below(bytes.len().saturating_sub(bin_header) + 1);
            bytes.truncate(cut.min(bytes.len()));
            let total = bytes.len() as u32;
            word(bytes, 8, total);
        }
        1 => bytes.truncate(random.below(bytes.len() + 1)),
        2 => {
            let length = random.pick(&[0, 1, 3, 1 << 20, u32::MAX]);
            word(bytes, bin_header, length);
        }
        3 => {
            let length = random.pick(&[0, 4, 1 << 20, u32::MAX]);
            word(bytes, 12, length);
        }
        4 => {
            let length = random.pick(&[0, 12, 20, 1 << 30, u32::MAX]);
            word(bytes, 8, length);
        }
        5 => {
            if bytes.len() >= bin_header + 8 {
                bytes[bin_header + 4..bin_header + 8].copy_from_slice(b"JSON");
            }
        }
        _ => word(bytes, 4, random.pick(&[1, 3])),
    }
}

/// One case: its file's name, bytes, and the mesh asked for.
struct Case {
    name: &'static str,
    /// The JSON as changed, before the placeholders are filled in and the
    /// bytes changed.
    json: Value,
    bytes: Vec<u8>,
    pick: MeshPick,
}

fn case(bases: &[Base], random: &mut Random) -> Case {
    let base = &bases[random.below(bases.len())];
    let mut json = base.json.clone();
    for _ in 0..1 + random.below(3) {
        match random.below(9) {
            0 | 1 => mutate_nodes(&mut json, random),
            2 => mutate_node_fields(&mut json, random),
            3 | 4 => mutate_accessor(&mut json, random),
            5 => mutate_view(&mut json, random),
            6 => mutate_buffer(&mut json, random),
            7 => mutate_primitive(&mut json, random),
            _ => mutate_document(&mut json, random),
        }
    }
    let mut text = serde_json::to_string(&json).unwrap();
    if text.contains(DEEP) {
        text = text.replace(DEEP, &deep(random));
    }
    let mut bytes = match &base.bin {
        Some(bin) => {
            let mut bytes = glb(text.as_bytes(), Some(bin));
            if random.chance(20) {
                mutate_container(&mut bytes, text.len(), random);
            }
            bytes
        }
        None => text.into_bytes(),
    };
    if random.chance(3) {
        bytes.truncate(random.below(bytes.len() + 1));
    }
    let pick = match random.below(10) {
        0 => MeshPick::Index(random.below(3)),
        1 => MeshPick::Name(random.pick(&["quad", "points", "x"]).to_owned()),
        _ => MeshPick::First,
    };
    Case {
        name: base.name,
        json,
        bytes,
        pick,
    }
}

/// Whether the JSON's nodes form a forest, found independently of the
/// reader: every child in range, listed once, with one parent, and no cycle.
fn is_forest(json: &Value) -> bool {
    let Some(nodes) = json.get("nodes").and_then(Value::as_array) else {
        return true;
    };
    let mut parents = vec![None; nodes.len()];
    for (n, node) in nodes.iter().enumerate() {
        let Some(children) = node.get("children").and_then(Value::as_array) else {
            continue;
        };
        for child in children {
            match child.as_u64().map(|c| c as usize) {
                Some(c) if c < nodes.len() && parents[c].is_none() && c != n => {
                    parents[c] = Some(n)
                }
                _ => return false,
            }
        }
    }
    // No walk to a root takes more steps than there are nodes.
    (0..nodes.len()).all(|start| {
        let mut at = start;
        for _ in 0..=nodes.len() {
            match parents[at] {
                Some(parent) => at = parent,
                None => return true,
            }
        }
        false
    })
}

/// The mesh `pick` names in the JSON, if it names one.
fn picked_mesh<'a>(json: &'a Value, pick: &MeshPick) -> Option<&'a Value> {
    let meshes = json.get("meshes")?.as_array()?;
    match pick {
        MeshPick::First => meshes.first(),
        MeshPick::Index(index) => meshes.get(*index),
        MeshPick::Name(name) => meshes
            .iter()
            .find(|m| m.get("name").and_then(Value::as_str) == Some(name)),
        // Not generated here.
        MeshPick::Object(_) => None,
    }
}

/// Whether a TRIANGLES primitive of the picked mesh declares a number of
/// indices, or of vertices where it has none, that is not a multiple of 3.
fn has_partial_triangle(json: &Value, pick: &MeshPick) -> bool {
    let count = |accessor: &Value| {
        let index = accessor.as_u64()? as usize;
        json.get("accessors")?.get(index)?.get("count")?.as_u64()
    };
    let Some(primitives) = picked_mesh(json, pick)
        .and_then(|mesh| mesh.get("primitives"))
        .and_then(Value::as_array)
    else {
        return false;
    };
    primitives.iter().any(|primitive| {
        let triangles = primitive.get("mode").is_none_or(|mode| mode == &json!(4));
        let counted = match primitive.get("indices") {
            Some(indices) => count(indices),
            None => primitive
                .get("attributes")
                .and_then(|a| a.get("POSITION"))
                .and_then(count),
        };
        triangles && counted.is_some_and(|c| c % 3 != 0)
    })
}

/// What a read must give: a mesh whose every index is in range and every
/// position finite, or one line naming the file. A hierarchy that is not a
/// forest and a partial triangle must be refused.
fn check(case: &Case, path: &Path, result: Result<MeshFile, LoadError>) -> Result<bool, String> {
    match result {
        Ok(file) => {
            if !is_forest(&case.json) {
                return Err("a node hierarchy that is not a forest was read".to_owned());
            }
            if has_partial_triangle(&case.json, &case.pick) {
                return Err("a partial triangle was read".to_owned());
            }
            let mesh = &file.mesh;
            if !mesh.positions.iter().all(|p| p.is_finite()) {
                return Err("a non-finite position was read".to_owned());
            }
            if !mesh
                .triangles
                .iter()
                .flatten()
                .all(|&i| (i as usize) < mesh.positions.len())
            {
                return Err("an index out of range was read".to_owned());
            }
            if mesh.triangle_faces.len() != mesh.triangles.len() {
                return Err("triangle faces and triangles differ in number".to_owned());
            }
            Ok(true)
        }
        Err(error) => {
            let text = error.to_string();
            let named = text.starts_with(&format!("{}: ", path.display()));
            if !named || text.contains('\n') || text.len() > 600 {
                return Err(format!("not a one-line message naming the file: {text:?}"));
            }
            if case.bytes.is_empty() != matches!(error, LoadError::Empty { .. }) {
                return Err(format!("empty or not: {text}"));
            }
            Ok(false)
        }
    }
}

#[test]
fn mutated_gltf_files_are_read_or_refused_cleanly_and_promptly() {
    let folder = tempfile::tempdir().unwrap();
    let bases = bases(folder.path());
    for base in &bases {
        let path = folder.path().join(base.name);
        let text = serde_json::to_vec(&base.json).unwrap();
        let bytes = match &base.bin {
            Some(bin) => glb(&text, Some(bin)),
            None => text,
        };
        let read = parse_gltf(&path, &bytes, &MeshPick::First);
        assert!(read.is_ok(), "{}: {read:?}", base.name);
    }
    // More cases, or others, for a longer run: PMVC_GLTF_FUZZ_CASES=100000
    // PMVC_GLTF_FUZZ_SEED=7 cargo test --release --lib fuzz_tests.
    let setting = |name: &str| std::env::var(name).ok().and_then(|v| v.parse::<u64>().ok());
    let seed = setting("PMVC_GLTF_FUZZ_SEED").unwrap_or(0x5eed_91f7_2c4a_0b13);
    let cases = setting("PMVC_GLTF_FUZZ_CASES").map_or(CASES, |n| n as usize);
    let started = Instant::now();
    let (send, receive) = mpsc::channel();
    let root = folder.path().to_owned();
    // The case being read, to name one that never ends.
    let current = Arc::new(Mutex::new(String::new()));
    let running = Arc::clone(&current);
    // The cases run on a thread of their own so that one that waits or
    // takes too long fails the test instead of holding it.
    std::thread::Builder::new()
        .name("gltf fuzz".to_owned())
        .spawn(move || {
            let mut random = Random(seed);
            for number in 0..cases {
                let case = case(&bases, &mut random);
                let path = root.join(case.name);
                let described = |why: &str| {
                    let shown = String::from_utf8_lossy(&case.bytes[..case.bytes.len().min(3000)]);
                    format!(
                        "case {number} (seed {seed:#x}, {}, {:?}): {why}\n{shown}",
                        case.name, case.pick
                    )
                };
                *running.lock().unwrap_or_else(|e| e.into_inner()) = described("still running");
                let began = Instant::now();
                let outcome = catch_unwind(AssertUnwindSafe(|| {
                    let json = if case.bytes.starts_with(b"glTF") {
                        split_glb(&case.bytes).map_or(&[][..], |(json, _)| json)
                    } else {
                        &case.bytes[..]
                    };
                    let predicted = JsonSize::of(json);
                    // Never below what the JSON's strings hold as text.
                    assert!(predicted.bytes >= predicted.strings);
                    parse_gltf(&path, &case.bytes, &case.pick)
                }));
                let verdict = match outcome {
                    Ok(result) => check(&case, &path, result),
                    Err(_) => Err("the reader panicked".to_owned()),
                };
                let took = began.elapsed();
                let accepted = matches!(verdict, Ok(true));
                let failed = match verdict {
                    Ok(_) if took > CASE_LIMIT => Some(format!("it took {took:?}")),
                    Ok(_) => None,
                    Err(why) => Some(why),
                };
                let report = failed.map(|why| described(&why));
                if send.send((number, report, accepted, took)).is_err() {
                    return;
                }
            }
        })
        .unwrap();
    let (mut accepted, mut slowest) = (0, Duration::ZERO);
    for expected in 0..cases {
        let Ok((number, report, read, took)) = receive.recv_timeout(CASE_LIMIT * 2) else {
            panic!("{}", current.lock().unwrap_or_else(|e| e.into_inner()));
        };
        assert_eq!(number, expected);
        if let Some(report) = report {
            panic!("{report}");
        }
        accepted += usize::from(read);
        slowest = slowest.max(took);
    }
    eprintln!(
        "{cases} glTF cases in {:?} (the slowest {slowest:?}): {accepted} read, {} refused",
        started.elapsed(),
        cases - accepted
    );
    assert!(
        accepted > cases / 10 && accepted < cases * 9 / 10,
        "{accepted} read"
    );
}

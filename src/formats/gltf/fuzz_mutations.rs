//! The glTF fuzz test's seeded randomness and its changes to a file: node
//! hierarchies, accessors, buffer views, buffers, primitives, the document's
//! odd corners and the GLB container ([`super::fuzz_tests`] says why each).

use serde_json::{json, Value};

/// xorshift64*: seeded, so that a failure names a case that can be replayed.
pub(super) struct Random(pub(super) u64);

impl Random {
    pub(super) fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    pub(super) fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    pub(super) fn chance(&mut self, percent: usize) -> bool {
        self.below(100) < percent
    }

    pub(super) fn pick<T: Clone>(&mut self, from: &[T]) -> T {
        from[self.below(from.len())].clone()
    }
}

/// Counts and offsets, from small to past any memory.
pub(super) fn number(random: &mut Random) -> Value {
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
pub(super) const DEEP: &str = "\"@deep@\"";

pub(super) fn deep(random: &mut Random) -> String {
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

pub(super) fn elements<'a>(json: &'a mut Value, key: &str) -> Option<&'a mut Vec<Value>> {
    json.get_mut(key)?.as_array_mut().filter(|a| !a.is_empty())
}

/// One element of `json[key]`, picked at random.
pub(super) fn element<'a>(
    json: &'a mut Value,
    key: &str,
    random: &mut Random,
) -> Option<&'a mut Value> {
    let list = elements(json, key)?;
    let at = random.below(list.len());
    list.get_mut(at)
}

pub(super) fn length(json: &Value, key: &str) -> usize {
    json.get(key).and_then(Value::as_array).map_or(0, Vec::len)
}

/// An index into `json[key]`: mostly in range, sometimes just past it or far.
pub(super) fn index(json: &Value, key: &str, random: &mut Random) -> Value {
    let count = length(json, key);
    match random.below(10) {
        0 => json!(count),
        1 => json!(count + 7),
        2 => json!(u32::MAX),
        3 => json!(-1),
        _ => json!(random.below(count.max(1))),
    }
}

pub(super) fn set(target: Option<&mut Value>, key: &str, value: Value) {
    if let Some(Value::Object(object)) = target {
        object.insert(key.to_owned(), value);
    }
}

pub(super) fn remove(target: Option<&mut Value>, key: &str) {
    if let Some(Value::Object(object)) = target {
        object.remove(key);
    }
}

/// The node hierarchy: children added (the node itself, its parent, an
/// ancestor, a node that has a parent already, one out of range, twice),
/// removed, or a long chain or cycle through many new nodes.
pub(super) fn mutate_nodes(json: &mut Value, random: &mut Random) {
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

pub(super) fn mutate_node_fields(json: &mut Value, random: &mut Random) {
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

pub(super) fn mutate_accessor(json: &mut Value, random: &mut Random) {
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

pub(super) fn mutate_view(json: &mut Value, random: &mut Random) {
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

pub(super) fn mutate_buffer(json: &mut Value, random: &mut Random) {
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

pub(super) fn mutate_primitive(json: &mut Value, random: &mut Random) {
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
pub(super) fn mutate_document(json: &mut Value, random: &mut Random) {
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
pub(super) fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
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
pub(super) fn mutate_container(bytes: &mut Vec<u8>, json_length: usize, random: &mut Random) {
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

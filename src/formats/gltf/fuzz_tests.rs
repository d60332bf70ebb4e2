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
use super::fuzz_mutations::*;
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

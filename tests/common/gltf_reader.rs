//! A glTF reader that shares no code with pmvc's writer or reader: the GLB
//! container, base64 and accessors decoded here, so that tests check pmvc's
//! files against the specification rather than against itself. And the Khronos
//! validator's report.

use glam::DVec3;
use serde_json::Value;
use std::path::Path;

/// A glTF file read here: its JSON and its one buffer.
pub struct Gltf {
    pub json: Value,
    pub buffer: Vec<u8>,
}

/// Base64 as RFC 4648 has it, decoded by hand.
fn base64_decode(text: &str) -> Vec<u8> {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = Vec::new();
    let (mut bits, mut held) = (0u32, 0);
    for byte in text.bytes().filter(|&b| b != b'=') {
        let value = ALPHABET.iter().position(|&a| a == byte).expect("base64") as u32;
        bits = (bits << 6) | value;
        held += 6;
        if held >= 8 {
            held -= 8;
            out.push((bits >> held) as u8);
        }
    }
    out
}

pub fn read_gltf(path: &Path) -> Gltf {
    let bytes = std::fs::read(path).unwrap();
    let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    if bytes.starts_with(b"glTF") {
        assert_eq!(u32_at(4), 2, "GLB version");
        assert_eq!(u32_at(8), bytes.len(), "GLB length");
        let json_length = u32_at(12);
        assert_eq!(&bytes[16..20], b"JSON");
        let json = serde_json::from_slice(&bytes[20..20 + json_length]).unwrap();
        let bin = 20 + json_length;
        assert_eq!(&bytes[bin + 4..bin + 8], b"BIN\0");
        let buffer = bytes[bin + 8..bin + 8 + u32_at(bin)].to_vec();
        assert_eq!(bin + 8 + buffer.len(), bytes.len());
        Gltf { json, buffer }
    } else {
        let json: Value = serde_json::from_slice(&bytes).unwrap();
        let uri = json["buffers"][0]["uri"].as_str().unwrap();
        let payload = uri
            .strip_prefix("data:application/octet-stream;base64,")
            .unwrap();
        let buffer = base64_decode(payload);
        Gltf { json, buffer }
    }
}

impl Gltf {
    /// Accessor `index`'s elements as f64 components (float or unsigned int).
    pub fn accessor(&self, index: &Value) -> Vec<Vec<f64>> {
        let accessor = &self.json["accessors"][index.as_u64().unwrap() as usize];
        let view = &self.json["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
        assert_eq!(view["buffer"], 0);
        let width = match accessor["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            other => panic!("type {other}"),
        };
        let float = match accessor["componentType"].as_u64().unwrap() {
            5126 => true,
            5125 => false,
            other => panic!("component type {other}"),
        };
        let stride = view["byteStride"]
            .as_u64()
            .map_or(4 * width, |s| s as usize);
        let start = view["byteOffset"].as_u64().unwrap_or(0) as usize
            + accessor["byteOffset"].as_u64().unwrap_or(0) as usize;
        let count = accessor["count"].as_u64().unwrap() as usize;
        (0..count)
            .map(|i| {
                (0..width)
                    .map(|c| {
                        let at = start + i * stride + 4 * c;
                        let word: [u8; 4] = self.buffer[at..at + 4].try_into().unwrap();
                        if float {
                            f64::from(f32::from_le_bytes(word))
                        } else {
                            f64::from(u32::from_le_bytes(word))
                        }
                    })
                    .collect()
            })
            .collect()
    }

    /// The morph targets' names (`mesh.extras.targetNames` of mesh 0).
    pub fn target_names(&self) -> Vec<&str> {
        self.json["meshes"][0]["extras"]["targetNames"]
            .as_array()
            .expect("targetNames")
            .iter()
            .map(|n| n.as_str().unwrap())
            .collect()
    }

    pub fn translation(&self) -> DVec3 {
        let node = &self.json["nodes"][0];
        assert_eq!(node["mesh"], 0);
        match node["translation"].as_array() {
            Some(t) => DVec3::new(
                t[0].as_f64().unwrap(),
                t[1].as_f64().unwrap(),
                t[2].as_f64().unwrap(),
            ),
            None => DVec3::ZERO,
        }
    }
}

pub fn vec3(c: &[f64]) -> DVec3 {
    DVec3::new(c[0], c[1], c[2])
}

/// The validator's report on `path`, or `None` where node or the package is
/// missing (a failure under `PMVC_REQUIRE_GLTF_VALIDATOR=1`, as `tests/run` sets).
pub fn validator_report(path: &Path) -> Option<Value> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/gltf/validate.mjs");
    let output = std::process::Command::new("node")
        .arg(&script)
        .arg(path)
        .output();
    let required = std::env::var("PMVC_REQUIRE_GLTF_VALIDATOR").as_deref() == Ok("1");
    let missing = match &output {
        Err(error) => format!("node did not run: {error}"),
        Ok(output) if output.status.code() == Some(3) => super::stderr(output),
        Ok(output) => {
            assert!(
                output.status.success(),
                "validator: {}",
                super::stderr(output)
            );
            return Some(serde_json::from_slice(&output.stdout).unwrap());
        }
    };
    assert!(
        !required,
        "PMVC_REQUIRE_GLTF_VALIDATOR=1 but the validator cannot run: {missing} (tests/run installs it)"
    );
    println!("glTF validator not run: {missing}");
    None
}

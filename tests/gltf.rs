//! `pmvc deform --out M.glb|M.gltf` with poses as morph targets and an
//! animation: checked by the Khronos glTF validator, read back by a GLB and
//! glTF reader written here (sharing no code with the writer) against
//! `pmvc deform`'s OBJ output for each pose, and imported again by `load_mesh`.
//! Bad glTF input and misused flags fail with a message naming file and fault.

mod common;
use common::*;
mod cli_support;
use cli_support::obj_vertices;
use glam::DVec3;
use pmvc::geometry::{load_mesh, procedural};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// A face's corners: each one's vertex and texture coordinate (u, v).
type Face = [(u32, [f64; 2]); 3];

/// A sphere in a cube cage, as OBJ with a texture coordinate per corner
/// (latitude and longitude, so the seam and the poles split vertices) and two
/// groups with materials: the faces above the equator, then those below.
struct Scene {
    mesh: PathBuf,
    cage: PathBuf,
    /// Per group, its faces in file order.
    groups: Vec<Vec<Face>>,
}

fn sphere_scene(dir: &Path) -> Scene {
    let sphere = procedural::uv_sphere(0.6, 10, 16);
    let cage = procedural::cube_cage(1.0);
    let positions = sphere.positions();
    let mut groups: Vec<Vec<Face>> = vec![Vec::new(), Vec::new()];
    for triangle in sphere.triangles() {
        let p = triangle.map(|i| positions[i as usize]);
        let mut u = p.map(|p| p.y.atan2(p.x) / std::f64::consts::TAU + 0.5);
        if u.iter().cloned().fold(0.0, f64::max) - u.iter().cloned().fold(1.0, f64::min) > 0.5 {
            u = u.map(|u| if u < 0.5 { u + 1.0 } else { u });
        }
        let v = p.map(|p| 1.0 - (p.z / 0.6).clamp(-1.0, 1.0).acos() / std::f64::consts::PI);
        let corners = [0, 1, 2].map(|k| (triangle[k], [u[k], v[k]]));
        let below = p.iter().map(|p| p.z).sum::<f64>() < 0.0;
        groups[usize::from(below)].push(corners);
    }
    let mut text = points_obj(positions);
    let mut uv_count = 0;
    let mut faces = String::new();
    for (group, name, material) in [(0, "top", "red"), (1, "bottom", "blue")] {
        faces.push_str(&format!("g {name}\nusemtl {material}\n"));
        for corners in &groups[group] {
            faces.push('f');
            for (vertex, [u, v]) in corners {
                text.push_str(&format!("vt {u} {v}\n"));
                uv_count += 1;
                faces.push_str(&format!(" {}/{uv_count}", vertex + 1));
            }
            faces.push('\n');
        }
    }
    text.push_str(&faces);
    Scene {
        mesh: write(dir, "sphere.obj", &text),
        cage: write(dir, "cage.obj", &cage_obj(&cage)),
        groups,
    }
}

/// The cube cage moved: every vertex by `f`.
fn pose(dir: &Path, name: &str, f: impl Fn(DVec3) -> DVec3) -> PathBuf {
    let cage = procedural::cube_cage(1.0);
    let moved: Vec<DVec3> = cage.positions().iter().map(|&p| f(p)).collect();
    write(
        dir,
        &format!("{name}.obj"),
        &triangles_obj(&moved, cage.triangles()),
    )
}

fn deform(scene: &Scene, pose: &Path, out: &Path, extra: &[&str]) {
    let mut args = vec![
        "deform",
        "--mesh",
        path_str(&scene.mesh),
        "--cage",
        path_str(&scene.cage),
        "--deformed-cage",
        path_str(pose),
        "--method",
        "mvc",
        "--backend",
        "cpu",
        "--out",
        path_str(out),
    ];
    args.extend(extra);
    let output = pmvc(&args);
    assert!(output.status.success(), "{}", stderr(&output));
}

/// A glTF file read here: its JSON and its one buffer.
struct Gltf {
    json: Value,
    buffer: Vec<u8>,
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

fn read_gltf(path: &Path) -> Gltf {
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
    fn accessor(&self, index: &Value) -> Vec<Vec<f64>> {
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

    fn translation(&self) -> DVec3 {
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

fn vec3(c: &[f64]) -> DVec3 {
    DVec3::new(c[0], c[1], c[2])
}

/// Every glTF corner against the OBJ outputs: the base plus each target's
/// delta is `pmvc deform` with that pose, its texture coordinate is the OBJ's
/// with v flipped; names, groups and the animation are as asked.
fn check_against_objs(gltf: &Gltf, scene: &Scene, base: &[DVec3], poses: &[(&str, Vec<DVec3>)]) {
    let mesh = &gltf.json["meshes"][0];
    let names: Vec<&str> = mesh["extras"]["targetNames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    let expected: Vec<&str> = poses.iter().map(|(name, _)| *name).collect();
    assert_eq!(names, expected);
    let primitives = mesh["primitives"].as_array().unwrap();
    assert_eq!(
        primitives.len(),
        scene.groups.len(),
        "one primitive per group"
    );
    let group_names: Vec<&Value> = primitives.iter().map(|p| &p["extras"]["name"]).collect();
    assert_eq!(group_names, [&Value::from("top"), &Value::from("bottom")]);
    let materials: Vec<&Value> = primitives
        .iter()
        .map(|p| &gltf.json["materials"][p["material"].as_u64().unwrap() as usize]["name"])
        .collect();
    assert_eq!(materials, [&Value::from("red"), &Value::from("blue")]);
    let (low, high) = base
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), p| {
            (l.min(*p), h.max(*p))
        });
    let tolerance = 1e-6 * (high - low).length();
    let translation = gltf.translation();
    let mut worst = 0.0f64;
    for (primitive, faces) in primitives.iter().zip(&scene.groups) {
        let attributes = &primitive["attributes"];
        let positions = gltf.accessor(&attributes["POSITION"]);
        let uvs = gltf.accessor(&attributes["TEXCOORD_0"]);
        assert_eq!(
            uvs.len(),
            positions.len(),
            "a texture coordinate per vertex"
        );
        let normals = gltf.accessor(&attributes["NORMAL"]);
        assert!(normals
            .iter()
            .all(|n| (vec3(n).length() - 1.0).abs() < 1e-5));
        let targets: Vec<Vec<Vec<f64>>> = primitive["targets"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| gltf.accessor(&t["POSITION"]))
            .collect();
        assert_eq!(targets.len(), poses.len());
        let indices = gltf.accessor(&primitive["indices"]);
        assert_eq!(indices.len(), 3 * faces.len(), "the group's triangles");
        for (face, corners) in faces.iter().enumerate() {
            for (k, &(vertex, [u, v])) in corners.iter().enumerate() {
                let at = indices[3 * face + k][0] as usize;
                let position = translation + vec3(&positions[at]);
                worst = worst.max((position - base[vertex as usize]).length());
                for (target, (_, pose)) in targets.iter().zip(poses) {
                    let moved = position + vec3(&target[at]);
                    worst = worst.max((moved - pose[vertex as usize]).length());
                }
                assert!((uvs[at][0] - u).abs() < 1e-6 && (uvs[at][1] - (1.0 - v)).abs() < 1e-6);
            }
        }
    }
    assert!(worst <= tolerance, "{worst} > {tolerance}");
}

fn check_animation(gltf: &Gltf, seconds: f64, targets: usize) {
    let animation = &gltf.json["animations"][0];
    let channel = &animation["channels"][0];
    assert_eq!(channel["target"]["path"], "weights");
    assert_eq!(channel["target"]["node"], 0);
    let sampler = &animation["samplers"][channel["sampler"].as_u64().unwrap() as usize];
    assert_eq!(sampler["interpolation"], "LINEAR");
    let times: Vec<f64> = gltf
        .accessor(&sampler["input"])
        .iter()
        .map(|t| t[0])
        .collect();
    let expected: Vec<f64> = (0..=targets)
        .map(|k| seconds * k as f64 / targets as f64)
        .collect();
    assert_eq!(times.len(), expected.len());
    assert!(
        times
            .iter()
            .zip(&expected)
            .all(|(a, b)| (a - b).abs() < 1e-6),
        "{times:?}"
    );
    let weights: Vec<f64> = gltf
        .accessor(&sampler["output"])
        .iter()
        .map(|w| w[0])
        .collect();
    for (key, row) in weights.chunks(targets).enumerate() {
        // The base at key 0, then pose k at key k + 1.
        let expected: Vec<f64> = (0..targets).map(|t| f64::from(key == t + 1)).collect();
        assert_eq!(row, expected, "key {key}");
    }
}

/// The validator's report on `path`, or `None` where node or the package is
/// missing (a failure under `PMVC_REQUIRE_GLTF_VALIDATOR=1`, as `tests/run` sets).
fn validator_report(path: &Path) -> Option<Value> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/gltf/validate.mjs");
    let output = std::process::Command::new("node")
        .arg(&script)
        .arg(path)
        .output();
    let required = std::env::var("PMVC_REQUIRE_GLTF_VALIDATOR").as_deref() == Ok("1");
    let missing = match &output {
        Err(error) => format!("node did not run: {error}"),
        Ok(output) if output.status.code() == Some(3) => stderr(output),
        Ok(output) => {
            assert!(output.status.success(), "validator: {}", stderr(output));
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

#[test]
fn poses_become_named_morph_targets_that_match_deform_and_pass_the_validator() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let scene = sphere_scene(dir);
    let base_cage = pose(dir, "base", |p| p + DVec3::new(0.1 * p.z, 0.0, 0.0));
    let poses = [
        pose(dir, "stretch", |p| {
            if p.x > 0.0 {
                p * DVec3::new(1.4, 1.0, 1.0)
            } else {
                p
            }
        }),
        pose(
            dir,
            "lift",
            |p| if p.z > 0.0 { p + DVec3::Z * 0.5 } else { p },
        ),
        pose(dir, "twist", |p| {
            let angle = if p.z > 0.0 { 0.4f64 } else { 0.0 };
            DVec3::new(
                p.x * angle.cos() - p.y * angle.sin(),
                p.x * angle.sin() + p.y * angle.cos(),
                p.z,
            )
        }),
    ];
    let base_obj = dir.join("base_out.obj");
    deform(&scene, &base_cage, &base_obj, &[]);
    let base = obj_vertices(&base_obj);
    let expected: Vec<(&str, Vec<DVec3>)> = poses
        .iter()
        .map(|path| {
            let out = dir.join("out.obj");
            deform(&scene, path, &out, &[]);
            let name = path.file_stem().unwrap().to_str().unwrap();
            (name, obj_vertices(&out))
        })
        .collect();
    let mut extra = vec!["--poses"];
    extra.extend(poses.iter().map(|p| path_str(p)));
    extra.extend(["--animate", "2.5"]);
    for name in ["sphere.glb", "sphere.gltf"] {
        let out = dir.join(name);
        deform(&scene, &base_cage, &out, &extra);
        let gltf = read_gltf(&out);
        check_against_objs(&gltf, &scene, &base, &expected);
        check_animation(&gltf, 2.5, poses.len());
        if let Some(report) = validator_report(&out) {
            let issues = &report["issues"];
            assert_eq!(issues["numErrors"], 0, "{name}: {report:#}");
            assert_eq!(issues["numWarnings"], 0, "{name}: {report:#}");
            assert_eq!(report["info"]["animationCount"], 1);
            assert_eq!(report["info"]["hasMorphTargets"], true);
            println!(
                "{name}: validator: {} errors, {} warnings, {} infos, {} hints",
                issues["numErrors"], issues["numWarnings"], issues["numInfos"], issues["numHints"]
            );
        }
    }
}

#[test]
fn a_written_gltf_imports_again_with_its_positions_and_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    // Without texture coordinates or groups, vertices keep their order.
    let sphere = procedural::uv_sphere(0.6, 8, 12);
    let cage = procedural::cube_cage(1.0);
    let mesh = write(
        dir,
        "plain.obj",
        &triangles_obj(sphere.positions(), sphere.triangles()),
    );
    let scene = Scene {
        mesh,
        cage: write(dir, "cage.obj", &cage_obj(&cage)),
        groups: Vec::new(),
    };
    let posed = pose(dir, "posed", |p| p * DVec3::new(1.2, 0.9, 1.0));
    let (obj, glb) = (dir.join("moved.obj"), dir.join("moved.glb"));
    deform(&scene, &posed, &obj, &[]);
    deform(&scene, &posed, &glb, &[]);
    let expected = load_mesh(&obj).unwrap();
    let read = load_mesh(&glb).unwrap();
    assert_eq!(read.mesh.triangles, expected.mesh.triangles);
    assert_eq!(read.mesh.positions.len(), expected.mesh.positions.len());
    for (a, b) in read.mesh.positions.iter().zip(&expected.mesh.positions) {
        assert!((*a - *b).length() < 1e-6, "{a} vs {b}");
    }
    // With seams and groups: the same surface, corner by corner, and a glTF
    // mesh deforms like any other.
    let scene = sphere_scene(dir);
    let (obj, gltf) = (dir.join("s.obj"), dir.join("s.gltf"));
    deform(&scene, &posed, &obj, &[]);
    deform(&scene, &posed, &gltf, &[]);
    let expected = load_mesh(&obj).unwrap();
    let read = load_mesh(&gltf).unwrap();
    assert_eq!(read.mesh.triangles.len(), expected.mesh.triangles.len());
    for (a, b) in read.mesh.triangles.iter().zip(&expected.mesh.triangles) {
        for (i, j) in a.iter().zip(b) {
            let (p, q) = (
                read.mesh.positions[*i as usize],
                expected.mesh.positions[*j as usize],
            );
            assert!((p - q).length() < 1e-6, "{p} vs {q}");
        }
    }
    let again = Scene {
        mesh: gltf.clone(),
        cage: scene.cage.clone(),
        groups: Vec::new(),
    };
    deform(&again, &scene.cage, &dir.join("again.obj"), &[]);
    let text = std::fs::read_to_string(dir.join("again.obj")).unwrap();
    assert!(
        text.contains("g top\nusemtl red\n") && text.contains("\nvt "),
        "groups and texture kept"
    );
}

#[test]
fn bad_gltf_input_and_misused_flags_fail_naming_the_file_and_the_fault() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let scene = sphere_scene(dir);
    let glb = dir.join("whole.glb");
    deform(&scene, &scene.cage, &glb, &[]);
    let run = |mesh: &Path, extra: &[&str], out: &str| {
        let mut args = vec![
            "deform",
            "--mesh",
            path_str(mesh),
            "--cage",
            path_str(&scene.cage),
            "--deformed-cage",
            path_str(&scene.cage),
            "--method",
            "mvc",
            "--backend",
            "cpu",
            "--out",
        ];
        let out = dir.join(out);
        args.push(path_str(&out));
        args.extend(extra);
        pmvc(&args)
    };
    // A truncated .glb.
    let bytes = std::fs::read(&glb).unwrap();
    let truncated = dir.join("truncated.glb");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let output = run(&truncated, &[], "t.obj");
    assert_clean_failure(&output, "truncated.glb", "the binary glTF is truncated");
    // An accessor index past the accessors.
    let json = dir.join("bad-index.gltf");
    let gltf = dir.join("whole.gltf");
    deform(&scene, &scene.cage, &gltf, &[]);
    let mut document: Value = serde_json::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
    document["meshes"][0]["primitives"][0]["indices"] = Value::from(999);
    std::fs::write(&json, serde_json::to_vec(&document).unwrap()).unwrap();
    let output = run(&json, &[], "j.obj");
    assert_clean_failure(
        &output,
        "bad-index.gltf",
        "meshes[0].primitives[0].indices: index out of bounds",
    );
    // A pose with another vertex count.
    let wrong = write(dir, "wrong.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let output = run(&scene.mesh, &["--poses", path_str(&wrong)], "p.glb");
    assert_clean_failure(&output, "wrong.obj", "has 3 vertices, but the cage");
    assert!(!dir.join("p.glb").exists());
    // --animate and --poses want glTF output.
    let output = run(
        &scene.mesh,
        &["--poses", path_str(&scene.cage), "--animate", "2"],
        "a.obj",
    );
    assert_clean_failure(&output, "a.obj", "--animate needs glTF output");
    let output = run(&scene.mesh, &["--poses", path_str(&scene.cage)], "a.obj");
    assert_clean_failure(&output, "a.obj", "--poses needs glTF output");
    let output = run(&scene.mesh, &["--animate", "2"], "a.glb");
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    assert!(stderr(&output).contains("--poses"), "{}", stderr(&output));
    let output = run(
        &scene.mesh,
        &["--poses", path_str(&scene.cage), "--animate", "0"],
        "a.glb",
    );
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    assert!(stderr(&output).contains("above 0"), "{}", stderr(&output));
}

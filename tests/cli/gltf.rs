//! `pmvc deform --out M.glb|M.gltf` with poses as morph targets and an
//! animation: checked by the Khronos glTF validator, read back by a GLB and
//! glTF reader written here (sharing no code with the writer) against
//! `pmvc deform`'s OBJ output for each pose, and imported again by `load_mesh`.
//! Bad glTF input and misused flags fail with a message naming file and fault.

use crate::cli_support;
use crate::common;
use cli_support::obj_vertices;
use common::gltf_reader::*;
use common::*;
use glam::DVec3;
use pmvc::formats::load_mesh;
use pmvc::geometry::procedural;
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

/// Every glTF corner against the OBJ outputs: the base plus each target's
/// delta is `pmvc deform` with that pose, its texture coordinate is the OBJ's
/// with v flipped; names, groups and the animation are as asked.
fn check_against_objs(gltf: &Gltf, scene: &Scene, base: &[DVec3], poses: &[(&str, Vec<DVec3>)]) {
    let mesh = &gltf.json["meshes"][0];
    let expected: Vec<&str> = poses.iter().map(|(name, _)| *name).collect();
    assert_eq!(gltf.target_names(), expected);
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

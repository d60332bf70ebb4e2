//! Helpers shared by the integration tests: writing scenes to files and running the binary.
#![allow(dead_code)]

#[cfg(feature = "ui-tests")]
pub mod editor;
pub mod gltf_reader;
#[allow(dead_code)]
pub mod measure;
#[allow(dead_code)]
pub mod shapes;

use pmvc::geometry::{procedural, Cage};
use std::path::{Path, PathBuf};
use std::process::Output;

pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

pub fn cage_obj(cage: &Cage) -> String {
    triangles_obj(cage.positions(), cage.triangles())
}

/// OBJ text with every coordinate written to round-trip f64 exactly, so that a
/// test reads back the geometry it made.
pub fn triangles_obj(positions: &[glam::DVec3], triangles: &[[u32; 3]]) -> String {
    let mut text = points_obj(positions);
    for [a, b, c] in triangles {
        text.push_str(&format!("f {} {} {}\n", a + 1, b + 1, c + 1));
    }
    text
}

pub fn points_obj(points: &[glam::DVec3]) -> String {
    points
        .iter()
        .map(|p| format!("v {} {} {}\n", p.x, p.y, p.z))
        .collect()
}

/// `points` as a mesh, `cage` and its pose `posed` (the cage's positions moved),
/// written to `dir` as mesh.obj, cage.obj and pose.obj.
pub fn posed_scene_files(
    dir: &Path,
    cage: &Cage,
    points: &[glam::DVec3],
    posed: &[glam::DVec3],
) -> (PathBuf, PathBuf, PathBuf) {
    (
        write(dir, "mesh.obj", &points_obj(points)),
        write(dir, "cage.obj", &cage_obj(cage)),
        write(dir, "pose.obj", &triangles_obj(posed, cage.triangles())),
    )
}

/// A comb cage and points inside it, written to `dir` as cage.obj and mesh.obj.
pub fn comb_scene(dir: &Path, points: usize) -> (PathBuf, PathBuf, Cage, Vec<glam::DVec3>) {
    let cage = procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5);
    let inside = procedural::points_inside(&cage, points, 5, 1e-3);
    let mesh = write(dir, "mesh.obj", &points_obj(&inside));
    let cage_path = write(dir, "cage.obj", &cage_obj(&cage));
    (mesh, cage_path, cage, inside)
}

#[cfg(feature = "editor")]
pub fn pmvc(args: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_pmvc"))
        .args(args)
        .output()
        .expect("run pmvc")
}

/// `pmvc bind --mesh mesh --cage cage --out out --backend cpu`, then `extra`.
#[cfg(feature = "editor")]
pub fn bind_on_cpu(mesh: &Path, cage: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["--backend", "cpu"];
    args.extend(extra);
    bind_with(mesh, cage, out, &args)
}

/// `pmvc bind --mesh mesh --cage cage --out out`, then `extra`.
#[cfg(feature = "editor")]
pub fn bind_with(mesh: &Path, cage: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "bind",
        "--mesh",
        path_str(mesh),
        "--cage",
        path_str(cage),
        "--out",
        path_str(out),
    ];
    args.extend(extra);
    pmvc(&args)
}

/// `pmvc deform --mesh mesh --cage cage --deformed-cage pose`, then `extra`,
/// then `--out out`.
#[cfg(feature = "editor")]
pub fn deform_with(mesh: &Path, cage: &Path, pose: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "deform",
        "--mesh",
        path_str(mesh),
        "--cage",
        path_str(cage),
        "--deformed-cage",
        path_str(pose),
    ];
    args.extend(extra);
    args.extend(["--out", path_str(out)]);
    pmvc(&args)
}

/// `pmvc deform` of `mesh` in `cage` to `pose` with stored `weights`, into `out`.
#[cfg(feature = "editor")]
pub fn deform_with_weights(
    mesh: &Path,
    cage: &Path,
    pose: &Path,
    weights: &Path,
    out: &Path,
) -> Output {
    deform_with(mesh, cage, pose, out, &["--weights", path_str(weights)])
}

pub fn path_str(path: &Path) -> &str {
    path.to_str().unwrap()
}

pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// The command failed cleanly: exit status 1, no panic, and an error line naming `file`.
pub fn assert_clean_failure(output: &Output, file: &str, what: &str) {
    let text = stderr(output);
    assert_eq!(
        output.status.code(),
        Some(1),
        "expected exit 1, stderr: {text}"
    );
    assert!(!text.contains("panicked"), "panic: {text}");
    let error_lines: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("pmvc: error:"))
        .collect();
    assert_eq!(error_lines.len(), 1, "expected one error line: {text}");
    assert!(
        error_lines[0].contains(file),
        "error should name {file}: {text}"
    );
    assert!(
        error_lines[0].contains(what),
        "error should say '{what}': {text}"
    );
}

/// Whether a `--backend gpu` command found an adapter. Without one it must have
/// failed cleanly, naming the adapter, and that fails the test under
/// `PMVC_REQUIRE_GPU=1` (CI, on lavapipe); elsewhere the caller skips its GPU part.
pub fn ran_on_gpu(output: &Output) -> bool {
    if output.status.success() {
        return true;
    }
    assert!(
        std::env::var("PMVC_REQUIRE_GPU").as_deref() != Ok("1"),
        "no GPU adapter: {}",
        stderr(output)
    );
    assert_clean_failure(output, "--backend gpu", "adapter");
    println!("GPU part not run: no adapter");
    false
}

/// A version 1.0 `.npy` of little-endian float32, parsed by hand (independent of
/// the library's reader): its shape, values and header text.
pub fn parse_npy_f32(bytes: &[u8]) -> (Vec<usize>, Vec<f32>, String) {
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00", "npy format version 1.0");
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = String::from_utf8(bytes[10..10 + header_len].to_vec()).unwrap();
    let shape_text = header
        .split("'shape': (")
        .nth(1)
        .unwrap()
        .split(')')
        .next()
        .unwrap();
    let shape: Vec<usize> = shape_text
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse().unwrap())
        .collect();
    let values = bytes[10 + header_len..]
        .chunks(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    (shape, values, header)
}

/// Generalised winding number of `x` with respect to a triangle soup, as the sum
/// of the triangles' signed solid angles (van Oosterom & Strackee 1983) over 4π,
/// every vector taken from `x`: an independent reference for the library's own.
pub fn winding_number(positions: &[glam::DVec3], triangles: &[[u32; 3]], x: glam::DVec3) -> f64 {
    let total: f64 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize] - x);
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let numerator = a.dot(b.cross(c));
            let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
            2.0 * numerator.atan2(denominator)
        })
        .sum();
    total / (4.0 * std::f64::consts::PI)
}

#[cfg(feature = "editor")]
/// A valid session of the bundled comb at rest, with every key a session may hold.
pub fn comb_session() -> serde_json::Value {
    let (_, cage) = pmvc::app::scenes::BundledScene::Comb
        .build()
        .expect("the comb builds");
    let pose: Vec<[f64; 3]> = cage.positions().iter().map(|p| p.to_array()).collect();
    serde_json::json!({
        "pmvc_session": 1,
        "title": "comb",
        "mesh": {"bundled": "comb"},
        "cage": {"bundled": "comb"},
        "pose": pose,
        "named_poses": [{"name": "rest", "positions": pose}],
        "method": "pmvc",
        "parameters": {"resolution": 16, "grid": 32},
        "view": {"handle_size": 4.0, "heat_vertex": 2},
        "cameras": [{"target": [0.0, 0.5, 0.0], "distance": 6.0, "yaw": 0.3, "pitch": 0.2}],
    })
}

/// xorshift64*: a seeded generator for the fuzz tests, deterministic so that a
/// failure names a reproducible case, and with no dependency.
pub struct Random(pub u64);

impl Random {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// A torus around z: major radius 1, tube radius 0.35, 48 × 20 quads split in
/// two, outward-facing.
pub fn torus_mesh() -> pmvc::geometry::TriMesh {
    use glam::DVec3;
    use std::f64::consts::PI;
    let (around, tube) = (48u32, 20u32);
    let mut positions = Vec::new();
    for i in 0..around {
        for j in 0..tube {
            let (u, v) = (
                2.0 * PI * f64::from(i) / f64::from(around),
                2.0 * PI * f64::from(j) / f64::from(tube),
            );
            let r = 1.0 + 0.35 * v.cos();
            positions.push(DVec3::new(r * u.cos(), r * u.sin(), 0.35 * v.sin()));
        }
    }
    let at = |i: u32, j: u32| (i % around) * tube + j % tube;
    let mut triangles = Vec::new();
    for i in 0..around {
        for j in 0..tube {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            triangles.extend([[a, b, c], [a, c, d]]);
        }
    }
    let volume: f64 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            a.dot(b.cross(c))
        })
        .sum();
    if volume < 0.0 {
        triangles.iter_mut().for_each(|t| t.swap(1, 2));
    }
    pmvc::geometry::TriMesh {
        positions,
        triangles,
        triangle_faces: Vec::new(),
    }
}

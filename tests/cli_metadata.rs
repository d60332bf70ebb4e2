//! What the command line tells a reader of its numbers: the metadata and class
//! mask `pmvc bind` writes beside the weights and `pmvc deform --weights` checks,
//! `.npy` point sets as input and output, the warning for a deformed cage that
//! crosses itself, and outside-vertex warnings in each family's own words.
#![cfg(feature = "editor")]

mod common;
use common::*;
use glam::DVec3;
use pmvc::coords::Method;
use pmvc::geometry::{procedural, Cage};
use std::path::{Path, PathBuf};

/// A version 1.0 `.npy` with this dtype, shape and raw little-endian values,
/// written by hand as NumPy's `np.save` writes it.
fn npy_bytes(descr: &str, shape: &[usize], fortran: bool, values: &[u8]) -> Vec<u8> {
    let shape_text = match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let order = if fortran { "True" } else { "False" };
    let mut header =
        format!("{{'descr': '{descr}', 'fortran_order': {order}, 'shape': {shape_text}, }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
    bytes.extend_from_slice(header.as_bytes());
    bytes.extend_from_slice(values);
    bytes
}

fn f64_points_npy(points: &[DVec3]) -> Vec<u8> {
    let values: Vec<u8> = points
        .iter()
        .flat_map(|p| p.to_array())
        .flat_map(f64::to_le_bytes)
        .collect();
    npy_bytes("<f8", &[points.len(), 3], false, &values)
}

fn f32_points_npy(points: &[DVec3]) -> Vec<u8> {
    let values: Vec<u8> = points
        .iter()
        .flat_map(|p| p.to_array())
        .flat_map(|v| (v as f32).to_le_bytes())
        .collect();
    npy_bytes("<f4", &[points.len(), 3], false, &values)
}

/// `(n, 3)` float64 points from a `.npy`, parsed by hand.
fn read_points_f64(path: &Path) -> Vec<DVec3> {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
    assert!(header.contains("'descr': '<f8'"), "{header}");
    assert!(header.contains("'fortran_order': False"), "{header}");
    let values: Vec<f64> = bytes[10 + header_len..]
        .chunks(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let rows = values.len() / 3;
    assert!(
        header.contains(&format!("'shape': ({rows}, 3)")),
        "{header}"
    );
    values
        .chunks(3)
        .map(|v| DVec3::new(v[0], v[1], v[2]))
        .collect()
}

/// The `v` lines of an OBJ file.
fn obj_vertices(path: &Path) -> Vec<DVec3> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter_map(|line| line.strip_prefix("v "))
        .map(|rest| {
            let v: Vec<f64> = rest
                .split_whitespace()
                .map(|t| t.parse().unwrap())
                .collect();
            DVec3::new(v[0], v[1], v[2])
        })
        .collect()
}

fn bind(
    mesh: &Path,
    cage: &Path,
    method: &str,
    out: &Path,
    extra: &[&str],
) -> std::process::Output {
    let mut args = vec![
        "bind",
        "--mesh",
        path_str(mesh),
        "--cage",
        path_str(cage),
        "--method",
        method,
        "--backend",
        "cpu",
        "--out",
        path_str(out),
    ];
    args.extend_from_slice(extra);
    pmvc(&args)
}

fn deform(
    mesh: &Path,
    cage: &Path,
    pose: &Path,
    out: &Path,
    extra: &[&str],
) -> std::process::Output {
    let mut args = vec![
        "deform",
        "--mesh",
        path_str(mesh),
        "--cage",
        path_str(cage),
        "--deformed-cage",
        path_str(pose),
        "--backend",
        "cpu",
        "--out",
        path_str(out),
    ];
    args.extend_from_slice(extra);
    pmvc(&args)
}

/// The comb of `comb_scene` with its second tooth's tip moved `shift` along x.
fn comb_pose(cage: &Cage, shift: f64) -> Vec<DVec3> {
    cage.positions()
        .iter()
        .map(|&p| {
            let second_tooth = (1.25..=2.25).contains(&p.x) && p.y > 3.9;
            if second_tooth {
                p + DVec3::new(shift, 0.0, 0.0)
            } else {
                p
            }
        })
        .collect()
}

#[test]
fn npy_point_sets_bind_and_deform_as_their_obj_does() {
    let dir = tempfile::tempdir().unwrap();
    let (_, cage_path, cage, points) = comb_scene(dir.path(), 150);
    let pose = write(
        dir.path(),
        "pose.obj",
        &triangles_obj(&comb_pose(&cage, 0.2), cage.triangles()),
    );
    // f32 input: the OBJ holds the same values, rounded to f32.
    let rounded: Vec<DVec3> = points.iter().map(|p| p.as_vec3().as_dvec3()).collect();
    for (name, npy, obj_points) in [
        ("f64", f64_points_npy(&points), points.clone()),
        ("f32", f32_points_npy(&points), rounded),
    ] {
        let npy_path = dir.path().join(format!("points-{name}.npy"));
        std::fs::write(&npy_path, npy).unwrap();
        let obj_path = write(
            dir.path(),
            &format!("points-{name}.obj"),
            &points_obj(&obj_points),
        );
        for method in ["pmvc", "green"] {
            let extension = if method == "green" { "npz" } else { "npy" };
            let from_npy = dir.path().join(format!("{name}-{method}-npy.{extension}"));
            let from_obj = dir.path().join(format!("{name}-{method}-obj.{extension}"));
            for (mesh, out) in [(&npy_path, &from_npy), (&obj_path, &from_obj)] {
                let output = bind(mesh, &cage_path, method, out, &["--resolution", "8"]);
                assert!(
                    output.status.success(),
                    "{name} {method}: {}",
                    stderr(&output)
                );
            }
            assert_eq!(
                std::fs::read(&from_npy).unwrap(),
                std::fs::read(&from_obj).unwrap(),
                "{name} {method}: weights from the .npy and the OBJ differ"
            );
        }
        let deformed_npy = dir.path().join(format!("{name}-deformed-npy.obj"));
        let deformed_obj = dir.path().join(format!("{name}-deformed-obj.obj"));
        for (mesh, out) in [(&npy_path, &deformed_npy), (&obj_path, &deformed_obj)] {
            let output = deform(mesh, &cage_path, &pose, out, &["--method", "mvc"]);
            assert!(output.status.success(), "{name}: {}", stderr(&output));
        }
        assert_eq!(
            obj_vertices(&deformed_npy),
            obj_vertices(&deformed_obj),
            "{name}"
        );
    }
    let output = pmvc(&[
        "check",
        "--mesh",
        path_str(&dir.path().join("points-f64.npy")),
        "--cage",
        path_str(&cage_path),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(
        text.contains("150 vertices, 0 triangles (a point set)"),
        "{text}"
    );
}

#[test]
fn bad_npy_point_files_say_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let (_, cage_path, _, points) = comb_scene(dir.path(), 4);
    let f64_values = |points: &[DVec3]| -> Vec<u8> {
        points
            .iter()
            .flat_map(|p| p.to_array())
            .flat_map(f64::to_le_bytes)
            .collect()
    };
    let mut with_nan = points.clone();
    with_nan[2].y = f64::NAN;
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "ints.npy",
            npy_bytes("<i4", &[4, 3], false, &[0; 48]),
            "dtype '<i4'",
        ),
        (
            "flat.npy",
            npy_bytes("<f8", &[12], false, &f64_values(&points)),
            "shape (12,)",
        ),
        (
            "pairs.npy",
            npy_bytes("<f8", &[6, 2], false, &f64_values(&points)),
            "shape (6, 2)",
        ),
        (
            "fortran.npy",
            npy_bytes("<f8", &[4, 3], true, &f64_values(&points)),
            "C (row-major) order",
        ),
        (
            "short.npy",
            npy_bytes("<f8", &[5, 3], false, &f64_values(&points)),
            "truncated",
        ),
        (
            "nan.npy",
            npy_bytes("<f8", &[4, 3], false, &f64_values(&with_nan)),
            "row 3",
        ),
        ("text.npy", b"v 0 0 0\n".to_vec(), "not a .npy file"),
    ];
    for (name, bytes, what) in cases {
        let mesh = dir.path().join(name);
        std::fs::write(&mesh, bytes).unwrap();
        let output = bind(&mesh, &cage_path, "mvc", &dir.path().join("w.npy"), &[]);
        assert_clean_failure(&output, name, what);
    }
}

#[test]
fn deform_writes_float64_points_to_an_npy_output() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, points) = comb_scene(dir.path(), 60);
    let pose = write(
        dir.path(),
        "pose.obj",
        &triangles_obj(&comb_pose(&cage, 0.2), cage.triangles()),
    );
    let as_obj = dir.path().join("deformed.obj");
    let as_npy = dir.path().join("deformed.npy");
    for out in [&as_obj, &as_npy] {
        let output = deform(&mesh, &cage_path, &pose, out, &["--method", "mvc"]);
        assert!(output.status.success(), "{}", stderr(&output));
        assert!(!stderr(&output).contains("warning"), "{}", stderr(&output));
    }
    let deformed = read_points_f64(&as_npy);
    assert_eq!(deformed.len(), points.len());
    // The OBJ's coordinates round-trip f64, so the two hold the same numbers.
    assert_eq!(deformed, obj_vertices(&as_obj));
}

#[test]
fn deform_warns_when_the_deformed_cage_crosses_itself() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, _) = comb_scene(dir.path(), 60);
    let crossed = write(
        dir.path(),
        "crossed.obj",
        &triangles_obj(&comb_pose(&cage, 1.6), cage.triangles()),
    );
    // `pmvc check` refuses the pose as a cage, naming the faces that cross.
    let check = pmvc(&[
        "check",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&crossed),
    ]);
    let refusal = stderr(&check);
    assert_eq!(check.status.code(), Some(1), "{refusal}");
    let faces = refusal
        .split("crosses itself: ")
        .nth(1)
        .and_then(|rest| rest.split(" intersect").next())
        .unwrap_or_else(|| panic!("no crossing named: {refusal}"))
        .to_owned();
    assert!(faces.starts_with("faces "), "{faces}");
    let out = dir.path().join("deformed.obj");
    let output = deform(&mesh, &cage_path, &crossed, &out, &["--method", "mvc"]);
    let text = stderr(&output);
    assert!(output.status.success(), "it warns, never refuses: {text}");
    assert!(out.exists());
    let warnings: Vec<&str> = text
        .lines()
        .filter(|l| l.contains("crosses itself"))
        .collect();
    assert_eq!(warnings.len(), 1, "{text}");
    assert!(warnings[0].contains("warning"), "{text}");
    assert!(warnings[0].contains("crossed.obj"), "{text}");
    assert!(warnings[0].contains(&faces), "expected {faces}: {text}");

    // A pose that moves the same tooth less does not cross: no warning.
    let leaning = write(
        dir.path(),
        "leaning.obj",
        &triangles_obj(&comb_pose(&cage, 0.2), cage.triangles()),
    );
    let output = deform(&mesh, &cage_path, &leaning, &out, &["--method", "mvc"]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(
        !stderr(&output).contains("crosses itself"),
        "{}",
        stderr(&output)
    );
}

/// Points in the comb and two beyond its surface.
fn partly_outside(dir: &Path) -> (PathBuf, PathBuf, Cage, Vec<DVec3>) {
    let (_, cage_path, cage, mut points) = comb_scene(dir, 30);
    points.push(DVec3::new(1.125, 2.5, 0.0)); // in the gap between two teeth
    points.push(DVec3::new(2.0, -3.0, 4.0));
    let mesh = write(dir, "outside.obj", &points_obj(&points));
    (mesh, cage_path, cage, points)
}

#[test]
fn outside_warnings_state_the_familys_own_policy() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, _) = partly_outside(dir.path());
    let pose = write(
        dir.path(),
        "pose.obj",
        &triangles_obj(&comb_pose(&cage, 0.2), cage.triangles()),
    );
    let green = dir.path().join("w.npz");
    let output = bind(&mesh, &cage_path, "green", &green, &[]);
    assert!(output.status.success(), "{}", stderr(&output));
    let policy = Method::Green.spec().outside_policy;
    assert!(stderr(&output).contains(policy), "{}", stderr(&output));
    // Stored Green coordinates, with --method left at its default.
    let out = dir.path().join("deformed.obj");
    let path = path_str(&green);
    let output = deform(&mesh, &cage_path, &pose, &out, &["--weights", path]);
    let text = stderr(&output);
    assert!(output.status.success(), "{text}");
    assert!(!text.contains("MVC weights"), "{text}");
    assert!(text.contains(policy), "{text}");
    for method in [Method::Mvc, Method::Pmvc, Method::Harmonic] {
        let output = deform(&mesh, &cage_path, &pose, &out, &["--method", method.id()]);
        let text = stderr(&output);
        assert!(output.status.success(), "{text}");
        assert!(
            text.contains(method.spec().outside_policy),
            "{method:?}: {text}"
        );
    }
}

//! `.npy` point sets on the command line: read wherever a mesh is (f32 and
//! f64, equal to the same points as OBJ), refused with the reason when
//! malformed, and written as float64 by `pmvc deform --out X.npy`; the warning
//! for a deformed cage that crosses itself; outside-vertex warnings in each
//! family's own words.

use crate::cli_support;
use crate::common;
use cli_support::*;
use common::*;
use glam::DVec3;
use pmvc::coords::Method;

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

#[test]
fn mutated_npy_point_sets_load_or_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let points: Vec<DVec3> = (0..9)
        .map(|i| DVec3::new(i as f64, 0.5 * i as f64, -0.25))
        .collect();
    let path = dir.path().join("mutated.npy");
    for valid in [f64_points_npy(&points), f32_points_npy(&points)] {
        std::fs::write(&path, valid).unwrap();
        assert_eq!(
            pmvc::formats::load_mesh(&path).unwrap().mesh.positions,
            points
        );
    }
    let mut random = Random(0x5eed_0f90_1700);
    let mut loaded = 0;
    for (case, valid) in [f64_points_npy(&points), f32_points_npy(&points)]
        .iter()
        .cycle()
        .take(600)
        .enumerate()
    {
        let mut bytes = valid.clone();
        for _ in 0..1 + random.below(4) {
            match random.below(3) {
                0 if !bytes.is_empty() => {
                    let at = random.below(bytes.len());
                    bytes[at] = random.next() as u8;
                }
                1 => bytes.truncate(random.below(bytes.len() + 1)),
                _ => bytes.extend((0..random.below(30)).map(|_| random.next() as u8)),
            }
        }
        std::fs::write(&path, &bytes).unwrap();
        match pmvc::formats::load_mesh(&path) {
            Ok(file) => {
                loaded += 1;
                assert!(
                    file.mesh.positions.iter().all(|p| p.is_finite()),
                    "case {case}"
                );
                assert!(file.mesh.triangles.is_empty(), "case {case}");
            }
            Err(error) => {
                let message = error.to_string();
                assert!(message.contains("mutated.npy"), "case {case}: {message}");
                assert!(!message.contains('\n'), "case {case}: {message}");
            }
        }
    }
    // Changed values and padding still read: the reader is not refusing everything.
    assert!(loaded > 0, "no mutated file loaded");
}

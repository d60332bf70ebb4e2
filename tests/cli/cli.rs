//! The command line end to end: the .npy format, deforming with and without stored
//! weights, `check`, and the shared evaluation data when it is present.

use crate::common;
use common::*;
use pmvc::coords::{bind_cpu, BindOptions, BindProgress, Method};
use pmvc::formats::load_mesh;
use pmvc::geometry::classify_points;
use std::path::Path;

fn read_npy_f32(path: &Path) -> (Vec<usize>, Vec<f32>, String) {
    parse_npy_f32(&std::fs::read(path).unwrap())
}

#[test]
fn bind_writes_little_endian_f32_rows_in_file_order() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, points) = comb_scene(dir.path(), 200);
    for (method, name) in [(Method::Pmvc, "pmvc"), (Method::Mvc, "mvc")] {
        let out = dir.path().join(format!("{name}.npy"));
        let output = pmvc(&[
            "bind",
            "--mesh",
            path_str(&mesh),
            "--cage",
            path_str(&cage_path),
            "--method",
            name,
            "--backend",
            "cpu",
            "--out",
            path_str(&out),
        ]);
        assert!(output.status.success(), "{}", stderr(&output));
        let (shape, values, header) = read_npy_f32(&out);
        assert!(
            header.contains("'descr': '<f4'") && header.contains("'fortran_order': False"),
            "{header}"
        );
        assert_eq!(shape, vec![points.len(), cage.vertex_count()]);
        let classes = classify_points(&cage, &points);
        let expected = bind_cpu(
            &points,
            &classes.classes,
            &cage,
            BindOptions {
                method,
                resolution: 32,
                ..Default::default()
            },
            &BindProgress::default(),
        )
        .unwrap();
        assert_eq!(
            values, expected.values,
            "{name}: CLI and library weights differ"
        );
    }
}

#[test]
fn every_backend_binds_and_agrees() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = comb_scene(dir.path(), 40);
    let bind = |backend: &str| {
        let out = dir.path().join(format!("{backend}.npy"));
        let output = pmvc(&[
            "bind",
            "--mesh",
            path_str(&mesh),
            "--cage",
            path_str(&cage),
            "--backend",
            backend,
            "--out",
            path_str(&out),
        ]);
        (output, out)
    };
    let (output, cpu) = bind("cpu");
    assert!(output.status.success(), "{}", stderr(&output));
    let (output, auto) = bind("auto");
    assert!(output.status.success(), "{}", stderr(&output));
    let (cpu_values, auto_values) = (read_npy_f32(&cpu).1, read_npy_f32(&auto).1);
    let (output, gpu) = bind("gpu");
    if !ran_on_gpu(&output) {
        return;
    }
    let gpu_values = read_npy_f32(&gpu).1;
    for values in [&auto_values, &gpu_values] {
        let worst = cpu_values
            .iter()
            .zip(values)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        assert!(worst <= 2e-4, "backends disagree by {worst}");
    }
}

#[test]
fn deform_keeps_faces_texture_coordinates_and_groups_and_recomputes_normals() {
    let dir = tempfile::tempdir().unwrap();
    let cage_text = cage_obj(&pmvc::geometry::procedural::cube_cage(1.0));
    let cage = write(dir.path(), "cage.obj", &cage_text);
    let mesh_text = "# a tile\nmtllib tile.mtl\no tile\nv -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nusemtl stone\nf 1/1/1 2/2/1 3/3/1\ng back\nf 3//1 2//1 1//1\n";
    let mesh = write(dir.path(), "tile.obj", mesh_text);
    // Stretch the cage by 2 along x: an affine map, reproduced exactly by both methods.
    let pose_text: String = cage_text
        .lines()
        .map(|line| match line.strip_prefix("v ") {
            Some(rest) => {
                let c: Vec<f64> = rest
                    .split_whitespace()
                    .map(|t| t.parse().unwrap())
                    .collect();
                format!("v {} {} {}\n", 2.0 * c[0], c[1], c[2])
            }
            None => format!("{line}\n"),
        })
        .collect();
    let pose = write(dir.path(), "pose.obj", &pose_text);
    let out = dir.path().join("out.obj");
    let output = deform_with(&mesh, &cage, &pose, &out, &[]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = std::fs::read_to_string(&out).unwrap();
    for kept in [
        "# a tile",
        "mtllib tile.mtl",
        "o tile",
        "vt 1 1",
        "usemtl stone",
        "f 1/1/1 2/2/2 3/3/3",
        "g back",
        "f 3//3 2//2 1//1",
        "vn 0 0 1",
    ] {
        assert!(
            text.lines().any(|l| l == kept),
            "missing line '{kept}' in:\n{text}"
        );
    }
    assert_eq!(
        text.lines().filter(|l| l.starts_with("vn ")).count(),
        3,
        "one recomputed normal per vertex, the stale one gone:\n{text}"
    );
    let deformed = load_mesh(&out).unwrap();
    let expected = [[-1.0, -0.5, 0.0], [1.0, -0.5, 0.0], [1.0, 0.5, 0.0]];
    for (p, e) in deformed.mesh.positions.iter().zip(expected) {
        assert!(
            p.distance(glam::DVec3::from_array(e)) < 1e-6,
            "{p} vs {e:?}"
        );
    }
}

#[test]
fn deform_with_stored_weights_matches_deform_that_binds() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, _) = comb_scene(dir.path(), 100);
    let mut pose = cage.positions().to_vec();
    for p in &mut pose {
        if p.y > 2.0 && p.x < 1.0 {
            p.x += 0.7; // bend the first prong
        }
    }
    let pose_path = write(
        dir.path(),
        "pose.obj",
        &triangles_obj(&pose, cage.triangles()),
    );
    let weights = dir.path().join("w.npy");
    let common = ["--mesh", path_str(&mesh), "--cage", path_str(&cage_path)];
    assert!(
        pmvc(&[&["bind"][..], &common, &["--out", path_str(&weights)]].concat())
            .status
            .success()
    );
    let (a, b) = (dir.path().join("a.obj"), dir.path().join("b.obj"));
    let output = pmvc(
        &[
            &["deform"][..],
            &common,
            &[
                "--deformed-cage",
                path_str(&pose_path),
                "--weights",
                path_str(&weights),
                "--out",
                path_str(&a),
            ],
        ]
        .concat(),
    );
    assert!(output.status.success(), "{}", stderr(&output));
    let output = pmvc(
        &[
            &["deform"][..],
            &common,
            &[
                "--deformed-cage",
                path_str(&pose_path),
                "--out",
                path_str(&b),
            ],
        ]
        .concat(),
    );
    assert!(output.status.success(), "{}", stderr(&output));
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    // Weights for another mesh are refused: by their metadata, and without it by
    // their shape.
    let small = dir.path().join("small.obj");
    std::fs::write(&small, "v 0.5 0.5 0\n").unwrap();
    let deform_small = || deform_with_weights(&small, &cage_path, &pose_path, &weights, &a);
    let json = weights.with_extension("json");
    assert_clean_failure(
        &deform_small(),
        path_str(&json),
        "rows is 100 there, 1 here",
    );
    std::fs::remove_file(&json).unwrap();
    assert_clean_failure(&deform_small(), path_str(&weights), "shape (100,");
}

#[test]
fn check_reports_topology_and_mvc_negativity() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = comb_scene(dir.path(), 300);
    let output = pmvc(&[
        "check",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage),
    ]);
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(
        text.contains("closed, edge-manifold, consistently oriented"),
        "{text}"
    );
    assert!(text.contains("inside: all 300 mesh vertices"), "{text}");
    assert!(text.contains("have a negative weight"), "{text}");
}

#[test]
fn help_lists_every_subcommand() {
    let output = pmvc(&["--help"]);
    assert!(output.status.success());
    let text = String::from_utf8_lossy(&output.stdout);
    for command in ["edit", "bind", "deform", "check", "bench", "info"] {
        assert!(text.contains(command), "{text}");
    }
}

/// The real meshes and artist-made cages in ../shared/data/qmvc, when present.
#[test]
fn shared_data_binds_and_reproduces_the_rest_pose() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/qmvc");
    if !data.join("ManHead.obj").exists() {
        println!("not run: {} is not present", data.display());
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let file = |name: &str| data.join(name).to_str().unwrap().to_owned();
    // Beast leaves about 2% of its vertices outside the cage; Ogre about 0.3%.
    for (model, low, high) in [("Beast", 1.0, 4.0), ("Ogre", 0.1, 1.0)] {
        let output = pmvc(&[
            "check",
            "--mesh",
            &file(&format!("{model}.obj")),
            "--cage",
            &file(&format!("{model}_Cage.obj")),
        ]);
        let text = String::from_utf8_lossy(&output.stdout).into_owned();
        assert!(output.status.success(), "{model}: {}", stderr(&output));
        let share: f64 = text
            .split(" vertices (")
            .nth(1)
            .and_then(|s| s.split('%').next())
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| panic!("{text}"));
        assert!((low..high).contains(&share), "{model}: {share}% outside");
    }
    // ManHead: bind PMVC, pose with the artist's deformed cage, and check the rest pose.
    let (mesh, cage, pose) = (
        file("ManHead.obj"),
        file("ManHead_Cage.obj"),
        file("ManHead_Cage_Deformed.obj"),
    );
    for (cage2, name) in [(&cage, "rest.obj"), (&pose, "posed.obj")] {
        let out = dir.path().join(name);
        let output = pmvc(&[
            "deform",
            "--mesh",
            &mesh,
            "--cage",
            &cage,
            "--deformed-cage",
            cage2,
            "--resolution",
            "16",
            "--out",
            path_str(&out),
        ]);
        assert!(output.status.success(), "{}", stderr(&output));
    }
    let original = load_mesh(Path::new(&mesh)).unwrap();
    let rest = load_mesh(&dir.path().join("rest.obj")).unwrap();
    let posed = load_mesh(&dir.path().join("posed.obj")).unwrap();
    let diagonal = original.mesh.diagonal();
    let worst = original
        .mesh
        .positions
        .iter()
        .zip(&rest.mesh.positions)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    assert!(worst <= 1e-5 * diagonal, "rest pose moved by {worst}");
    assert!(posed.mesh.positions.iter().all(|p| p.is_finite()));
    // Quads may be re-cut along the other diagonal once posed; the face count stays.
    assert_eq!(posed.mesh.triangles.len(), original.mesh.triangles.len());
    let moved = original
        .mesh
        .positions
        .iter()
        .zip(&posed.mesh.positions)
        .filter(|(a, b)| a.distance(**b) > 1e-3 * diagonal)
        .count();
    assert!(moved > 0, "the pose moved nothing");
}

#[test]
fn bind_harmonic_writes_the_library_weights_and_check_reports_the_grid() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, points) = comb_scene(dir.path(), 150);
    let out = dir.path().join("hc.npy");
    let output = pmvc(&[
        "bind",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage_path),
        "--method",
        "harmonic",
        "--grid",
        "32",
        "--out",
        path_str(&out),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let (shape, values, _) = read_npy_f32(&out);
    assert_eq!(shape, [points.len(), cage.vertex_count()]);
    let classes = classify_points(&cage, &points);
    let (expected, _) = pmvc::coords::harmonic::bind_harmonic(
        &points,
        &classes.classes,
        &cage,
        32,
        &BindProgress::default(),
    )
    .unwrap();
    assert_eq!(
        values, expected.values,
        "the CLI writes what the library binds"
    );
    assert!(values.iter().all(|&w| w >= -1e-6));

    let output = pmvc(&[
        "check",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage_path),
        "--grid",
        "32",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = String::from_utf8_lossy(&output.stdout);
    let plan = pmvc::coords::harmonic::plan(&cage, 32, points.len()).unwrap();
    assert!(
        text.contains(&format!("{} inside the cage", plan.inside_nodes)),
        "{text}"
    );

    // A grid below the minimum is bad input: a message and exit status 1.
    let output = pmvc(&[
        "bind",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage_path),
        "--method",
        "harmonic",
        "--grid",
        "0",
        "--out",
        path_str(&dir.path().join("bad.npy")),
    ]);
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    assert!(stderr(&output).contains("--grid"), "{}", stderr(&output));
    assert!(!dir.path().join("bad.npy").exists());
}

/// A reader that goes away (`pmvc check … | head -1`) and a stderr that cannot be
/// written (`2>/dev/full`) end the command cleanly, never with a panic.
#[test]
fn closed_stdout_and_full_stderr_end_cleanly() {
    use std::process::{Command, Stdio};
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, _, _) = comb_scene(dir.path(), 50);
    let args = [
        "check",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage_path),
    ];
    let mut child = Command::new(env!("CARGO_BIN_EXE_pmvc"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Close the pipe before the command writes (it reads its files first), as a
    // reader that has already gone would.
    drop(child.stdout.take());
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_ne!(output.status.code(), Some(101), "{stderr}");

    if std::path::Path::new("/dev/full").exists() {
        // A bind of points partly outside the cage warns on stderr.
        let outside = write(dir.path(), "outside.obj", "v 0.5 0.5 0\nv 40 40 40\n");
        let output = Command::new(env!("CARGO_BIN_EXE_pmvc"))
            .args([
                "bind",
                "--mesh",
                path_str(&outside),
                "--cage",
                path_str(&cage_path),
                "--out",
                path_str(&dir.path().join("w.npy")),
            ])
            .stderr(std::fs::File::create("/dev/full").unwrap())
            .output()
            .unwrap();
        assert_eq!(output.status.code(), Some(0), "the bind itself succeeds");
        assert!(dir.path().join("w.npy").exists());
    }
}

/// Run `pmvc` with a terminal as its stderr (util-linux `script`); what it
/// printed there.
fn on_a_terminal(args: &[&str]) -> Option<String> {
    let command: Vec<String> = std::iter::once(env!("CARGO_BIN_EXE_pmvc"))
        .chain(args.iter().copied())
        .map(|a| format!("'{a}'"))
        .collect();
    let output = std::process::Command::new("script")
        .args(["-qec", &command.join(" "), "/dev/null"])
        .output()
        .ok()?;
    assert!(output.status.success(), "{}", stderr(&output));
    Some(String::from_utf8_lossy(&output.stdout).into_owned())
}

#[test]
fn bind_and_deform_say_what_they_wrote_on_a_terminal_and_nothing_on_a_pipe() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, comb, _) = comb_scene(dir.path(), 50);
    let weights = dir.path().join("w.npy");
    let deformed = dir.path().join("deformed.obj");
    let bind = [
        "bind",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage),
        "--out",
        path_str(&weights),
        "--backend",
        "cpu",
    ];
    let deform = [
        "deform",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage),
        "--deformed-cage",
        path_str(&cage),
        "--weights",
        path_str(&weights),
        "--out",
        path_str(&deformed),
    ];
    let Some(said) = on_a_terminal(&bind) else {
        println!("not run: no `script` command to give pmvc a terminal");
        return;
    };
    let expected = format!(
        "pmvc: wrote {} (classes in {}, metadata in {}): 50 × {} float32 weights (PMVC 32², CPU) bound in ",
        weights.display(),
        weights.with_extension("classes.npy").display(),
        weights.with_extension("json").display(),
        comb.vertex_count()
    );
    assert!(said.contains(&expected), "{said}");
    assert!(said.contains("; all vertices inside the cage"), "{said}");
    let said = on_a_terminal(&deform).unwrap();
    let expected = format!(
        "pmvc: wrote {}: 50 vertices deformed with PMVC 32² weights from {} in ",
        deformed.display(),
        weights.display()
    );
    assert!(said.contains(&expected), "{said}");
    // A pipe, as in scripts: nothing.
    for args in [&bind[..], &deform[..]] {
        let output = pmvc(args);
        assert!(output.status.success());
        assert_eq!(stderr(&output), "", "{args:?}");
    }
}

#[test]
fn deform_writes_normals_that_follow_the_deformation() {
    let dir = tempfile::tempdir().unwrap();
    let cube = pmvc::geometry::procedural::cube_cage(1.0);
    let cage = write(dir.path(), "cage.obj", &cage_obj(&cube));
    // A flat tile facing +z (front face counter-clockwise seen from +z).
    let mesh = write(
        dir.path(),
        "tile.obj",
        "v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\nf 1 2 3\nf 1 3 4\n",
    );
    // Shear the cage, z' = z + x: an affine map, so the tile becomes the plane
    // z = x, whose normal is (-1, 0, 1)/√2.
    let sheared: Vec<glam::DVec3> = cube
        .positions()
        .iter()
        .map(|p| glam::DVec3::new(p.x, p.y, p.z + p.x))
        .collect();
    let pose = write(
        dir.path(),
        "pose.obj",
        &common::triangles_obj(&sheared, cube.triangles()),
    );
    let out = dir.path().join("out.obj");
    let output = deform_with(&mesh, &cage, &pose, &out, &[]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = std::fs::read_to_string(&out).unwrap();
    let expected = glam::DVec3::new(-1.0, 0.0, 1.0).normalize();
    let normals: Vec<glam::DVec3> = text
        .lines()
        .filter_map(|l| l.strip_prefix("vn "))
        .map(|rest| {
            let c: Vec<f64> = rest.split(' ').map(|t| t.parse().unwrap()).collect();
            glam::DVec3::new(c[0], c[1], c[2])
        })
        .collect();
    assert_eq!(normals.len(), 4, "{text}");
    for n in normals {
        assert!((n - expected).length() < 1e-6, "{n} vs {expected}");
    }
    assert!(text.lines().any(|l| l == "f 1//1 2//2 3//3"), "{text}");
}

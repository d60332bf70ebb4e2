//! Reading meshes and cages: file vertex order, polygon triangulation, point sets,
//! OFF, and inward-facing cages.

use crate::common;
use common::*;
use glam::DVec3;
use pmvc::coords::{bind_cpu, BindOptions, BindProgress, Method};
use pmvc::formats::{load_cage, load_mesh};
use pmvc::geometry::{classify_points, procedural};

#[test]
fn rows_follow_the_files_v_order_across_shuffled_groups() {
    let dir = tempfile::tempdir().unwrap();
    // Groups reference vertices out of order, and two vertices share a position:
    // tobj would renumber each group from 0 in first-use order.
    let text = "v 0 0 0\nv 1 0 0\no second\nv 0 1 0\nv 0 0 1\nf 4 3 2\ng again\nv 1 0 0\nf 5/1 4/1 1/1\no first\nf 1 2 4\nvt 0 0\n";
    let path = write(dir.path(), "groups.obj", text);
    let file = load_mesh(&path).unwrap();
    let expected_positions = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z, DVec3::X];
    assert_eq!(file.mesh.positions, expected_positions);
    assert_eq!(file.mesh.triangles, vec![[3, 2, 1], [4, 3, 0], [0, 1, 3]]);
    assert_eq!(file.mesh.triangle_faces, vec![0, 1, 2]);
}

#[test]
fn quads_are_cut_along_the_shorter_diagonal() {
    let dir = tempfile::tempdir().unwrap();
    // Non-planar quad: diagonal 1–3 (√6) is longer than 2–4 (√5).
    let path = write(
        dir.path(),
        "quad.obj",
        "v 0 0 0\nv 2 0 0\nv 2 1 1\nv 0 1 0\nf 1 2 3 4\n",
    );
    let file = load_mesh(&path).unwrap();
    assert_eq!(file.mesh.triangles, vec![[0, 1, 3], [1, 2, 3]]);
    // A cube of quads makes a valid cage of 12 triangles.
    let cube =
        "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
                f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    let (cage, report) = load_cage(&write(dir.path(), "cube.obj", cube)).unwrap();
    assert_eq!(cage.triangles().len(), 12);
    assert!(!report.flipped);
    assert!((report.volume - 8.0).abs() < 1e-12);
}

#[test]
fn a_file_without_faces_is_a_point_set() {
    let dir = tempfile::tempdir().unwrap();
    let cage = procedural::cube_cage(1.0);
    let points = [DVec3::ZERO, DVec3::new(0.5, -0.2, 0.1)];
    let path = write(dir.path(), "points.obj", &points_obj(&points));
    let file = load_mesh(&path).unwrap();
    assert_eq!(file.mesh.positions, points);
    assert!(file.mesh.triangles.is_empty());
    let classes = classify_points(&cage, &file.mesh.positions);
    let weights = bind_cpu(
        &file.mesh.positions,
        &classes.classes,
        &cage,
        BindOptions::default(),
        &BindProgress::default(),
    )
    .unwrap();
    assert_eq!((weights.rows, weights.cols), (2, 8));
}

#[test]
fn off_and_obj_give_the_same_cage() {
    let dir = tempfile::tempdir().unwrap();
    let off = "OFF\n# a tetrahedron\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2 255 0 0\n3 1 2 3\n";
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    let (from_off, _) = load_cage(&write(dir.path(), "t.off", off)).unwrap();
    let (from_obj, _) = load_cage(&write(dir.path(), "t.obj", obj)).unwrap();
    assert_eq!(from_off, from_obj);
}

#[test]
fn an_inward_facing_cage_is_flipped_and_binds_exactly_like_its_outward_twin() {
    let dir = tempfile::tempdir().unwrap();
    let outward = procedural::extrude(&procedural::star_outline(5, 0.4, 1.0), -0.3, 0.3);
    let reversed: Vec<[u32; 3]> = outward
        .triangles()
        .iter()
        .map(|&[a, b, c]| [a, c, b])
        .collect();
    let (outward_cage, outward_report) =
        load_cage(&write(dir.path(), "out.obj", &cage_obj(&outward))).unwrap();
    let (inward_cage, inward_report) = load_cage(&write(
        dir.path(),
        "in.obj",
        &triangles_obj(outward.positions(), &reversed),
    ))
    .unwrap();
    assert!(!outward_report.flipped);
    assert!(inward_report.flipped);
    assert!(inward_report.messages()[0].contains("flipped"));
    assert!(inward_cage.signed_volume() > 0.0);
    let points = procedural::points_inside(&outward_cage, 50, 1, 1e-3);
    for method in [Method::Mvc, Method::Pmvc] {
        let bind = |cage: &pmvc::geometry::Cage| {
            let classes = classify_points(cage, &points);
            bind_cpu(
                &points,
                &classes.classes,
                cage,
                BindOptions {
                    method,
                    resolution: 16,
                    ..Default::default()
                },
                &BindProgress::default(),
            )
            .unwrap()
        };
        assert_eq!(
            bind(&inward_cage),
            bind(&outward_cage),
            "{method:?} weights differ"
        );
    }
}

#[test]
fn unreferenced_cage_vertices_are_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 7 7 7\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    let (_, report) = load_cage(&write(dir.path(), "t.obj", text)).unwrap();
    assert_eq!(report.unreferenced, vec![4]);
    assert!(report.messages()[0].starts_with("warning"));
}

/// The only way to a `Cage` is validation: each defect is its own error variant,
/// and the message names the element without inventing a file.
#[test]
fn cage_new_rejects_each_defect_with_its_own_error() {
    use pmvc::geometry::{Cage, CageError, TriMesh};
    let cube = procedural::cube_cage(1.0);
    let with = |edit: &dyn Fn(&mut TriMesh)| {
        let mut mesh = TriMesh {
            positions: cube.positions().to_vec(),
            triangles: cube.triangles().to_vec(),
            triangle_faces: cube.triangle_faces().to_vec(),
        };
        edit(&mut mesh);
        Cage::new(mesh).map(|_| ()).unwrap_err()
    };
    let open = with(&|mesh| {
        mesh.triangles.pop();
        mesh.triangle_faces.pop();
    });
    assert!(matches!(open, CageError::OpenEdge { .. }), "{open}");
    let out_of_range = with(&|mesh| mesh.triangles[2][1] = 8);
    assert!(
        matches!(
            out_of_range,
            CageError::IndexOutOfRange {
                face: 2,
                index: 8,
                count: 8
            }
        ),
        "{out_of_range}"
    );
    let degenerate = with(&|mesh| mesh.positions[3] = mesh.positions[1]);
    assert!(
        matches!(degenerate, CageError::DegenerateTriangle { .. }),
        "{degenerate}"
    );
    let inconsistent = with(&|mesh| mesh.triangles[0].swap(0, 1));
    assert!(
        matches!(inconsistent, CageError::InconsistentOrientation { .. }),
        "{inconsistent}"
    );
    let non_manifold = with(&|mesh| {
        let (first, second) = (mesh.triangles[0], mesh.triangles[1]);
        mesh.triangles
            .extend([first, second].map(|[a, b, c]| [a, c, b]));
        mesh.triangle_faces.extend([12, 13]);
    });
    assert!(
        matches!(non_manifold, CageError::NonManifoldEdge { .. }),
        "{non_manifold}"
    );
    let not_finite = with(&|mesh| mesh.positions[5].y = f64::NAN);
    assert!(
        matches!(not_finite, CageError::NonFinite { vertex: 5 }),
        "{not_finite}"
    );
    for error in [
        open,
        out_of_range,
        degenerate,
        inconsistent,
        non_manifold,
        not_finite,
    ] {
        assert!(!error.to_string().contains(".obj"), "{error}");
    }
}

/// Text parsed under a name (as the bundled scenes are) reports that name and the
/// 1-based line of a bad number instead of reading it as 0.
#[test]
fn a_bad_number_names_the_file_and_line() {
    use pmvc::formats::parse_mesh;
    let text = "v 0 0 0\nv 1 0 0\nv 0 1.5x 0\nf 1 2 3\n".to_owned();
    let error = parse_mesh(std::path::Path::new("assets/example.obj"), text).unwrap_err();
    let message = error.to_string();
    assert!(message.starts_with("assets/example.obj:3:"), "{message}");
}

/// Every benchmark scene's cage passes validation (they are built through it).
#[test]
fn every_table1_scene_builds_a_valid_cage() {
    for &name in procedural::table1_scene_names() {
        let scene = procedural::table1_scene(name).expect("a known scene");
        assert!(scene.cage.vertex_count() > 0, "{name}");
        assert!(!scene.points.is_empty(), "{name}");
    }
}

/// `text` with `suffix` after the numbers of every `v` line.
fn with_vertex_suffix(text: &str, suffix: &str) -> String {
    text.lines()
        .map(|line| {
            if line.starts_with("v ") {
                format!("{line}{suffix}\n")
            } else {
                format!("{line}\n")
            }
        })
        .collect()
}

/// Inputs are never silently changed: a byte-order mark, CR-only line endings and
/// the common `v` forms read as what the file says; other forms are errors that
/// name the line.
#[test]
fn byte_order_marks_line_endings_and_vertex_forms() {
    use pmvc::formats::parse_mesh;
    let path = std::path::Path::new("cube.obj");
    let cube = procedural::cube_cage(1.0);
    let plain = cage_obj(&cube);
    let expected = parse_mesh(path, plain.clone()).unwrap().mesh;
    assert_eq!(expected.positions.len(), 8);
    let variants = [
        ("byte-order mark", format!("\u{feff}{plain}")),
        ("CR line endings", plain.replace('\n', "\r")),
        ("CRLF line endings", plain.replace('\n', "\r\n")),
        ("x y z w", with_vertex_suffix(&plain, " 1")),
        ("x y z r g b", with_vertex_suffix(&plain, " 0.5 0.5 0.5")),
    ];
    for (name, text) in variants {
        let mesh = parse_mesh(path, text)
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .mesh;
        assert_eq!(mesh.positions, expected.positions, "{name}");
        assert_eq!(mesh.triangles, expected.triangles, "{name}");
    }
    let bad = [
        ("v 0 0 0 1 2\n", ":1:", "has 5 numbers"),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1 a b c\nf 1 2 3\n",
            ":4:",
            "'a' is not a number",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 x 1\nf 1 2 3\n",
            ":4:",
            "normal: 'x'",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5 nope\nf 1 2 3\n",
            ":4:",
            "texture coordinate",
        ),
    ];
    for (text, line, what) in bad {
        let message = parse_mesh(path, text.to_owned()).unwrap_err().to_string();
        assert!(message.starts_with(&format!("cube.obj{line}")), "{message}");
        assert!(message.contains(what), "{message}");
    }
    // A runaway token is quoted short.
    let long = format!("v 0 0 {}\n", "9".repeat(100_000) + "x");
    let message = parse_mesh(path, long).unwrap_err().to_string();
    assert!(message.len() < 200, "{} bytes of message", message.len());
}

/// A polyline (`l`) is not a face, and a face needs three corners: the OBJ library
/// would read the first as a face and drop the second, and either would shift the
/// face numbers that cage errors name.
#[test]
fn polylines_are_skipped_and_short_faces_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let tetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    let with_line = tetra.replace("f 1 2 4\n", "l 1 2 3\nf 1 2 4\n");
    let file = load_mesh(&write(dir.path(), "line.obj", &with_line)).unwrap();
    assert_eq!(file.mesh.triangles.len(), 4);
    assert_eq!(file.mesh.triangle_faces, vec![0, 1, 2, 3]);

    let short = tetra.replace("f 1 2 4\n", "f 1 2\nf 1 2 4\n");
    let path = write(dir.path(), "short.obj", &short);
    let message = load_mesh(&path).unwrap_err().to_string();
    assert_eq!(
        message,
        format!(
            "{}:6: face 2 has 2 corners; a face needs at least 3",
            path.display()
        )
    );
}

/// A device as a mesh (`/dev/zero` under an .obj name) ends in an error naming
/// it at its first NUL byte; a pipe still delivers a mesh.
#[cfg(unix)]
#[test]
fn devices_are_read_with_a_limit_and_pipes_still_deliver_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let zero = dir.path().join("zero.obj");
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    let message = load_mesh(&zero).unwrap_err().to_string();
    assert!(message.contains("zero.obj"), "{message}");
    assert!(message.contains("binary data near byte 0"), "{message}");

    let fifo = dir.path().join("piped.obj");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|status| status.success()) {
        eprintln!("not run: no mkfifo");
        return;
    }
    let writer = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::write(fifo, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"))
    };
    let file = load_mesh(&fifo).unwrap();
    writer.join().unwrap().unwrap();
    assert_eq!(file.mesh.positions.len(), 3);
    assert_eq!(file.mesh.triangles, vec![[0, 1, 2]]);
}

/// Run by the test below in a child process with little address space: loads
/// the mesh named by `PMVC_TEST_MESH` and prints how it ended.
#[test]
fn child_loads_the_mesh_named_by_its_environment() {
    let Ok(path) = std::env::var("PMVC_TEST_MESH") else {
        return;
    };
    match load_mesh(std::path::Path::new(&path)) {
        Ok(file) => println!("CHILD: loaded {} vertices", file.mesh.positions.len()),
        Err(error) => println!("CHILD: refused: {error}"),
    }
}

/// `load_mesh(path)` in a child process limited to 1 GiB of address space:
/// what it printed, once it ended with success (no abort).
#[cfg(unix)]
fn load_in_a_limited_child(path: &std::path::Path) -> String {
    let output = std::process::Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 1048576 && exec \"$0\" \"$@\"")
        .arg(std::env::current_exe().unwrap())
        .args([
            "--exact",
            // The test's name as the harness lists it: its path below the crate root.
            concat!(
                module_path!(),
                "::child_loads_the_mesh_named_by_its_environment"
            )
            .split_once("::")
            .unwrap()
            .1,
            "--nocapture",
            "--test-threads=1",
        ])
        .env("PMVC_TEST_MESH", path)
        .output()
        .expect("run the test binary");
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stdout}\n{stderr}");
    stdout
}

/// A regular file too large to read is refused by its size before it is read:
/// with 1 GiB of address space, a 768 MiB mesh file (sparse, so nothing is
/// written) and its copy would not fit.
#[cfg(unix)]
#[test]
fn a_mesh_file_too_large_to_read_is_refused_by_its_size() {
    let dir = tempfile::tempdir().unwrap();
    let big = dir.path().join("big.obj");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(768 << 20)
        .unwrap();
    let stdout = load_in_a_limited_child(&big);
    assert!(stdout.contains("CHILD: refused: "), "{stdout}");
    assert!(stdout.contains("big.obj"), "{stdout}");
    assert!(stdout.contains("768.0 MiB"), "{stdout}");
}

/// A file whose parse would not fit is refused by what its text holds before
/// it is parsed: 38 MiB of nine-cornered faces take about 1.1 GiB to parse
/// (the OBJ library keeps 24 bytes per corner), more than 1 GiB of address space.
#[cfg(unix)]
#[test]
fn a_mesh_whose_parse_would_not_fit_is_refused_before_it_is_parsed() {
    let dir = tempfile::tempdir().unwrap();
    let dense = dir.path().join("dense.obj");
    let mut text = String::from("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n");
    text.push_str("v 1 0 1\nv 1 1 1\nv 0 1 1\nv 0 0 2\n");
    text.push_str(&"f 1 2 3 4 5 6 7 8 9\n".repeat(2_000_000));
    std::fs::write(&dense, text).unwrap();
    let stdout = load_in_a_limited_child(&dense);
    assert!(stdout.contains("CHILD: refused: "), "{stdout}");
    assert!(stdout.contains("dense.obj"), "{stdout}");
    assert!(stdout.contains("parsing its 38.1 MiB of text"), "{stdout}");
}

#[test]
fn a_deformed_obj_says_its_normals_are_recomputed_and_drops_comments_counting_the_old_ones() {
    let dir = tempfile::tempdir().unwrap();
    let source = dir.path().join("tile.obj");
    // As MeshLab writes it: a count of normals that the export no longer fits.
    let text = "# OBJ File Generated by Meshlab\n# Vertices: 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n# 3 vertices, 0 vertices normals\n# Normals: none\nf 1 2 3\n# 1 faces, 0 coords texture\n";
    std::fs::write(&source, text).unwrap();
    let file = load_mesh(&source).unwrap();
    let moved: Vec<DVec3> = file
        .mesh
        .positions
        .iter()
        .map(|p| *p + DVec3::new(0.0, 0.0, 2.0))
        .collect();
    let out = dir.path().join("out.obj");
    pmvc::formats::write_deformed_mesh(&file, &moved, &out).unwrap();
    let written = std::fs::read_to_string(&out).unwrap();
    for kept in [
        "# OBJ File Generated by Meshlab",
        "# Vertices: 3",
        "# 1 faces, 0 coords texture",
        "# 3 vertex normals, recomputed by pmvc from the deformed positions",
    ] {
        assert!(
            written.lines().any(|l| l == kept),
            "no '{kept}' in:\n{written}"
        );
    }
    assert!(
        !written.contains("0 vertices normals") && !written.contains("Normals: none"),
        "a stale comment about normals is kept:\n{written}"
    );
    assert_eq!(written.lines().filter(|l| l.starts_with("vn ")).count(), 3);
}

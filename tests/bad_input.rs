//! Bad input, one test per case, through the real binary: each fails with exit
//! status 1 and one error line naming the file and what is wrong, never a panic.

mod common;
use common::*;

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

fn bind_with_cage(cage_text: &str, name: &str) -> (std::process::Output, String) {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "mesh.obj", "v 0.1 0.1 0.1\n");
    let cage = write(dir.path(), name, cage_text);
    let out = dir.path().join("w.npy");
    let output = pmvc(&[
        "bind",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage),
        "--out",
        path_str(&out),
    ]);
    assert_eq!(
        out.exists(),
        output.status.success(),
        "output is written exactly when the command succeeds"
    );
    (output, cage.display().to_string())
}

#[test]
fn missing_file() {
    let (output, _) = bind_with_cage(TETRA, "cage.obj");
    assert!(
        output.status.success(),
        "the valid tetrahedron binds: {}",
        stderr(&output)
    );
    let output = pmvc(&[
        "bind",
        "--mesh",
        "/nonexistent/mesh.obj",
        "--cage",
        "/nonexistent/cage.obj",
        "--out",
        "/tmp/never.npy",
    ]);
    assert_clean_failure(&output, "/nonexistent/mesh.obj", "cannot read");
}

#[test]
fn empty_file() {
    let (output, cage) = bind_with_cage("", "cage.obj");
    assert_clean_failure(&output, &cage, "empty");
}

#[test]
fn binary_garbage() {
    let garbage: String = (0..512u32)
        .map(|i| char::from_u32(i % 7).unwrap())
        .collect();
    let (output, cage) = bind_with_cage(&garbage, "cage.obj");
    assert_clean_failure(&output, &cage, "binary");
}

#[test]
fn open_cage() {
    let open = TETRA.replace("f 2 3 4\n", "");
    let (output, cage) = bind_with_cage(&open, "cage.obj");
    assert_clean_failure(&output, &cage, "not closed");
}

#[test]
fn non_manifold_cage() {
    // A second tetrahedron hung on edge 1–2 of the first: that edge has four faces.
    let text = format!("{TETRA}v 0 -1 0\nv 0 0 -1\nf 1 5 2\nf 1 2 6\nf 1 6 5\nf 2 5 6\n");
    let (output, cage) = bind_with_cage(&text, "cage.obj");
    assert_clean_failure(&output, &cage, "not edge-manifold");
}

#[test]
fn inconsistent_orientation() {
    let text = TETRA.replace("f 2 3 4\n", "f 2 4 3\n");
    let (output, cage) = bind_with_cage(&text, "cage.obj");
    assert_clean_failure(&output, &cage, "oriented inconsistently");
}

#[test]
fn nan_coordinate() {
    let text = TETRA.replace("v 0 0 1\n", "v 0 nan 1\n");
    let (output, cage) = bind_with_cage(&text, "cage.obj");
    assert_clean_failure(&output, &cage, "non-finite");
    assert!(
        stderr(&output).contains(":4:"),
        "names the line: {}",
        stderr(&output)
    );
}

#[test]
fn face_index_out_of_range() {
    let text = TETRA.replace("f 2 3 4\n", "f 2 3 9\n");
    let (output, cage) = bind_with_cage(&text, "cage.obj");
    assert_clean_failure(&output, &cage, "face 4 refers to vertex 9");
}

#[test]
fn degenerate_triangle() {
    // A fifth vertex on edge 1–2 makes face 4 a zero-area sliver.
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 0.5 0 0\nf 1 3 2\nf 1 5 4\nf 5 2 4\nf 1 4 3\nf 2 3 4\nf 1 2 5\n";
    let (output, cage) = bind_with_cage(text, "cage.obj");
    assert_clean_failure(&output, &cage, "degenerate");
}

#[test]
fn too_few_cage_vertices() {
    let (output, cage) =
        bind_with_cage("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 2\n", "cage.obj");
    assert_clean_failure(&output, &cage, "at least 4 vertices");
}

#[test]
fn off_parse_error_names_the_line() {
    let (output, cage) = bind_with_cage("OFF\n4 4 0\n0 0 0\n1 0 0\n0 one 0\n0 0 1\n", "cage.off");
    assert_clean_failure(&output, &cage, ":5:");
}

#[test]
fn deformed_cage_with_another_vertex_count() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "mesh.obj", "v 0.1 0.1 0.1\n");
    let cage = write(dir.path(), "cage.obj", TETRA);
    let pose = write(dir.path(), "pose.obj", &format!("{TETRA}v 2 2 2\n"));
    let out = dir.path().join("out.obj");
    let output = pmvc(&[
        "deform",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage),
        "--deformed-cage",
        path_str(&pose),
        "--out",
        path_str(&out),
    ]);
    assert_clean_failure(&output, path_str(&pose), "has 5 vertices, but the cage");
    assert!(!out.exists());
}

#[test]
fn existing_output_survives_a_failure_and_is_replaced_on_success() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "mesh.obj", "v 0.1 0.1 0.1\n");
    let good = write(dir.path(), "good.obj", TETRA);
    let bad = write(dir.path(), "bad.obj", &TETRA.replace("f 2 3 4\n", ""));
    let out = write(dir.path(), "w.npy", "precious");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o640)).unwrap();
    }
    let output = pmvc(&[
        "bind",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&bad),
        "--out",
        path_str(&out),
    ]);
    assert_clean_failure(&output, path_str(&bad), "not closed");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "precious");
    // A missing output folder fails before anything is written, too.
    let output = pmvc(&[
        "bind",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&good),
        "--out",
        "/nonexistent/dir/w.npy",
    ]);
    assert_clean_failure(&output, "/nonexistent/dir/w.npy", "cannot write");
    let output = pmvc(&[
        "bind",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&good),
        "--out",
        path_str(&out),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(std::fs::read(&out).unwrap().starts_with(b"\x93NUMPY"));
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&out).unwrap().permissions().mode() & 0o777;
        assert_eq!(
            mode, 0o640,
            "the replaced file keeps its permissions, got {mode:o}"
        );
    }
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left behind");
}

#[test]
fn strict_rejects_vertices_outside_the_cage() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "mesh.obj", "v 0.1 0.1 0.1\nv 5 5 5\n");
    let cage = write(dir.path(), "cage.obj", TETRA);
    let out = dir.path().join("w.npy");
    let args = [
        "bind",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage),
        "--out",
        path_str(&out),
    ];
    let output = pmvc(&args);
    assert!(output.status.success());
    assert!(
        stderr(&output).contains("1 of 2 vertices (50.00%) lie outside the cage (first: 1)"),
        "{}",
        stderr(&output)
    );
    std::fs::remove_file(&out).unwrap();
    let output = pmvc(&[&args[..], &["--strict"]].concat());
    assert_clean_failure(&output, path_str(&mesh), "lie outside the cage");
    assert!(!out.exists());
}

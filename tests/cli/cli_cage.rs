//! `pmvc cage` end to end: the cage it writes loads as a valid cage around the
//! mesh, OFF meshes work, outputs are protected as for the other commands, and
//! bad input fails with status 1 and a message naming the file.

use crate::common;
use common::*;
use pmvc::formats::{load_cage, load_mesh};
use pmvc::geometry::{classify_points, procedural};
use std::path::{Path, PathBuf};
use std::process::Output;

fn comb_mesh() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/comb_mesh.obj")
}

fn generate(mesh: &Path, vertices: &str, out: &Path) -> Output {
    pmvc(&[
        "cage",
        "--mesh",
        path_str(mesh),
        "--vertices",
        vertices,
        "--out",
        path_str(out),
    ])
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// The cage at `path` is valid and every vertex of `mesh` lies inside it.
fn assert_encloses(path: &Path, mesh: &Path) {
    let (cage, _) = load_cage(path).expect("the written cage loads as a valid cage");
    let mesh = load_mesh(mesh).unwrap();
    let classes = classify_points(&cage, &mesh.mesh.positions);
    assert!(
        classes.outside.is_empty(),
        "{} mesh vertices lie outside the generated cage",
        classes.outside.len()
    );
}

#[test]
fn a_cage_around_the_comb_is_written_and_its_properties_printed() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cage.obj");
    let output = generate(&comb_mesh(), "64", &out);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_encloses(&out, &comb_mesh());
    let text = stdout(&output);
    let (cage, _) = load_cage(&out).unwrap();
    assert!(
        text.contains(&format!("vertices: {} (target 64)", cage.vertex_count())),
        "{text}"
    );
    for heading in [
        "wrote ",
        "shell",
        "minimum clearance: ",
        "% of the mesh diagonal",
        "volume ratio (cage / mesh): ",
        "minimum angle: ",
        "gaps between parts: ",
        "time: ",
    ] {
        assert!(text.contains(heading), "no '{heading}' in: {text}");
    }
    // Reached or not, the summary says which.
    let within = (cage.vertex_count() as f64 - 64.0).abs() <= 0.15 * 64.0;
    assert_eq!(!within, text.contains("target not reached"), "{text}");
}

/// Without a voxel size, the generator chooses one for the target and says so,
/// with the distance under which parts may merge: the comb reaches 8 vertices
/// (a box). A voxel size that is asked for is used as asked, and the finest
/// keeps the fingers apart at the cost of the target.
#[test]
fn the_voxel_size_is_chosen_or_used_as_asked_and_reported() {
    let dir = tempfile::tempdir().unwrap();
    let (chosen, fine) = (dir.path().join("chosen.obj"), dir.path().join("fine.obj"));
    let auto = generate(&comb_mesh(), "8", &chosen);
    assert!(auto.status.success(), "{}", stderr(&auto));
    let text = stdout(&auto);
    assert!(
        text.contains("chosen for the target and the gaps"),
        "{text}"
    );
    assert!(text.contains("may share one part of the cage"), "{text}");
    // A box around five fingers bridges the gaps between them, and says so.
    assert!(
        text.contains("points in them are inside the cage (bridged gaps up to"),
        "{text}"
    );
    let asked = pmvc(&[
        "cage",
        "--mesh",
        path_str(&comb_mesh()),
        "--vertices",
        "8",
        "--cell-size",
        "0.0078125",
        "--out",
        path_str(&fine),
    ]);
    assert!(asked.status.success(), "{}", stderr(&asked));
    let text = stdout(&asked);
    assert!(
        text.contains("(0.78% of the mesh diagonal, as asked)"),
        "{text}"
    );
    assert!(text.contains("target not reached"), "{text}");
    let count = |path: &Path| load_cage(path).unwrap().0.vertex_count();
    assert!((7..=9).contains(&count(&chosen)), "{}", count(&chosen));
    assert!(count(&fine) > 20, "{}", count(&fine));
}

#[test]
fn an_off_mesh_gets_a_cage() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = procedural::icosphere(1.0, 2);
    let mut off = format!(
        "OFF\n{} {} 0\n",
        sphere.vertex_count(),
        sphere.triangle_count()
    );
    for p in sphere.positions() {
        off.push_str(&format!("{} {} {}\n", p.x, p.y, p.z));
    }
    for [a, b, c] in sphere.triangles() {
        off.push_str(&format!("3 {a} {b} {c}\n"));
    }
    let mesh = write(dir.path(), "sphere.off", &off);
    let out = dir.path().join("sphere_cage.obj");
    let output = generate(&mesh, "32", &out);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_encloses(&out, &mesh);
    assert!(stdout(&output).contains("(target 32)"));
}

#[test]
fn inputs_are_never_overwritten_and_an_existing_output_survives_a_failure() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("comb.obj");
    std::fs::copy(comb_mesh(), &mesh).unwrap();
    let before = std::fs::read(&mesh).unwrap();
    assert_clean_failure(
        &generate(&mesh, "64", &mesh),
        path_str(&mesh),
        "never overwrites",
    );
    assert_eq!(std::fs::read(&mesh).unwrap(), before);

    let out = write(dir.path(), "old_cage.obj", "# an earlier cage\n");
    let output = generate(&mesh, "3", &out);
    assert_eq!(output.status.code(), Some(1));
    assert_eq!(
        std::fs::read_to_string(&out).unwrap(),
        "# an earlier cage\n"
    );
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
    // A run that succeeds replaces it, as every command's output.
    let output = generate(&mesh, "64", &out);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_encloses(&out, &mesh);
}

#[test]
fn too_few_or_too_many_vertices_fail_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cage.obj");
    let mesh = comb_mesh();
    assert_clean_failure(
        &generate(&mesh, "3", &out),
        "comb_mesh.obj",
        "at least 8 vertices",
    );
    assert_clean_failure(
        &generate(&mesh, "10000000", &out),
        "comb_mesh.obj",
        "more than the 20000",
    );
    assert!(!out.exists());
}

#[test]
fn a_mesh_without_triangles_fails_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let (points, _, _, _) = comb_scene(dir.path(), 50);
    let out = dir.path().join("generated.obj");
    assert_clean_failure(
        &generate(&points, "16", &out),
        path_str(&points),
        "no triangles",
    );
    assert!(!out.exists());
}

/// An icosphere of radius `radius` around `centre`, written as OBJ.
fn sphere_obj(dir: &Path, name: &str, radius: f64, centre: glam::DVec3) -> PathBuf {
    let sphere = procedural::icosphere(1.0, 3);
    let moved: Vec<glam::DVec3> = sphere
        .positions()
        .iter()
        .map(|p| *p * radius + centre)
        .collect();
    write(dir, name, &triangles_obj(&moved, sphere.triangles()))
}

/// `pmvc cage` with `args` in a shell whose address space is capped at
/// `kib`: an allocation past it aborts the process instead of failing slowly.
fn cage_capped(kib: u64, args: &[&str]) -> Output {
    let mut command = format!(
        "ulimit -v {kib}; exec '{}' cage",
        env!("CARGO_BIN_EXE_pmvc")
    );
    for arg in args {
        command.push_str(&format!(" '{arg}'"));
    }
    std::process::Command::new("sh")
        .args(["-c", &command])
        .output()
        .expect("run sh")
}

/// Temporary outputs left in `dir`.
fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.starts_with(".pmvc-") || name.ends_with(".tmp"))
        .collect()
}

const ONE_GIB_IN_KIB: u64 = 1 << 20;

/// A clearance so fine that its surface samples would need gigabytes is
/// refused with their size and a clearance that fits, before the output's
/// temporary file exists; it used to abort (status 134) and leave one.
#[test]
fn a_clearance_too_fine_for_memory_is_refused_with_sizes() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = sphere_obj(dir.path(), "sphere.obj", 1.0, glam::DVec3::ZERO);
    let out = dir.path().join("cage.obj");
    for clearance in ["1e-4", "1e-12"] {
        let output = cage_capped(
            ONE_GIB_IN_KIB,
            &[
                "--mesh",
                path_str(&mesh),
                "--vertices",
                "64",
                "--clearance",
                clearance,
                "--out",
                path_str(&out),
            ],
        );
        assert_clean_failure(&output, "sphere.obj", "surface samples");
        let text = stderr(&output);
        assert!(text.contains("iB"), "no size: {text}");
        assert!(
            text.contains("a clearance of"),
            "no clearance that fits: {text}"
        );
        assert!(!out.exists());
        assert_eq!(leftovers(dir.path()), Vec::<String>::new());
    }
}

/// Fine voxels with a wide clearance need a grid with wide margins: under a
/// 1 GiB cap it is refused with its size and a coarser voxel size that fits.
#[test]
fn a_grid_past_the_memory_left_is_refused_with_a_voxel_size_that_fits() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = sphere_obj(dir.path(), "sphere.obj", 1.0, glam::DVec3::ZERO);
    let out = dir.path().join("cage.obj");
    let output = cage_capped(
        ONE_GIB_IN_KIB,
        &[
            "--mesh",
            path_str(&mesh),
            "--vertices",
            "64",
            "--clearance",
            "0.45",
            "--cell-size",
            "0.004",
            "--out",
            path_str(&out),
        ],
    );
    assert_clean_failure(&output, "sphere.obj", "voxel grid");
    let text = stderr(&output);
    assert!(text.contains("iB"), "no size: {text}");
    assert!(!out.exists());
    assert_eq!(leftovers(dir.path()), Vec::<String>::new());
    let suggested: f64 = text
        .split("a voxel size of ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|value| value.parse().ok())
        .unwrap_or_else(|| panic!("no voxel size that fits: {text}"));
    assert!(suggested > 0.004 && suggested < 0.25, "{text}");
}

/// Random triangles across a box, 30,000 vertices: their surface samples at
/// the default clearance would need tens of gigabytes. Refused at once with
/// the size, where it used to grow until the system killed it.
#[test]
fn a_noise_mesh_is_refused_with_sizes_under_a_memory_cap() {
    let dir = tempfile::tempdir().unwrap();
    let mut random = pmvc::geometry::procedural::SplitMix64(11);
    let count = 30_000u64;
    let mut obj = String::new();
    for _ in 0..count {
        let [x, y, z] = [random.unit(), random.unit(), random.unit()];
        obj.push_str(&format!("v {x} {y} {z}\n"));
    }
    for _ in 0..2 * count {
        let [a, b, c] = [0; 3].map(|_| 1 + random.next_u64() % count);
        if a != b && b != c && a != c {
            obj.push_str(&format!("f {a} {b} {c}\n"));
        }
    }
    let mesh = write(dir.path(), "noise.obj", &obj);
    let out = dir.path().join("cage.obj");
    let output = cage_capped(
        2 * ONE_GIB_IN_KIB,
        &[
            "--mesh",
            path_str(&mesh),
            "--vertices",
            "64",
            "--out",
            path_str(&out),
        ],
    );
    assert_clean_failure(&output, "noise.obj", "surface samples");
    assert!(
        stderr(&output).contains("a clearance of"),
        "{}",
        stderr(&output)
    );
    assert!(!out.exists());
    assert_eq!(leftovers(dir.path()), Vec::<String>::new());
}

/// A sphere a million units from the origin gets a cage as at the origin.
#[test]
fn a_mesh_far_from_the_origin_gets_a_cage() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = sphere_obj(dir.path(), "far.obj", 1.0, glam::DVec3::splat(1e6));
    let out = dir.path().join("cage.obj");
    let output = generate(&mesh, "64", &out);
    assert!(output.status.success(), "{}", stderr(&output));
    let (cage, _) = load_cage(&out).unwrap();
    assert!(
        cage.positions()
            .iter()
            .all(|p| (*p - glam::DVec3::splat(1e6)).length() < 2.0),
        "the cage is not around the sphere"
    );
}

/// A mesh 1e-8 across: its figures are printed with significant digits,
/// not as 0.000000.
#[test]
fn a_tiny_mesh_prints_its_figures_with_significant_digits() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = sphere_obj(dir.path(), "tiny.obj", 0.5e-8, glam::DVec3::ZERO);
    let out = dir.path().join("cage.obj");
    let output = generate(&mesh, "32", &out);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = stdout(&output);
    assert!(!text.contains("0.000000"), "{text}");
    let clearance = text
        .lines()
        .find(|line| line.starts_with("minimum clearance: "))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(clearance.contains("e-"), "{clearance}");
}

/// The summary says when the voxel size asked for was finer than the grid
/// allows and was coarsened, and to what.
#[test]
fn a_coarsened_voxel_size_is_reported_as_coarsened() {
    use pmvc::app::cage_generation::stats_lines;
    use pmvc::cagegen::{generate_cage, CageOptions};
    let sphere = procedural::icosphere(1.0, 2);
    let mesh = pmvc::geometry::TriMesh {
        positions: sphere.positions().to_vec(),
        triangles: sphere.triangles().to_vec(),
        triangle_faces: sphere.triangle_faces().to_vec(),
    };
    let generated = generate_cage(&mesh, &CageOptions::new(32), &|_| true).unwrap();
    let mut stats = generated.stats;
    stats.cell_size_chosen = false;
    stats.cell_size_asked = Some(1e-3 * stats.mesh_diagonal);
    let lines = stats_lines(&stats, false);
    let voxel = lines
        .iter()
        .find(|line| line.starts_with("voxel size: "))
        .unwrap();
    assert!(
        voxel.contains("coarsened from the 0.003464 asked"),
        "{voxel}"
    );
    assert!(!voxel.contains("as asked"), "{voxel}");
}

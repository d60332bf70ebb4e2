//! Green coordinates on the command line: the `.npz` contract of `pmvc bind
//! --method green` (read here with the zip crate and a hand-written `.npy` parser),
//! `pmvc deform` with and without stored coordinates, and the errors for the wrong
//! file format and a cage given inside out.

use crate::common;
use common::*;
use glam::{DMat3, DVec3};
use pmvc::coords::green::bind_green;
use pmvc::coords::BindProgress;
use pmvc::formats::load_mesh;
use std::io::Read as _;
use std::path::Path;

/// The arrays of an `.npz`, by name, each as (shape, values).
fn read_npz(path: &Path) -> Vec<(String, Vec<usize>, Vec<f32>)> {
    let file = std::fs::File::open(path).unwrap();
    let mut archive = zip::ZipArchive::new(file).expect("a zip archive");
    let mut arrays = Vec::new();
    for index in 0..archive.len() {
        let mut entry = archive.by_index(index).unwrap();
        assert_eq!(
            entry.compression(),
            zip::CompressionMethod::Stored,
            "stored, as numpy.savez writes"
        );
        let mut bytes = Vec::new();
        entry.read_to_end(&mut bytes).unwrap();
        let (shape, values, header) = parse_npy_f32(&bytes);
        assert!(
            header.contains("'descr': '<f4'") && header.contains("'fortran_order': False"),
            "{header}"
        );
        arrays.push((entry.name().to_owned(), shape, values));
    }
    arrays
}

fn bind_args<'a>(mesh: &'a Path, cage: &'a Path, out: &'a Path) -> Vec<&'a str> {
    vec![
        "bind",
        "--mesh",
        path_str(mesh),
        "--cage",
        path_str(cage),
        "--method",
        "green",
        "--out",
        path_str(out),
    ]
}

#[test]
fn bind_writes_phi_and_psi_as_two_float32_arrays_in_an_npz() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, points) = comb_scene(dir.path(), 120);
    let out = dir.path().join("w.npz");
    let output = pmvc(&bind_args(&mesh, &cage_path, &out));
    assert!(output.status.success(), "{}", stderr(&output));
    let arrays = read_npz(&out);
    let names: Vec<&str> = arrays.iter().map(|(name, ..)| name.as_str()).collect();
    assert_eq!(names, ["phi.npy", "psi.npy"]);
    let library = bind_green(&points, &cage, &BindProgress::default()).unwrap();
    let (_, phi_shape, phi) = &arrays[0];
    let (_, psi_shape, psi) = &arrays[1];
    assert_eq!(phi_shape, &[points.len(), cage.vertex_count()]);
    assert_eq!(psi_shape, &[points.len(), cage.triangle_count()]);
    assert_eq!(phi, &library.phi.values);
    assert_eq!(psi, &library.psi.values);
    // ψ's columns follow the cage's triangles: each row reproduces its point with
    // the rest normals in that order.
    for (row, x) in points.iter().enumerate() {
        let mut y = DVec3::ZERO;
        for (i, &p) in cage.positions().iter().enumerate() {
            y += f64::from(phi[row * cage.vertex_count() + i]) * p;
        }
        for (t, corners) in cage.triangles().iter().enumerate() {
            let [a, b, c] = corners.map(|i| cage.positions()[i as usize]);
            let normal = (b - a).cross(c - a).normalize();
            y += f64::from(psi[row * cage.triangle_count() + t]) * normal;
        }
        assert!((y - *x).length() < 1e-5 * cage.diagonal(), "row {row}");
    }
}

#[test]
fn the_format_must_fit_the_family_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, ..) = comb_scene(dir.path(), 10);
    let npy = dir.path().join("w.npy");
    let output = pmvc(&bind_args(&mesh, &cage_path, &npy));
    assert_clean_failure(&output, path_str(&npy), "use --out");
    assert!(stderr(&output).contains("w.npz"), "{}", stderr(&output));
    assert!(!npy.exists());
    let npz = dir.path().join("m.npz");
    let mut args = bind_args(&mesh, &cage_path, &npz);
    args[6] = "mvc";
    let output = pmvc(&args);
    assert_clean_failure(&output, path_str(&npz), "written as .npy");
    assert!(!npz.exists());
}

#[test]
fn deform_applies_stored_or_fresh_green_coordinates_and_keeps_similarities() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, points) = comb_scene(dir.path(), 80);
    let rotation = DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 0.5).normalize(), 0.7);
    let moved = |p: DVec3| 1.7 * (rotation * p) + DVec3::new(3.0, -1.0, 0.25);
    let pose: Vec<DVec3> = cage.positions().iter().map(|&p| moved(p)).collect();
    let pose_path = write(
        dir.path(),
        "pose.obj",
        &triangles_obj(&pose, cage.triangles()),
    );
    let weights = dir.path().join("w.npz");
    assert!(pmvc(&bind_args(&mesh, &cage_path, &weights))
        .status
        .success());
    let deform =
        |out: &Path, extra: &[&str]| deform_with(&mesh, &cage_path, &pose_path, out, extra);
    let (stored, fresh) = (dir.path().join("a.obj"), dir.path().join("b.obj"));
    let output = deform(&stored, &["--weights", path_str(&weights)]);
    assert!(output.status.success(), "{}", stderr(&output));
    let output = deform(&fresh, &["--method", "green"]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_eq!(
        std::fs::read(&stored).unwrap(),
        std::fs::read(&fresh).unwrap()
    );
    let deformed = load_mesh(&stored).unwrap().mesh.positions;
    let worst = points
        .iter()
        .zip(&deformed)
        .map(|(&x, &y)| (moved(x) - y).length())
        .fold(0.0, f64::max);
    assert!(worst < 1e-5 * 1.7 * cage.diagonal(), "worst {worst:e}");

    // Green coordinates cannot come from a .npy. With its metadata a .npy
    // applies as the family recorded there, whatever --method says.
    let npy = dir.path().join("p.npy");
    let mut args = bind_args(&mesh, &cage_path, &npy);
    args[6] = "pmvc";
    assert!(pmvc(&args).status.success());
    let output = deform(&stored, &["--method", "green", "--weights", path_str(&npy)]);
    assert!(output.status.success(), "{}", stderr(&output));
    std::fs::remove_file(npy.with_extension("json")).unwrap();
    let output = deform(&stored, &["--method", "green", "--weights", path_str(&npy)]);
    assert_clean_failure(&output, path_str(&npy), "read from a .npz");
    // A .npz for another cage is refused with both shapes.
    let small = dir.path().join("small.obj");
    std::fs::write(&small, "v 0.5 0.5 0\n").unwrap();
    let deform_small = || deform_with_weights(&small, &cage_path, &pose_path, &weights, &stored);
    assert_clean_failure(&deform_small(), "w.json", "rows is");
    std::fs::remove_file(weights.with_extension("json")).unwrap();
    assert_clean_failure(
        &deform_small(),
        path_str(&weights),
        "but the mesh has 1 vertices",
    );
}

#[test]
fn a_cage_given_inside_out_is_flipped_with_a_notice_and_binds_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, _) = comb_scene(dir.path(), 40);
    let reversed: Vec<[u32; 3]> = cage
        .triangles()
        .iter()
        .map(|&[a, b, c]| [a, c, b])
        .collect();
    let inward = write(
        dir.path(),
        "inward.obj",
        &triangles_obj(cage.positions(), &reversed),
    );
    let (outward_npz, inward_npz) = (dir.path().join("o.npz"), dir.path().join("i.npz"));
    assert!(pmvc(&bind_args(&mesh, &cage_path, &outward_npz))
        .status
        .success());
    let output = pmvc(&bind_args(&mesh, &inward, &inward_npz));
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(
        stderr(&output).contains("pointed inward; they were flipped"),
        "{}",
        stderr(&output)
    );
    let (outward, inward) = (read_npz(&outward_npz), read_npz(&inward_npz));
    for ((name, shape, a), (_, _, b)) in outward.iter().zip(&inward) {
        let worst = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f32::max);
        assert!(worst < 1e-6, "{name} {shape:?}: {worst:e}");
    }
}

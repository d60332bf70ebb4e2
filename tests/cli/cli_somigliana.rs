//! Somigliana coordinates on the command line: `pmvc bind --method somigliana`
//! writes 9 columns per cage vertex and triangle with the layout and Poisson
//! ratio in W.json, `pmvc deform` with them or bound afresh follows the
//! library's global deformation (with bulging and a local blend, read when
//! deforming), and settings out of range are refused.

use crate::cli_support::*;
use crate::common::*;
use glam::{DQuat, DVec3};
use pmvc::coords::somigliana::{deform as somigliana_deform, deform_blended, somigliana_blocks};
use pmvc::formats::load_mesh;
use std::path::Path;

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn bind_and_deform_follow_the_library_global_deformation() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, points) = comb_scene(dir.path(), 30);
    let weights = dir.path().join("w.npy");
    let output = bind(
        &mesh,
        &cage_path,
        "somigliana",
        &weights,
        &["--poisson-ratio", "0.3"],
    );
    assert!(output.status.success(), "{}", stderr(&output));
    let json = read_json(&dir.path().join("w.json"));
    assert_eq!(json["method"], "somigliana");
    assert_eq!(json["columns_layout"], "blocks_per_vertex_then_triangle");
    assert_eq!(
        json["parameters"],
        serde_json::json!({"poisson_ratio": 0.3})
    );
    assert_eq!(
        json["columns"],
        9 * (cage.vertex_count() + cage.triangle_count())
    );
    // A bent tooth, turned, scaled and moved: no similarity.
    let turn = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 0.5).normalize(), 0.7);
    let pose: Vec<DVec3> = comb_pose(&cage, 0.4)
        .into_iter()
        .map(|p| 1.3 * (turn * p) + DVec3::new(3.0, -1.0, 2.0))
        .collect();
    let pose_path = write(
        dir.path(),
        "pose.obj",
        &triangles_obj(&pose, cage.triangles()),
    );
    let (stored, fresh) = (dir.path().join("a.obj"), dir.path().join("b.obj"));
    let output = deform(
        &mesh,
        &cage_path,
        &pose_path,
        &stored,
        &["--weights", path_str(&weights)],
    );
    assert!(output.status.success(), "{}", stderr(&output));
    let fresh_args = ["--method", "somigliana", "--poisson-ratio", "0.3"];
    let output = deform(&mesh, &cage_path, &pose_path, &fresh, &fresh_args);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_eq!(
        std::fs::read(&stored).unwrap(),
        std::fs::read(&fresh).unwrap()
    );
    let blocks = somigliana_blocks(&points, &cage, 0.3).unwrap();
    let expected = somigliana_deform(&blocks, &cage, &pose, 0.0).unwrap();
    let deformed = load_mesh(&stored).unwrap().mesh.positions;
    let diagonal = cage.diagonal();
    let worst = largest_gap(&expected, &deformed) / diagonal;
    assert!(worst < 1e-5, "{worst} of the diagonal");
    // The bulging γ is read when deforming: the same weights, another result,
    // the library's.
    let bulged = dir.path().join("bulged.obj");
    let weights_args = ["--weights", path_str(&weights), "--bulging", "2.5"];
    let output = deform(&mesh, &cage_path, &pose_path, &bulged, &weights_args);
    assert!(output.status.success(), "{}", stderr(&output));
    let expected = somigliana_deform(&blocks, &cage, &pose, 2.5).unwrap();
    let bulged = load_mesh(&bulged).unwrap().mesh.positions;
    let worst = largest_gap(&expected, &bulged) / diagonal;
    assert!(worst < 1e-5, "{worst} of the diagonal");
    assert!(largest_gap(&deformed, &bulged) / diagonal > 1e-3);
    // So is the local blend: the library's blended deformation.
    let blended = dir.path().join("blended.obj");
    let blend_args = [
        "--weights",
        path_str(&weights),
        "--bulging",
        "2.5",
        "--local-blend",
        "0.5",
    ];
    let output = deform(&mesh, &cage_path, &pose_path, &blended, &blend_args);
    assert!(output.status.success(), "{}", stderr(&output));
    let expected = deform_blended(&blocks, &cage, &pose, 2.5, 0.5).unwrap();
    let blended = load_mesh(&blended).unwrap().mesh.positions;
    let worst = largest_gap(&expected, &blended) / diagonal;
    assert!(worst < 1e-5, "{worst} of the diagonal");
    assert!(largest_gap(&bulged, &blended) / diagonal > 1e-3);
}

fn largest_gap(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0f64, f64::max)
}

#[test]
fn deformation_settings_out_of_range_are_refused_and_other_families_say_they_ignore_them() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, _) = comb_scene(dir.path(), 4);
    let pose_path = write(
        dir.path(),
        "pose.obj",
        &triangles_obj(&comb_pose(&cage, 0.4), cage.triangles()),
    );
    let out = dir.path().join("out.obj");
    let refused = [
        ("--bulging", ["10.5", "-1", "much"]),
        ("--local-blend", ["1.01", "-0.1", "half"]),
    ];
    for (flag, values) in refused {
        for value in values {
            let args = ["--method", "somigliana", flag, value];
            let output = deform(&mesh, &cage_path, &pose_path, &out, &args);
            assert_eq!(output.status.code(), Some(1), "{flag} {value}");
            let said = stderr(&output);
            assert!(said.contains(flag), "{value}: {said}");
            assert!(!out.exists());
        }
        let args = ["--method", "mvc", flag, "0.5"];
        let output = deform(&mesh, &cage_path, &pose_path, &out, &args);
        assert!(output.status.success(), "{}", stderr(&output));
        let said = stderr(&output);
        assert!(said.contains(&format!("{flag} is ignored")), "{said}");
        std::fs::remove_file(&out).unwrap();
    }
}

#[test]
fn a_poisson_ratio_out_of_range_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, _, _) = comb_scene(dir.path(), 4);
    for value in ["0.7", "-1", "soft"] {
        let out = dir.path().join("w.npy");
        let output = bind(
            &mesh,
            &cage_path,
            "somigliana",
            &out,
            &["--poisson-ratio", value],
        );
        assert_eq!(output.status.code(), Some(1), "{value}");
        let said = stderr(&output);
        assert!(said.contains("--poisson-ratio"), "{value}: {said}");
        assert!(!out.exists());
    }
    let said = stderr(&bind(
        &mesh,
        &cage_path,
        "somigliana",
        &dir.path().join("w.npy"),
        &["--poisson-ratio", "0.7"],
    ));
    assert!(said.contains("-0.999 to 0.499"), "{said}");
}

//! What `pmvc bind` writes beside the weights for a reader to trust them, and
//! what `pmvc deform --weights` does with it: the metadata and class mask of
//! every family (classes against an independent winding number), the same
//! files from a bind in blocks, weights for other inputs refused by the field
//! that differs, weights without metadata used with one warning, and the files
//! beside the weights refused as the weights are.

use crate::cli_support;
use crate::common;
use cli_support::*;
use common::*;
use glam::DVec3;
use pmvc::coords::family::ColumnLayout;
use pmvc::coords::{Method, Parameter};
use pmvc::geometry::Cage;
use std::path::{Path, PathBuf};

/// A 1-D int8 `.npy`, parsed by hand.
fn read_classes(path: &Path) -> Vec<i8> {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
    assert!(header.contains("'descr': '|i1'"), "{header}");
    let values: Vec<i8> = bytes[10 + header_len..].iter().map(|&b| b as i8).collect();
    assert!(
        header.contains(&format!("'shape': ({},)", values.len())),
        "{header}"
    );
    values
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Comb points inside, two outside and two on the cage (a corner and the middle
/// of a face), with each row's class by an independent winding number.
fn classed_scene(dir: &Path) -> (PathBuf, PathBuf, Cage, Vec<DVec3>, Vec<i8>) {
    let (_, cage_path, cage, mut points) = comb_scene(dir, 40);
    points.push(DVec3::new(1.125, 2.5, 0.0));
    points.push(DVec3::new(2.0, -3.0, 4.0));
    let on_cage = [cage.positions()[0], DVec3::new(0.5, 0.5, 0.5)];
    points.extend(on_cage);
    let classes = points
        .iter()
        .map(|&p| {
            if on_cage.contains(&p) {
                1
            } else if winding_number(cage.positions(), cage.triangles(), p) > 0.5 {
                0
            } else {
                2
            }
        })
        .collect();
    let mesh = write(dir, "classed.obj", &points_obj(&points));
    (mesh, cage_path, cage, points, classes)
}

#[test]
fn bind_writes_metadata_and_row_classes_for_every_family() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, points, expected_classes) = classed_scene(dir.path());
    let counts = |code: i8| expected_classes.iter().filter(|&&c| c == code).count();
    assert_eq!(
        (counts(1), counts(2)),
        (2, 2),
        "the scene has rows of each class"
    );
    for method in Method::ALL {
        // Read from the family's spec, so that a new family is covered unedited.
        let extension = match method.spec().columns {
            ColumnLayout::CageVerticesThenTriangles => "npz",
            ColumnLayout::CageVertices | ColumnLayout::BlocksPerVertexThenTriangle => "npy",
        };
        let (parameter, extra) = match method.spec().parameter {
            None => (serde_json::json!({}), Vec::new()),
            Some(spec) => {
                // Small values, for speed.
                let (value, text) = match spec.key {
                    Parameter::Resolution => (serde_json::json!(8), "8"),
                    Parameter::Grid => (serde_json::json!(16), "16"),
                    // A decimal parameter is written as the decimal.
                    Parameter::PoissonRatio => (serde_json::json!(0.3), "0.3"),
                    // Read when deforming: no family binds with it.
                    Parameter::Bulging | Parameter::LocalBlend => {
                        unreachable!("{spec:?} is no bind parameter")
                    }
                };
                let mut parameter = serde_json::Map::new();
                parameter.insert(spec.key.id().to_owned(), value);
                (parameter.into(), vec![spec.flag, text])
            }
        };
        let extra = &extra[..];
        let out = dir.path().join(format!("{}.{extension}", method.id()));
        let output = bind(&mesh, &cage_path, method.id(), &out, extra);
        assert!(output.status.success(), "{method:?}: {}", stderr(&output));
        let json_path = dir.path().join(format!("{}.json", method.id()));
        let classes_file = format!("{}.classes.npy", method.id());
        let json = read_json(&json_path);
        let spec = method.spec();
        let columns = method.columns(&cage);
        let field = |name: &str| json[name].clone();
        assert_eq!(field("format"), "pmvc-weights");
        assert_eq!(field("format_version"), 1);
        assert_eq!(
            field("program"),
            format!("pmvc {}", env!("CARGO_PKG_VERSION"))
        );
        assert_eq!(field("method"), method.id());
        assert_eq!(field("method_name"), spec.name);
        assert_eq!(field("parameters"), parameter, "{method:?}");
        assert_eq!(field("backend"), "cpu");
        assert_eq!(field("device"), "CPU");
        let seconds = field("seconds").as_f64().unwrap();
        assert!(seconds > 0.0 && seconds < 600.0, "{seconds}");
        assert_eq!(field("rows"), points.len());
        assert_eq!(field("columns"), columns);
        assert_eq!(field("positive_inside"), spec.positive_inside);
        assert_eq!(field("outside_policy"), spec.outside_policy);
        if method == Method::Green {
            assert_eq!(field("columns_layout"), "cage_vertices_then_triangles");
            // ψ column k is the cage's k-th triangle, as the library cuts the faces.
            let triangles: Vec<[u32; 3]> = serde_json::from_value(field("triangles")).unwrap();
            assert_eq!(triangles, cage.triangles());
            assert_eq!(triangles.len(), columns - cage.vertex_count());
        } else if spec.columns == ColumnLayout::BlocksPerVertexThenTriangle {
            assert_eq!(field("columns_layout"), "blocks_per_vertex_then_triangle");
            // Block columns 9(V + t) on are the cage's t-th triangle.
            let triangles: Vec<[u32; 3]> = serde_json::from_value(field("triangles")).unwrap();
            assert_eq!(triangles, cage.triangles());
            assert_eq!(9 * (triangles.len() + cage.vertex_count()), columns);
        } else {
            assert_eq!(field("columns_layout"), "cage_vertices");
            assert!(json.get("triangles").is_none(), "{json}");
        }
        let classes = &json["classes"];
        assert_eq!(classes["file"], classes_file.as_str());
        assert_eq!(classes["codes"]["1"], "on the cage");
        assert_eq!(
            [&classes["inside"], &classes["on_cage"], &classes["outside"]],
            [counts(0), counts(1), counts(2)]
                .map(serde_json::Value::from)
                .each_ref()
        );
        assert_eq!(json["mesh"]["file"], path_str(&mesh));
        assert_eq!(json["mesh"]["points"], points.len());
        assert_eq!(
            json["mesh"]["digest"],
            pmvc::formats::metadata::positions_digest(&points)
        );
        assert_eq!(json["cage"]["file"], path_str(&cage_path));
        assert_eq!(json["cage"]["vertices"], cage.vertex_count());
        assert_eq!(json["cage"]["triangles"], cage.triangle_count());
        let mask = read_classes(&dir.path().join(&classes_file));
        assert_eq!(mask, expected_classes, "{method:?}: classes");
    }
}

#[test]
fn a_bind_in_blocks_writes_the_same_metadata_and_classes() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, _, _, expected_classes) = classed_scene(dir.path());
    let whole = dir.path().join("whole.npy");
    let blocks = dir.path().join("blocks.npy");
    for (out, extra) in [(&whole, &[][..]), (&blocks, &["--block-rows", "7"][..])] {
        let output = bind(&mesh, &cage_path, "mvc", out, extra);
        assert!(output.status.success(), "{}", stderr(&output));
    }
    assert_eq!(
        std::fs::read(&whole).unwrap(),
        std::fs::read(&blocks).unwrap()
    );
    assert_eq!(
        read_classes(&dir.path().join("blocks.classes.npy")),
        expected_classes
    );
    let comparable = |name: &str| {
        let mut json = read_json(&dir.path().join(name));
        json["seconds"] = serde_json::Value::Null;
        json["classes"]["file"] = serde_json::Value::Null;
        json
    };
    assert_eq!(comparable("whole.json"), comparable("blocks.json"));
}

#[test]
fn deform_refuses_weights_whose_metadata_names_other_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, points) = comb_scene(dir.path(), 30);
    let weights = dir.path().join("w.npy");
    let output = bind(&mesh, &cage_path, "pmvc", &weights, &["--resolution", "8"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let pose = write(dir.path(), "pose.obj", &cage_obj(&cage));
    let out = dir.path().join("deformed.obj");
    let with_weights = ["--weights", path_str(&weights)];
    let output = deform(&mesh, &cage_path, &pose, &out, &with_weights);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(!stderr(&output).contains("warning"), "{}", stderr(&output));

    // The same number of points, one of them moved.
    let mut moved = points.clone();
    moved[3].x += 1e-3;
    let other_mesh = write(dir.path(), "other.obj", &points_obj(&moved));
    let output = deform(&other_mesh, &cage_path, &pose, &out, &with_weights);
    assert_clean_failure(&output, "w.json", "mesh.digest");
    // The same cage with one vertex moved a little.
    let mut nudged: Vec<DVec3> = cage.positions().to_vec();
    nudged[0] += DVec3::new(-1e-3, 0.0, 0.0);
    let other_cage = write(
        dir.path(),
        "other-cage.obj",
        &triangles_obj(&nudged, cage.triangles()),
    );
    let output = deform(&mesh, &other_cage, &pose, &out, &with_weights);
    assert_clean_failure(&output, "w.json", "cage.digest");
    // Fewer points.
    let fewer = write(dir.path(), "fewer.obj", &points_obj(&points[1..]));
    let output = deform(&fewer, &cage_path, &pose, &out, &with_weights);
    assert_clean_failure(&output, "w.json", "rows");
}

#[test]
fn deform_warns_once_when_weights_have_no_metadata_and_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, _) = partly_outside(dir.path());
    let weights = dir.path().join("w.npy");
    let output = bind(&mesh, &cage_path, "harmonic", &weights, &["--grid", "16"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let pose = write(
        dir.path(),
        "pose.obj",
        &triangles_obj(&comb_pose(&cage, 0.2), cage.triangles()),
    );
    let out = dir.path().join("deformed.obj");
    let with_weights = ["--weights", path_str(&weights)];
    let output = deform(&mesh, &cage_path, &pose, &out, &with_weights);
    let text = stderr(&output);
    assert!(output.status.success(), "{text}");
    assert!(!text.contains("cannot be checked"), "{text}");
    // The family is the metadata's (harmonic), whatever --method says.
    assert!(
        text.contains(Method::Harmonic.spec().outside_policy),
        "{text}"
    );
    let checked = obj_vertices(&out);

    std::fs::remove_file(dir.path().join("w.json")).unwrap();
    let output = deform(&mesh, &cage_path, &pose, &out, &with_weights);
    let text = stderr(&output);
    assert!(output.status.success(), "{text}");
    let warnings: Vec<&str> = text
        .lines()
        .filter(|line| line.contains("cannot be checked"))
        .collect();
    assert_eq!(warnings.len(), 1, "{text}");
    assert!(
        warnings[0].contains("w.json") && warnings[0].contains("warning"),
        "{text}"
    );
    // Nothing says how the rows outside were made: the warning does not guess.
    assert!(
        !text.contains(Method::Harmonic.spec().outside_policy),
        "{text}"
    );
    assert_eq!(
        obj_vertices(&out),
        checked,
        "the same weights deform the same"
    );
}

#[test]
fn the_files_beside_the_weights_are_refused_as_the_weights_are() {
    let dir = tempfile::tempdir().unwrap();
    let (_, cage_path, _, points) = comb_scene(dir.path(), 20);
    // A point set whose name is the class mask's for --out w.npy.
    let mesh = dir.path().join("w.classes.npy");
    std::fs::write(&mesh, f64_points_npy(&points)).unwrap();
    let out = dir.path().join("w.npy");
    let output = bind(&mesh, &cage_path, "mvc", &out, &[]);
    assert_clean_failure(&output, "w.classes.npy", "is the input");
    assert!(!out.exists() && !dir.path().join("w.json").exists());
    // Metadata that links to an input.
    let out = dir.path().join("u.npy");
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&cage_path, dir.path().join("u.json")).unwrap();
        let output = bind(&mesh, &cage_path, "mvc", &out, &[]);
        assert_clean_failure(&output, "u.json", "is the input");
        assert!(!out.exists());
    }

    // Metadata no one may write.
    let out = dir.path().join("v.npy");
    let json = dir.path().join("v.json");
    std::fs::write(&json, "{}").unwrap();
    let mut permissions = std::fs::metadata(&json).unwrap().permissions();
    permissions.set_readonly(true);
    std::fs::set_permissions(&json, permissions).unwrap();
    let output = bind(&mesh, &cage_path, "mvc", &out, &[]);
    assert_clean_failure(&output, "v.json", "");
    assert!(!out.exists(), "nothing written");
    assert!(!dir.path().join("v.classes.npy").exists());
    assert_eq!(std::fs::read_to_string(&json).unwrap(), "{}");

    // A device has no folder of its own: only the weights go there.
    let output = bind(&mesh, &cage_path, "mvc", Path::new("/dev/null"), &[]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(!Path::new("/dev/null.json").exists());
    assert!(!Path::new("/dev/null.classes.npy").exists());
}

#[test]
fn weights_of_one_name_in_both_formats_are_not_mistaken_for_each_other() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, cage, _) = comb_scene(dir.path(), 20);
    let npy = dir.path().join("w.npy");
    let npz = dir.path().join("w.npz");
    for (method, out) in [("mvc", &npy), ("green", &npz)] {
        let output = bind(&mesh, &cage_path, method, out, &[]);
        assert!(output.status.success(), "{}", stderr(&output));
    }
    // w.json is the Green bind's now: the .npy is refused, not applied as Green.
    let pose = write(dir.path(), "pose.obj", &cage_obj(&cage));
    let out = dir.path().join("deformed.obj");
    let output = deform(
        &mesh,
        &cage_path,
        &pose,
        &out,
        &["--weights", path_str(&npy)],
    );
    assert_clean_failure(&output, "w.npy", "w.json says it holds Green coordinates");
    let output = deform(
        &mesh,
        &cage_path,
        &pose,
        &out,
        &["--weights", path_str(&npz)],
    );
    assert!(output.status.success(), "{}", stderr(&output));
}
#[test]
fn help_says_what_bind_writes_and_what_deform_reads_and_writes() {
    let help = |command: &str| {
        let output = pmvc(&[command, "--help"]);
        assert!(output.status.success());
        String::from_utf8_lossy(&output.stdout).into_owned()
    };
    let bind = help("bind");
    for said in [
        "W.json",
        "W.classes.npy",
        "0 inside, 1 on the cage, 2 outside",
        ".npy array of shape (n, 3)",
    ] {
        assert!(bind.contains(said), "bind --help: {said}: {bind}");
    }
    let deform = help("deform");
    for said in ["W.json beside them", "float64 of shape (mesh vertices, 3)"] {
        assert!(deform.contains(said), "deform --help: {said}: {deform}");
    }
}

#[test]
fn metadata_records_where_the_rows_were_computed() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, _, _) = comb_scene(dir.path(), 30);
    let bind_on_gpu = |method: &str, extra: &[&str]| {
        let out = dir.path().join(format!("{method}.npy"));
        let mut args = vec![
            "bind",
            "--mesh",
            path_str(&mesh),
            "--cage",
            path_str(&cage_path),
            "--method",
            method,
            "--backend",
            "gpu",
            "--out",
            path_str(&out),
        ];
        args.extend_from_slice(extra);
        (pmvc(&args), dir.path().join(format!("{method}.json")))
    };
    let (output, json) = bind_on_gpu("pmvc", &["--resolution", "8"]);
    if !ran_on_gpu(&output) {
        return;
    }
    let json = read_json(&json);
    assert_eq!(json["backend"], "gpu");
    let device = json["device"].as_str().unwrap();
    assert!(!device.is_empty() && device != "CPU", "{device}");
    // The PMVC kernel that computed the rows is part of where they were computed.
    assert!(device.ends_with("PMVC tile kernel"), "{device}");
    // Asked for, the band kernel binds instead (as GPU binds did before the tile
    // kernel), and says so.
    let (output, json) = bind_on_gpu("pmvc", &["--resolution", "8", "--pmvc-kernel", "bands"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let device = read_json(&json)["device"].as_str().unwrap().to_owned();
    assert!(device.ends_with("PMVC band kernel"), "{device}");
    // Harmonic coordinates have no GPU kernel: their rows come from the CPU.
    let (output, json) = bind_on_gpu("harmonic", &["--grid", "16"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let json = read_json(&json);
    assert_eq!(
        (&json["backend"], &json["device"]),
        (&"cpu".into(), &"CPU".into())
    );
}

//! The metadata and class mask written beside weights (formats::metadata): what
//! a reader gets back is what was bound, a file for other inputs is refused by
//! naming the field, broken metadata is refused by naming the line, and the
//! three files are replaced together or not at all.

use glam::DVec3;
use pmvc::coords::{bind_cpu, BindOptions, BindProgress, Method};
use pmvc::formats::metadata::{
    classes_path, load_weights_set, metadata_path, read_classes_npy, read_metadata,
    save_weights_set, BindRecord, MetadataError, WeightsMetadata, CLASS_INSIDE, CLASS_ON_CAGE,
    CLASS_OUTSIDE,
};
use pmvc::geometry::procedural;
use pmvc::geometry::{classify_points, Cage};
use std::path::Path;

/// Points inside, on and outside a cube of half-size 1 that sits far from the
/// origin, so that nothing depends on it.
fn scene() -> (Cage, Vec<DVec3>) {
    let offset = DVec3::new(1.0e4, -2.5e3, 7.0e2);
    let cube = procedural::cube_cage(1.0);
    let cage = cube.with_positions(cube.positions().iter().map(|&p| p + offset).collect());
    let points = [
        DVec3::new(0.1, 0.2, -0.3),
        DVec3::new(-0.5, 0.5, 0.25),
        DVec3::new(1.0, 0.3, 0.1),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, -3.0, 1.0),
    ]
    .map(|p| p + offset)
    .to_vec();
    (cage, points)
}

/// The metadata of a CPU bind of `points` to `cage` written to `path`.
fn cpu_metadata(
    options: BindOptions,
    cage: &Cage,
    points: &[DVec3],
    classes: &[pmvc::geometry::PointClass],
    path: &Path,
) -> WeightsMetadata {
    WeightsMetadata::new(&BindRecord {
        options,
        cage,
        points,
        classes,
        backend: "cpu",
        device: "CPU",
        seconds: 0.25,
        mesh_file: "mesh.obj",
        cage_file: "cage.obj",
        mesh_object: None,
        cage_object: Some("Cage"),
        weights_file: path,
    })
}

fn bind_and_save(dir: &Path, method: Method) -> (std::path::PathBuf, Cage, Vec<DVec3>) {
    let (cage, points) = scene();
    let classes = classify_points(&cage, &points).classes;
    let mut options = BindOptions::for_method(method);
    if matches!(method, Method::Bbw | Method::Lbc) {
        // The metadata is what is tested: a coarse grid keeps the solve short.
        options.grid = 12;
    }
    let weights = bind_cpu(&points, &classes, &cage, options, &BindProgress::default()).unwrap();
    let extension = if method == Method::Green {
        "npz"
    } else {
        "npy"
    };
    let path = dir.join(format!("W.{extension}"));
    let metadata = cpu_metadata(options, &cage, &points, &classes, &path);
    let codes = pmvc::formats::metadata::class_codes(&classes);
    save_weights_set(&path, &weights, &metadata, &codes).unwrap();
    let loaded = load_weights_set(&path).unwrap();
    assert_eq!(
        loaded.weights,
        weights,
        "{}: the weights read back",
        method.id()
    );
    assert_eq!(loaded.metadata, metadata);
    assert_eq!(loaded.options, options);
    assert_eq!(loaded.classes, codes);
    (path, cage, points)
}

#[test]
fn every_family_reads_back_what_was_bound_with_its_classes_and_columns() {
    for method in Method::ALL {
        let dir = tempfile::tempdir().unwrap();
        let (path, cage, points) = bind_and_save(dir.path(), method);
        let metadata = read_metadata(&metadata_path(&path)).unwrap();
        assert_eq!(metadata.method, method.id());
        assert_eq!(metadata.rows, points.len());
        // Inside, on a face, then three outside, found here by the point's
        // distance from the cube's centre rather than by the library's classifier.
        let centre = DVec3::new(1.0e4, -2.5e3, 7.0e2);
        let expected: Vec<i8> = points
            .iter()
            .map(|p| {
                let far = (*p - centre).abs().max_element();
                if far < 1.0 - 1e-12 {
                    CLASS_INSIDE
                } else if far <= 1.0 + 1e-12 {
                    CLASS_ON_CAGE
                } else {
                    CLASS_OUTSIDE
                }
            })
            .collect();
        assert_eq!(
            read_classes_npy(&classes_path(&path), points.len()).unwrap(),
            expected
        );
        assert_eq!(
            (
                metadata.classes.inside,
                metadata.classes.on_cage,
                metadata.classes.outside
            ),
            (2, 1, 2)
        );
        if method == Method::Green {
            assert_eq!(
                metadata.columns,
                cage.vertex_count() + cage.triangle_count()
            );
            assert_eq!(metadata.triangles.as_deref(), Some(cage.triangles()));
        } else if method == Method::Somigliana {
            let blocks = cage.vertex_count() + cage.triangle_count();
            assert_eq!(metadata.columns, 9 * blocks);
            assert_eq!(metadata.triangles.as_deref(), Some(cage.triangles()));
        } else {
            assert_eq!(metadata.columns, cage.vertex_count());
            assert_eq!(metadata.triangles, None);
        }
        let parameters: Vec<&str> = metadata.parameters.keys().map(String::as_str).collect();
        let expected_parameters: Vec<&str> =
            method.spec().parameter.iter().map(|p| p.key.id()).collect();
        assert_eq!(parameters, expected_parameters, "{}", method.id());
    }
}

#[test]
fn weights_bound_for_other_inputs_are_refused_by_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let (path, cage, mut points) = bind_and_save(dir.path(), Method::Mvc);
    let metadata = read_metadata(&metadata_path(&path)).unwrap();
    metadata
        .check_inputs(&metadata_path(&path), &points, &cage)
        .unwrap();
    points[3].x += 1e-9;
    let error = metadata
        .check_inputs(&metadata_path(&path), &points, &cage)
        .unwrap_err();
    assert!(
        matches!(
            error,
            MetadataError::Mismatch {
                field: "mesh.digest",
                ..
            }
        ),
        "{error}"
    );
    points.pop();
    let error = metadata
        .check_inputs(&metadata_path(&path), &points, &cage)
        .unwrap_err();
    assert!(
        error.to_string().contains("rows is 5 there, 4 here"),
        "{error}"
    );
    let moved = cage.with_positions(cage.positions().iter().map(|&p| p * 1.0001).collect());
    points.push(DVec3::ZERO);
    let (_, original) = scene();
    let error = metadata
        .check_inputs(&metadata_path(&path), &original, &moved)
        .unwrap_err();
    assert!(error.to_string().contains("cage.digest"), "{error}");
}

#[test]
fn broken_metadata_is_refused_with_the_line_or_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let (path, _, _) = bind_and_save(dir.path(), Method::Pmvc);
    let json_path = metadata_path(&path);
    let good = std::fs::read_to_string(&json_path).unwrap();
    let cases = [
        (good.replacen("\"rows\": 5", "\"rows\": 5,,", 1), "line"),
        (
            good.replacen("\"method\": \"pmvc\"", "\"method\": \"qmvc\"", 1),
            "field method: \"qmvc\" is not a family",
        ),
        (
            good.replacen("\"resolution\": 32", "\"resolution\": 4096", 1),
            "resolution 4096 is out of range",
        ),
        (
            good.replacen("\"format_version\": 1", "\"format_version\": 7", 1),
            "field format_version: is 7",
        ),
        (
            good.replacen("\"columns\": 8", "\"columns\": 9", 1),
            "field columns",
        ),
        (
            good.replacen(
                "\"file\": \"W.classes.npy\"",
                "\"file\": \"../W.classes.npy\"",
                1,
            ),
            "field classes.file",
        ),
    ];
    for (text, expected) in cases {
        assert_ne!(text, good, "the case must change the file: {expected}");
        std::fs::write(&json_path, &text).unwrap();
        let error = match load_weights_set(&path) {
            Ok(_) => panic!("accepted metadata that should say {expected:?}"),
            Err(error) => error.to_string(),
        };
        assert!(error.contains(expected), "{error} (expected {expected:?})");
        assert!(error.contains("W.json"), "{error}");
    }
}

#[test]
fn a_bad_class_mask_names_the_row() {
    let dir = tempfile::tempdir().unwrap();
    let (path, _, _) = bind_and_save(dir.path(), Method::Mvc);
    let mask = classes_path(&path);
    let mut bytes = std::fs::read(&mask).unwrap();
    let last = bytes.len() - 2;
    bytes[last] = 7;
    std::fs::write(&mask, &bytes).unwrap();
    let error = read_classes_npy(&mask, 5).unwrap_err().to_string();
    assert!(error.contains("row 4: class 7"), "{error}");
    bytes.truncate(bytes.len() - 1);
    std::fs::write(&mask, &bytes).unwrap();
    let error = read_classes_npy(&mask, 5).unwrap_err().to_string();
    assert!(error.contains("holds 4 class values"), "{error}");
}

#[test]
fn the_three_files_are_replaced_together_or_not_at_all() {
    let dir = tempfile::tempdir().unwrap();
    let (path, cage, points) = bind_and_save(dir.path(), Method::Mvc);
    let before: Vec<Vec<u8>> = [path.clone(), classes_path(&path)]
        .iter()
        .map(|p| std::fs::read(p).unwrap())
        .collect();
    // A folder where the metadata should go: the weights and mask stay as they were.
    std::fs::remove_file(metadata_path(&path)).unwrap();
    std::fs::create_dir(metadata_path(&path)).unwrap();
    let classes = classify_points(&cage, &points).classes;
    let options = BindOptions::for_method(Method::Mvc);
    let mut weights =
        bind_cpu(&points, &classes, &cage, options, &BindProgress::default()).unwrap();
    weights.values.reverse();
    let metadata = cpu_metadata(options, &cage, &points, &classes, &path);
    let codes = vec![0; points.len()];
    assert!(save_weights_set(&path, &weights, &metadata, &codes).is_err());
    let after: Vec<Vec<u8>> = [path.clone(), classes_path(&path)]
        .iter()
        .map(|p| std::fs::read(p).unwrap())
        .collect();
    assert_eq!(before, after);
}

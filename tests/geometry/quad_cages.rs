//! Cages of quads as bilinear patches: what validation refuses (folded and
//! degenerate quads, patches that cross), how points between a bent patch and
//! its triangles are classified, and what `pmvc check` reports about the split.

use glam::DVec3;
use pmvc::formats::load_cage;
use pmvc::geometry::procedural_quads::{cage_from_polygons, twisted_box};
use pmvc::geometry::{classify_points, CageError, PointClass, QuadSplit};
#[cfg(feature = "editor")]
use std::process::Command;

fn cube_positions() -> Vec<DVec3> {
    (0..8)
        .map(|i| DVec3::new(f64::from(i & 1), f64::from((i >> 1) & 1), f64::from(i >> 2)))
        .collect()
}

fn cube_quads() -> Vec<Vec<u32>> {
    pmvc::geometry::procedural::CUBE_QUADS
        .iter()
        .map(|q| q.to_vec())
        .collect()
}

#[test]
fn a_cube_of_quads_keeps_six_patches_and_they_survive_a_flip() {
    let (cage, report) = cage_from_polygons(&cube_positions(), &cube_quads()).unwrap();
    assert!(!report.flipped);
    assert_eq!(cage.quads().len(), 6);
    let reversed: Vec<Vec<u32>> = cube_quads()
        .into_iter()
        .map(|q| q.into_iter().rev().collect())
        .collect();
    let (flipped, report) = cage_from_polygons(&cube_positions(), &reversed).unwrap();
    assert!(report.flipped);
    assert_eq!(flipped.quads().len(), 6);
    // Flipped quads face outward again: the patch normal at the centre points
    // away from the cube's centre.
    for k in 0..6 {
        let q = flipped.quad(k);
        let normal = pmvc::geometry::quads::bilinear_normal(&q, 0.5, 0.5);
        let centre = pmvc::geometry::quads::bilinear_point(&q, 0.5, 0.5);
        assert!(normal.dot(centre - DVec3::splat(0.5)) > 0.0, "quad {k}");
    }
}

#[test]
fn a_folded_quad_is_refused_naming_its_face() {
    let mut quads = cube_quads();
    // A bow tie: two corners of face 2 swapped.
    quads[1].swap(1, 2);
    let error = cage_from_polygons(&cube_positions(), &quads).expect_err("a folded quad");
    assert!(
        matches!(error, CageError::FoldedQuad { face: 1, .. }),
        "{error}"
    );
    let text = error.to_string();
    assert!(
        text.starts_with("face 2 is a quad that folds over itself"),
        "{text}"
    );
}

#[test]
fn a_degenerate_quad_is_refused_naming_its_face_and_corners() {
    // A box whose top quad has three collinear corners: corner 6 moved onto
    // the line through 4 and 7... (4 = (0,0,1), 7 = (1,1,1)): 6 = (0.5, 0.5, 1).
    let mut positions = cube_positions();
    positions[6] = DVec3::new(0.5, 0.5, 1.0);
    let error = cage_from_polygons(&positions, &cube_quads()).expect_err("a degenerate quad");
    assert!(matches!(error, CageError::DegenerateQuad { .. }), "{error}");
    let text = error.to_string();
    assert!(text.contains("is a degenerate quad"), "{text}");
    assert!(text.contains("are collinear"), "{text}");
}

#[test]
fn patches_that_cross_are_refused_although_their_triangles_do_not() {
    // A box whose floor rises to a spike at (½, ½, 0.9) and whose lid is bent:
    // its corners over (0, 0) and (1, 1) at height 1, the other two at 0.6. The
    // lid's split along the (0, 0)–(1, 1) diagonal is at height 1 over the
    // spike, but the patch dips to 0.8 there, and the spike pierces it.
    let d = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let positions = vec![
        d(0.0, 0.0, 0.0),
        d(1.0, 0.0, 0.0),
        d(1.0, 1.0, 0.0),
        d(0.0, 1.0, 0.0),
        d(0.0, 0.0, 1.0),
        d(1.0, 0.0, 0.6),
        d(1.0, 1.0, 1.0),
        d(0.0, 1.0, 0.6),
        d(0.5, 0.5, 0.9),
    ];
    let mut faces = vec![
        vec![4, 5, 6, 7],
        vec![0, 1, 5, 4],
        vec![1, 2, 6, 5],
        vec![2, 3, 7, 6],
        vec![3, 0, 4, 7],
    ];
    faces.extend([[1, 0, 8], [2, 1, 8], [3, 2, 8], [0, 3, 8]].map(|t| t.to_vec()));
    let error = cage_from_polygons(&positions, &faces).expect_err("the spike pierces the lid");
    assert!(
        matches!(error, CageError::SelfIntersecting { .. }),
        "{error}"
    );
    let text = error.to_string();
    assert!(text.contains("crosses itself"), "{text}");
    assert!(text.contains("faces 1 and"), "{text}");
    // The same lid given as its two triangles is a valid cage.
    let mut triangles = vec![vec![4, 5, 6], vec![4, 6, 7]];
    triangles.extend(faces[1..].iter().cloned());
    cage_from_polygons(&positions, &triangles).expect("the split lid stays above the spike");
}

#[test]
fn points_between_a_bent_patch_and_its_triangles_are_classified_by_the_patch() {
    let cage = twisted_box(2.0, 0.6);
    let mut checked = 0;
    for k in 0..cage.quads().len() {
        let q = cage.quad(k);
        if pmvc::geometry::quads::out_of_plane(&q) < 1e-3 {
            continue;
        }
        // The patch passes through its centre c, half-way between the two
        // diagonals' midpoints; each split's surface passes through its own.
        let centre = (q[0] + q[1] + q[2] + q[3]) * 0.25;
        let ac = (q[0] + q[2]) * 0.5;
        let bd = (q[1] + q[3]) * 0.5;
        let points = [(centre + ac) * 0.5, (centre + bd) * 0.5];
        let class = |cage: &pmvc::geometry::Cage| -> Vec<bool> {
            classify_points(cage, &points)
                .classes
                .iter()
                .map(|c| matches!(c, PointClass::Inside))
                .collect()
        };
        let patches = class(&cage);
        assert_ne!(patches[0], patches[1], "quad {k}: the patch separates them");
        for split in [QuadSplit::Shorter, QuadSplit::Longer] {
            let triangles = class(&cage.split_quads(split));
            assert_eq!(
                triangles[0], triangles[1],
                "quad {k}, {split:?}: one side of the split"
            );
        }
        checked += 1;
    }
    assert_eq!(checked, 4);
}

#[test]
fn a_point_on_a_bent_patch_is_on_the_surface_with_the_patch_basis() {
    let cage = twisted_box(2.0, 0.6);
    let k = (0..6)
        .find(|&k| pmvc::geometry::quads::out_of_plane(&cage.quad(k)) > 1e-3)
        .unwrap();
    let q = cage.quad(k);
    let (u, v) = (0.3, 0.6);
    let x = pmvc::geometry::quads::bilinear_point(&q, u, v);
    let classes = classify_points(&cage, &[x]);
    assert!(
        matches!(classes.classes[0], PointClass::OnSurface { .. }),
        "{:?}",
        classes.classes[0]
    );
    for method in pmvc::coords::Method::ALL {
        // Green has its own surface policy; a family of triangles only splits
        // the patch.
        let triangles_only = method.spec().quads == pmvc::coords::QuadSupport::Triangles;
        if method == pmvc::coords::Method::Green || triangles_only {
            continue;
        }
        let weights = pmvc::coords::bind_cpu(
            &[x],
            &classes.classes,
            &cage,
            pmvc::coords::BindOptions::for_method(method),
            &Default::default(),
        )
        .unwrap();
        let basis = pmvc::geometry::quads::bilinear_basis(u, v);
        for (corner, expected) in cage.quads()[k].corners.iter().zip(basis) {
            let got = f64::from(weights.row(0)[*corner as usize]);
            assert!(
                (got - expected).abs() < 1e-6,
                "{method:?}: {got} vs {expected}"
            );
        }
    }
}

fn write_obj(
    dir: &std::path::Path,
    name: &str,
    positions: &[DVec3],
    faces: &[Vec<u32>],
) -> std::path::PathBuf {
    let mut text = String::new();
    for p in positions {
        text += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for face in faces {
        let corners: Vec<String> = face.iter().map(|i| (i + 1).to_string()).collect();
        text += &format!("f {}\n", corners.join(" "));
    }
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_folded_quad_in_a_file_is_an_error_naming_the_file_and_face() {
    let dir = tempfile::tempdir().unwrap();
    let mut quads = cube_quads();
    quads[3].swap(0, 1);
    let path = write_obj(dir.path(), "folded.obj", &cube_positions(), &quads);
    let error = load_cage(&path).expect_err("folded");
    let text = error.to_string();
    assert!(text.contains("folded.obj"), "{text}");
    assert!(
        text.contains("face 4 is a quad that folds over itself"),
        "{text}"
    );

    // `pmvc check` says the same (the command line needs the `editor` feature).
    #[cfg(feature = "editor")]
    {
        let mesh = write_obj(dir.path(), "mesh.obj", &[DVec3::splat(0.5)], &[]);
        let output = Command::new(env!("CARGO_BIN_EXE_pmvc"))
            .args(["check", "--mesh"])
            .arg(&mesh)
            .arg("--cage")
            .arg(&path)
            .output()
            .unwrap();
        assert_eq!(output.status.code(), Some(1));
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            stderr.contains("face 4 is a quad that folds over itself"),
            "{stderr}"
        );
    }
}

#[cfg(feature = "editor")]
#[test]
fn check_reports_how_far_the_split_moves_the_mesh_on_a_cage_with_quads() {
    let dir = tempfile::tempdir().unwrap();
    let cage = twisted_box(2.0, 0.6);
    let polygons: Vec<Vec<u32>> = cage.quads().iter().map(|q| q.corners.to_vec()).collect();
    let cage_path = write_obj(dir.path(), "box.obj", cage.positions(), &polygons);
    let points = pmvc::geometry::procedural::points_inside(&cage, 200, 7, 0.05);
    let mesh_path = write_obj(dir.path(), "points.obj", &points, &[]);
    let output = Command::new(env!("CARGO_BIN_EXE_pmvc"))
        .args([
            "check",
            "--sample",
            "200",
            "--grid",
            "16",
            "--resolution",
            "16",
            "--mesh",
        ])
        .arg(&mesh_path)
        .arg("--cage")
        .arg(&cage_path)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(
        stdout.contains("6 quads (bilinear patches) and 0 triangles"),
        "{stdout}"
    );
    let line = |family: &str| {
        stdout
            .lines()
            .find(|l| l.trim_start().starts_with(family))
            .unwrap_or_else(|| panic!("no {family} line in {stdout}"))
            .to_owned()
    };
    for family in ["QMVC:", "PMVC 16²:", "HC grid 16:", "QGC:"] {
        let text = line(family);
        assert!(text.contains("shorter vs longer"), "{text}");
        assert!(text.contains("bilinear patches vs shorter"), "{text}");
        // The split moves the mesh: the figure is not zero.
        let shown = text.split("shorter vs longer ").nth(1).unwrap();
        let mean: f64 = shown.split('%').next().unwrap().trim().parse().unwrap();
        assert!(mean > 0.01, "{text}");
    }
}

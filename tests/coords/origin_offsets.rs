//! The same scene at the origin and far from it gives the same answers: cage
//! validation (orientation, volume), point classes, the weights of every family and
//! the deformed positions, through the library and through the command line.
//! Offsets of 1e3, 1e6 and 1e7 along (1, 1, 1): a scene in world or geodetic
//! coordinates must not depend on where the origin is.

use glam::DVec3;
use pmvc::coords::{bind_cpu, BindOptions, BindProgress, Method, Weights};
use pmvc::geometry::{classify_points, procedural, Cage, PointClass, TriMesh};
use std::path::{Path, PathBuf};

const OFFSETS: [f64; 3] = [1e3, 1e6, 1e7];
/// Weights of the same point at two offsets agree to this (they are f32: a few
/// units of their last place).
const WEIGHT_TOLERANCE: f64 = 1e-6;
/// Positions, relative to the offset, agree to this share of the cage diagonal.
const POSITION_TOLERANCE: f64 = 1e-6;

fn shift(positions: &[DVec3], offset: f64) -> Vec<DVec3> {
    positions
        .iter()
        .map(|&p| p + DVec3::splat(offset))
        .collect()
}

fn cage_at(cage: &Cage, offset: f64) -> Cage {
    let (shifted, report) = Cage::new(TriMesh {
        positions: shift(cage.positions(), offset),
        triangles: cage.triangles().to_vec(),
        // The faces keep the quads: without them the shifted cage would be split.
        triangle_faces: cage.triangle_faces().to_vec(),
    })
    .unwrap_or_else(|e| panic!("offset {offset}: {e}"));
    assert_eq!(
        shifted.quads().len(),
        cage.quads().len(),
        "offset {offset}: quads lost"
    );
    assert!(
        !report.flipped,
        "offset {offset}: an outward cage was flipped"
    );
    shifted
}

/// A 2.34-wide box around a 762-vertex sphere of radius 1.
fn box_and_sphere() -> (Cage, Vec<DVec3>) {
    let sphere = procedural::uv_sphere(1.0, 20, 40);
    assert_eq!(sphere.vertex_count(), 762);
    (procedural::cube_cage(1.17), sphere.positions().to_vec())
}

/// A comb (non-convex: PMVC's visibility matters) with points inside, some of them
/// on its surface.
fn comb_and_points() -> (Cage, Vec<DVec3>) {
    let cage = procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5);
    let mut points = procedural::points_inside(&cage, 150, 17, 1e-3);
    points.extend((0..cage.triangle_count()).step_by(3).map(|t| {
        let [a, b, c] = cage.triangle(t);
        (a + 2.0 * b + 3.0 * c) / 6.0
    }));
    (cage, points)
}

fn options(method: Method) -> BindOptions {
    BindOptions {
        resolution: 32,
        // BBW's factor grows as the grid's fourth power and LBC's iterations
        // with its size: a coarse grid keeps this test about the offsets.
        grid: if matches!(method, Method::Bbw | Method::Lbc) {
            12
        } else {
            32
        },
        ..BindOptions::for_method(method)
    }
}

fn bind(cage: &Cage, points: &[DVec3], method: Method) -> Weights {
    let classes = classify_points(cage, points).classes;
    bind_cpu(
        points,
        &classes,
        cage,
        options(method),
        &BindProgress::default(),
    )
    .expect("bound")
}

/// The largest difference between two weights matrices of the same shape; Green's
/// ψ columns (past `vertex_columns`) are lengths and are compared relative to
/// `diagonal`.
fn weights_difference(a: &Weights, b: &Weights, vertex_columns: usize, diagonal: f64) -> f64 {
    assert_eq!((a.rows, a.cols), (b.rows, b.cols));
    let mut worst = 0.0f64;
    for (k, (&x, &y)) in a.values.iter().zip(&b.values).enumerate() {
        let scale = if k % a.cols < vertex_columns {
            1.0
        } else {
            diagonal
        };
        worst = worst.max((f64::from(x) - f64::from(y)).abs() / scale);
    }
    worst
}

fn same_classes(at_origin: &[PointClass], shifted: &[PointClass]) -> Result<(), String> {
    for (i, (a, b)) in at_origin.iter().zip(shifted).enumerate() {
        let same = match (a, b) {
            (
                PointClass::OnSurface { triangle: s, .. },
                PointClass::OnSurface { triangle: t, .. },
            ) => s == t,
            _ => a == b,
        };
        if !same {
            return Err(format!("point {i}: {a:?} at the origin, {b:?} shifted"));
        }
    }
    Ok(())
}

/// A pose of the cage: every vertex moved by a smooth, non-affine map.
fn pose_of(positions: &[DVec3], centre: DVec3) -> Vec<DVec3> {
    positions
        .iter()
        .map(|&p| {
            let q = p - centre;
            p + DVec3::new(0.3 * q.y * q.z, 0.2 * q.x.sin(), 0.25 * q.x * q.y)
        })
        .collect()
}

/// Deformed positions, relative to `centre`: the rest points moved by the
/// weights applied to the pose's column displacements (what `pmvc deform` does).
fn deformed(
    cage: &Cage,
    points: &[DVec3],
    weights: &Weights,
    method: Method,
    centre: DVec3,
) -> Vec<DVec3> {
    let pose = pose_of(cage.positions(), centre);
    let moves = method.column_displacements(cage, &pose);
    weights
        .apply_displacements(points, &moves)
        .into_iter()
        .map(|p| p - centre)
        .collect()
}

fn library_scene_is_the_same_everywhere(name: &str, cage: &Cage, points: &[DVec3]) {
    let diagonal = cage.diagonal();
    let classes = classify_points(cage, points);
    let volume = cage.signed_volume();
    let reference: Vec<(Method, Weights, Vec<DVec3>)> = Method::ALL
        .iter()
        .map(|&method| {
            let weights = bind(cage, points, method);
            let moved = deformed(cage, points, &weights, method, DVec3::ZERO);
            (method, weights, moved)
        })
        .collect();
    for offset in OFFSETS {
        let shifted_cage = cage_at(cage, offset);
        let shifted_points = shift(points, offset);
        let volume_at = shifted_cage.signed_volume();
        assert!(
            (volume_at - volume).abs() <= 1e-6 * volume,
            "{name} at {offset}: volume {volume_at}, {volume} at the origin"
        );
        let shifted_classes = classify_points(&shifted_cage, &shifted_points);
        if let Err(problem) = same_classes(&classes.classes, &shifted_classes.classes) {
            panic!("{name} at {offset}: {problem}");
        }
        for (method, weights, moved) in &reference {
            let shifted_weights = bind(&shifted_cage, &shifted_points, *method);
            let difference = weights_difference(
                weights,
                &shifted_weights,
                method.vertex_columns(cage),
                diagonal,
            );
            assert!(
                difference <= WEIGHT_TOLERANCE,
                "{name} at {offset}, {method:?}: weights differ by {difference:e}"
            );
            let shifted_moved = deformed(
                &shifted_cage,
                &shifted_points,
                &shifted_weights,
                *method,
                DVec3::splat(offset),
            );
            let what = format!("{name} at {offset}, {method:?}");
            assert_same_positions(&what, moved, &shifted_moved, diagonal);
        }
    }
}

/// The deformed positions of the scene at the origin and of the shifted one
/// (with the offset taken off) agree within the tolerance.
fn assert_same_positions(what: &str, at_origin: &[DVec3], shifted: &[DVec3], diagonal: f64) {
    let worst = at_origin
        .iter()
        .zip(shifted)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    assert!(
        worst <= POSITION_TOLERANCE * diagonal,
        "{what}: deformed positions differ by {worst:e}"
    );
}

#[test]
fn a_box_around_a_sphere_binds_the_same_far_from_the_origin() {
    let (cage, points) = box_and_sphere();
    library_scene_is_the_same_everywhere("box and sphere", &cage, &points);
}

#[test]
fn a_comb_binds_the_same_far_from_the_origin() {
    let (cage, points) = comb_and_points();
    library_scene_is_the_same_everywhere("comb", &cage, &points);
}

#[test]
fn an_inward_cage_far_from_the_origin_is_flipped_with_its_volume() {
    let cube = procedural::cube_cage(1.17);
    let expected = 2.34f64.powi(3);
    for offset in [0.0, 6.4e6, 1e7] {
        let inward = TriMesh {
            positions: shift(cube.positions(), offset),
            triangles: cube
                .triangles()
                .iter()
                .map(|&[a, b, c]| [a, c, b])
                .collect(),
            triangle_faces: Vec::new(),
        };
        let (cage, report) = Cage::new(inward).expect("valid");
        assert!(report.flipped, "offset {offset}: not flipped");
        assert!(
            (report.volume - expected).abs() <= 1e-6 * expected,
            "offset {offset}: volume {}, expected {expected}",
            report.volume
        );
        assert!(cage.signed_volume() > 0.0, "offset {offset}: still inward");
    }
}

/// The harmonic grid's node count is exact even where it does not fit 64 bits.
#[test]
fn a_huge_harmonic_grid_reports_its_true_node_count() {
    let cube = procedural::cube_cage(1.0);
    let error = pmvc::coords::harmonic::plan(&cube, u32::MAX, 1).expect_err("refused");
    let text = error.to_string();
    let nodes: u128 = text
        .split(" has ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no node count in: {text}"));
    // 2³² cells and the margins, rounded up to whole multigrid steps: a little over
    // 2³² nodes per side.
    let side = (1u128 << 32) as f64;
    assert!(
        nodes as f64 >= side.powi(3) && (nodes as f64) < (side + 256.0).powi(3),
        "{text}"
    );
}

/// Where the shared evaluation data is.
fn qmvc_data() -> Option<PathBuf> {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/qmvc");
    data.join("ManHead.obj").exists().then_some(data)
}

/// ManHead and its artist cage, triangulated at the origin.
fn man_head() -> Option<(Cage, Vec<DVec3>)> {
    let data = qmvc_data()?;
    let mesh = pmvc::formats::load_mesh(&data.join("ManHead.obj")).expect("mesh");
    let (cage, _) = pmvc::formats::load_cage(&data.join("ManHead_Cage.obj")).expect("cage");
    Some((cage, mesh.mesh.positions))
}

#[test]
fn a_real_model_binds_the_same_far_from_the_origin() {
    let Some((cage, points)) = man_head() else {
        println!("not run: ../shared/data/qmvc is not present");
        return;
    };
    // Every 8th vertex: the whole head, at a fraction of the time.
    let points: Vec<DVec3> = points.into_iter().step_by(8).collect();
    library_scene_is_the_same_everywhere("ManHead", &cage, &points);
}

#[cfg(feature = "editor")]
mod command_line {
    use super::*;
    use crate::common::*;
    use pmvc::formats::npy::{read_npy, ExpectedArray};
    use pmvc::formats::npz::read_npz;

    /// What `pmvc check` says about one scene, the parts that must not move.
    #[derive(Debug, PartialEq)]
    struct Checked {
        orientation: String,
        inside: String,
        volume: f64,
    }

    fn check(mesh: &Path, cage: &Path) -> Checked {
        let output = pmvc(&["check", "--mesh", path_str(mesh), "--cage", path_str(cage)]);
        let text = String::from_utf8_lossy(&output.stdout).into_owned();
        assert!(output.status.success(), "{}{}", text, stderr(&output));
        let line = |prefix: &str| {
            text.lines()
                .find(|l| l.trim_start().starts_with(prefix))
                .unwrap_or_else(|| panic!("no '{prefix}' line in:\n{text}"))
                .trim()
                .to_owned()
        };
        let volume_line = line("volume ");
        let volume = volume_line
            .strip_prefix("volume ")
            .and_then(|rest| rest.split(',').next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("{volume_line}"));
        let orientation = volume_line
            .split("faces point ")
            .nth(1)
            .and_then(|rest| rest.split(", diagonal").next())
            .unwrap_or_else(|| panic!("{volume_line}"))
            .to_owned();
        let inside = text
            .lines()
            .find(|l| l.starts_with("inside:") || l.starts_with("outside:"))
            .unwrap_or_else(|| panic!("no inside/outside line in:\n{text}"))
            .to_owned();
        Checked {
            orientation,
            inside,
            volume,
        }
    }

    struct SceneFiles {
        mesh: PathBuf,
        cage: PathBuf,
        pose: PathBuf,
    }

    fn write_scene(dir: &Path, cage: &Cage, points: &[DVec3], offset: f64) -> SceneFiles {
        let centre = DVec3::splat(offset);
        let shifted = shift(cage.positions(), offset);
        SceneFiles {
            mesh: write(dir, "mesh.obj", &points_obj(&shift(points, offset))),
            cage: write(dir, "cage.obj", &triangles_obj(&shifted, cage.triangles())),
            pose: write(
                dir,
                "pose.obj",
                &triangles_obj(&pose_of(&shifted, centre), cage.triangles()),
            ),
        }
    }

    fn cli_bind(
        files: &SceneFiles,
        dir: &Path,
        method: Method,
        cage: &Cage,
        rows: usize,
    ) -> Weights {
        let name = method.spec().id;
        let green = method == Method::Green;
        let out = dir.join(format!("{name}.{}", if green { "npz" } else { "npy" }));
        let output = pmvc(&[
            "bind",
            "--mesh",
            path_str(&files.mesh),
            "--cage",
            path_str(&files.cage),
            "--method",
            name,
            "--resolution",
            "32",
            "--grid",
            cli_grid(method),
            "--backend",
            "cpu",
            "--out",
            path_str(&out),
        ]);
        assert!(output.status.success(), "{name}: {}", stderr(&output));
        if green {
            read_npz(&out, rows, cage.vertex_count(), cage.triangle_count()).expect("npz")
        } else {
            let expected = ExpectedArray::of_layout(
                method.spec().columns,
                rows,
                cage.vertex_count(),
                cage.triangle_count(),
            );
            read_npy(&out, expected).expect("npy")
        }
    }

    /// BBW and LBC bind at a coarse grid, as [`options`] says why.
    fn cli_grid(method: Method) -> &'static str {
        if matches!(method, Method::Bbw | Method::Lbc) {
            "12"
        } else {
            "32"
        }
    }

    fn cli_deform(files: &SceneFiles, dir: &Path, method: Method, offset: f64) -> Vec<DVec3> {
        let name = method.spec().id;
        let out = dir.join(format!("{name}-deformed.obj"));
        let output = pmvc(&[
            "deform",
            "--mesh",
            path_str(&files.mesh),
            "--cage",
            path_str(&files.cage),
            "--deformed-cage",
            path_str(&files.pose),
            "--method",
            name,
            "--resolution",
            "32",
            "--grid",
            cli_grid(method),
            "--backend",
            "cpu",
            "--out",
            path_str(&out),
        ]);
        assert!(output.status.success(), "{name}: {}", stderr(&output));
        let moved = pmvc::formats::load_mesh(&out).expect("deformed mesh");
        moved
            .mesh
            .positions
            .iter()
            .map(|&p| p - DVec3::splat(offset))
            .collect()
    }

    fn command_line_scene_is_the_same_everywhere(name: &str, cage: &Cage, points: &[DVec3]) {
        let diagonal = cage.diagonal();
        let run = |offset: f64| {
            let dir = tempfile::tempdir().unwrap();
            let files = write_scene(dir.path(), cage, points, offset);
            let checked = check(&files.mesh, &files.cage);
            let results: Vec<(Method, Weights, Vec<DVec3>)> = Method::ALL
                .iter()
                .map(|&method| {
                    (
                        method,
                        cli_bind(&files, dir.path(), method, cage, points.len()),
                        cli_deform(&files, dir.path(), method, offset),
                    )
                })
                .collect();
            (checked, results)
        };
        let (checked, reference) = run(0.0);
        assert_eq!(checked.orientation, "outward", "{name}");
        for offset in OFFSETS {
            let (shifted_checked, results) = run(offset);
            assert_eq!(
                (&shifted_checked.orientation, &shifted_checked.inside),
                (&checked.orientation, &checked.inside),
                "{name} at {offset}"
            );
            assert!(
                (shifted_checked.volume - checked.volume).abs() <= 1e-5 * checked.volume,
                "{name} at {offset}: volume {} against {}",
                shifted_checked.volume,
                checked.volume
            );
            for ((method, weights, moved), (_, shifted_weights, shifted_moved)) in
                reference.iter().zip(&results)
            {
                let difference = weights_difference(
                    weights,
                    shifted_weights,
                    method.vertex_columns(cage),
                    diagonal,
                );
                assert!(
                    difference <= WEIGHT_TOLERANCE,
                    "{name} at {offset}, {method:?}: weights differ by {difference:e}"
                );
                let what = format!("{name} at {offset}, {method:?}");
                assert_same_positions(&what, moved, shifted_moved, diagonal);
            }
        }
    }

    #[test]
    fn every_command_gives_the_same_box_and_sphere_far_from_the_origin() {
        let (cage, points) = box_and_sphere();
        command_line_scene_is_the_same_everywhere("box and sphere", &cage, &points);
    }

    #[test]
    fn every_command_gives_the_same_real_model_far_from_the_origin() {
        let Some((cage, points)) = man_head() else {
            println!("not run: ../shared/data/qmvc is not present");
            return;
        };
        command_line_scene_is_the_same_everywhere("ManHead", &cage, &points);
    }
}

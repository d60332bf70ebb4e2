//! Figures quoted in docs/*.md that no other suite prints: each test computes one,
//! prints it (`cargo test --release --no-default-features --test coords
//! doc_figures:: -- --nocapture`) and asserts the claim the docs make of it.

use glam::DVec3;
use pmvc::coords::green::{bind_green, face_vectors};
use pmvc::coords::{bind_cpu, BindOptions, BindProgress, Method, Weights};
use pmvc::formats::{load_cage, load_mesh};
use pmvc::geometry::{classify_points, Cage, TriMesh};
use std::path::{Path, PathBuf};

/// The comparison gallery's pose of the bundled comb.
const GALLERY_POSE: &str = "docs/poses/middle-finger-forward.obj";
/// The comb's fingers: one unit wide, 0.4 apart, above a palm one unit high.
const FINGER_PITCH: f64 = 1.4;
const PALM_TOP: f64 = 1.0;
const MIDDLE_FINGER: usize = 2;

fn repository(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

fn positions(path: &Path) -> Vec<DVec3> {
    load_mesh(path).unwrap().mesh.positions
}

/// The finger a mesh vertex of the bundled comb belongs to; `None` in the palm.
fn finger_of(p: DVec3) -> Option<usize> {
    (p.y > PALM_TOP + 0.5).then(|| (p.x / FINGER_PITCH).floor() as usize)
}

/// Every mesh vertex moved by `weights` from the rest cage to `pose`, in the
/// displacement form every front end uses.
/// The mesh deformed by `method`'s weights: each column's vector moved as the
/// family says (cage vertices' moves, and Green's or Somigliana's face terms).
fn deformed(
    method: Method,
    weights: &Weights,
    mesh: &[DVec3],
    cage: &Cage,
    pose: &[DVec3],
) -> Vec<DVec3> {
    weights.apply_displacements(mesh, &method.column_displacements(cage, pose))
}

fn bind(mesh: &[DVec3], cage: &Cage, options: BindOptions) -> Weights {
    let classes = classify_points(cage, mesh).classes;
    bind_cpu(
        mesh,
        &classes,
        cage,
        options,
        &BindProgress::new(mesh.len()),
    )
    .unwrap()
}

#[test]
fn the_gallery_pose_does_not_cross_itself() {
    let loaded = load_cage(&repository(GALLERY_POSE));
    assert!(loaded.is_ok(), "{}", loaded.unwrap_err());
}

/// docs/comparison.md and docs/user-guide.md: in the gallery's pose, MVC move the
/// middle finger's neighbours the other way, PMVC and HC leave them in place,
/// MEC, MLC, BBW and LBC (positive, not local) move them with the pull, if at
/// all, and Somigliana coordinates (elastic) by a fraction of a percent with it.
#[test]
fn in_the_gallery_pose_mvc_move_the_neighbours_the_other_way() {
    let mesh = positions(&repository("assets/comb_mesh.obj"));
    let (cage, _) = load_cage(&repository("assets/comb_cage.obj")).unwrap();
    let pose = positions(&repository(GALLERY_POSE));
    let diagonal = cage.diagonal();
    let moved: Vec<DVec3> = pose
        .iter()
        .zip(cage.positions())
        .map(|(a, b)| *a - *b)
        .filter(|m| m.length() > 1e-9 * diagonal)
        .collect();
    let pulled = moved[0];
    assert!(
        moved.iter().all(|m| m.distance(pulled) < 1e-6 * diagonal),
        "one move"
    );
    println!(
        "pose: {} cage vertices moved by {pulled:?} ({:.3} of the diagonal {diagonal:.3})",
        moved.len(),
        pulled.length() / diagonal
    );
    let direction = pulled.normalize();
    for (name, options) in [
        ("MVC", BindOptions::for_method(Method::Mvc)),
        ("PMVC 32²", BindOptions::for_method(Method::Pmvc)),
        ("HC 64", BindOptions::for_method(Method::Harmonic)),
        ("MEC", BindOptions::for_method(Method::Mec)),
        ("MLC", BindOptions::for_method(Method::Mlc)),
        ("BBW 32", BindOptions::for_method(Method::Bbw)),
        ("LBC 32", BindOptions::for_method(Method::Lbc)),
        (
            "Somigliana ν 0",
            BindOptions::for_method(Method::Somigliana),
        ),
    ] {
        let after = deformed(
            options.method,
            &bind(&mesh, &cage, options),
            &mesh,
            &cage,
            &pose,
        );
        for finger in [MIDDLE_FINGER - 1, MIDDLE_FINGER + 1] {
            let (vertex, shift) = (0..mesh.len())
                .filter(|&i| finger_of(mesh[i]) == Some(finger))
                .map(|i| (i, after[i] - mesh[i]))
                .max_by(|a, b| a.1.length().total_cmp(&b.1.length()))
                .unwrap();
            let along = shift.dot(direction);
            println!(
                "{name}: finger {} moves most at mesh vertex {vertex} (0-based, at {:.2}), by {:.2e} of the diagonal, {:+.2e} along the pull, {:.3}",
                finger + 1,
                mesh[vertex],
                shift.length() / diagonal,
                along / diagonal,
                shift
            );
            match options.method {
                Method::Mvc => assert!(
                    along < -0.01 * diagonal,
                    "MVC: finger {} does not move against the pull",
                    finger + 1
                ),
                // Positive but global: the neighbours follow the pull a little,
                // never against it.
                // (A positive partition of unity moves every point by a
                // share of the one move.)
                Method::Mec | Method::Mlc | Method::Bbw | Method::Lbc => assert!(
                    along > -1e-9 * diagonal && along >= 0.5 * shift.length(),
                    "{name}: finger {} moves against the pull",
                    finger + 1
                ),
                // Elastic and global: the palm under the pulled finger is
                // dragged along, and the neighbours' roots with it, by a
                // fraction of a percent.
                Method::Somigliana => assert!(
                    shift.length() < 1e-2 * diagonal && along > 0.5 * shift.length(),
                    "{name}: finger {} moves more, or not with the pull",
                    finger + 1
                ),
                _ => assert!(shift.length() < 1e-3 * diagonal, "{name} moves it"),
            }
        }
    }
}

/// docs/coordinates.md: harmonic coordinates on the bundled comb's own vertices,
/// grid 32 against 64 and 64 against 128.
#[test]
fn harmonic_coordinates_on_the_comb_vertices_converge() {
    let mesh = positions(&repository("assets/comb_mesh.obj"));
    let (cage, _) = load_cage(&repository("assets/comb_cage.obj")).unwrap();
    let solutions: Vec<Weights> = [32, 64, 128]
        .into_iter()
        .map(|grid| {
            let options = BindOptions {
                grid,
                ..BindOptions::for_method(Method::Harmonic)
            };
            bind(&mesh, &cage, options)
        })
        .collect();
    let difference = |a: &Weights, b: &Weights| {
        a.values
            .iter()
            .zip(&b.values)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f32, f32::max)
    };
    let coarse = difference(&solutions[0], &solutions[1]);
    let fine = difference(&solutions[1], &solutions[2]);
    println!(
        "bundled comb, its {} vertices: max |h32 − h64| = {coarse:.3e}, max |h64 − h128| = {fine:.3e}",
        mesh.len()
    );
    assert!(fine < coarse, "no convergence: {coarse} then {fine}");
}

fn qmvc_data() -> Option<PathBuf> {
    let candidates = [
        std::env::var_os("PMVC_QMVC_DATA").map(PathBuf::from),
        Some(repository("../shared/data/qmvc")),
        Some(PathBuf::from("/work/shared/data/qmvc")),
    ];
    candidates.into_iter().flatten().find(|path| path.is_dir())
}

/// The cage of an OBJ file with every polygon fanned from its first corner, the
/// triangulation docs/green.md used to describe.
fn fanned_cage(path: &Path) -> Cage {
    let text = std::fs::read_to_string(path).unwrap();
    let mut mesh = TriMesh::default();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let c: Vec<f64> = words.take(3).map(|w| w.parse().unwrap()).collect();
                mesh.positions.push(DVec3::new(c[0], c[1], c[2]));
            }
            Some("f") => {
                let corners: Vec<u32> = words
                    .map(|w| w.split('/').next().unwrap().parse::<u32>().unwrap() - 1)
                    .collect();
                let face = mesh.triangle_faces.iter().max().map_or(0, |f| f + 1);
                for k in 1..corners.len() - 1 {
                    mesh.triangles
                        .push([corners[0], corners[k], corners[k + 1]]);
                    mesh.triangle_faces.push(face);
                }
            }
            _ => {}
        }
    }
    Cage::new(mesh).unwrap().0
}

/// docs/green.md: how far a Green deformation goes wrong when ψ's columns are
/// taken to be the fan triangles of each polygon instead of the binary's
/// shorter-diagonal ones, on the shared models with quad cages.
#[test]
fn reading_psi_as_fan_triangles_moves_the_shared_models() {
    let Some(data) = qmvc_data() else {
        eprintln!("not run: ../shared/data/qmvc is missing");
        return;
    };
    for name in ["Ogre", "Beast"] {
        let mesh = positions(&data.join(format!("{name}.obj")));
        let cage_path = data.join(format!("{name}_Cage.obj"));
        let (cage, _) = load_cage(&cage_path).unwrap();
        let fanned = fanned_cage(&cage_path);
        let pose = positions(&data.join(format!("{name}_Cage_Deformed.obj")));
        let differing = (0..cage.triangle_count())
            .filter(|&t| cage.triangles()[t] != fanned.triangles()[t])
            .count();
        let weights = bind_green(&mesh, &cage, &BindProgress::new(mesh.len())).unwrap();
        let right = weights
            .deform_with_face_vectors(&pose, &face_vectors(&cage, &pose).unwrap())
            .unwrap();
        let wrong = weights
            .deform_with_face_vectors(&pose, &face_vectors(&fanned, &pose).unwrap())
            .unwrap();
        let worst = right
            .iter()
            .zip(&wrong)
            .map(|(a, b)| a.distance(*b))
            .fold(0.0, f64::max);
        println!(
            "{name}: {differing} of {} triangles differ from the fan; Σφv′ + Σψsn′ off by up to {:.2}% of the cage diagonal",
            cage.triangle_count(),
            100.0 * worst / cage.diagonal()
        );
        assert!(
            differing > 0,
            "{name}: the fan is the binary's triangulation"
        );
    }
}

//! QGC, Green coordinates on bilinear quads: φ and ψ against their defining
//! boundary integrals by brute-force quadrature written here, the rest pose and
//! similarities (rotations, uniform scale, translation, far from the origin)
//! reproduced, rotation invariance, and an all-triangle cage giving today's
//! Green coordinates exactly. Figures print with `--nocapture`
//! (docs/coordinates.md quotes them).

use glam::{DMat3, DVec3};
use pmvc::coords::green::{
    face_columns, green_coordinates, qgc_coordinates, qgc_face_vectors, rest_face_vectors,
};
use pmvc::coords::{bind_cpu_f64, BindOptions, BindProgress, Method};
use pmvc::geometry::procedural::{self, SplitMix64};
use pmvc::geometry::procedural_quads::{cage_from_polygons, quad_comb, twisted_box};
use pmvc::geometry::Cage;
use std::f64::consts::PI;

/// A box whose roof is four triangles meeting at an apex: quads and triangles.
fn house() -> Cage {
    let mut positions: Vec<DVec3> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .flat_map(|&(x, y)| [DVec3::new(x, y, 0.0), DVec3::new(x, y, 1.2)])
        .collect();
    positions.push(DVec3::new(0.1, -0.2, 2.0));
    // Bottom corners 0 2 4 6, top corners 1 3 5 7, apex 8.
    let polygons = vec![
        vec![0, 6, 4, 2],
        vec![0, 2, 3, 1],
        vec![2, 4, 5, 3],
        vec![4, 6, 7, 5],
        vec![6, 0, 1, 7],
        vec![1, 3, 8],
        vec![3, 5, 8],
        vec![5, 7, 8],
        vec![7, 1, 8],
    ];
    cage_from_polygons(&positions, &polygons).unwrap().0
}

/// Convex and non-convex cages with bent quads.
fn cages() -> Vec<(&'static str, Cage)> {
    vec![
        ("twisted box", twisted_box(2.0, 0.7)),
        ("house", house()),
        ("bent comb", quad_comb(3, 1.0, 0.5, 2.0, 1.0, 0.4)),
    ]
}

fn coordinates(cage: &Cage, x: DVec3) -> (Vec<f64>, Vec<f64>) {
    let mut phi = vec![0.0; cage.vertex_count()];
    let mut psi = vec![0.0; face_columns(cage)];
    qgc_coordinates(x, cage, &mut phi, &mut psi).unwrap();
    (phi, psi)
}

/// `Σ φᵢ vᵢ + Σ ψⱼ fⱼ`, summed relative to `origin` (the sums carry no far
/// coordinates).
fn apply(phi: &[f64], psi: &[f64], positions: &[DVec3], faces: &[DVec3], origin: DVec3) -> DVec3 {
    let vertices: DVec3 = phi
        .iter()
        .zip(positions)
        .map(|(&w, &p)| w * (p - origin))
        .sum();
    let total: f64 = phi.iter().sum();
    let faces: DVec3 = psi.iter().zip(faces).map(|(&w, &f)| w * f).sum();
    origin * total + vertices + faces
}

// --- The reference: the defining integrals by brute force. ---

/// The faces as bilinear patches: quads as they are, triangles (a, b, c) as
/// the collapsed patch (a, b, c, c), with the column each one's ψ goes to.
fn patches(cage: &Cage) -> Vec<([u32; 4], Vec<usize>)> {
    let mut list = Vec::new();
    let lone: Vec<usize> = cage.lone_triangles().collect();
    for (column, &t) in lone.iter().enumerate() {
        let [a, b, c] = cage.triangles()[t];
        list.push(([a, b, c, c], vec![column]));
    }
    for (k, quad) in cage.quads().iter().enumerate() {
        let base = lone.len() + 4 * k;
        list.push((quad.corners, (base..base + 4).collect()));
    }
    list
}

/// φ and ψ of `x` as `∫ B (P − x)·N / 4π|P − x|³` and `∫ B / 4π|P − x|`, with
/// `N = ∂P/∂u × ∂P/∂v`, by 4-point Gauss–Legendre on a `cells`² grid. For a
/// triangle, ψ is the single layer over its area: `∫ |N| / 4π r`.
fn reference(cage: &Cage, x: DVec3, cells: usize) -> (Vec<f64>, Vec<f64>) {
    let nodes = [
        (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
        (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    ];
    let mut phi = vec![0.0; cage.vertex_count()];
    let mut psi = vec![0.0; face_columns(cage)];
    let h = 1.0 / cells as f64;
    for (corners, columns) in patches(cage) {
        let q = corners.map(|i| cage.positions()[i as usize] - x);
        for cell in 0..cells * cells {
            let (u0, v0) = ((cell % cells) as f64 * h, (cell / cells) as f64 * h);
            for (s, ws) in nodes {
                for (t, wt) in nodes {
                    let (u, v) = (u0 + h * (s + 1.0) / 2.0, v0 + h * (t + 1.0) / 2.0);
                    let b = [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v];
                    let p: DVec3 = (0..4).map(|i| b[i] * q[i]).sum();
                    let du = (1.0 - v) * (q[1] - q[0]) + v * (q[2] - q[3]);
                    let dv = (1.0 - u) * (q[3] - q[0]) + u * (q[2] - q[1]);
                    let n = du.cross(dv);
                    let r = p.length();
                    let w = ws * wt * h * h / 4.0 / (4.0 * PI);
                    for i in 0..4 {
                        phi[corners[i] as usize] += w * b[i] * p.dot(n) / (r * r * r);
                    }
                    if columns.len() == 1 {
                        psi[columns[0]] += w * n.length() / r;
                    } else {
                        for i in 0..4 {
                            psi[columns[i]] += w * b[i] / r;
                        }
                    }
                }
            }
        }
    }
    (phi, psi)
}

#[test]
fn coordinates_match_their_defining_integrals() {
    for (name, cage) in cages() {
        let mut worst = 0.0f64;
        for x in procedural::points_inside(&cage, 6, 3, 0.04) {
            let (phi, psi) = coordinates(&cage, x);
            let (ref_phi, ref_psi) = reference(&cage, x, 128);
            for (a, b) in phi.iter().zip(&ref_phi).chain(psi.iter().zip(&ref_psi)) {
                worst = worst.max((a - b).abs());
            }
        }
        eprintln!("{name}: |QGC − brute force| ≤ {worst:.1e}");
        assert!(worst < 1e-8, "{name}: {worst}");
    }
}

/// Points on the patches (inside, on an edge, at a corner) of the first quads.
fn points_on_quads(cage: &Cage) -> Vec<DVec3> {
    let mut points = Vec::new();
    for k in 0..cage.quads().len().min(4) {
        let q = cage.quad(k);
        let at = |u: f64, v: f64| {
            (1.0 - u) * (1.0 - v) * q[0]
                + u * (1.0 - v) * q[1]
                + u * v * q[2]
                + (1.0 - u) * v * q[3]
        };
        points.extend([at(0.3, 0.6), at(0.0, 0.4), at(1.0, 1.0)]);
    }
    points
}

/// Points off the surface: inside, some near it, and outside.
fn points_off_surface(cage: &Cage, seed: u64) -> Vec<DVec3> {
    let mut points = procedural::points_inside(cage, 30, seed, 1e-3);
    points.extend(procedural::points_inside(cage, 10, seed + 1, 1e-6));
    let (lo, hi) = pmvc::geometry::bounds_of(cage.positions());
    let mut random = SplitMix64(seed + 2);
    while points.len() < 60 {
        let unit = DVec3::new(random.unit(), random.unit(), random.unit()) * 2.0 - 1.0;
        let x = (lo + hi) / 2.0 + unit * (hi - lo) * 0.8;
        if procedural::distance_to_surface(cage, x) > 1e-3 * cage.diagonal() {
            points.push(x);
        }
    }
    points
}

/// Inside, near the surface, on it (on quads, on edges and corners), outside.
fn test_points(cage: &Cage, seed: u64) -> Vec<DVec3> {
    let mut points = points_off_surface(cage, seed);
    points.extend(points_on_quads(cage));
    points
}

#[test]
fn the_rest_pose_is_reproduced_inside_on_and_outside() {
    for (name, cage) in cages() {
        let faces = rest_face_vectors(&cage);
        let mut worst = 0.0f64;
        for x in test_points(&cage, 5) {
            let (phi, psi) = coordinates(&cage, x);
            let y = apply(&phi, &psi, cage.positions(), &faces, x);
            worst = worst.max((y - x).length());
            assert!((phi.iter().sum::<f64>() - 1.0).abs() < 1e-9, "{name} {x}");
        }
        eprintln!(
            "{name}: rest error {:.1e} of the diagonal",
            worst / cage.diagonal()
        );
        assert!(worst <= 1e-10 * cage.diagonal(), "{name}: {worst}");
    }
}

fn rotation() -> DMat3 {
    DMat3::from_axis_angle(DVec3::new(1.0, -2.0, 0.5).normalize(), 0.9)
}

/// The largest error, over the test points, of the cage moved by `map` moving
/// each point by `map`, relative to the diagonal; weights bound by the family.
fn similarity_error(cage: &Cage, map: impl Fn(DVec3) -> DVec3) -> f64 {
    let points = test_points(cage, 9);
    let options = BindOptions::for_method(Method::Green);
    let classes = options.classify(cage, &points);
    let weights = bind_cpu_f64(
        &points,
        &classes.classes,
        cage,
        options,
        &BindProgress::new(points.len()),
    )
    .unwrap();
    let posed: Vec<DVec3> = cage.positions().iter().map(|&p| map(p)).collect();
    let moves = Method::Green.column_displacements(cage, &posed);
    assert_eq!(moves.len(), weights.cols);
    let mut worst = 0.0f64;
    for (row, &x) in points.iter().enumerate() {
        let w = &weights.values[row * weights.cols..(row + 1) * weights.cols];
        // The displacement form the deform paths use: x + Σ w d.
        let moved = x + w.iter().zip(&moves).map(|(&w, &d)| w * d).sum::<DVec3>();
        worst = worst.max((moved - map(x)).length());
    }
    worst / cage.diagonal()
}

type Map = Box<dyn Fn(DVec3) -> DVec3>;

#[test]
fn similarities_of_the_cage_move_points_alike() {
    for (name, cage) in cages() {
        let centre = cage.positions().iter().sum::<DVec3>() / cage.vertex_count() as f64;
        let maps: Vec<(&str, Map)> = vec![
            ("identity", Box::new(|p| p)),
            (
                "rotation",
                Box::new(move |p| centre + rotation() * (p - centre)),
            ),
            ("scale 2.5", Box::new(move |p| centre + 2.5 * (p - centre))),
            ("scale 0.3", Box::new(move |p| centre + 0.3 * (p - centre))),
            ("translation", Box::new(|p| p + DVec3::new(3.0, -1.0, 2.5))),
            (
                "similarity",
                Box::new(move |p| 1.7 * (rotation() * (p - centre)) + DVec3::new(3.0, -1.0, 2.5)),
            ),
        ];
        for (what, map) in &maps {
            let error = similarity_error(&cage, map);
            eprintln!("{name}, {what}: {error:.1e} of the diagonal");
            assert!(error < 1e-10, "{name}, {what}: {error}");
        }
    }
}

#[test]
fn far_from_the_origin_similarities_are_reproduced_alike() {
    let offset = DVec3::splat(1e7);
    for (name, cage) in cages() {
        let polygons = cage.polygons();
        let shifted: Vec<DVec3> = cage.positions().iter().map(|&p| p + offset).collect();
        let far = cage_from_polygons(&shifted, &polygons).unwrap().0;
        assert_eq!(far.quads().len(), cage.quads().len());
        let centre = far.positions().iter().sum::<DVec3>() / far.vertex_count() as f64;
        let error = similarity_error(&far, |p| {
            centre + 1.7 * (rotation() * (p - centre)) + DVec3::new(0.5, 0.2, -0.1)
        });
        eprintln!("{name} at 1e7: similarity error {error:.1e} of the diagonal");
        assert!(error < 1e-8, "{name}: {error}");
    }
}

#[test]
fn coordinates_are_invariant_under_rotation_of_cage_and_point() {
    for (name, cage) in cages() {
        let polygons = cage.polygons();
        let turned: Vec<DVec3> = cage.positions().iter().map(|&p| rotation() * p).collect();
        let rotated = cage_from_polygons(&turned, &polygons).unwrap().0;
        let mut worst = 0.0f64;
        // Off the surface: a point on it is evaluated pushed inward by a
        // fraction of the bounding box's diagonal, which turns with the cage.
        for x in points_off_surface(&cage, 13) {
            let (phi, psi) = coordinates(&cage, x);
            let (phi_r, psi_r) = coordinates(&rotated, rotation() * x);
            for (a, b) in phi.iter().zip(&phi_r).chain(psi.iter().zip(&psi_r)) {
                worst = worst.max((a - b).abs());
            }
        }
        eprintln!("{name}: rotated coordinates differ by {worst:.1e}");
        assert!(worst < 1e-9, "{name}: {worst}");
    }
}

#[test]
fn an_all_triangle_cage_gives_todays_green_coordinates_exactly() {
    let star = procedural::extrude(&procedural::star_outline(5, 0.4, 1.0), -0.3, 0.3);
    for cage in [
        procedural::cube_cage(1.0),
        star,
        twisted_box(2.0, 0.7).split_quads(pmvc::geometry::QuadSplit::Shorter),
    ] {
        assert!(!cage.has_quads());
        assert_eq!(face_columns(&cage), cage.triangle_count());
        let mut points = procedural::points_inside(&cage, 20, 41, 1e-3);
        points.push(cage.positions()[0]);
        points.push(DVec3::new(3.0, 0.2, -0.1));
        for x in points {
            let (phi, psi) = coordinates(&cage, x);
            let mut green_phi = vec![0.0; cage.vertex_count()];
            let mut green_psi = vec![0.0; cage.triangle_count()];
            green_coordinates(x, &cage, &mut green_phi, &mut green_psi).unwrap();
            assert_eq!(phi, green_phi);
            assert_eq!(psi, green_psi);
        }
        let posed: Vec<DVec3> = cage
            .positions()
            .iter()
            .map(|&p| 1.3 * p + DVec3::X)
            .collect();
        assert_eq!(
            qgc_face_vectors(&cage, &posed).unwrap(),
            pmvc::coords::green::face_vectors(&cage, &posed).unwrap()
        );
    }
}

#[test]
fn quads_are_patches_not_their_split_and_a_stretch_is_not_a_similarity() {
    // Guards the tests above against coordinates that ignore the patches or
    // the pose.
    let cage = twisted_box(2.0, 0.7);
    let split = cage.split_quads(pmvc::geometry::QuadSplit::Shorter);
    let x = DVec3::new(0.3, -0.2, 1.0);
    let (phi, _) = coordinates(&cage, x);
    let (split_phi, _) = coordinates(&split, x);
    let difference = phi
        .iter()
        .zip(&split_phi)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(difference > 1e-3, "{difference}");
    let stretched = |p: DVec3| DVec3::new(2.0 * p.x, p.y, p.z);
    assert!(similarity_error(&cage, stretched) > 1e-3);
}

fn qmvc_data() -> Option<std::path::PathBuf> {
    let candidates = [
        std::env::var_os("PMVC_QMVC_DATA").map(std::path::PathBuf::from),
        Some(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/qmvc")),
    ];
    candidates.into_iter().flatten().find(|path| path.is_dir())
}

#[test]
fn on_the_ogre_qgc_reproduce_similarities_and_differ_from_the_split() {
    let Some(data) = qmvc_data() else {
        eprintln!("not run: ../shared/data/qmvc is missing");
        return;
    };
    let load = |name: &str| {
        pmvc::formats::load_mesh(&data.join(name))
            .unwrap()
            .mesh
            .positions
    };
    let (cage, _) = pmvc::formats::load_cage(&data.join("Ogre_Cage.obj")).unwrap();
    assert!(cage.has_quads());
    // Every 20th vertex, for speed.
    let points: Vec<DVec3> = load("Ogre.obj").into_iter().step_by(20).collect();
    let deform = |options: BindOptions, pose: &[DVec3]| {
        let classes = options.classify(&cage, &points);
        let started = std::time::Instant::now();
        let weights = bind_cpu_f64(
            &points,
            &classes.classes,
            &cage,
            options,
            &BindProgress::new(points.len()),
        )
        .unwrap();
        let seconds = started.elapsed().as_secs_f64();
        let moves = options
            .method
            .column_displacements(&options.cage_to_bind(&cage), pose);
        let moved: Vec<DVec3> = (0..points.len())
            .map(|row| {
                let w = &weights.values[row * weights.cols..(row + 1) * weights.cols];
                points[row] + w.iter().zip(&moves).map(|(&w, &d)| w * d).sum::<DVec3>()
            })
            .collect();
        (moved, seconds)
    };
    let qgc = BindOptions::for_method(Method::Green);
    let centre = cage.positions().iter().sum::<DVec3>() / cage.vertex_count() as f64;
    let map = |p: DVec3| centre + 1.7 * (rotation() * (p - centre)) + DVec3::new(0.3, -0.2, 0.1);
    let similar: Vec<DVec3> = cage.positions().iter().map(|&p| map(p)).collect();
    let (moved, seconds) = deform(qgc, &similar);
    let worst = points
        .iter()
        .zip(&moved)
        .map(|(&x, &y)| (map(x) - y).length())
        .fold(0.0, f64::max)
        / cage.diagonal();
    let target = load("Ogre_Cage_Deformed.obj");
    let (posed, _) = deform(qgc, &target);
    let split = BindOptions {
        quads: pmvc::geometry::QuadSplit::Shorter,
        ..qgc
    };
    let (split_posed, split_seconds) = deform(split, &target);
    let apart = posed
        .iter()
        .zip(&split_posed)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max)
        / cage.diagonal();
    eprintln!(
        "Ogre, {} points, {} quads: similarity error {worst:.1e} of the diagonal; at the \
         target pose QGC and the shorter split's Green coordinates {:.2}% of the diagonal \
         apart; bind {seconds:.2} s (split {split_seconds:.2} s)",
        points.len(),
        cage.quads().len(),
        100.0 * apart
    );
    assert!(worst < 1e-8, "{worst}");
    assert!(apart > 1e-4, "{apart}");
}

/// The ψ columns name what they multiply: the house's four lone roof
/// triangles, then four corner normals for each of its five quads; a cage
/// of triangles has one per triangle. Views and exports label ψ by this.
#[test]
fn each_psi_column_names_its_triangle_or_quad_corner() {
    use pmvc::coords::green::{face_column, FaceColumn};
    let cage = house();
    let lone: Vec<usize> = (0..cage.triangle_count())
        .filter(|&t| {
            let corners = cage.triangles()[t];
            !cage
                .quads()
                .iter()
                .any(|q| corners.iter().all(|c| q.corners.contains(c)))
        })
        .collect();
    assert_eq!(lone.len(), 4, "the roof");
    assert_eq!(face_columns(&cage), 4 + 4 * 5);
    for (k, &t) in lone.iter().enumerate() {
        assert_eq!(face_column(&cage, k), Some(FaceColumn::Triangle(t)));
    }
    assert_eq!(
        face_column(&cage, 4 + 4 * 2 + 3),
        Some(FaceColumn::QuadCorner { quad: 2, corner: 3 })
    );
    assert_eq!(
        face_column(&cage, 4 + 4 * 2 + 3).unwrap().to_string(),
        "quad 2, corner 3"
    );
    assert_eq!(face_column(&cage, face_columns(&cage)), None);
    let split = cage.split_quads(pmvc::geometry::QuadSplit::Shorter);
    assert_eq!(split.triangle_count(), 4 + 2 * 5);
    assert_eq!(face_column(&split, 13), Some(FaceColumn::Triangle(13)));
    assert_eq!(face_column(&split, split.triangle_count()), None);
}

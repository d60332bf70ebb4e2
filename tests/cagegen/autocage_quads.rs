//! Generated cages with quads (`CageOptions::quads`, `pmvc cage --quads`): the
//! triangles are paired into near-planar, near-square quads where the quad's
//! bilinear patch keeps every guarantee of the triangles.
//!
//! Measured here, independently of the library: each patch is refined into a
//! fine grid of triangles (its own bilinear evaluation), and the mesh's vertices
//! and surface samples are tested against that surface by winding number and
//! distance; the quads' shapes from their corners.

use crate::common;

use common::winding_number;
use glam::DVec3;
use pmvc::cagegen::{generate_cage, CageOptions, GeneratedCage, DEFAULT_CLEARANCE};
use pmvc::geometry::{procedural, Cage, TriMesh};

/// Grid steps per patch side in the refined surface: the grid is within
/// `|twist| / (4·STEPS²)` of the patch.
const STEPS: usize = 16;

/// A torus: saddles as well as domes.
fn torus() -> TriMesh {
    common::torus_mesh()
}

/// Five prongs 1 wide, 0.5 apart, 4 long: valleys between them.
fn comb() -> TriMesh {
    let cage = procedural::extrude(&procedural::comb_outline(5, 1.0, 0.5, 4.0), -0.5, 0.5);
    TriMesh {
        positions: cage.positions().to_vec(),
        triangles: cage.triangles().to_vec(),
        triangle_faces: Vec::new(),
    }
}

fn generate(mesh: &TriMesh, target: usize, quads: bool) -> GeneratedCage {
    let options = CageOptions {
        quads,
        ..CageOptions::new(target)
    };
    generate_cage(mesh, &options, &|_| true).unwrap_or_else(|e| panic!("no cage: {e}"))
}

fn bilinear(q: &[DVec3; 4], u: f64, v: f64) -> DVec3 {
    q[0] * ((1.0 - u) * (1.0 - v))
        + q[1] * (u * (1.0 - v))
        + q[2] * (u * v)
        + q[3] * ((1.0 - u) * v)
}

/// The cage's surface with each quad refined into a `STEPS`² grid that follows
/// its patch, built from the polygons and positions alone.
fn refined_surface(cage: &Cage) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut positions = cage.positions().to_vec();
    let mut triangles = Vec::new();
    for polygon in cage.polygons() {
        if polygon.len() == 3 {
            triangles.push([polygon[0], polygon[1], polygon[2]]);
            continue;
        }
        let q: [DVec3; 4] = std::array::from_fn(|k| positions[polygon[k] as usize]);
        let first = positions.len() as u32;
        for j in 0..=STEPS {
            for i in 0..=STEPS {
                let (u, v) = (i as f64 / STEPS as f64, j as f64 / STEPS as f64);
                positions.push(bilinear(&q, u, v));
            }
        }
        let at = |i: usize, j: usize| first + (j * (STEPS + 1) + i) as u32;
        for j in 0..STEPS {
            for i in 0..STEPS {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                triangles.extend([[a, b, c], [a, c, d]]);
            }
        }
    }
    (positions, triangles)
}

fn point_triangle_distance(p: DVec3, [a, b, c]: [DVec3; 3]) -> f64 {
    let segment = |a: DVec3, b: DVec3| {
        let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
        p.distance(a + (b - a) * t)
    };
    let n = (b - a).cross(c - a);
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|&(u, v)| (v - u).cross(p - u).dot(n) >= 0.0);
    if inside && n.length() > 0.0 {
        ((p - a).dot(n) / n.length()).abs()
    } else {
        segment(a, b).min(segment(b, c)).min(segment(c, a))
    }
}

/// Points on every mesh triangle: its corners and centroid.
fn samples(mesh: &TriMesh) -> Vec<DVec3> {
    let mut points = mesh.positions.clone();
    points.extend(mesh.triangles.iter().map(|t| {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        (a + b + c) / 3.0
    }));
    points
}

/// The checks of a cage with quads: shapes, enclosure and clearance measured on
/// the refined patches; returns the number of quads.
fn check_quads(name: &str, mesh: &TriMesh, generated: &GeneratedCage) -> usize {
    let (cage, stats) = (&generated.cage, &generated.stats);
    assert_eq!(stats.quads, cage.quads().len(), "{name}");
    for polygon in cage.polygons().iter().filter(|p| p.len() == 4) {
        let q: [DVec3; 4] = std::array::from_fn(|k| cage.positions()[polygon[k] as usize]);
        // Flat within 30° across either diagonal's split, and every corner
        // within 50° of square, as docs/cages.md promises.
        let normal = |a: DVec3, b: DVec3, c: DVec3| (b - a).cross(c - a).normalize();
        let bend = normal(q[0], q[1], q[2])
            .angle_between(normal(q[0], q[2], q[3]))
            .min(normal(q[1], q[2], q[3]).angle_between(normal(q[1], q[3], q[0])));
        assert!(
            bend.to_degrees() <= 30.0 + 1e-9,
            "{name}: bend {}",
            bend.to_degrees()
        );
        for k in 0..4 {
            let (next, previous) = (q[(k + 1) % 4] - q[k], q[(k + 3) % 4] - q[k]);
            let corner = next.angle_between(previous).to_degrees();
            assert!(
                (corner - 90.0).abs() <= 50.0 + 1e-9,
                "{name}: corner {corner}°"
            );
        }
    }
    let (positions, triangles) = refined_surface(cage);
    let points = samples(mesh);
    let outside = points
        .iter()
        .filter(|&&p| winding_number(&positions, &triangles, p) < 0.5)
        .count();
    assert_eq!(outside, 0, "{name}: mesh points outside the patches");
    let nearest = mesh
        .positions
        .iter()
        .map(|&p| {
            triangles
                .iter()
                .map(|t| point_triangle_distance(p, t.map(|i| positions[i as usize])))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(f64::INFINITY, f64::min);
    let clearance = DEFAULT_CLEARANCE * mesh.diagonal();
    eprintln!(
        "{name}: {} quads, {} triangles; clearance {nearest:.5} measured, {:.5} reported, {clearance:.5} asked",
        stats.quads,
        stats.triangles - 2 * stats.quads,
        stats.min_clearance
    );
    // The grid stands within 1/1024 of a patch's twist of it.
    assert!(
        nearest >= 0.999 * clearance,
        "{name}: {nearest} < {clearance}"
    );
    assert!(
        (nearest - stats.min_clearance).abs() <= 1e-3 * clearance + 1e-9,
        "{name}: measured {nearest}, reported {}",
        stats.min_clearance
    );
    stats.quads
}

#[test]
fn a_torus_cage_gets_quads_that_keep_the_clearance_and_enclose_the_mesh() {
    let mesh = torus();
    let generated = generate(&mesh, 64, true);
    let quads = check_quads("torus", &mesh, &generated);
    assert!(quads >= 4, "torus: only {quads} quads");
}

#[test]
fn a_comb_cage_gets_quads_and_keeps_its_prongs_apart() {
    let mesh = comb();
    let generated = generate(&mesh, 120, true);
    let quads = check_quads("comb", &mesh, &generated);
    assert!(quads >= 4, "comb: only {quads} quads");
    // Midway between two prongs stays outside the cage's patches.
    let (positions, triangles) = refined_surface(&generated.cage);
    let gap = DVec3::new(1.25, 3.0, 0.0);
    assert!(winding_number(&positions, &triangles, gap) < 0.5);
}

#[test]
fn without_quads_asked_the_cage_is_triangles_as_before() {
    let mesh = torus();
    let triangles = generate(&mesh, 64, false);
    assert_eq!(triangles.stats.quads, 0);
    assert!(!triangles.cage.has_quads());
    // Quads only pair the same cage's triangles: the vertices are the same.
    let quads = generate(&mesh, 64, true);
    assert_eq!(quads.cage.positions(), triangles.cage.positions());
    assert_eq!(quads.stats.triangles, triangles.stats.triangles);
}

#[cfg(feature = "editor")]
#[test]
fn pmvc_cage_quads_writes_quads_that_read_back_as_quads() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = torus();
    let mesh_path = dir.path().join("torus.obj");
    common::write(
        dir.path(),
        "torus.obj",
        &common::triangles_obj(&mesh.positions, &mesh.triangles),
    );
    let out = dir.path().join("cage.obj");
    let output = common::pmvc(&[
        "cage",
        "--mesh",
        common::path_str(&mesh_path),
        "--vertices",
        "64",
        "--out",
        common::path_str(&out),
        "--quads",
    ]);
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{text}{}", common::stderr(&output));
    assert!(text.contains(" quads and "), "{text}");
    let written = std::fs::read_to_string(&out).unwrap();
    let quad_lines = written
        .lines()
        .filter(|l| l.starts_with("f ") && l.split_whitespace().count() == 5)
        .count();
    assert!(quad_lines >= 4, "{quad_lines} quads written");
    let (cage, _) = pmvc::formats::load_cage(&out).expect("the written cage loads");
    assert_eq!(cage.quads().len(), quad_lines);
}

//! The bundled scenes. The default one, a "hand" of five close fingers inside a
//! comb-shaped cage, is generated here so that it can be rebuilt and checked; the
//! scanned model is embedded from `assets/` because it cannot be generated.
//!
//! The comb is the paper's Figure 1 situation: the cage's prongs are close, so mean
//! value coordinates of a point in one prong are negative for the vertices of the
//! neighbouring prong, and moving one prong drags its neighbours under MVC but not
//! under PMVC.

use crate::geometry::procedural::{comb_outline, extrude};
use crate::geometry::{validate_cage, Cage, TriMesh};
use glam::{DVec2, DVec3};
use std::path::Path;

/// Number of fingers (and cage prongs) of the default scene.
pub const COMB_FINGERS: usize = 5;
/// Mesh finger width and gap between neighbouring fingers.
const FINGER_WIDTH: f64 = 1.0;
const FINGER_GAP: f64 = 0.4;
/// How far the cage stands off the mesh on every side. Smaller than half the gap,
/// so the cage prongs stay separate.
const CAGE_MARGIN: f64 = 0.1;
/// Cage prong length, measured from the top of the spine.
const PRONG_LENGTH: f64 = 4.0;
/// Palm half-thickness; the cage is `CAGE_MARGIN` thicker on each side.
const PALM_HALF_DEPTH: f64 = 0.4;

/// A scene shipped with the editor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BundledScene {
    /// Five close fingers in a comb cage: the default, and the MVC/PMVC showcase.
    Comb,
    /// A scanned elephant figurine (CGAL's sample data, CC0) in a coarse star-shaped cage.
    Scan,
}

impl BundledScene {
    pub const ALL: [BundledScene; 2] = [BundledScene::Comb, BundledScene::Scan];

    pub fn title(self) -> &'static str {
        match self {
            BundledScene::Comb => "Comb of close fingers",
            BundledScene::Scan => "Scanned elephant (CGAL sample)",
        }
    }

    /// The scene's mesh and cage.
    pub fn build(self) -> (TriMesh, Cage) {
        match self {
            BundledScene::Comb => (comb_mesh(), comb_cage()),
            BundledScene::Scan => (
                parse_bundled_obj(include_str!("../../assets/scan_mesh.obj")),
                bundled_cage(include_str!("../../assets/scan_cage.obj")),
            ),
        }
    }
}

/// The default scene's cage: an extruded comb standing `CAGE_MARGIN` off the mesh.
pub fn comb_cage() -> Cage {
    let outline: Vec<DVec2> = comb_outline(
        COMB_FINGERS,
        FINGER_WIDTH + 2.0 * CAGE_MARGIN,
        FINGER_GAP - 2.0 * CAGE_MARGIN,
        PRONG_LENGTH,
    )
    .into_iter()
    .map(|p| p - DVec2::splat(CAGE_MARGIN))
    .collect();
    let depth = PALM_HALF_DEPTH + CAGE_MARGIN;
    extrude(&outline, -depth, depth)
}

/// The default scene's mesh: a rounded-box palm with five capsule-like fingers,
/// each a finely tessellated superellipsoid (about 7,500 vertices in all).
pub fn comb_mesh() -> TriMesh {
    let mut mesh = TriMesh::default();
    let palm_width = COMB_FINGERS as f64 * FINGER_WIDTH + (COMB_FINGERS as f64 - 1.0) * FINGER_GAP;
    // The palm fills the cage's spine (y ∈ [0, FINGER_WIDTH]).
    append_superellipsoid(
        &mut mesh,
        DVec3::new(palm_width / 2.0, FINGER_WIDTH / 2.0, 0.0),
        DVec3::new(palm_width / 2.0, FINGER_WIDTH / 2.0, PALM_HALF_DEPTH),
        [0.3, 0.3],
        [32, 64],
    );
    // Fingers start inside the palm and end `CAGE_MARGIN` short of the prong tips.
    let tip = FINGER_WIDTH + CAGE_MARGIN + PRONG_LENGTH - CAGE_MARGIN - 0.05;
    let base = FINGER_WIDTH * 0.5;
    for finger in 0..COMB_FINGERS {
        let left = finger as f64 * (FINGER_WIDTH + FINGER_GAP);
        append_superellipsoid(
            &mut mesh,
            DVec3::new(left + FINGER_WIDTH / 2.0, (base + tip) / 2.0, 0.0),
            DVec3::new(
                FINGER_WIDTH / 2.0 - 0.05,
                (tip - base) / 2.0,
                PALM_HALF_DEPTH - 0.05,
            ),
            [0.4, 1.0],
            [40, 28],
        );
    }
    mesh
}

/// Append a closed superellipsoid whose pole axis is y.
///
/// `exponents[0]` shapes the profile along y (small: flat ends, like a capsule);
/// `exponents[1]` the cross-section in xz (1: an ellipse). `[rings, segments]` set
/// the tessellation: `segments · (rings − 1) + 2` vertices.
fn append_superellipsoid(
    mesh: &mut TriMesh,
    centre: DVec3,
    radii: DVec3,
    exponents: [f64; 2],
    [rings, segments]: [u32; 2],
) {
    let signed_power = |v: f64, e: f64| v.signum() * v.abs().powf(e);
    let first = mesh.positions.len() as u32;
    let point = |latitude: f64, longitude: f64| {
        let (sin_lat, cos_lat) = latitude.sin_cos();
        let (sin_lon, cos_lon) = longitude.sin_cos();
        let ring = signed_power(cos_lat, exponents[0]);
        centre
            + radii
                * DVec3::new(
                    ring * signed_power(cos_lon, exponents[1]),
                    signed_power(sin_lat, exponents[0]),
                    ring * signed_power(sin_lon, exponents[1]),
                )
    };
    use std::f64::consts::{FRAC_PI_2, PI, TAU};
    mesh.positions.push(point(-FRAC_PI_2, 0.0));
    for ring in 1..rings {
        let latitude = -FRAC_PI_2 + PI * ring as f64 / rings as f64;
        for segment in 0..segments {
            mesh.positions
                .push(point(latitude, TAU * segment as f64 / segments as f64));
        }
    }
    mesh.positions.push(point(FRAC_PI_2, 0.0));
    let south = first;
    let north = mesh.positions.len() as u32 - 1;
    let at = |ring: u32, segment: u32| first + 1 + (ring - 1) * segments + segment % segments;
    for segment in 0..segments {
        mesh.triangles
            .push([south, at(1, segment + 1), at(1, segment)]);
        mesh.triangles
            .push([north, at(rings - 1, segment), at(rings - 1, segment + 1)]);
    }
    for ring in 1..rings - 1 {
        for segment in 0..segments {
            let (a, b) = (at(ring, segment), at(ring, segment + 1));
            let (c, d) = (at(ring + 1, segment), at(ring + 1, segment + 1));
            mesh.triangles.push([a, b, d]);
            mesh.triangles.push([a, d, c]);
        }
    }
    let faces = mesh.triangle_faces.len() as u32;
    mesh.triangle_faces
        .extend(faces..mesh.triangles.len() as u32);
}

/// Parse a bundled OBJ (only `v` and triangular or polygonal `f` lines, written by
/// this crate or checked by a test), so bundled scenes need no file system.
fn parse_bundled_obj(text: &str) -> TriMesh {
    let mut mesh = TriMesh::default();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let mut xyz = words.filter_map(|w| w.parse::<f64>().ok());
                let (x, y, z) = (xyz.next(), xyz.next(), xyz.next());
                mesh.positions.push(DVec3::new(
                    x.unwrap_or(0.0),
                    y.unwrap_or(0.0),
                    z.unwrap_or(0.0),
                ));
            }
            Some("f") => {
                let corners: Vec<u32> = words
                    .filter_map(|w| w.split('/').next()?.parse::<u32>().ok())
                    .map(|i| i.saturating_sub(1))
                    .collect();
                let before = mesh.triangles.len();
                crate::geometry::triangulate_polygon(
                    &corners,
                    &mesh.positions,
                    &mut mesh.triangles,
                );
                let face = mesh.triangle_faces.last().map_or(0, |f| f + 1);
                for _ in before..mesh.triangles.len() {
                    mesh.triangle_faces.push(face);
                }
            }
            _ => {}
        }
    }
    mesh
}

fn bundled_cage(text: &str) -> Cage {
    let mesh = parse_bundled_obj(text);
    // The bundled cages are checked by `tests/editor_assets.rs`; validation here only
    // orients them, so a failure is a packaging bug.
    validate_cage(Path::new("bundled cage"), mesh)
        .map(|(cage, _)| cage)
        .expect("bundled cage is valid (checked by tests/editor_assets.rs)")
}

/// OBJ text of a mesh: `v` lines then 1-based `f` lines, six decimals.
pub fn obj_text(positions: &[DVec3], triangles: &[[u32; 3]]) -> String {
    use std::fmt::Write;
    let mut text = String::new();
    for p in positions {
        let _ = writeln!(text, "v {:.6} {:.6} {:.6}", p.x, p.y, p.z);
    }
    for [a, b, c] in triangles {
        let _ = writeln!(text, "f {} {} {}", a + 1, b + 1, c + 1);
    }
    text
}

/// A coarse cage enclosing `points`: an icosphere stretched to their bounding box,
/// with each vertex pulled in along its ray from the centre to just outside the
/// farthest point in a cone around that ray. Moving vertices only along rays from
/// one centre keeps the sphere star-shaped, so the cage never self-intersects; the
/// margin grows until every point is inside.
pub fn star_cage(points: &[DVec3], subdivisions: u32, cone_degrees: f64, margin: f64) -> Cage {
    let (lo, hi) = crate::geometry::bounds_of(points);
    let centre = (lo + hi) / 2.0;
    let half = ((hi - lo) / 2.0).max(DVec3::splat(1e-9));
    let sphere = crate::geometry::procedural::icosphere(1.0, subdivisions);
    let cone_cos = cone_degrees.to_radians().cos();
    // Work in the box-normalised space so that the cone is fair along every axis.
    let normalised: Vec<DVec3> = points.iter().map(|p| (*p - centre) / half).collect();
    let reach: Vec<f64> = sphere
        .positions
        .iter()
        .map(|direction| {
            let direction = direction.normalize();
            normalised
                .iter()
                .filter_map(|q| {
                    let length = q.length();
                    (length > 0.0 && q.dot(direction) >= cone_cos * length).then_some(length)
                })
                .fold(0.0, f64::max)
        })
        .collect();
    // Directions with no point in their cone would dent the cage down to the
    // centre; lift every vertex at least to the mean of its neighbours.
    let mut neighbours = vec![Vec::new(); sphere.positions.len()];
    for [a, b, c] in &sphere.triangles {
        for (u, v) in [(a, b), (b, c), (c, a)] {
            neighbours[*u as usize].push(*v as usize);
        }
    }
    let mut reach = reach;
    for _ in 0..3 {
        reach = reach
            .iter()
            .zip(&neighbours)
            .map(|(r, around)| {
                let mean =
                    around.iter().map(|&n| reach[n]).sum::<f64>() / around.len().max(1) as f64;
                r.max(mean)
            })
            .collect();
    }
    let mut scale = 1.0 + margin;
    loop {
        let positions = sphere
            .positions
            .iter()
            .zip(&reach)
            .map(|(direction, r)| centre + direction.normalize() * (r * scale) * half)
            .collect();
        let cage = sphere.with_positions(positions);
        let classes = crate::geometry::classify_points(&cage, points);
        if classes.outside.is_empty() || scale > 4.0 {
            return cage;
        }
        scale += margin;
    }
}

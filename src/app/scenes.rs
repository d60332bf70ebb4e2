//! The bundled scenes. The default one, a "hand" of five close fingers inside a
//! comb-shaped cage, is generated here so that it can be rebuilt and checked; the
//! scanned model is embedded from `assets/` because it cannot be generated.
//!
//! The comb is the paper's Figure 1 situation: the cage's prongs are close, so mean
//! value coordinates of a point in one prong are negative for the vertices of the
//! neighbouring prong, and moving one prong drags its neighbours under MVC but not
//! under PMVC.

use crate::formats::{cage_from_file, parse_mesh, CageLoadError, LoadError, MeshFile};
use crate::geometry::procedural::{comb_outline, extrude};
use crate::geometry::{Cage, TriMesh};
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

    /// The name sessions save the scene by.
    pub fn id(self) -> &'static str {
        match self {
            BundledScene::Comb => "comb",
            BundledScene::Scan => "scan",
        }
    }

    pub fn from_id(id: &str) -> Option<BundledScene> {
        Self::ALL.into_iter().find(|scene| scene.id() == id)
    }

    pub fn title(self) -> &'static str {
        match self {
            BundledScene::Comb => "Comb of close fingers",
            BundledScene::Scan => "Scanned elephant (CGAL sample)",
        }
    }

    /// The scene's mesh and cage. The scan is embedded text that goes through the
    /// same loader as a user's files, so a bad number is an error, never 0.0
    /// (`tests/editor/editor_assets.rs` checks that it loads).
    pub fn build(self) -> Result<(TriMesh, Cage), CageLoadError> {
        match self {
            BundledScene::Comb => Ok((comb_mesh(), comb_cage())),
            BundledScene::Scan => {
                const MESH: &str = "assets/scan_mesh.obj";
                const CAGE: &str = "assets/scan_cage.obj";
                let mesh = bundled_mesh(MESH, include_str!("../../assets/scan_mesh.obj"))?;
                let cage = bundled_mesh(CAGE, include_str!("../../assets/scan_cage.obj"))?;
                let (cage, _report) = cage_from_file(Path::new(CAGE), cage)?;
                Ok((mesh.mesh, cage))
            }
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

/// How far the first run's pose pulls the middle prong's tip: up, along the
/// finger, by this many finger widths.
const DEMO_LIFT: f64 = 4.5;

/// The first run's pose of the comb cage: the middle prong's tip pulled up. MVC
/// give the neighbouring fingers negative weights for those handles, so they
/// sink and bend toward it; PMVC leave them where they are. The difference is
/// a visible share of the cage (tests/editor/editor_views.rs measures it).
pub fn comb_demo_pose(cage: &Cage) -> Vec<DVec3> {
    let top = cage
        .positions()
        .iter()
        .map(|p| p.y)
        .fold(f64::NEG_INFINITY, f64::max);
    let middle = COMB_FINGERS / 2;
    let left = middle as f64 * (FINGER_WIDTH + FINGER_GAP) - CAGE_MARGIN;
    let right = left + FINGER_WIDTH + 2.0 * CAGE_MARGIN;
    let on_middle_tip = |p: &DVec3| p.y > top - 1e-9 && p.x > left - 1e-9 && p.x < right + 1e-9;
    cage.positions()
        .iter()
        .map(|p| {
            if on_middle_tip(p) {
                *p + DVec3::new(0.0, DEMO_LIFT * FINGER_WIDTH, 0.0)
            } else {
                *p
            }
        })
        .collect()
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

/// A bundled file, read through the same parser and validation as a user's file,
/// under its path in the source tree (which the messages name).
fn bundled_mesh(path: &str, text: &str) -> Result<MeshFile, LoadError> {
    parse_mesh(Path::new(path), text.to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coords::{bind_cpu, BindOptions, BindProgress, Method};
    use crate::geometry::classify_points;

    /// The first run's claim: under MVC the fingers beside the pulled one sink by
    /// a visible share of the cage; under PMVC they do not move.
    #[test]
    fn the_demo_pose_sinks_the_neighbouring_fingers_under_mvc_only() {
        let (mesh, cage) = (comb_mesh(), comb_cage());
        let classes = classify_points(&cage, &mesh.positions).classes;
        let pose = comb_demo_pose(&cage);
        let moves: Vec<DVec3> = pose
            .iter()
            .zip(cage.positions())
            .map(|(a, b)| *a - *b)
            .collect();
        assert_eq!(moves.iter().filter(|m| **m != DVec3::ZERO).count(), 4);
        // Mesh vertices of the second and fourth fingers, above the palm.
        let pitch = FINGER_WIDTH + FINGER_GAP;
        let neighbours: Vec<usize> = (0..mesh.positions.len())
            .filter(|&i| {
                let p = mesh.positions[i];
                let finger = (p.x / pitch).floor() as usize;
                (finger == 1 || finger == 3) && p.y > 1.5 * FINGER_WIDTH
            })
            .collect();
        assert!(neighbours.len() > 1000);
        let largest_move = |method| {
            let options = BindOptions::for_method(method);
            let progress = BindProgress::new(mesh.positions.len());
            let weights = bind_cpu(&mesh.positions, &classes, &cage, options, &progress).unwrap();
            let deformed = weights.apply_displacements(&mesh.positions, &moves);
            let largest = neighbours
                .iter()
                .map(|&i| deformed[i] - mesh.positions[i])
                .max_by(|a, b| a.length().total_cmp(&b.length()))
                .unwrap();
            largest / cage.diagonal()
        };
        let mvc = largest_move(Method::Mvc);
        assert!(
            mvc.y < -0.05,
            "MVC: the neighbours sink by {mvc:?} diagonals"
        );
        let pmvc = largest_move(Method::Pmvc);
        assert!(
            pmvc.length() < 1e-6,
            "PMVC: the neighbours move {pmvc:?} diagonals"
        );
    }
}

//! Procedural test meshes for generated cages, each with what a test needs to
//! judge a cage around it: its volume, computed from its shape rather than from
//! its triangles, and points that must stay outside any cage that follows it.

use glam::DVec3;
use pmvc::geometry::TriMesh;
use std::f64::consts::PI;

/// A mesh and what is known about it independently of its triangles.
#[derive(Clone)]
pub struct Shape {
    pub mesh: TriMesh,
    /// The volume of the solid the triangles approximate (to within the
    /// triangulation's chordal error, under 1 %).
    pub volume: f64,
    /// Points in the gaps between parts of the solid, at least `gap / 2` from
    /// it: a cage that keeps the parts apart leaves them outside.
    pub gap_points: Vec<DVec3>,
}

fn mesh(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> TriMesh {
    TriMesh {
        triangle_faces: (0..triangles.len() as u32).collect(),
        positions,
        triangles,
    }
}

/// Appends a tube through `rings` (centre, two unit axes of the circle's plane
/// whose cross product points along the tube, radius), outward: a loop, or
/// closed at both ends by fans to the first and last centres.
fn append_tube(
    positions: &mut Vec<DVec3>,
    triangles: &mut Vec<[u32; 3]>,
    rings: &[(DVec3, DVec3, DVec3, f64)],
    segments: u32,
    closed_loop: bool,
) {
    let base = positions.len() as u32;
    for &(centre, side, up, radius) in rings {
        for s in 0..segments {
            let angle = 2.0 * PI * f64::from(s) / f64::from(segments);
            positions.push(centre + (side * angle.cos() + up * angle.sin()) * radius);
        }
    }
    let count = rings.len() as u32;
    let at = |r: u32, s: u32| base + (r % count) * segments + s % segments;
    let spans = if closed_loop { count } else { count - 1 };
    for r in 0..spans {
        for s in 0..segments {
            let (a, b, c, d) = (at(r, s), at(r, s + 1), at(r + 1, s + 1), at(r + 1, s));
            triangles.extend([[a, c, d], [a, b, c]]);
        }
    }
    if !closed_loop {
        // Caps: fans to the first and last centres.
        let (first, last) = (rings[0].0, rings[rings.len() - 1].0);
        let start = positions.len() as u32;
        positions.extend([first, last]);
        for s in 0..segments {
            triangles.push([start, at(0, s + 1), at(0, s)]);
            triangles.push([start + 1, at(count - 1, s), at(count - 1, s + 1)]);
        }
    }
}

/// Appends a capsule of `radius` whose axis runs along +y from `base` for
/// `length` (hemispheres at both ends, beyond the axis's ends).
fn append_capsule(
    positions: &mut Vec<DVec3>,
    triangles: &mut Vec<[u32; 3]>,
    base: DVec3,
    length: f64,
    radius: f64,
) {
    let (cap_rings, body_rings) = (12, 40);
    let mut rings = Vec::new();
    // Bottom hemisphere from just above its pole, the body, the top hemisphere.
    for k in 1..=cap_rings {
        let angle = 0.5 * PI * f64::from(k) / f64::from(cap_rings);
        rings.push((-angle.cos() * radius, angle.sin() * radius));
    }
    for k in 1..body_rings {
        rings.push((length * f64::from(k) / f64::from(body_rings), radius));
    }
    for k in 0..cap_rings {
        let angle = 0.5 * PI * f64::from(k) / f64::from(cap_rings);
        rings.push((length + angle.sin() * radius, angle.cos() * radius));
    }
    let circles: Vec<(DVec3, DVec3, DVec3, f64)> = rings
        .iter()
        .map(|&(y, r)| (base + DVec3::Y * y, DVec3::Z, DVec3::X, r))
        .collect();
    append_tube(positions, triangles, &circles, 48, false);
    // The caps' fan centres go to the poles.
    let poles = positions.len() - 2;
    positions[poles] = base - DVec3::Y * radius;
    positions[poles + 1] = base + DVec3::Y * (length + radius);
}

/// A box from `lo` to `hi`, outward: the procedural unit cube, stretched.
fn append_box(positions: &mut Vec<DVec3>, triangles: &mut Vec<[u32; 3]>, lo: DVec3, hi: DVec3) {
    let cube = pmvc::geometry::procedural::cube_cage(1.0);
    let base = positions.len() as u32;
    positions.extend(
        cube.positions()
            .iter()
            .map(|p| lo + (*p + DVec3::ONE) * 0.5 * (hi - lo)),
    );
    triangles.extend(cube.triangles().iter().map(|t| t.map(|i| base + i)));
}

/// A hand: four fingers (capsules of radius 0.5 with 4 units between their
/// hemispheres' centres) whose surfaces are `gap` apart, standing on a palm
/// box they dip into. The gap points are midway between neighbouring fingers
/// from y = 1 to 4, where nothing but the two fingers is near.
pub fn hand(gap: f64) -> Shape {
    let (radius, length) = (0.5, 4.0);
    let pitch = 2.0 * radius + gap;
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    let palm_top = 0.3;
    append_box(
        &mut positions,
        &mut triangles,
        DVec3::new(-0.6, -2.0, -0.6),
        DVec3::new(3.0 * pitch + 0.6, palm_top, 0.6),
    );
    for k in 0..4 {
        let base = DVec3::new(f64::from(k) * pitch, 0.0, 0.0);
        append_capsule(&mut positions, &mut triangles, base, length, radius);
    }
    let palm = (3.0 * pitch + 1.2) * 2.3 * 1.2;
    // Each finger adds its body and top hemisphere above the palm.
    let finger = PI * radius * radius * (length - palm_top) + 2.0 / 3.0 * PI * radius.powi(3);
    let gap_points = (0..3)
        .flat_map(|k| {
            (0..7).map(move |j| {
                DVec3::new((f64::from(k) + 0.5) * pitch, 1.0 + 0.5 * f64::from(j), 0.0)
            })
        })
        .collect();
    Shape {
        mesh: mesh(positions, triangles),
        volume: palm + 4.0 * finger,
        gap_points,
    }
}

/// A (2, 3) torus knot (a trefoil) swept by a tube of radius 0.25. The tube's
/// strands pass 0.7 or more apart (centre to centre), and the gap points lie
/// midway where they pass closest, well off the tube.
pub fn torus_knot() -> Shape {
    let radius = 0.25;
    let curve = |t: f64| {
        let r = 2.0 + (3.0 * t).cos();
        DVec3::new(r * (2.0 * t).cos(), r * (2.0 * t).sin(), -(3.0 * t).sin())
    };
    let samples = 360;
    let points: Vec<DVec3> = (0..samples)
        .map(|k| curve(2.0 * PI * f64::from(k) / f64::from(samples)))
        .collect();
    // Frames by parallel transport, closed up by spreading the final twist.
    let tangent = |k: usize| {
        (points[(k + 1) % points.len()] - points[(k + points.len() - 1) % points.len()]).normalize()
    };
    let mut side = tangent(0).any_orthonormal_vector();
    let mut frames = Vec::new();
    for k in 0..points.len() {
        let t = tangent(k);
        side = (side - t * side.dot(t)).normalize();
        frames.push((side, t.cross(side)));
    }
    let closing = {
        let (s0, u0) = frames[0];
        let (sn, _) = frames[points.len() - 1];
        sn.dot(u0).atan2(sn.dot(s0))
    };
    let rings: Vec<(DVec3, DVec3, DVec3, f64)> = (0..points.len())
        .map(|k| {
            let (s, u) = frames[k];
            let turn = -closing * k as f64 / points.len() as f64;
            let (c, d) = (turn.cos(), turn.sin());
            (points[k], s * c + u * d, u * c - s * d, radius)
        })
        .collect();
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    append_tube(&mut positions, &mut triangles, &rings, 24, true);
    let length: f64 = (0..points.len())
        .map(|k| points[k].distance(points[(k + 1) % points.len()]))
        .sum();
    // Midway between the two strands that pass closest over each other.
    let mut gap_points = Vec::new();
    for k in (0..samples as usize).step_by(samples as usize / 12) {
        let (mut best, mut at) = (f64::INFINITY, 0);
        for j in 0..points.len() {
            let apart = (j as i64 - k as i64).rem_euclid(points.len() as i64);
            let along = apart.min(points.len() as i64 - apart);
            if along > points.len() as i64 / 6 && points[k].distance(points[j]) < best {
                (best, at) = (points[k].distance(points[j]), j);
            }
        }
        if best < 2.5 {
            gap_points.push((points[k] + points[at]) * 0.5);
        }
    }
    Shape {
        mesh: mesh(positions, triangles),
        volume: PI * radius * radius * length,
        gap_points,
    }
}

/// A thin plate, 4 × 3 × 0.06: its two sides 1.2 % of its diagonal apart.
pub fn thin_plate() -> Shape {
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    append_box(
        &mut positions,
        &mut triangles,
        DVec3::new(-2.0, -1.5, -0.03),
        DVec3::new(2.0, 1.5, 0.03),
    );
    Shape {
        mesh: mesh(positions, triangles),
        volume: 4.0 * 3.0 * 0.06,
        gap_points: Vec::new(),
    }
}

/// Two spheres of radius 1 (icospheres, subdivided 3 times) whose surfaces are
/// `gap` apart along x; the gap points lie on the segment between them.
pub fn two_blobs(gap: f64) -> Shape {
    let sphere = pmvc::geometry::procedural::icosphere(1.0, 3);
    let n = sphere.vertex_count() as u32;
    let offset = DVec3::X * (1.0 + gap / 2.0);
    let mut positions: Vec<DVec3> = sphere.positions().iter().map(|p| *p - offset).collect();
    positions.extend(sphere.positions().iter().map(|p| *p + offset));
    let mut triangles = sphere.triangles().to_vec();
    triangles.extend(sphere.triangles().iter().map(|t| t.map(|i| i + n)));
    let gap_points = (-2..=2)
        .map(|k| DVec3::new(0.0, 0.1 * f64::from(k), 0.0))
        .collect();
    Shape {
        mesh: mesh(positions, triangles),
        volume: 2.0 * 4.0 / 3.0 * PI,
        gap_points,
    }
}

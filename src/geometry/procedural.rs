//! Procedural cages and point sets: the test shapes (a convex box, a comb of close
//! prongs, an extruded star, subdivided spheres) and benchmark scenes of the sizes
//! in the paper's tables. Deterministic: the same arguments give the same geometry.

use super::{Cage, TriMesh};
use glam::{DVec2, DVec3};

/// A cube's six outward quads over corners numbered by bits (x = 1, y = 2,
/// z = 4).
pub const CUBE_QUADS: [[u32; 4]; 6] = [
    [0, 2, 3, 1],
    [4, 5, 7, 6],
    [0, 1, 5, 4],
    [2, 6, 7, 3],
    [0, 4, 6, 2],
    [1, 3, 7, 5],
];

/// An axis-aligned cube cage of half-size `half`, centred at the origin, 8 vertices.
pub fn cube_cage(half: f64) -> Cage {
    let positions: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { -half } else { half },
                if i & 2 == 0 { -half } else { half },
                if i & 4 == 0 { -half } else { half },
            )
        })
        .collect();
    let mut triangles = Vec::new();
    for [a, b, c, d] in CUBE_QUADS {
        triangles.push([a, b, c]);
        triangles.push([a, c, d]);
    }
    cage_from(positions, triangles)
}

/// An extruded comb: a spine along x with `prongs` teeth along +y, each `width`
/// wide with gaps of `gap`, `length` long, extruded over `z ∈ [−depth/2, depth/2]`.
/// Close prongs are where MVC goes negative (the paper's Figure 1).
pub fn comb_outline(prongs: usize, width: f64, gap: f64, length: f64) -> Vec<DVec2> {
    let spine = width;
    let total = prongs as f64 * width + (prongs as f64 - 1.0) * gap;
    let mut outline = vec![DVec2::new(0.0, 0.0), DVec2::new(total, 0.0)];
    // The rightmost tooth's outer side continues the spine's right end, the leftmost its left end.
    // Counter-clockwise: along the bottom, then up and down each tooth from the right.
    for k in (0..prongs).rev() {
        let x0 = k as f64 * (width + gap);
        let x1 = x0 + width;
        outline.push(DVec2::new(x1, spine + length));
        outline.push(DVec2::new(x0, spine + length));
        if k > 0 {
            outline.push(DVec2::new(x0, spine));
            outline.push(DVec2::new(x0 - gap, spine));
        }
    }
    outline
}

/// A star outline with `points` tips at radius `outer` and notches at `inner`.
pub fn star_outline(points: usize, inner: f64, outer: f64) -> Vec<DVec2> {
    (0..2 * points)
        .map(|k| {
            let angle = std::f64::consts::PI * k as f64 / points as f64;
            let radius = if k % 2 == 0 { outer } else { inner };
            DVec2::new(radius * angle.cos(), radius * angle.sin())
        })
        .collect()
}

/// Extrude a simple counter-clockwise polygon over `z ∈ [z0, z1]` into a closed cage.
/// Caps are ear-clipped, so the outline may be non-convex. `2n` vertices.
pub fn extrude(outline: &[DVec2], z0: f64, z1: f64) -> Cage {
    let n = outline.len();
    let mut positions: Vec<DVec3> = outline.iter().map(|p| p.extend(z0)).collect();
    positions.extend(outline.iter().map(|p| p.extend(z1)));
    let mut triangles = Vec::new();
    for [a, b, c] in ear_clip(outline) {
        triangles.push([c, b, a]); // bottom faces −z
        triangles.push([a + n as u32, b + n as u32, c + n as u32]);
    }
    for k in 0..n as u32 {
        let next = (k + 1) % n as u32;
        triangles.push([k, next, next + n as u32]);
        triangles.push([k, next + n as u32, k + n as u32]);
    }
    cage_from(positions, triangles)
}

/// Triangulate a simple counter-clockwise polygon by ear clipping (O(n²), for cages).
pub fn ear_clip(outline: &[DVec2]) -> Vec<[u32; 3]> {
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let (lo, hi) = outline
        .iter()
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    // An ear flatter than this would be a degenerate triangle to cage validation
    // (refined outlines have runs of collinear vertices).
    let flat = 1e-9 * (hi - lo).length_squared();
    let mut remaining: Vec<u32> = (0..outline.len() as u32).collect();
    let mut triangles = Vec::new();
    while remaining.len() > 3 {
        let m = remaining.len();
        let is_ear = |k: usize, min_area: f64| {
            let (ia, ib, ic) = (
                remaining[(k + m - 1) % m],
                remaining[k],
                remaining[(k + 1) % m],
            );
            let (a, b, c) = (
                outline[ia as usize],
                outline[ib as usize],
                outline[ic as usize],
            );
            if cross(a, b, c) <= min_area {
                return false;
            }
            remaining.iter().all(|&other| {
                if other == ia || other == ib || other == ic {
                    return true;
                }
                let p = outline[other as usize];
                !(cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0)
            })
        };
        let ear = (0..m)
            .find(|&k| is_ear(k, flat))
            .or_else(|| (0..m).find(|&k| is_ear(k, 0.0)));
        let k = ear.expect("a simple polygon always has an ear");
        triangles.push([
            remaining[(k + m - 1) % m],
            remaining[k],
            remaining[(k + 1) % m],
        ]);
        remaining.remove(k);
    }
    triangles.push([remaining[0], remaining[1], remaining[2]]);
    triangles
}

/// An icosphere of radius `radius` after `subdivisions` 1-to-4 splits.
pub fn icosphere(radius: f64, subdivisions: u32) -> Cage {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions: Vec<DVec3> = [
        [-1.0, phi, 0.0],
        [1.0, phi, 0.0],
        [-1.0, -phi, 0.0],
        [1.0, -phi, 0.0],
        [0.0, -1.0, phi],
        [0.0, 1.0, phi],
        [0.0, -1.0, -phi],
        [0.0, 1.0, -phi],
        [phi, 0.0, -1.0],
        [phi, 0.0, 1.0],
        [-phi, 0.0, -1.0],
        [-phi, 0.0, 1.0],
    ]
    .iter()
    .map(|p| DVec3::from_array(*p).normalize() * radius)
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoints = std::collections::HashMap::new();
        let mut midpoint = |a: u32, b: u32, positions: &mut Vec<DVec3>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let p = (positions[a as usize] + positions[b as usize]).normalize() * radius;
                positions.push(p);
                positions.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(triangles.len() * 4);
        for [a, b, c] in triangles {
            let (ab, bc, ca) = (
                midpoint(a, b, &mut positions),
                midpoint(b, c, &mut positions),
                midpoint(c, a, &mut positions),
            );
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    cage_from(positions, triangles)
}

/// A UV sphere with `rings` latitude bands and `segments` longitudes: `segments·(rings−1) + 2` vertices.
/// Used to make spherical cages of chosen vertex counts (the paper's Table 2).
pub fn uv_sphere(radius: f64, rings: u32, segments: u32) -> Cage {
    let mut positions = vec![DVec3::new(0.0, 0.0, radius)];
    for ring in 1..rings {
        let polar = std::f64::consts::PI * ring as f64 / rings as f64;
        for segment in 0..segments {
            let azimuth = 2.0 * std::f64::consts::PI * segment as f64 / segments as f64;
            positions.push(
                radius
                    * DVec3::new(
                        polar.sin() * azimuth.cos(),
                        polar.sin() * azimuth.sin(),
                        polar.cos(),
                    ),
            );
        }
    }
    positions.push(DVec3::new(0.0, 0.0, -radius));
    let south = positions.len() as u32 - 1;
    let at = |ring: u32, segment: u32| 1 + (ring - 1) * segments + segment % segments;
    let mut triangles = Vec::new();
    for segment in 0..segments {
        triangles.push([0, at(1, segment), at(1, segment + 1)]);
        triangles.push([south, at(rings - 1, segment + 1), at(rings - 1, segment)]);
    }
    for ring in 1..rings - 1 {
        for segment in 0..segments {
            let (a, b, c, d) = (
                at(ring, segment),
                at(ring, segment + 1),
                at(ring + 1, segment + 1),
                at(ring + 1, segment),
            );
            triangles.push([a, d, c]);
            triangles.push([a, c, b]);
        }
    }
    cage_from(positions, triangles)
}

/// `count` points strictly inside `cage`, uniformly distributed, from a fixed seed.
/// Points closer than `margin` (relative to the cage diagonal) to the surface are rejected.
pub fn points_inside(cage: &Cage, count: usize, seed: u64, margin: f64) -> Vec<DVec3> {
    let (lo, hi) = super::bounds_of(cage.positions());
    let min_distance = margin * cage.diagonal();
    let mut random = SplitMix64(seed);
    let mut points = Vec::with_capacity(count);
    while points.len() < count {
        let candidates: Vec<DVec3> = (0..count.max(64))
            .map(|_| lo + (hi - lo) * DVec3::new(random.unit(), random.unit(), random.unit()))
            .collect();
        let inside: Vec<DVec3> = {
            use rayon::prelude::*;
            candidates
                .into_par_iter()
                .filter(|&x| {
                    super::generalized_winding_number(cage, x) > 0.5
                        && distance_to_surface(cage, x) > min_distance
                })
                .collect()
        };
        points.extend(inside.into_iter().take(count - points.len()));
    }
    points
}

/// Unsigned distance from `x` to the cage surface.
pub fn distance_to_surface(cage: &Cage, x: DVec3) -> f64 {
    (0..cage.triangles().len())
        .map(|t| {
            let [a, b, c] = cage.triangle(t);
            super::closest_point_on_triangle(x, a, b, c).0.distance(x)
        })
        .fold(f64::INFINITY, f64::min)
}

/// A small deterministic generator (SplitMix64), so scenes need no RNG dependency.
#[derive(Clone, Debug)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Every procedural cage goes through validation like a loaded one; the shapes
/// here are closed and outward by construction (each has a test), so a failure is
/// a bug in this file.
fn cage_from(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Cage {
    let triangle_faces = (0..triangles.len() as u32).collect();
    let mesh = TriMesh {
        positions,
        triangles,
        triangle_faces,
    };
    match Cage::new(mesh) {
        Ok((cage, _report)) => cage,
        Err(error) => panic!("procedural cage is invalid: {error}"),
    }
}

/// A coarse cage enclosing `points`: an icosphere stretched to their bounding box,
/// with each vertex pulled in along its ray from the centre to just outside the
/// farthest point in a cone around that ray. Moving vertices only along rays from
/// one centre keeps the sphere star-shaped, so the cage never self-intersects; the
/// margin grows until every point is inside.
pub fn star_cage(points: &[DVec3], subdivisions: u32, cone_degrees: f64, margin: f64) -> Cage {
    let (lo, hi) = super::bounds_of(points);
    let centre = (lo + hi) / 2.0;
    let half = ((hi - lo) / 2.0).max(DVec3::splat(1e-9));
    let sphere = icosphere(1.0, subdivisions);
    let cone_cos = cone_degrees.to_radians().cos();
    // Work in the box-normalised space so that the cone is fair along every axis.
    let normalised: Vec<DVec3> = points.iter().map(|p| (*p - centre) / half).collect();
    let reach: Vec<f64> = sphere
        .positions()
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
    let mut neighbours = vec![Vec::new(); sphere.vertex_count()];
    for [a, b, c] in sphere.triangles() {
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
            .positions()
            .iter()
            .zip(&reach)
            .map(|(direction, r)| centre + direction.normalize() * (r * scale) * half)
            .collect();
        let cage = sphere.with_positions(positions);
        let classes = super::classify_points(&cage, points);
        if classes.outside.is_empty() || scale > 4.0 {
            return cage;
        }
        scale += margin;
    }
}

/// Split the longest edge of a closed outline at its midpoint until it has `count`
/// vertices: keeps the shape and hits an exact vertex count.
pub fn refine_outline(outline: &[DVec2], count: usize) -> Vec<DVec2> {
    let mut refined = outline.to_vec();
    while refined.len() < count {
        let n = refined.len();
        let longest = (0..n)
            .max_by(|&a, &b| {
                let length = |k: usize| refined[k].distance_squared(refined[(k + 1) % n]);
                length(a).total_cmp(&length(b))
            })
            .unwrap_or(0);
        let midpoint = 0.5 * (refined[longest] + refined[(longest + 1) % n]);
        refined.insert(longest + 1, midpoint);
    }
    refined
}

/// Like [`extrude`], but the top cap is a low pyramid over the outline's centroid
/// (one extra vertex). The outline must be star-shaped around its centroid.
pub fn extrude_with_apex(outline: &[DVec2], z0: f64, z1: f64, apex_height: f64) -> Cage {
    let n = outline.len() as u32;
    let mut positions: Vec<DVec3> = outline.iter().map(|p| p.extend(z0)).collect();
    positions.extend(outline.iter().map(|p| p.extend(z1)));
    let centroid = outline.iter().copied().sum::<DVec2>() / outline.len() as f64;
    positions.push(centroid.extend(z1 + apex_height));
    let apex = 2 * n;
    let mut triangles = Vec::new();
    for [a, b, c] in ear_clip(outline) {
        triangles.push([c, b, a]);
    }
    for k in 0..n {
        let next = (k + 1) % n;
        triangles.push([k, next, next + n]);
        triangles.push([k, next + n, k + n]);
        triangles.push([k + n, next + n, apex]);
    }
    cage_from(positions, triangles)
}

/// A benchmark scene: a non-convex cage and points inside it.
#[derive(Clone, Debug)]
pub struct Scene {
    pub name: &'static str,
    pub cage: Cage,
    pub points: Vec<DVec3>,
}

/// Names of the scenes of the sizes in the paper's Table 1, all with non-convex
/// cages: Armadillo (15,002 vertices, 110 cage vertices), Horse (48,485 in 51),
/// Hand (24,795 in 252).
pub fn table1_scene_names() -> &'static [&'static str] {
    &["armadillo-size", "horse-size", "hand-size"]
}

/// One of [`table1_scene_names`], or `None`.
pub fn table1_scene(name: &str) -> Option<Scene> {
    let (name, cage, count) = match name {
        "armadillo-size" => {
            // A six-prong comb: a body with limbs close together.
            let outline = refine_outline(&comb_outline(6, 1.0, 0.35, 3.0), 55);
            ("armadillo-size", extrude(&outline, -0.6, 0.6), 15_002)
        }
        "horse-size" => {
            let outline = refine_outline(&star_outline(5, 0.45, 1.6), 25);
            (
                "horse-size",
                extrude_with_apex(&outline, -0.5, 0.5, 0.3),
                48_485,
            )
        }
        "hand-size" => {
            // Five fingers close together, as in the paper's hand.
            let outline = refine_outline(&comb_outline(5, 0.8, 0.2, 3.5), 126);
            ("hand-size", extrude(&outline, -0.4, 0.4), 24_795)
        }
        _ => return None,
    };
    let points = points_inside(&cage, count, 2007, 1e-3);
    Some(Scene { name, cage, points })
}

/// The name of [`sculpt_size_scene`] for `pmvc generate`.
pub const SCULPT_SIZE: &str = "sculpt-size";

/// A triangle mesh of about a million vertices, the size of an artist's sculpt, in
/// a 120-vertex non-convex cage (a six-prong comb, as armadillo-size): a rippled
/// sheet filling the comb's outline, for the editor's large-mesh benchmark.
pub fn sculpt_size_scene() -> (TriMesh, Cage) {
    // Just over a million once the margin strip is left out.
    const VERTICES: f64 = 1.001e6;
    const MARGIN: f64 = 0.05;
    let outline = refine_outline(&comb_outline(6, 1.0, 0.35, 3.0), 60);
    let cage = extrude(&outline, -0.6, 0.6);
    let edges = || (0..outline.len()).map(|k| (outline[k], outline[(k + 1) % outline.len()]));
    let area = 0.5 * edges().map(|(a, b)| a.perp_dot(b)).sum::<f64>();
    let perimeter: f64 = edges().map(|(a, b)| a.distance(b)).sum();
    let step = ((area - perimeter * MARGIN) / VERTICES).sqrt();
    // Inside by the even-odd rule, and MARGIN away from every edge.
    let keeps = |p: DVec2| {
        let crossings = edges()
            .filter(|(a, b)| (a.y > p.y) != (b.y > p.y))
            .filter(|(a, b)| p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x))
            .count();
        let clear = edges().all(|(a, b)| {
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            p.distance(a + t * (b - a)) > MARGIN
        });
        crossings % 2 == 1 && clear
    };
    let (lo, hi) = super::bounds_of(cage.positions());
    let columns = ((hi.x - lo.x) / step) as usize + 1;
    let rows = ((hi.y - lo.y) / step) as usize + 1;
    let mut mesh = TriMesh::default();
    let mut index = vec![u32::MAX; columns * rows];
    for (cell, slot) in index.iter_mut().enumerate() {
        let p = DVec2::new(lo.x, lo.y)
            + step * DVec2::new((cell % columns) as f64, (cell / columns) as f64);
        if keeps(p) {
            *slot = mesh.positions.len() as u32;
            mesh.positions
                .push(p.extend(0.3 * (4.0 * p.x).sin() * (3.0 * p.y).cos()));
        }
    }
    for cell in (0..index.len() - columns).filter(|cell| cell % columns + 1 < columns) {
        let [a, b, c, d] = [cell, cell + 1, cell + columns + 1, cell + columns].map(|k| index[k]);
        if [a, b, c, d].iter().all(|&k| k != u32::MAX) {
            mesh.triangles.extend([[a, b, c], [a, c, d]]);
        }
    }
    (mesh, cage)
}

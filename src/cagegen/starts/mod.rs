//! Second starts for small targets, each tightened and polished like any
//! other cage, and kept only when valid and either smaller or keeping open
//! gaps that the simplification's cage bridged (a comb's or a hand's seen
//! along the palm's normal): a start never bridges a gap that cage kept
//! open, and is larger only to keep more open. The simplification's own
//! coarse cages can end twisted, with
//! corners well out, where moving one vertex at a time cannot straighten
//! them; an artist starts such a cage from a box, or from a profile drawn
//! once and extruded along the model (a bench, a rail, a limb).
//! - The mesh's bounding box, grown by the clearance (eight vertices).
//! - Along each axis, a prism: the mesh seen along the axis, its convex hull
//!   or its traced (concave) outline ([`outline`]), grown by the clearance
//!   and cut down to half the target's corners ([`profile`]), extruded over
//!   the mesh's extent.

use crate::cagegen::gaps::GapPoint;
use crate::cagegen::points::PointTree;
use crate::cagegen::simplify::{self, Goal, Simplified};
use crate::cagegen::voxels::Envelope;
use crate::cagegen::Attempt;
use crate::geometry::cage::signed_volume;
use crate::geometry::procedural::cube_cage;
use crate::geometry::TriMesh;
use glam::{DVec2, DVec3};
use rayon::prelude::*;

mod cap;
mod choice;
pub use choice::StartReason;
use choice::{gaps_to_keep, is_better_and_valid, Standing};
mod outline;
#[cfg(test)]
mod polygon_checks;
mod profile;

/// Where a generated cage's shape came from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CageStart {
    /// The voxel surface around the mesh, simplified.
    #[default]
    Voxels,
    /// The mesh's bounding box grown by the clearance.
    BoundingBox,
    /// A prism along an axis (0 for x, 1 for y, 2 for z) over the mesh's
    /// outline seen along it.
    Prism { axis: usize },
}

impl CageStart {
    /// Its name in the summary and in Python's report.
    pub fn name(self) -> &'static str {
        match self {
            CageStart::Voxels => "voxels",
            CageStart::BoundingBox => "bounding box",
            CageStart::Prism { axis: 0 } => "prism along x",
            CageStart::Prism { axis: 1 } => "prism along y",
            CageStart::Prism { .. } => "prism along z",
        }
    }
}

/// Replace the attempt's cage with the best of the starts that fit the
/// target: the one that keeps the most gaps open, then the smallest, when
/// it is better and valid ([`is_better_and_valid`]).
pub(super) fn replace_if_better(
    best: &mut Attempt,
    (mesh, mesh_points, gap_points): (&TriMesh, &PointTree, &[GapPoint]),
    goal: &Goal,
) {
    let target = goal.target_vertices;
    if target < 8 {
        return;
    }
    let to_beat = signed_volume(&best.simplified.positions, &best.simplified.triangles);
    // Between walls only: where a gap opens out, a coarse cage from the
    // voxels (a spiky ball's nine vertices) leaves points outside that no
    // part of the mesh is kept apart by, and a start bridging those bridges
    // no gap the simplification kept open; the report still counts them.
    let gaps: Vec<DVec3> = (gap_points.iter())
        .filter(|g| !g.opening)
        .map(|g| g.position)
        .collect();
    let voxels = Standing::of(&best.simplified, &gaps);
    let prisms_tried = prisms_fit(target, voxels.bridges_any());
    if !box_fits(target) && !prisms_tried {
        return;
    }
    let worth_tightening: &WorthTightening =
        &|start: (&[DVec3], &[[u32; 3]])| gaps_to_keep(start, &voxels, &gaps);
    // Each start is tightened on its own, so they share the cores.
    let (boxed, prisms) = rayon::join(
        || {
            box_fits(target)
                .then(|| boxed_cage(mesh, mesh_points, goal, (best.cell, worth_tightening)))
                .flatten()
                .map(|cage| (CageStart::BoundingBox, cage))
        },
        || {
            let beat = (best.cell, to_beat, worth_tightening);
            if prisms_tried {
                prism_cages(mesh, (mesh_points, &gaps), goal, beat)
            } else {
                Vec::new()
            }
        },
    );
    let mut standing = voxels.clone();
    for (kind, start) in boxed.into_iter().chain(prisms) {
        if let Some(better) = is_better_and_valid(&start, &standing, mesh, &gaps) {
            best.simplified = start;
            best.start = kind;
            standing = better;
        }
    }
    // Said against the voxels' cage, whichever start the winner beat last.
    best.start_reason = (best.start != CageStart::Voxels)
        .then(|| StartReason::between(&voxels, &standing))
        .flatten();
}

/// Targets a box's eight vertices are within 15 % of.
fn box_fits(target: usize) -> bool {
    8.0 >= 0.85 * target as f64
}

/// Prisms are tried up to this target, each at the cost of a polish of its
/// own, and above it only where the cage from the voxels bridges gaps: a
/// hand of four fingers needs 32 corners (16 on each cap) to keep its gaps
/// as a prism, the bundled comb 40, and a hand whose fingers are 2.07 % of
/// the diagonal apart is kept apart by the voxels only from about 120.
const MAX_PRISM_TARGET: usize = 64;

/// Whether prisms are tried for `target`, where the cage from the voxels
/// has `bridged` gap points midway between walls or not.
fn prisms_fit(target: usize, bridged: bool) -> bool {
    target >= 8 && (target <= MAX_PRISM_TARGET || bridged)
}

/// A prism starting over this many times the cage it would replace is
/// left untried.
const HOPELESS: f64 = 1.25;

/// The clearance is kept with a little to spare, so that rounding never
/// puts a start closer than it.
const SPARE: f64 = 1.001;

/// The bounding box grown by a little more than the clearance, tightened and
/// polished under the usual checks: the box starts across most gaps, and
/// the report says which it bridges.
fn boxed_cage(
    mesh: &TriMesh,
    mesh_points: &PointTree,
    goal: &Goal,
    (cell, worth_tightening): (f64, &WorthTightening),
) -> Option<Simplified> {
    if mesh.positions.is_empty() {
        return None;
    }
    let (lo, hi) = mesh.bounds();
    let (centre, half) = (0.5 * (lo + hi), 0.5 * (hi - lo) + SPARE * goal.clearance);
    let (positions, triangles) = box_around(centre, half);
    let kept_out = worth_tightening((&positions, &triangles))?;
    tighten(
        mesh,
        (mesh_points, kept_out),
        goal,
        cell,
        (positions, triangles),
    )
}

/// The gap points to keep outside while a start is tightened, or None when
/// it cannot be kept ([`choice::gaps_to_keep`]).
type WorthTightening<'a> = dyn Fn((&[DVec3], &[[u32; 3]])) -> Option<Vec<DVec3>> + Sync + 'a;

/// A closed box of eight corners.
fn box_around(centre: DVec3, half: DVec3) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let unit = cube_cage(1.0);
    let positions = unit
        .positions()
        .iter()
        .map(|p| centre + *p * half)
        .collect();
    (positions, unit.triangles().to_vec())
}

/// Prisms along x, y and z with about half the target's corners on each
/// cap, tightened and polished; none where the mesh is flat along the
/// axis's view. A prism that starts
/// well over `to_beat` (the volume of the cage it would replace) is not
/// tightened: tightening took back at most 18 % of a prism (the bundled
/// comb's); nor is one that bridges a gap the cage keeps open.
fn prism_cages(
    mesh: &TriMesh,
    (mesh_points, gaps): (&PointTree, &[DVec3]),
    goal: &Goal,
    (cell, to_beat, worth_tightening): (f64, f64, &WorthTightening),
) -> Vec<(CageStart, Simplified)> {
    if mesh.positions.is_empty() {
        return Vec::new();
    }
    let target = goal.target_vertices;
    (0..3)
        .into_par_iter()
        .filter_map(|axis| {
            let prism = prism(mesh, axis, (target / 2, SPARE * goal.clearance), gaps)?;
            // A view with fewer corners (a box seen along an edge) would
            // fall short of the target.
            let reached = prism.0.len() as f64;
            ((reached - target as f64).abs() <= 0.15 * target as f64).then_some(())?;
            (signed_volume(&prism.0, &prism.1) <= HOPELESS * to_beat).then_some(())?;
            let kept_out = worth_tightening((&prism.0, &prism.1))?;
            let tightened = tighten(mesh, (mesh_points, kept_out), goal, cell, prism)?;
            Some((CageStart::Prism { axis }, tightened))
        })
        .collect()
}

/// A closed start at the target already, tightened and polished. The gap
/// points it leaves outside (`kept_out`) stay outside: without them, a
/// prism around a hand (fingers 2 % of its diagonal apart, N = 100) came
/// out of tightening over 14 of its 1,344 gap points and was refused.
fn tighten(
    mesh: &TriMesh,
    (mesh_points, kept_out): (&PointTree, Vec<DVec3>),
    goal: &Goal,
    cell: f64,
    (positions, triangles): (Vec<DVec3>, Vec<[u32; 3]>),
) -> Option<Simplified> {
    // No collapse runs, so the envelope only sets the step. Its reach, half
    // the diagonal, says in the summary that any parts may share the cage.
    let (lo, _) = mesh.bounds();
    let envelope = Envelope {
        origin: lo,
        cell,
        dims: [1, 1, 1],
        distance: vec![0],
        limit: (0.5 * goal.diagonal / cell).ceil().min(f64::from(u16::MAX)) as u16,
    };
    let kept_out = PointTree::new(kept_out);
    simplify::simplify(
        (mesh_points, &kept_out),
        positions,
        triangles,
        envelope,
        goal,
        &|_| true,
    )
}

/// The other two axes, in the order that makes (u, w, axis) right-handed.
fn plane_axes(axis: usize) -> (usize, usize) {
    ((axis + 1) % 3, (axis + 2) % 3)
}

/// The prism along `axis` over a polygon of at most `corners` corners
/// around the mesh's view along it, everything `margin` or more from the
/// mesh: of its convex hull's cut and its traced outline's, which follows a
/// concave view (a bench's side, the slots between fingers), the one that
/// leaves more of `gaps` outside seen along the axis, then the smaller.
/// Vertices 0..n are the lower cap's, n..2n the upper's.
fn prism(
    mesh: &TriMesh,
    axis: usize,
    (corners, margin): (usize, f64),
    gaps: &[DVec3],
) -> Option<(Vec<DVec3>, Vec<[u32; 3]>)> {
    let (u, w) = plane_axes(axis);
    let seen = |p: &DVec3| DVec2::new(p[u], p[w]);
    let hull = grown(
        &convex_hull(mesh.positions.iter().map(seen).collect()),
        margin,
    )?;
    let keep_out: Vec<DVec2> = gaps.iter().map(seen).collect();
    // A convex outline has no reflex corner, so only the edge cuts apply.
    let convex = profile::fewer_corners_holding(hull, corners, &keep_out);
    let view = mesh
        .triangles
        .iter()
        .map(|t| t.map(|i| seen(&mesh.positions[i as usize])));
    // The traced outline when it keeps more gaps open, or as many in less area.
    let concave = outline::traced_outline(view, margin)
        .and_then(|traced| profile::fewer_corners_holding(traced, corners, &keep_out))
        .filter(|(concave, kept)| {
            convex.as_ref().is_none_or(|(convex, convex_kept)| {
                kept > convex_kept || (kept == convex_kept && area(concave) < area(convex))
            })
        })
        .map(|(polygon, _)| polygon);
    let convex = convex.map(|(polygon, _)| polygon);
    let (outline, cap) = match concave {
        Some(concave) => {
            let cap = cap::cap_triangles(&concave)?;
            (concave, cap)
        }
        None => {
            let convex = convex?;
            let cap = strip(convex.len());
            (convex, cap)
        }
    };
    let (lo, hi) = mesh.bounds();
    let (bottom, top) = (lo[axis] - margin, hi[axis] + margin);
    let n = outline.len();
    let mut positions = Vec::with_capacity(2 * n);
    for height in [bottom, top] {
        for corner in &outline {
            let mut p = DVec3::ZERO;
            (p[u], p[w], p[axis]) = (corner.x, corner.y, height);
            positions.push(p);
        }
    }
    let n32 = n as u32;
    let mut triangles = Vec::with_capacity(4 * n - 4);
    for i in 0..n32 {
        let j = (i + 1) % n32;
        triangles.push([i, j, n32 + j]);
        triangles.push([i, n32 + j, n32 + i]);
    }
    for [a, b, c] in cap {
        triangles.push([n32 + a, n32 + b, n32 + c]);
        triangles.push([a, c, b]);
    }
    Some((positions, triangles))
}

/// A polygon's area, positive when counter-clockwise.
fn area(polygon: &[DVec2]) -> f64 {
    let n = polygon.len();
    0.5 * (0..n)
        .map(|i| polygon[i].perp_dot(polygon[(i + 1) % n]))
        .sum::<f64>()
}

/// Andrew's monotone chain: the hull's corners, counter-clockwise, without
/// points on its edges.
fn convex_hull(mut points: Vec<DVec2>) -> Vec<DVec2> {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let turn = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<DVec2> = Vec::with_capacity(points.len() + 1);
    let add = |hull: &mut Vec<DVec2>, floor: usize, p: DVec2| {
        while hull.len() >= floor + 2 && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
        {
            hull.pop();
        }
        hull.push(p);
    };
    // The lower chain left to right, then the upper one back; each chain's
    // last point is the other's first.
    for &p in &points {
        add(&mut hull, 0, p);
    }
    let lower = hull.len() - 1;
    for &p in points.iter().rev().skip(1) {
        add(&mut hull, lower, p);
    }
    hull.pop();
    hull
}

/// Each edge of a convex counter-clockwise polygon moved out by `margin`,
/// and the corners where the moved edges meet: every point of the polygon
/// is then at least `margin` inside.
fn grown(polygon: &[DVec2], margin: f64) -> Option<Vec<DVec2>> {
    let n = polygon.len();
    if n < 3 {
        return None;
    }
    let outward = |i: usize| {
        let edge = polygon[(i + 1) % n] - polygon[i];
        DVec2::new(edge.y, -edge.x).try_normalize()
    };
    (0..n)
        .map(|i| {
            let before = (i + n - 1) % n;
            let (a, b) = (outward(before)?, outward(i)?);
            let p = polygon[i];
            meet(
                (p + a * margin, polygon[i] - polygon[before]),
                (p + b * margin, polygon[(i + 1) % n] - p),
            )
        })
        .collect()
}

/// Where the line through `p` along `d` meets the line through `q` along
/// `e`, unless they are (nearly) parallel.
fn meet((p, d): (DVec2, DVec2), (q, e): (DVec2, DVec2)) -> Option<DVec2> {
    let denominator = d.perp_dot(e);
    if denominator.abs() <= 1e-12 * d.length() * e.length() {
        return None;
    }
    Some(p + d * ((q - p).perp_dot(e) / denominator))
}

/// A counter-clockwise triangulation of a convex n-gon zig-zagging between
/// its two ends, which keeps its triangles wider than a fan does.
fn strip(n: usize) -> Vec<[u32; 3]> {
    let (mut low, mut high) = (0u32, n as u32 - 1);
    let mut triangles = Vec::with_capacity(n - 2);
    let mut from_low = true;
    while high - low >= 2 {
        if from_low {
            triangles.push([low, low + 1, high]);
            low += 1;
        } else {
            triangles.push([low, high - 1, high]);
            high -= 1;
        }
        from_low = !from_low;
    }
    triangles
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cagegen::measure::enclosure;
    use crate::geometry::procedural::{icosphere, SplitMix64};
    use crate::geometry::Cage;

    /// Signed distance of `p` inside each edge of a counter-clockwise polygon.
    fn inside_by(polygon: &[DVec2], p: DVec2) -> f64 {
        let n = polygon.len();
        (0..n)
            .map(|i| {
                let (a, b) = (polygon[i], polygon[(i + 1) % n]);
                (b - a).perp_dot(p - a) / (b - a).length()
            })
            .fold(f64::INFINITY, f64::min)
    }

    fn circle(points: usize, radius: f64) -> Vec<DVec2> {
        (0..points)
            .map(|k| {
                let angle = std::f64::consts::TAU * k as f64 / points as f64;
                DVec2::new(angle.cos(), angle.sin()) * radius + DVec2::new(5.0, -3.0)
            })
            .collect()
    }

    #[test]
    fn the_hull_holds_every_point_and_has_only_corners() {
        let mut random = SplitMix64(5);
        let points: Vec<DVec2> = (0..2_000)
            .map(|_| DVec2::new(random.unit(), random.unit() * 0.3))
            .collect();
        let hull = convex_hull(points.clone());
        assert!(area(&hull) > 0.0, "counter-clockwise");
        assert!(points.iter().all(|&p| inside_by(&hull, p) >= -1e-12));
        let n = hull.len();
        for i in 0..n {
            let [a, b, c] = [0, 1, 2].map(|k| hull[(i + k) % n]);
            assert!((b - a).perp_dot(c - b) > 0.0, "corner {i} turns left");
        }
    }

    /// Cut down, the polygon still holds the points the clearance away, and
    /// is within 10 % of the best four corners around a circle (a square of
    /// side 2r; the greedy cut measured 8.4 % over it).
    #[test]
    fn fewer_corners_hold_the_grown_polygon_and_stay_small() {
        let (radius, margin) = (2.0, 0.1);
        let points = circle(90, radius);
        let outline = grown(&convex_hull(points.clone()), margin).unwrap();
        for corners in [4, 6, 12] {
            let polygon = profile::fewer_corners_holding(outline.clone(), corners, &[])
                .unwrap()
                .0;
            assert_eq!(polygon.len(), corners);
            let least = points
                .iter()
                .map(|&p| inside_by(&polygon, p))
                .fold(f64::INFINITY, f64::min);
            assert!(least >= margin * (1.0 - 1e-9), "{corners}: {least}");
            let reach = radius + margin;
            if corners == 4 {
                assert!(
                    area(&polygon) < 1.1 * 4.0 * reach * reach,
                    "{}",
                    area(&polygon)
                );
            }
            // Any enclosing polygon is larger than the circle's own.
            assert!(area(&polygon) > std::f64::consts::PI * reach * reach * 0.99);
        }
    }

    /// The prism is a valid cage, every mesh vertex inside at the margin.
    #[test]
    fn a_prism_is_a_closed_cage_around_the_mesh_at_the_margin() {
        let sphere = icosphere(1.0, 2);
        let mesh = TriMesh {
            positions: (sphere.positions().iter())
                .map(|p| *p * DVec3::new(3.0, 1.0, 0.5))
                .collect(),
            triangles: sphere.triangles().to_vec(),
            triangle_faces: (0..sphere.triangles().len() as u32).collect(),
        };
        for axis in 0..3 {
            let (positions, triangles) = prism(&mesh, axis, (7, 0.05), &[]).unwrap();
            assert_eq!(positions.len(), 14);
            let (cage, report) = Cage::new(TriMesh {
                triangle_faces: (0..triangles.len() as u32).collect(),
                positions,
                triangles,
            })
            .unwrap();
            assert!(!report.flipped, "axis {axis}: faces outward as built");
            let enclosed = enclosure(&cage, &mesh);
            assert!(enclosed.first_outside.is_none(), "axis {axis}");
            assert!(enclosed.min_clearance >= 0.05 * (1.0 - 1e-9), "axis {axis}");
        }
    }
}

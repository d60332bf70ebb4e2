//! Gaps between parts of the mesh, found on its surface: from points on each
//! face, a ray along the face's outward normal that meets the mesh again
//! within a few clearances, through empty space, crosses a gap, and the point
//! midway is a *gap point*. Where the faces' normals reliably point outward
//! (a sample of faces has the mesh's inside behind each), only the outward
//! ray is cast: the inward one meets the far side of the solid, which is no
//! gap. (On four shared models the inward rays were half the casts, found no
//! gap point, and asked for 23–99.7 % of the winding numbers.) A mesh whose
//! faces all face inward casts the other way; an open sheet, whose two sides
//! are both outside, or a mesh of mixed orientation, casts both ways.
//!
//! The simplification and the tightening keep every gap point outside the
//! cage that is outside the voxels they start from, so a cage that keeps a gap
//! open in its voxels keeps it open to the end: the mirror of the mesh's
//! samples, which must stay inside.

use super::plan::lattice_divisions;
use super::winding::TriangleTree;
use crate::geometry::{classify_points, Cage, PointClass, TriMesh};
use glam::DVec3;
use rayon::prelude::*;

/// A point midway across a gap, and the gap's width there.
#[derive(Clone, Copy, Debug)]
pub(super) struct GapPoint {
    pub position: DVec3,
    pub width: f64,
    /// Where the gap opens out, not between its walls ([`mouth_points`]).
    pub opening: bool,
}

/// Gap points across gaps from `widths.0` to `widths.1` wide, from points
/// about `spacing` apart on every face. Their number is at most the faces'
/// lattice points at that spacing, which [`super::plan`] bounds (it checks the
/// count at half this spacing).
pub(super) fn gap_points(
    mesh: &TriMesh,
    tree: &TriangleTree,
    spacing: f64,
    (narrowest, widest): (f64, f64),
) -> Vec<GapPoint> {
    let start_offset = 1e-9 * mesh.diagonal();
    let sides = ray_sides(mesh, tree);
    mesh.triangles
        .par_iter()
        .flat_map_iter(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let normal = (b - a).cross(c - a).normalize_or_zero();
            let n = lattice_divisions([a, b, c], spacing).max(1.0) as usize;
            let third = 1.0 / 3.0;
            let starts = (0..n).flat_map(move |i| {
                (0..n - i).map(move |j| {
                    let (u, v) = ((i as f64 + third) / n as f64, (j as f64 + third) / n as f64);
                    a + (b - a) * u + (c - a) * v
                })
            });
            starts.flat_map(move |p| {
                sides.iter().flat_map(move |&side| {
                    let d = side * normal;
                    if d == DVec3::ZERO {
                        return Vec::new();
                    }
                    let Some(hit) = tree.first_hit(p + d * start_offset, d, widest) else {
                        return Vec::new();
                    };
                    let width = start_offset + hit;
                    let position = p + d * (0.5 * width);
                    // Midway between two surfaces, not beside a third (the palm
                    // at a finger's foot); and outside the mesh, where a face
                    // facing the wrong way or a hole let the ray into the solid.
                    let medial = |at: DVec3| !tree.is_within(at, 0.45 * width);
                    let outside = |at: DVec3| tree.winding_number(at).abs() < 0.5;
                    if width < narrowest || !medial(position) || !outside(position) {
                        return Vec::new();
                    }
                    let mut found = vec![GapPoint {
                        position,
                        width,
                        opening: false,
                    }];
                    found.extend(mouth_points(tree, position, d, width, |at| {
                        medial(at) && outside(at)
                    }));
                    found
                })
            })
        })
        .collect()
}

/// Points where the gap at `position` (across `direction`, `width` wide)
/// opens out: a width from it along the gap's two other directions, where
/// no wall lies within a width on either side and `keeps` holds (off the
/// mesh, outside it). Past two fingertips, or in
/// front of the gap between two fingers, a face joining them would cover
/// no point midway between walls, yet join the parts all the same.
fn mouth_points<'a>(
    tree: &'a TriangleTree,
    position: DVec3,
    direction: DVec3,
    width: f64,
    keeps: impl Fn(DVec3) -> bool + 'a,
) -> impl Iterator<Item = GapPoint> + 'a {
    let (first, second) = direction.any_orthonormal_pair();
    [first, -first, second, -second]
        .into_iter()
        .map(move |t| position + t * width)
        .filter(move |&at| {
            let walled = |d: DVec3| tree.first_hit(at, d, width).is_some();
            !walled(direction) && !walled(-direction) && keeps(at)
        })
        .map(move |position| GapPoint {
            position,
            width,
            opening: true,
        })
}

/// Faces sampled to tell which way the normals point.
const ORIENTATION_SAMPLES: usize = 64;
/// Of the sampled faces that have the mesh's inside on one side only, the
/// share that must agree for one ray per start; and the least share of the
/// samples those faces must be (on an open sheet neither side is inside).
const ORIENTATION_AGREEMENT: f64 = 0.9;
const ORIENTATION_DECIDED: f64 = 0.25;

/// Along which normals the gap rays go: `[1.0]` when the sampled faces that
/// have the mesh's inside (winding number over ½) on one side have it behind
/// them, `[-1.0]` when in front, both ways when they disagree or too few have
/// an inside at all (an open sheet). An open mesh with holes or loose sheets
/// (FireHydrant: 29 faces with the inside behind, 1 in front, 34 with none)
/// still casts one way.
fn ray_sides(mesh: &TriMesh, tree: &TriangleTree) -> &'static [f64] {
    let step = mesh.triangles.len().div_ceil(ORIENTATION_SAMPLES).max(1);
    let offset = 1e-6 * mesh.diagonal();
    let (mut outward, mut inward, mut sampled) = (0usize, 0usize, 0usize);
    for t in mesh.triangles.iter().step_by(step) {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let Some(normal) = (b - a).cross(c - a).try_normalize() else {
            continue;
        };
        let centre = (a + b + c) / 3.0;
        let front = tree.winding_number(centre + normal * offset).abs() > 0.5;
        let back = tree.winding_number(centre - normal * offset).abs() > 0.5;
        sampled += 1;
        outward += usize::from(back && !front);
        inward += usize::from(front && !back);
    }
    let decided = outward + inward;
    let enough = decided > 0 && decided as f64 >= ORIENTATION_DECIDED * sampled as f64;
    let agreed = |count: usize| count as f64 >= ORIENTATION_AGREEMENT * decided as f64;
    if enough && agreed(outward) {
        &[1.0]
    } else if enough && agreed(inward) {
        &[-1.0]
    } else {
        &[1.0, -1.0]
    }
}

/// Points midway across the gaps between parts of the mesh (from two
/// clearances wide to twice the farthest the cage may stand off the mesh), and
/// how many of them the cage leaves outside. A gap point inside the cage is in
/// a gap the cage bridges.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GapReport {
    /// Gaps up to this wide were looked for (in the mesh's units).
    pub range: f64,
    pub points: usize,
    /// Gap points outside the cage (its patches, where it has quads).
    pub open: usize,
    /// The narrowest gap with a point outside the cage, and the widest with
    /// one inside, in the mesh's units.
    pub narrowest_open: Option<f64>,
    pub widest_closed: Option<f64>,
    /// The gap points inside the cage, in the mesh's coordinates: where it
    /// bridges a gap, for a view to show.
    pub bridged: Vec<DVec3>,
}

impl GapReport {
    pub fn closed(&self) -> usize {
        self.points - self.open
    }
}

/// Which gap points the finished cage leaves outside, classified as any point
/// is against a cage (by its patches where it has quads).
pub(super) fn report(points: &[GapPoint], range: f64, cage: &Cage) -> GapReport {
    let positions: Vec<DVec3> = points.iter().map(|g| g.position).collect();
    let classes = classify_points(cage, &positions).classes;
    let mut report = GapReport {
        range,
        points: points.len(),
        ..GapReport::default()
    };
    for (point, class) in points.iter().zip(&classes) {
        let widest = |w: Option<f64>| Some(w.map_or(point.width, |w: f64| w.max(point.width)));
        let narrowest = |w: Option<f64>| Some(w.map_or(point.width, |w: f64| w.min(point.width)));
        if matches!(class, PointClass::Outside) {
            report.open += 1;
            report.narrowest_open = narrowest(report.narrowest_open);
        } else {
            report.widest_closed = widest(report.widest_closed);
            report.bridged.push(point.position);
        }
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> TriMesh {
        TriMesh {
            triangle_faces: (0..triangles.len() as u32).collect(),
            positions,
            triangles,
        }
    }

    fn sides(mesh: &TriMesh) -> &'static [f64] {
        ray_sides(mesh, &TriangleTree::new(&mesh.positions, &mesh.triangles))
    }

    #[test]
    fn rays_go_outward_from_a_solid_either_way_round_and_both_ways_when_unsure() {
        let sphere = crate::geometry::procedural::icosphere(1.0, 2);
        let solid = mesh(sphere.positions().to_vec(), sphere.triangles().to_vec());
        assert_eq!(sides(&solid), &[1.0]);
        let mut inside_out = solid.clone();
        for t in &mut inside_out.triangles {
            t.swap(1, 2);
        }
        assert_eq!(sides(&inside_out), &[-1.0]);
        // Every other face turned round: no way is outward for most.
        let mut mixed = solid.clone();
        for t in mixed.triangles.iter_mut().step_by(2) {
            t.swap(1, 2);
        }
        assert_eq!(sides(&mixed), &[1.0, -1.0]);
        // A square sheet of 8 × 8 cells: both sides are outside.
        let n = 8u32;
        let positions = (0..=n)
            .flat_map(|i| (0..=n).map(move |j| DVec3::new(f64::from(i), f64::from(j), 0.0)))
            .collect();
        let corner = |i: u32, j: u32| i * (n + 1) + j;
        let triangles = (0..n)
            .flat_map(|i| {
                (0..n).flat_map(move |j| {
                    let [a, b, c, d] = [
                        corner(i, j),
                        corner(i + 1, j),
                        corner(i + 1, j + 1),
                        corner(i, j + 1),
                    ];
                    [[a, b, c], [a, c, d]]
                })
            })
            .collect();
        assert_eq!(sides(&mesh(positions, triangles)), &[1.0, -1.0]);
    }
}

//! Gaps between parts of the mesh, found on its surface: from points on each
//! face, a ray along the face's outward normal that meets the mesh again
//! within a few clearances, through empty space, crosses a gap, and the point
//! midway is a *gap point*. Only the outward ray is cast: the inward one meets
//! the far side of the solid, which is no gap. (On four shared models the
//! inward rays were half the casts, found no gap point, and asked for 23–99.7 %
//! of the winding numbers.) A part of the mesh facing inward, against the
//! rest, finds its gaps from the other side of each gap.
//!
//! The simplification and the tightening keep every gap point outside the
//! cage that is outside the voxels they start from, so a cage that keeps a gap
//! open in its voxels keeps it open to the end: the mirror of the mesh's
//! samples, which must stay inside.

use super::plan::lattice_divisions;
use super::winding::TriangleTree;
use crate::geometry::cage::signed_volume;
use crate::geometry::{classify_points, Cage, PointClass, TriMesh};
use glam::DVec3;
use rayon::prelude::*;

/// A point midway across a gap, and the gap's width there.
#[derive(Clone, Copy, Debug)]
pub(super) struct GapPoint {
    pub position: DVec3,
    pub width: f64,
}

/// Gap points across gaps from `widths.0` to `widths.1` wide, from points
/// about `spacing` apart on every face. Outward is the side that makes the
/// mesh's signed volume positive. Their number is at most the faces'
/// lattice points at that spacing, which [`super::plan`] bounds (it checks the
/// count at half this spacing).
pub(super) fn gap_points(
    mesh: &TriMesh,
    tree: &TriangleTree,
    spacing: f64,
    (narrowest, widest): (f64, f64),
) -> Vec<GapPoint> {
    let start_offset = 1e-9 * mesh.diagonal();
    let outward = if signed_volume(&mesh.positions, &mesh.triangles) < 0.0 {
        -1.0
    } else {
        1.0
    };
    mesh.triangles
        .par_iter()
        .flat_map_iter(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let d = outward * (b - a).cross(c - a).normalize_or_zero();
            let n = lattice_divisions([a, b, c], spacing).max(1.0) as usize;
            let third = 1.0 / 3.0;
            let starts = (0..n).flat_map(move |i| {
                (0..n - i).map(move |j| {
                    let (u, v) = ((i as f64 + third) / n as f64, (j as f64 + third) / n as f64);
                    a + (b - a) * u + (c - a) * v
                })
            });
            starts.filter_map(move |p| {
                if d == DVec3::ZERO {
                    return None;
                }
                let width = start_offset + tree.first_hit(p + d * start_offset, d, widest)?;
                let position = p + d * (0.5 * width);
                // Midway between two surfaces, not beside a third (the palm at
                // a finger's foot); and outside the mesh, where a face facing
                // the wrong way or a hole let the ray into the solid.
                let medial = || !tree.is_within(position, 0.45 * width);
                (width >= narrowest && medial() && tree.winding_number(position).abs() < 0.5)
                    .then_some(GapPoint { position, width })
            })
        })
        .collect()
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

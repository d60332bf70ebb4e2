//! A second start for cages of eight vertices: the mesh's bounding box,
//! grown by the clearance, then tightened and polished like any other
//! cage. Eight vertices are what an artist gives a box-like model, and the
//! simplification's own 8-vertex cage can end twisted, with corners well
//! out, where moving one vertex at a time cannot straighten it. The smaller
//! of the two is kept, so this start never makes a cage larger.

use super::measure::enclosure;
use super::points::PointTree;
use super::simplify::{self, Goal, Simplified};
use super::voxels::Envelope;
use super::Attempt;
use crate::geometry::cage::signed_volume;
use crate::geometry::procedural::cube_cage;
use crate::geometry::{Cage, TriMesh};

/// Targets a box's eight vertices are within 15 % of.
pub(super) fn box_fits(target: usize) -> bool {
    8.0 >= 0.85 * target as f64
}

/// The bounding box grown by a little more than the clearance, tightened and
/// polished under the usual checks, with no gap points: the box starts
/// across every gap, and the report says which it bridges.
pub(super) fn boxed_cage(
    mesh: &TriMesh,
    mesh_points: &PointTree,
    goal: &Goal,
    cell: f64,
) -> Option<Simplified> {
    if mesh.positions.is_empty() {
        return None;
    }
    let (lo, hi) = mesh.bounds();
    let (centre, half) = (0.5 * (lo + hi), 0.5 * (hi - lo) + 1.001 * goal.clearance);
    let unit = cube_cage(1.0);
    let positions = unit
        .positions()
        .iter()
        .map(|p| centre + *p * half)
        .collect();
    let triangles = unit.triangles().to_vec();
    // The box is already at the target: no collapse runs, so the envelope
    // only sets the step. Its reach, half the diagonal, says in the summary
    // that any parts may share the cage.
    let envelope = Envelope {
        origin: lo,
        cell,
        dims: [1, 1, 1],
        distance: vec![0],
        limit: (0.5 * goal.diagonal / cell).ceil().min(f64::from(u16::MAX)) as u16,
    };
    let no_gaps = PointTree::new(Vec::new());
    simplify::simplify(
        (mesh_points, &no_gaps),
        positions,
        triangles,
        envelope,
        goal,
        &|_| true,
    )
}

/// Whether `boxed` encloses less than the attempt's cage, and is a valid
/// cage around every mesh vertex (checked here as well as when the chosen
/// cage is finished, so that a box that fails costs nothing).
pub(super) fn is_smaller_and_valid(boxed: &Simplified, attempt: &Attempt, mesh: &TriMesh) -> bool {
    let volume = |cage: &Simplified| signed_volume(&cage.positions, &cage.triangles);
    if volume(boxed) >= volume(&attempt.simplified) {
        return false;
    }
    let cage = Cage::new(TriMesh {
        triangle_faces: (0..boxed.triangles.len() as u32).collect(),
        positions: boxed.positions.clone(),
        triangles: boxed.triangles.clone(),
    });
    cage.is_ok_and(|(cage, _)| enclosure(&cage, mesh).first_outside.is_none())
}

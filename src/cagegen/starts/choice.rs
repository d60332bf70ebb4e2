//! Which start replaces the simplification's cage: a gap kept open comes
//! before a smaller volume, and no start bridges a gap the cage kept open.

use crate::cagegen::measure::enclosure;
use crate::cagegen::simplify::Simplified;
use crate::geometry::cage::signed_volume;
use crate::geometry::{classify_points, Cage, PointClass, TriMesh};
use glam::DVec3;

/// Why a start replaced the cage. Either way it keeps open every gap point
/// the cage kept open.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StartReason {
    /// It encloses less.
    Smaller,
    /// It keeps open gap points that the cage bridged, though larger.
    MoreGapsOpen,
    /// It encloses less and keeps open gap points that the cage bridged.
    SmallerAndMoreGapsOpen,
}

impl StartReason {
    /// Its name in Python's report.
    pub fn name(self) -> &'static str {
        match self {
            StartReason::Smaller => "smaller",
            StartReason::MoreGapsOpen => "more gaps open",
            StartReason::SmallerAndMoreGapsOpen => "smaller and more gaps open",
        }
    }

    /// Why `after` is better than `before`; None when it is not (it bridges
    /// a gap point `before` kept open, or is neither smaller nor opens any).
    pub(super) fn between(before: &Standing, after: &Standing) -> Option<StartReason> {
        let keeps_all = keeps_every_open(&before.open, &after.open);
        let opens_more = (before.open.iter().zip(&after.open)).any(|(&was, &is)| is && !was);
        let smaller = after.volume < before.volume;
        match (keeps_all, opens_more, smaller) {
            (false, _, _) | (true, false, false) => None,
            (true, false, true) => Some(StartReason::Smaller),
            (true, true, false) => Some(StartReason::MoreGapsOpen),
            (true, true, true) => Some(StartReason::SmallerAndMoreGapsOpen),
        }
    }
}

/// What a start must beat: a cage's volume, and which gap points it leaves
/// outside.
#[derive(Clone)]
pub(super) struct Standing {
    volume: f64,
    open: Vec<bool>,
}

impl Standing {
    pub(super) fn of(cage: &Simplified, gap_points: &[DVec3]) -> Standing {
        let open = match as_cage(cage) {
            Some(cage) => Standing::open(&cage, gap_points),
            None => vec![false; gap_points.len()],
        };
        Standing {
            volume: signed_volume(&cage.positions, &cage.triangles),
            open,
        }
    }

    /// Whether the cage bridges any of the gap points.
    pub(super) fn bridges_any(&self) -> bool {
        self.open.contains(&false)
    }

    fn open(cage: &Cage, gap_points: &[DVec3]) -> Vec<bool> {
        let classes = classify_points(cage, gap_points).classes;
        (classes.into_iter())
            .map(|c| matches!(c, PointClass::Outside))
            .collect()
    }
}

/// Whether `start` is a valid cage around every mesh vertex that keeps
/// outside every gap point the cage standing so far keeps outside, and
/// either encloses less or keeps more of them outside: a start begins
/// across every gap, and may close only those the simplification could not
/// keep open at this target; a gap kept open comes before a smaller volume.
/// (Checked here as well as when the chosen cage is finished, so that a
/// start that fails costs nothing.) Returns where `start` stands when it
/// passes.
pub(super) fn is_better_and_valid(
    start: &Simplified,
    standing: &Standing,
    mesh: &TriMesh,
    gap_points: &[DVec3],
) -> Option<Standing> {
    let volume = signed_volume(&start.positions, &start.triangles);
    // Cheap refusals first: a larger start matters only where gaps were bridged.
    if volume >= standing.volume && standing.open.iter().all(|&open| open) {
        return None;
    }
    let cage = as_cage(start)?;
    let after = Standing {
        volume,
        open: Standing::open(&cage, gap_points),
    };
    StartReason::between(standing, &after)?;
    enclosure(&cage, mesh)
        .first_outside
        .is_none()
        .then_some(after)
}

fn as_cage(cage: &Simplified) -> Option<Cage> {
    cage_of(&cage.positions, &cage.triangles)
}

fn cage_of(positions: &[DVec3], triangles: &[[u32; 3]]) -> Option<Cage> {
    let mesh = TriMesh {
        triangle_faces: (0..triangles.len() as u32).collect(),
        positions: positions.to_vec(),
        triangles: triangles.to_vec(),
    };
    Cage::new(mesh).ok().map(|(cage, _)| cage)
}

/// The gap points a start leaves outside before it is tightened, which
/// tightening then keeps outside; None when it already bridges a gap point
/// that `voxels` leaves outside. Tightening moves its faces inward, so such
/// a start would almost always be refused after it: it is not tightened (a
/// comb's prisms seen from the side, which fill every slot).
pub(super) fn gaps_to_keep(
    (positions, triangles): (&[DVec3], &[[u32; 3]]),
    voxels: &Standing,
    gap_points: &[DVec3],
) -> Option<Vec<DVec3>> {
    let Some(cage) = cage_of(positions, triangles) else {
        // Not a valid cage yet: tightened with nothing to keep out, and
        // judged when it is one.
        return (!voxels.open.contains(&true)).then(Vec::new);
    };
    let open = Standing::open(&cage, gap_points);
    keeps_every_open(&voxels.open, &open).then(|| {
        (gap_points.iter().zip(&open))
            .filter(|(_, &is)| is)
            .map(|(&p, _)| p)
            .collect()
    })
}

/// Whether every gap point open `before` is open `after`.
fn keeps_every_open(before: &[bool], after: &[bool]) -> bool {
    before.iter().zip(after).all(|(&was, &is)| is || !was)
}

#[cfg(test)]
mod tests {
    use super::super::{box_around, CageStart};
    use super::*;
    use crate::cagegen::Attempt;

    fn simplified((positions, triangles): (Vec<DVec3>, Vec<[u32; 3]>)) -> Simplified {
        Simplified {
            positions,
            triangles,
            envelope_limit: 0,
        }
    }

    /// Two cubes apart, each in a loose box of its own, and one box around
    /// both that encloses less: the one box is kept only when no gap point
    /// between the cubes says the loose boxes kept that gap open. The other
    /// way round, the loose boxes replace the one box, though larger, when
    /// they keep open a gap point it bridges, and only then.
    #[test]
    fn a_start_is_kept_when_smaller_or_when_it_keeps_more_gaps_open() {
        let (left, right) = (DVec3::new(-2.0, 0.0, 0.0), DVec3::new(2.0, 0.0, 0.0));
        let cube = |centre| box_around(centre, DVec3::splat(0.5));
        let join = |(mut p, mut t): (Vec<DVec3>, Vec<[u32; 3]>),
                    (q, u): (Vec<DVec3>, Vec<[u32; 3]>)| {
            let offset = p.len() as u32;
            p.extend(q);
            t.extend(u.into_iter().map(|tri| tri.map(|i| i + offset)));
            (p, t)
        };
        let (positions, triangles) = join(cube(left), cube(right));
        let mesh = TriMesh {
            triangle_faces: (0..triangles.len() as u32).collect(),
            positions,
            triangles,
        };
        let loose = |centre| box_around(centre, DVec3::splat(1.4));
        let attempt = Attempt {
            simplified: simplified(join(loose(left), loose(right))),
            cell: 0.1,
            grid: [1, 1, 1],
            surface_vertices: 0,
            winding_volume: 0.0,
            start: CageStart::Voxels,
            start_reason: None,
        };
        let one_box = simplified(box_around(DVec3::ZERO, DVec3::new(2.6, 0.6, 0.6)));
        let better = |start: &Simplified, attempt: &Attempt, gaps: &[DVec3]| {
            let before = Standing::of(&attempt.simplified, gaps);
            let after = is_better_and_valid(start, &before, &mesh, gaps)?;
            StartReason::between(&before, &after)
        };
        assert_eq!(better(&one_box, &attempt, &[]), Some(StartReason::Smaller));
        let between = [DVec3::ZERO];
        assert_eq!(better(&one_box, &attempt, &between), None);
        // A gap point the loose boxes cover too does not hold the start back.
        let inside_both = [DVec3::new(2.0, 0.55, 0.0)];
        assert_eq!(
            better(&one_box, &attempt, &inside_both),
            Some(StartReason::Smaller)
        );
        // Before it is tightened, a start that bridges a gap point the cage
        // keeps open is not worth tightening; one that bridges only what
        // the cage bridges too is.
        let may_keep = |start: &Simplified, attempt: &Attempt, gaps: &[DVec3]| {
            let standing = Standing::of(&attempt.simplified, gaps);
            gaps_to_keep((&start.positions, &start.triangles), &standing, gaps).is_some()
        };
        assert!(!may_keep(&one_box, &attempt, &between));
        assert!(may_keep(&one_box, &attempt, &inside_both));
        // What a start leaves outside is what its tightening keeps outside.
        let far = DVec3::new(0.0, 3.0, 0.0);
        let gaps = [inside_both[0], far];
        let standing = Standing::of(&attempt.simplified, &gaps);
        let start = (&one_box.positions[..], &one_box.triangles[..]);
        assert_eq!(gaps_to_keep(start, &standing, &gaps), Some(vec![far]));
        let bridged = Attempt {
            simplified: one_box,
            ..attempt
        };
        let loose_boxes = simplified(join(loose(left), loose(right)));
        assert_eq!(better(&loose_boxes, &bridged, &[]), None);
        assert_eq!(better(&loose_boxes, &bridged, &inside_both), None);
        assert_eq!(
            better(&loose_boxes, &bridged, &between),
            Some(StartReason::MoreGapsOpen)
        );
    }
}

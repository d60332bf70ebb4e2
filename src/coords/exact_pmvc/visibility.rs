//! Which part of each candidate x sees first: its cone less the cones of the
//! candidates in front of it, as convex pieces.

use super::polygon::{clip, side_of, Corner, EdgePlane, Label};
use super::{Candidate, Cone, ExactPmvcScratch, ExactPmvcStats};
use glam::DVec3;

#[derive(Debug, Default)]
pub(super) struct Pieces {
    pub(super) corners: Vec<Corner>,
    pub(super) ends: Vec<usize>,
}

impl Pieces {
    pub(super) fn clear(&mut self) {
        self.corners.clear();
        self.ends.clear();
    }

    pub(super) fn push(&mut self, piece: &[Corner]) {
        self.corners.extend_from_slice(piece);
        self.ends.push(self.corners.len());
    }

    pub(super) fn iter(&self) -> impl Iterator<Item = &[Corner]> {
        let starts = std::iter::once(0).chain(self.ends.iter().copied());
        starts
            .zip(self.ends.iter().copied())
            .map(|(start, end)| &self.corners[start..end])
    }

    pub(super) fn is_empty(&self) -> bool {
        self.ends.is_empty()
    }
}

/// Whether the cones of two candidates may share a direction.
#[inline]
fn cones_overlap(a: &Cone, b: &Cone) -> bool {
    if a.cos_radius + b.cos_radius <= 0.0 {
        // The two half angles add up to π or more.
        return true;
    }
    let cos_sum = a.cos_radius * b.cos_radius - a.sin_radius * b.sin_radius;
    a.axis.dot(b.axis) >= cos_sum - 1e-9
}

/// How candidate s lies in front of candidate t, seen from x.
enum Order {
    /// s is nowhere in front of t (or they do not overlap).
    Behind,
    /// s is in front of t wherever both are seen.
    Front,
    /// Each straddles the other's plane: ask one ray through their overlap.
    Probe,
}

/// Where b (B corners) lies against a's plane (A corners; a quad's slab,
/// which holds its patch): `Some(true)` wholly beyond it seen from x,
/// `Some(false)` wholly on x's side, `None` across it.
#[inline]
fn against<const A: usize, const B: usize>(
    a: &Candidate,
    b: &Candidate,
    relative: &[DVec3],
) -> Option<bool> {
    let vertices = b.vertices::<B>();
    if A == 3 {
        let sides = vertices.map(|v| a.plane_side(v, relative[v as usize]));
        if sides.iter().all(|&d| d >= 0.0) {
            return Some(true);
        }
        if sides.iter().all(|&d| d <= 0.0) {
            return Some(false);
        }
        return None;
    }
    // x must be on the near side of the whole slab for a ray's order to follow.
    if a.offset.is_nan() || a.offset <= 0.0 {
        return None;
    }
    let along = vertices.map(|v| a.normal.dot(relative[v as usize]));
    if along.iter().all(|&d| d >= a.far_offset) {
        return Some(true);
    }
    if along.iter().all(|&d| d <= a.offset) {
        return Some(false);
    }
    None
}

/// Whether s is in front of t where both are seen, as far as the sides of
/// their planes tell: s wholly beyond t's plane (seen from x) is behind it,
/// wholly on x's side of it in front, and the same for t against s's plane.
/// A quad's plane is the slab between its corners across its diagonals'
/// normal, which holds its patch. T and S are their corner counts.
#[inline]
fn order<const T: usize, const S: usize>(
    t: &Candidate,
    s: &Candidate,
    relative: &[DVec3],
) -> Order {
    match against::<T, S>(t, s, relative) {
        Some(true) => Order::Behind,
        Some(false) => Order::Front,
        None => match against::<S, T>(s, t, relative) {
            Some(true) => Order::Front,
            Some(false) => Order::Behind,
            None => Order::Probe,
        },
    }
}

/// Fills `scratch.pieces` with the part of candidate t that x sees first:
/// its cone less those of the candidates in front of it.
pub(super) fn visible_pieces(t: usize, scratch: &mut ExactPmvcScratch) {
    // One scan per corner count of t, and one test per count of the other
    // face: the loops over corners have a constant length.
    if scratch.candidates[t].count == 3 {
        scan::<3>(t, scratch);
    } else {
        scan::<4>(t, scratch);
    }
}

/// [`visible_pieces`] for a candidate t of T corners.
fn scan<const T: usize>(t: usize, scratch: &mut ExactPmvcScratch) {
    let ExactPmvcScratch {
        relative,
        directions,
        candidates,
        cones,
        pieces,
        next,
        work,
        cut,
        sides,
        stats,
        ..
    } = scratch;
    let target = &candidates[t];
    let target_cone = &cones[t];
    pieces.clear();
    pieces.push(&target.corners::<T>());
    for (s, cone) in cones.iter().enumerate() {
        if cone.nearest >= target.farthest {
            // This one and all after it are wholly farther than t.
            return;
        }
        stats.scanned += 1;
        if s == t || !cones_overlap(target_cone, cone) {
            continue;
        }
        stats.cones_overlapping += 1;
        let occluder = &candidates[s];
        let buffers = (&mut *work, &mut *cut, &mut *sides);
        let occludes = if occluder.count == 3 {
            occludes::<T, 3>(target, occluder, directions, relative, buffers, stats)
        } else {
            occludes::<T, 4>(target, occluder, directions, relative, buffers, stats)
        };
        if !occludes {
            continue;
        }
        next.clear();
        stats.occluding += 1;
        for piece in pieces.iter() {
            let overlapped = if occluder.count == 3 {
                subtract::<3>(piece, occluder, directions, next, work, cut, sides)
            } else {
                subtract::<4>(piece, occluder, directions, next, work, cut, sides)
            };
            if overlapped {
                stats.splits += 1;
            }
        }
        std::mem::swap(pieces, next);
        if pieces.is_empty() {
            return;
        }
    }
}

/// Whether s (S corners) is in front of t (T corners) somewhere both are
/// seen: the cheaper tests first, depth by planes, then overlap, then a ray.
#[inline]
fn occludes<const T: usize, const S: usize>(
    target: &Candidate,
    occluder: &Candidate,
    directions: &[DVec3],
    relative: &[DVec3],
    (work, cut, sides): (&mut Vec<Corner>, &mut Vec<Corner>, &mut Vec<f64>),
    stats: &mut ExactPmvcStats,
) -> bool {
    let order = order::<T, S>(target, occluder, relative);
    if matches!(order, Order::Behind) {
        stats.behind += 1;
        return false;
    }
    if faces_separated::<T, S>(target, occluder, directions) {
        stats.separated += 1;
        return false;
    }
    if matches!(order, Order::Probe) {
        stats.probed += 1;
        return probe_in_front::<T, S>(target, occluder, directions, relative, work, cut, sides);
    }
    true
}

/// Whether s is in front of t over the overlap of their cones, by one ray
/// through it; false when they do not overlap. With a quad, the order is
/// taken to hold over the whole overlap, as it does for planar faces.
fn probe_in_front<const T: usize, const S: usize>(
    t: &Candidate,
    s: &Candidate,
    directions: &[DVec3],
    relative: &[DVec3],
    work: &mut Vec<Corner>,
    cut: &mut Vec<Corner>,
    sides: &mut Vec<f64>,
) -> bool {
    work.clear();
    work.extend_from_slice(&t.corners::<T>());
    for plane in s.sides::<S>() {
        sides.clear();
        sides.extend(work.iter().map(|c| side_of(c.direction, c.label, plane)));
        cut.clear();
        if !clip(work, sides, plane, directions, cut) {
            return false;
        }
        std::mem::swap(work, cut);
    }
    let d: DVec3 = work.iter().map(|c| c.direction).sum();
    if T == 3 && S == 3 {
        // t_s < t_t, with t = offset / (N·d) and both N·d > 0 inside both cones.
        return s.offset * d.dot(t.normal) < t.offset * d.dot(s.normal);
    }
    s.distance(d, relative) < t.distance(d, relative)
}

/// Appends to `out` the parts of `piece` outside the cone of `occluder`, cut
/// along its sides in turn. Returns whether the two overlapped (the piece was
/// cut or hidden).
fn subtract<const S: usize>(
    piece: &[Corner],
    occluder: &Candidate,
    directions: &[DVec3],
    out: &mut Pieces,
    work: &mut Vec<Corner>,
    cut: &mut Vec<Corner>,
    sides: &mut Vec<f64>,
) -> bool {
    if separated::<S>(piece, occluder, directions) {
        out.push(piece);
        return false;
    }
    work.clear();
    work.extend_from_slice(piece);
    for plane in occluder.sides::<S>() {
        sides.clear();
        sides.extend(work.iter().map(|c| side_of(c.direction, c.label, plane)));
        if sides.iter().all(|&d| d >= 0.0) {
            continue;
        }
        if sides.iter().all(|&d| d <= 0.0) {
            out.push(work);
            return true;
        }
        // The part outside this side is kept; the rest goes on to the next.
        let outside = plane.flipped();
        for d in sides.iter_mut() {
            *d = -*d;
        }
        if clip(work, sides, &outside, directions, &mut out.corners) {
            out.ends.push(out.corners.len());
        }
        for d in sides.iter_mut() {
            *d = -*d;
        }
        cut.clear();
        if !clip(work, sides, plane, directions, cut) {
            return true;
        }
        std::mem::swap(work, cut);
    }
    true
}

/// Whether a side of either face (t of T corners, s of S) has the other
/// wholly on its outer side: then their cones do not overlap.
#[inline]
fn faces_separated<const T: usize, const S: usize>(
    t: &Candidate,
    s: &Candidate,
    directions: &[DVec3],
) -> bool {
    if !t.vertices::<T>().iter().any(|&v| s.holds::<S>(v)) {
        // No corner in common: no side is exactly 0 by its label.
        let outside = |plane: &EdgePlane, corners: &[DVec3]| {
            corners
                .iter()
                .all(|&d| plane.normal.dot(d) <= plane.tolerance)
        };
        return (t.sides::<T>().iter()).any(|plane| outside(plane, s.directions::<S>()))
            || (s.sides::<S>().iter()).any(|plane| outside(plane, t.directions::<T>()));
    }
    let outside = |plane: &EdgePlane, corners: &[u32]| {
        corners
            .iter()
            .all(|&v| side_of(directions[v as usize], Label::Vertex(v), plane) <= 0.0)
    };
    (t.sides::<T>().iter()).any(|plane| outside(plane, s.vertices::<S>()))
        || (s.sides::<S>().iter()).any(|plane| outside(plane, t.vertices::<T>()))
}

/// Whether a side of either polygon has the other (of S corners) wholly on
/// its outer side.
fn separated<const S: usize>(piece: &[Corner], occluder: &Candidate, directions: &[DVec3]) -> bool {
    let by_occluder = occluder.sides::<S>().iter().any(|plane| {
        piece
            .iter()
            .all(|c| side_of(c.direction, c.label, plane) <= 0.0)
    });
    by_occluder
        || piece.iter().any(|corner| {
            occluder
                .vertices::<S>()
                .iter()
                .all(|&v| side_of(directions[v as usize], Label::Vertex(v), &corner.side) <= 0.0)
        })
}

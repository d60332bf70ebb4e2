//! A prism's profile cut down to a few corners while it keeps holding what
//! it held, and its caps' triangles. Two steps only ever add area to a
//! simple counter-clockwise polygon: a reflex corner is filled by the
//! chord across it, and an edge between two convex corners is cut off by
//! extending its neighbours until they meet. The step that adds the least
//! area and keeps the polygon simple goes first (greedy; a convex outline
//! has only the second).

use glam::DVec2;

/// One step that removes a corner.
#[derive(Clone, Copy, Debug)]
enum Step {
    /// Corner `i` is reflex: the chord from its neighbour before to its
    /// neighbour after replaces it.
    Fill(usize),
    /// Corners `i` and `i + 1` are replaced by where the edges before and
    /// after them, extended, meet.
    Cut(usize, DVec2),
}

/// `polygon` (simple, counter-clockwise) with at most `corners` corners,
/// holding it, and how many of `keep_out` it leaves outside; None when no
/// step that keeps it simple is left first. A step that would cover one of
/// `keep_out` (gap points seen along the prism's axis, between fingers or
/// the legs of a bench) is taken only when no other step is left, so the
/// slots between parts are filled last.
pub(super) fn fewer_corners_holding(
    mut polygon: Vec<DVec2>,
    corners: usize,
    keep_out: &[DVec2],
) -> Option<(Vec<DVec2>, usize)> {
    if corners < 3 {
        return None;
    }
    // Only the points still outside can be covered: a step adds area outside.
    let mut outside: Vec<DVec2> = (keep_out.iter())
        .copied()
        .filter(|&p| winding_number(&polygon, p) == 0)
        .collect();
    while polygon.len() > corners {
        let n = polygon.len();
        if n <= 3 {
            return None;
        }
        let mut steps: Vec<(f64, Step)> = (0..n)
            .flat_map(|i| [fill(&polygon, i), cut(&polygon, i)])
            .flatten()
            .collect();
        // Least added area first; a step that would make the polygon touch
        // itself is passed over.
        steps.sort_by(|a, b| a.0.total_cmp(&b.0));
        // The first simple step covering no point, else the first simple one.
        let mut first_simple = None;
        for step in (steps.iter()).map(|&(_, step)| step) {
            if !keeps_simple(&polygon, step) {
                continue;
            }
            first_simple.get_or_insert(step);
            let triangle = added(&polygon, step);
            if !outside.iter().any(|&p| in_closed_triangle(p, triangle)) {
                first_simple = Some(step);
                break;
            }
        }
        let step = first_simple?;
        let triangle = added(&polygon, step);
        outside.retain(|&p| !in_closed_triangle(p, triangle));
        match step {
            Step::Fill(i) => {
                polygon.remove(i);
            }
            Step::Cut(i, corner) => {
                polygon[i] = corner;
                polygon.remove((i + 1) % n);
            }
        }
    }
    Some((polygon, outside.len()))
}

/// How many times the polygon winds around `p`; 0 outside.
fn winding_number(polygon: &[DVec2], p: DVec2) -> i32 {
    let n = polygon.len();
    (0..n)
        .map(|i| {
            let (a, b) = (polygon[i], polygon[(i + 1) % n]);
            let side = orientation(a, b, p);
            match (a.y <= p.y, b.y <= p.y) {
                (true, false) if side > 0.0 => 1,
                (false, true) if side < 0.0 => -1,
                _ => 0,
            }
        })
        .sum()
}

/// The triangle that `step` adds to the polygon.
fn added(polygon: &[DVec2], step: Step) -> [DVec2; 3] {
    let n = polygon.len();
    match step {
        Step::Fill(i) => [polygon[(i + n - 1) % n], polygon[i], polygon[(i + 1) % n]],
        Step::Cut(i, corner) => [polygon[i], corner, polygon[(i + 1) % n]],
    }
}

/// Corners `i - 1`, `i`, `i + 1` and `i + 2`, wrapping.
fn around(polygon: &[DVec2], i: usize) -> [DVec2; 4] {
    let n = polygon.len();
    [n - 1, 0, 1, 2].map(|k| polygon[(i + k) % n])
}

fn fill(polygon: &[DVec2], i: usize) -> Option<(f64, Step)> {
    let [before, here, after, _] = around(polygon, i);
    let turn = (here - before).perp_dot(after - here);
    (turn < 0.0).then_some((-0.5 * turn, Step::Fill(i)))
}

fn cut(polygon: &[DVec2], i: usize) -> Option<(f64, Step)> {
    let [before, a, b, after] = around(polygon, i);
    let (d, e) = (a - before, b - after);
    let corner = super::meet((a, d), (b, e))?;
    // Ahead of both ends, and outside the edge it replaces.
    let outside = (b - a).perp_dot(corner - a);
    ((corner - a).dot(d) > 0.0 && (corner - b).dot(e) > 0.0 && outside < 0.0)
        .then_some((-0.5 * outside, Step::Cut(i, corner)))
}

/// Whether the polygon stays simple after `step`: the triangle it adds
/// holds no other corner, and its new edges cross no edge they do not
/// share a corner with.
fn keeps_simple(polygon: &[DVec2], step: Step) -> bool {
    let n = polygon.len();
    let at = |k: usize| polygon[k % n];
    // The triangle added, the new edges, the corners whose edges change,
    // and the corners the triangle may hold (its own, or on the lines
    // extended).
    let triangle = added(polygon, step);
    let (new_edges, changed, spared) = match step {
        Step::Fill(i) => {
            let [p, q, r] = [i + n - 1, i, i + 1].map(|k| k % n);
            (vec![(at(p), at(r))], vec![p, q, r], vec![p, q, r])
        }
        Step::Cut(i, corner) => {
            let [p, a, b, q] = [i + n - 1, i, i + 1, i + 2].map(|k| k % n);
            let new_edges = vec![(at(a), corner), (corner, at(b))];
            (new_edges, vec![a, b], vec![p, a, b, q])
        }
    };
    let corner_inside = (0..n)
        .filter(|k| !spared.contains(k))
        .any(|k| in_closed_triangle(polygon[k], triangle));
    let crossed = (0..n)
        .filter(|&k| !changed.contains(&k) && !changed.contains(&((k + 1) % n)))
        .any(|k| {
            let edge = (polygon[k], at(k + 1));
            new_edges.iter().any(|&new| segments_meet(new, edge))
        });
    !corner_inside && !crossed
}

pub(super) fn orientation(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

pub(super) fn in_closed_triangle(p: DVec2, [a, b, c]: [DVec2; 3]) -> bool {
    let s = [
        orientation(a, b, p),
        orientation(b, c, p),
        orientation(c, a, p),
    ];
    s.iter().all(|&x| x >= 0.0) || s.iter().all(|&x| x <= 0.0)
}

/// Whether two closed segments share a point.
fn segments_meet((a, b): (DVec2, DVec2), (c, d): (DVec2, DVec2)) -> bool {
    let [o1, o2, o3, o4] = [
        orientation(a, b, c),
        orientation(a, b, d),
        orientation(c, d, a),
        orientation(c, d, b),
    ];
    let on = |p: DVec2, q: DVec2, r: DVec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    if o1 * o2 < 0.0 && o3 * o4 < 0.0 {
        return true;
    }
    (o1 == 0.0 && on(a, b, c))
        || (o2 == 0.0 && on(a, b, d))
        || (o3 == 0.0 && on(c, d, a))
        || (o4 == 0.0 && on(c, d, b))
}

#[cfg(test)]
mod tests {
    use super::super::polygon_checks::{
        area, boundary_distance, comb, contains, is_simple, star, tangle,
    };
    use super::*;

    fn polygon(corners: &[(f64, f64)]) -> Vec<DVec2> {
        corners.iter().map(|&(x, y)| DVec2::new(x, y)).collect()
    }

    fn holds(outer: &[DVec2], p: DVec2) -> bool {
        contains(outer, p) || boundary_distance(outer, p) <= 1e-9
    }

    #[test]
    fn cut_down_profiles_hold_the_original_and_stay_simple() {
        let shapes = [
            comb(5),
            star(60, 1),
            star(200, 2),
            tangle(40, 3),
            tangle(80, 4),
        ];
        for (s, shape) in shapes.iter().enumerate() {
            assert!(is_simple(shape) && area(shape) > 0.0, "shape {s}");
            for corners in [3, 4, 6, 9, 12] {
                let cut = fewer_corners_holding(shape.clone(), corners, &[])
                    .map(|(cut, _)| cut)
                    .unwrap_or_else(|| panic!("shape {s} at {corners}"));
                assert!(cut.len() <= corners, "shape {s}: {} corners", cut.len());
                assert!(is_simple(&cut), "shape {s} at {corners} crosses itself");
                assert!(area(&cut) > 0.0);
                for &p in shape {
                    assert!(holds(&cut, p), "shape {s} at {corners} leaves {p} out");
                }
                // Edge midpoints too: a corner held is not an edge held.
                for (i, &p) in shape.iter().enumerate() {
                    let q = shape[(i + 1) % shape.len()];
                    assert!(holds(&cut, 0.5 * (p + q)), "shape {s} at {corners}");
                }
            }
        }
    }

    /// An L (area 5) with its five convex corners chamfered is cut back to
    /// the L at six corners; a convex cut could not go under its hull (7).
    #[test]
    fn a_chamfered_l_is_cut_back_to_the_l() {
        let l = [
            (0.0, 0.0),
            (3.0, 0.0),
            (3.0, 1.0),
            (1.0, 1.0),
            (1.0, 3.0),
            (0.0, 3.0),
        ];
        let chamfer = 0.05;
        let n = l.len();
        let mut corners = Vec::new();
        for i in 0..n {
            let p = DVec2::from(l[i]);
            if i == 3 {
                // The reflex corner stays.
                corners.push(p);
                continue;
            }
            let (before, after) = (DVec2::from(l[(i + n - 1) % n]), DVec2::from(l[(i + 1) % n]));
            corners.push(p + (before - p).normalize() * chamfer);
            corners.push(p + (after - p).normalize() * chamfer);
        }
        let cut = fewer_corners_holding(corners, 6, &[]).unwrap().0;
        assert_eq!(cut.len(), 6);
        assert!(area(&cut) <= 5.0 + 1e-9, "area {}", area(&cut));
        assert!(is_simple(&cut));
        for p in polygon(&l) {
            assert!(holds(&cut, p));
        }
    }

    /// Four fingers 2 wide and 6 long, 0.05 apart, on a palm, each with a
    /// round tip of `tip` corners; and points midway across each slot.
    fn fingers(tip: usize) -> (Vec<DVec2>, Vec<DVec2>) {
        let (width, gap, length) = (2.0, 0.05, 6.0);
        let pitch = width + gap;
        let mut corners = vec![DVec2::new(0.0, -1.0), DVec2::new(3.0 * pitch + width, -1.0)];
        for k in (0..4).rev() {
            let centre = DVec2::new(f64::from(k) * pitch + 0.5 * width, length);
            corners.extend((0..=tip).map(|j| {
                let angle = std::f64::consts::PI * j as f64 / tip as f64;
                centre + 0.5 * width * DVec2::new(angle.cos(), angle.sin())
            }));
            if k > 0 {
                let left = f64::from(k) * pitch;
                corners.extend([DVec2::new(left, 0.0), DVec2::new(left - gap, 0.0)]);
            }
        }
        let midway = (1..4)
            .flat_map(|k| {
                (1..6)
                    .map(move |j| DVec2::new(f64::from(k) * pitch - 0.5 * gap, 0.5 * f64::from(j)))
            })
            .collect();
        (corners, midway)
    }

    /// Cut down to the fewest corners that keep the slots (two at each
    /// fingertip, two at each slot's end, two for the palm), the points in
    /// the slots stay outside; without them the least-area steps fill a slot
    /// instead of squaring a fingertip. With too few corners for every slot,
    /// the count says how many stay outside.
    #[test]
    fn points_to_keep_out_keep_the_slots_between_fingers() {
        let (shape, midway) = fingers(8);
        assert!(is_simple(&shape) && area(&shape) > 0.0);
        assert!(midway.iter().all(|&p| !contains(&shape, p)));
        let outside = |cut: &[DVec2]| midway.iter().filter(|&&p| !contains(cut, p)).count();
        let (kept, count) = fewer_corners_holding(shape.clone(), 16, &midway).unwrap();
        assert_eq!(kept.len(), 16);
        assert!(is_simple(&kept));
        assert!(shape.iter().all(|&p| holds(&kept, p)));
        assert_eq!((count, outside(&kept)), (midway.len(), midway.len()));
        let (blind, _) = fewer_corners_holding(shape.clone(), 16, &[]).unwrap();
        assert!(outside(&blind) < midway.len(), "{}", outside(&blind));
        let (fewer, count) = fewer_corners_holding(shape.clone(), 12, &midway).unwrap();
        assert!(shape.iter().all(|&p| holds(&fewer, p)));
        assert_eq!(count, outside(&fewer));
        assert!(count < midway.len());
    }
}

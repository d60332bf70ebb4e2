//! A prism's caps: the triangles of its profile, with the largest smallest
//! angle any triangulation of the profile's corners has. Ear clipping alone
//! left slivers between a hand's fingers (its finished cage's smallest angle
//! was 0.2° where the fingers are 2 % of the diagonal apart, 0.9° with the
//! flips); flipping each diagonal that widens its two triangles' smallest
//! angle ends at the constrained Delaunay triangulation, which has the
//! largest smallest angle of all (Lawson).

use super::profile::{in_closed_triangle, orientation};
use glam::DVec2;
use std::collections::HashMap;

/// The triangles of a simple counter-clockwise polygon, each
/// counter-clockwise, with the largest smallest angle there is.
pub(super) fn cap_triangles(polygon: &[DVec2]) -> Option<Vec<[u32; 3]>> {
    let mut triangles = ear_clipped(polygon)?;
    widen_by_flips(polygon, &mut triangles);
    Some(triangles)
}

/// Ear clipping that clips, each time, the ear whose smallest angle is
/// largest: a valid start for the flips.
fn ear_clipped(polygon: &[DVec2]) -> Option<Vec<[u32; 3]>> {
    let mut left: Vec<usize> = (0..polygon.len()).collect();
    let mut triangles = Vec::with_capacity(polygon.len().saturating_sub(2));
    while left.len() > 3 {
        let m = left.len();
        let ear = (0..m)
            .filter_map(|k| {
                let [a, b, c] = [left[(k + m - 1) % m], left[k], left[(k + 1) % m]];
                let corners = [polygon[a], polygon[b], polygon[c]];
                if orientation(corners[0], corners[1], corners[2]) <= 0.0 {
                    return None;
                }
                let blocked = left
                    .iter()
                    .filter(|&&o| o != a && o != b && o != c)
                    .any(|&o| in_closed_triangle(polygon[o], corners));
                (!blocked).then(|| (smallest_angle(corners), k))
            })
            .max_by(|x, y| x.0.total_cmp(&y.0))?
            .1;
        let [a, b, c] = [left[(ear + m - 1) % m], left[ear], left[(ear + 1) % m]];
        triangles.push([a as u32, b as u32, c as u32]);
        left.remove(ear);
    }
    if let [a, b, c] = left[..] {
        triangles.push([a as u32, b as u32, c as u32]);
    }
    Some(triangles)
}

/// Flips diagonals (never the polygon's edges, which have one triangle)
/// while a flip raises the smallest angle of the two triangles. Each flip
/// raises the triangulation's sorted angles, so this ends; the bound only
/// guards against rounding.
fn widen_by_flips(polygon: &[DVec2], triangles: &mut [[u32; 3]]) {
    let corners = |t: [u32; 3]| t.map(|i| polygon[i as usize]);
    let least = |t: [u32; 3]| smallest_angle(corners(t));
    let limit = triangles.len() * triangles.len() + 1;
    for _ in 0..limit {
        let by_edge: HashMap<(u32, u32), usize> = (triangles.iter().enumerate())
            .flat_map(|(t, tri)| (0..3).map(move |k| ((tri[k], tri[(k + 1) % 3]), t)))
            .collect();
        let flip = (0..triangles.len()).find_map(|t| {
            (0..3).find_map(|k| {
                let tri = triangles[t];
                let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
                let u = *by_edge.get(&(b, a))?;
                let d = *triangles[u].iter().find(|&&v| v != a && v != b)?;
                let (first, second) = ([a, d, c], [b, c, d]);
                let convex = [first, second].iter().all(|&f| {
                    let [p, q, r] = corners(f);
                    orientation(p, q, r) > 0.0
                });
                let before = least(tri).min(least(triangles[u]));
                let after = least(first).min(least(second));
                (convex && after > before * (1.0 + 1e-12)).then_some((t, u, first, second))
            })
        });
        let Some((t, u, first, second)) = flip else {
            return;
        };
        (triangles[t], triangles[u]) = (first, second);
    }
}

fn smallest_angle([a, b, c]: [DVec2; 3]) -> f64 {
    let angle = |p: DVec2, q: DVec2, r: DVec2| (q - p).angle_to(r - p).abs();
    angle(a, b, c).min(angle(b, c, a)).min(angle(c, a, b))
}

#[cfg(test)]
mod tests {
    use super::super::polygon_checks::{area, comb, contains, star, tangle};
    use super::*;

    fn covers_once(shape: &[DVec2], triangles: &[[u32; 3]]) {
        assert_eq!(triangles.len(), shape.len() - 2);
        let mut total = 0.0;
        for t in triangles {
            let [a, b, c] = t.map(|i| shape[i as usize]);
            let twice = (b - a).perp_dot(c - a);
            assert!(twice > 0.0, "{t:?} turns clockwise");
            assert!(contains(shape, (a + b + c) / 3.0), "{t:?} is outside");
            total += 0.5 * twice;
        }
        assert!((total - area(shape)).abs() <= 1e-9 * area(shape));
    }

    /// Each cap triangle turns counter-clockwise and lies inside, and their
    /// areas add up to the profile's.
    #[test]
    fn caps_cover_the_profile_once() {
        for shape in [comb(4), star(12, 4), star(16, 5), tangle(20, 6)] {
            covers_once(&shape, &cap_triangles(&shape).unwrap());
        }
    }

    /// Whether the chord from corner i to corner j lies inside the polygon:
    /// it meets no edge but at its ends, and its midpoint is inside.
    fn is_chord(polygon: &[DVec2], i: usize, j: usize) -> bool {
        let n = polygon.len();
        if (i + 1) % n == j || (j + 1) % n == i {
            return true;
        }
        let (p, q) = (polygon[i], polygon[j]);
        let crosses = (0..n).any(|k| {
            let l = (k + 1) % n;
            if [k, l].contains(&i) || [k, l].contains(&j) {
                return false;
            }
            let (a, b) = (polygon[k], polygon[l]);
            if side(p, q, a) == 0.0 && side(p, q, b) == 0.0 {
                // On one line: they meet where their spans along it overlap.
                let along = |x: DVec2| (x - p).dot(q - p);
                let (lo, hi) = (along(a).min(along(b)), along(a).max(along(b)));
                return hi >= 0.0 && lo <= (q - p).length_squared();
            }
            side(p, q, a) * side(p, q, b) <= 0.0 && side(a, b, p) * side(a, b, q) <= 0.0
        });
        !crosses && contains(polygon, (p + q) / 2.0)
    }

    /// The largest smallest angle over every triangulation, by dynamic
    /// programming over chords (each triangulation of corners i..=j is a
    /// triangle i k j and triangulations of i..=k and k..=j).
    fn best_smallest_angle(polygon: &[DVec2]) -> f64 {
        let n = polygon.len();
        let mut best = vec![vec![f64::NEG_INFINITY; n]; n];
        for i in 0..n - 1 {
            best[i][i + 1] = f64::INFINITY;
        }
        for span in 2..n {
            for i in 0..n - span {
                let j = i + span;
                if !is_chord(polygon, i, j) {
                    continue;
                }
                for k in i + 1..j {
                    let corners = [polygon[i], polygon[k], polygon[j]];
                    if !is_chord(polygon, i, k)
                        || !is_chord(polygon, k, j)
                        || side(corners[0], corners[1], corners[2]) <= 0.0
                    {
                        continue;
                    }
                    let value = smallest_angle(corners).min(best[i][k]).min(best[k][j]);
                    best[i][j] = best[i][j].max(value);
                }
            }
        }
        best[0][n - 1]
    }

    /// Twice the signed area of a b c: positive when they turn
    /// counter-clockwise.
    fn side(a: DVec2, b: DVec2, c: DVec2) -> f64 {
        (b - a).perp_dot(c - a)
    }

    fn smallest_of(polygon: &[DVec2], triangles: &[[u32; 3]]) -> f64 {
        (triangles.iter())
            .map(|t| smallest_angle(t.map(|i| polygon[i as usize])))
            .fold(f64::INFINITY, f64::min)
    }

    /// The caps' smallest angle is the best of any triangulation of the
    /// corners, on combs, stars and random polygons; ear clipping alone
    /// falls short of it on some of them, so the comparison can tell.
    #[test]
    fn caps_have_the_largest_smallest_angle_of_any_triangulation() {
        let mut shapes = vec![comb(3), comb(5), star(9, 1), star(14, 2)];
        shapes.extend((0..12).map(|seed| tangle(8 + seed as usize, 100 + seed)));
        let mut short = 0;
        for shape in &shapes {
            let best = best_smallest_angle(shape);
            assert!(best.is_finite() && best > 0.0, "{best} {shape:?}");
            let caps = cap_triangles(shape).unwrap();
            covers_once(shape, &caps);
            let found = smallest_of(shape, &caps);
            assert!(
                (found - best).abs() <= 1e-9 * best,
                "{found} against {best}"
            );
            if smallest_of(shape, &ear_clipped(shape).unwrap()) < best * (1.0 - 1e-6) {
                short += 1;
            }
        }
        assert!(short >= 3, "ear clipping fell short on {short} shapes only");
    }
}

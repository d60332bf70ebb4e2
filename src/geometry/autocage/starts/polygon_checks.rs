//! Tests' own measures of plane polygons, written apart from what they
//! check: crossings counted along a ray, distances to edges, and
//! intersections solved for their parameters.

use glam::DVec2;

/// Whether `p` is inside, by the parity of the edges a ray along +x crosses.
pub fn contains(polygon: &[DVec2], p: DVec2) -> bool {
    let n = polygon.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
            if x > p.x {
                inside = !inside;
            }
        }
    }
    inside
}

/// The distance from `p` to the polygon's boundary.
pub fn boundary_distance(polygon: &[DVec2], p: DVec2) -> f64 {
    let n = polygon.len();
    (0..n)
        .map(|i| {
            let (a, b) = (polygon[i], polygon[(i + 1) % n]);
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            p.distance(a + (b - a) * t)
        })
        .fold(f64::INFINITY, f64::min)
}

/// How far inside `p` is: positive inside, negative outside.
pub fn depth(polygon: &[DVec2], p: DVec2) -> f64 {
    let d = boundary_distance(polygon, p);
    if contains(polygon, p) {
        d
    } else {
        -d
    }
}

/// The signed area (trapezoids under each edge), positive
/// counter-clockwise.
pub fn area(polygon: &[DVec2]) -> f64 {
    let n = polygon.len();
    -0.5 * (0..n)
        .map(|i| {
            let (a, b) = (polygon[i], polygon[(i + 1) % n]);
            (b.x - a.x) * (b.y + a.y)
        })
        .sum::<f64>()
}

/// Whether no two edges meet except neighbours at their shared corner.
pub fn is_simple(polygon: &[DVec2]) -> bool {
    let n = polygon.len();
    let meet = |(a, b): (DVec2, DVec2), (c, d): (DVec2, DVec2)| {
        // a + s (b - a) = c + t (d - c), solved by Cramer's rule.
        let (r, q) = (b - a, d - c);
        let det = r.x * -q.y + q.x * r.y;
        let w = c - a;
        if det == 0.0 {
            // Parallel: they meet when collinear and overlapping.
            let cross = r.x * w.y - r.y * w.x;
            if cross != 0.0 {
                return false;
            }
            let along = |p: DVec2| (p - a).dot(r) / r.length_squared();
            let (lo, hi) = (along(c).min(along(d)), along(c).max(along(d)));
            return hi >= 0.0 && lo <= 1.0;
        }
        let s = (w.x * -q.y + q.x * w.y) / det;
        let t = (r.x * w.y - r.y * w.x) / det;
        (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t)
    };
    let edge = |i: usize| (polygon[i], polygon[(i + 1) % n]);
    (0..n).all(|i| {
        (i + 1..n).all(|j| {
            let neighbours = j == i + 1 || (i == 0 && j == n - 1);
            neighbours || !meet(edge(i), edge(j))
        })
    })
}

//! Tests' own measures of plane polygons, written apart from what they
//! check: crossings counted along a ray, distances to edges, and
//! intersections solved for their parameters.

use crate::geometry::procedural::SplitMix64;
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

/// A comb: a spine along the bottom and `teeth` teeth upward, each as
/// wide as the gap after it.
pub fn comb(teeth: usize) -> Vec<DVec2> {
    let mut corners = vec![(0.0, 0.0), (2.0 * teeth as f64 - 1.0, 0.0)];
    for k in (0..teeth).rev() {
        let x = 2.0 * k as f64;
        corners.extend([(x + 1.0, 3.0), (x, 3.0)]);
        if k > 0 {
            corners.extend([(x, 1.0), (x - 1.0, 1.0)]);
        }
    }
    // The spine's right end rises into the last tooth.
    corners[1].0 = 2.0 * teeth as f64 - 1.0;
    corners.iter().map(|&(x, y)| DVec2::new(x, y)).collect()
}

/// A star-shaped polygon of random radii.
pub fn star(corners: usize, seed: u64) -> Vec<DVec2> {
    let mut random = SplitMix64(seed);
    (0..corners)
        .map(|k| {
            let angle = std::f64::consts::TAU * k as f64 / corners as f64;
            DVec2::new(angle.cos(), angle.sin()) * (0.3 + random.unit())
        })
        .collect()
}

/// A random simple polygon, wiggling every way: random points joined
/// in random order, then untangled by reversing the path between any
/// two edges that cross (2-opt, which shortens the loop each time).
pub fn tangle(corners: usize, seed: u64) -> Vec<DVec2> {
    let mut random = SplitMix64(seed);
    let mut points: Vec<DVec2> = (0..corners)
        .map(|_| DVec2::new(random.unit(), random.unit()))
        .collect();
    let crosses = |a: DVec2, b: DVec2, c: DVec2, d: DVec2| {
        let side = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
        side(a, b, c) * side(a, b, d) < 0.0 && side(c, d, a) * side(c, d, b) < 0.0
    };
    'untangle: loop {
        let n = points.len();
        for i in 0..n {
            for j in i + 2..n {
                let (a, b, c, d) = (points[i], points[i + 1], points[j], points[(j + 1) % n]);
                if (j + 1) % n != i && crosses(a, b, c, d) {
                    points[i + 1..=j].reverse();
                    continue 'untangle;
                }
            }
        }
        break;
    }
    if area(&points) < 0.0 {
        points.reverse();
    }
    points
}

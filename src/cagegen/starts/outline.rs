//! The outline of a mesh seen along an axis, for prism starts: the profile
//! an artist draws once and extrudes (a bench's side, an L-shaped beam),
//! which is concave where the mesh is. The triangles seen along the axis
//! are rasterised, grown by the margin, and the outer boundary of the one
//! region they make is traced; [`super::profile`] then cuts it down to a few
//! corners by steps that only add area, so it still holds the view.

use glam::DVec2;

/// Cells along the raster's longer side: it costs at most about this
/// squared in bytes and in distance values, whatever the mesh.
const RESOLUTION: usize = 256;

/// Cells of the raster's border that stay empty, besides the margin, so
/// that the outside is connected around the region.
const BORDER_CELLS: f64 = 3.5;

/// A grid of square cells over a view.
struct Raster {
    origin: DVec2,
    cell: f64,
    width: usize,
    height: usize,
    filled: Vec<bool>,
}

impl Raster {
    fn index(&self, i: usize, j: usize) -> usize {
        j * self.width + i
    }

    /// Cell (i, j)'s centre.
    fn centre(&self, i: usize, j: usize) -> DVec2 {
        self.origin + DVec2::new(i as f64 + 0.5, j as f64 + 0.5) * self.cell
    }

    fn at(&self, i: isize, j: isize) -> bool {
        i >= 0
            && j >= 0
            && (i as usize) < self.width
            && (j as usize) < self.height
            && self.filled[self.index(i as usize, j as usize)]
    }
}

/// A simple counter-clockwise polygon around every one of `triangles` (in
/// the view's plane) with every point of them at least `margin` inside,
/// with its corners on a grid of about 1/256 of the view's longer side.
/// None when the view is a point or a line, or when it falls apart into
/// separate regions (one prism could not hold them all).
pub(super) fn traced_outline(
    triangles: impl Iterator<Item = [DVec2; 3]> + Clone,
    margin: f64,
) -> Option<Vec<DVec2>> {
    let mut raster = covering_raster(triangles, margin)?;
    grow(&mut raster, margin);
    close_pinches(&mut raster);
    if regions(&raster) != 1 {
        return None;
    }
    Some(trace(&raster))
}

/// A raster over the triangles, padded for the margin, with every cell
/// that any triangle touches filled.
fn covering_raster(
    triangles: impl Iterator<Item = [DVec2; 3]> + Clone,
    margin: f64,
) -> Option<Raster> {
    let (lo, hi) = triangles.clone().flatten().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    );
    let longest = (hi - lo).max_element();
    if !longest.is_finite() || longest <= 0.0 || !margin.is_finite() || margin < 0.0 {
        return None;
    }
    // The padded extent is `RESOLUTION` cells: longest + 2 (margin + border).
    let cell = (longest + 2.0 * margin) / (RESOLUTION as f64 - 2.0 * BORDER_CELLS);
    let pad = margin + BORDER_CELLS * cell;
    let origin = lo - DVec2::splat(pad);
    let cells = |extent: f64| (((extent + 2.0 * pad) / cell).ceil() as usize).clamp(1, RESOLUTION);
    let (width, height) = (cells(hi.x - lo.x), cells(hi.y - lo.y));
    let mut raster = Raster {
        origin,
        cell,
        width,
        height,
        filled: vec![false; width * height],
    };
    for triangle in triangles {
        fill_covered(&mut raster, &triangle);
    }
    Some(raster)
}

/// Fills every cell the (possibly degenerate) triangle touches: those
/// whose square and the triangle overlap along both axes and across each
/// edge's normal.
fn fill_covered(raster: &mut Raster, triangle: &[DVec2; 3]) {
    let [a, b, c] = *triangle;
    let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
    let to_cell = |x: f64, along: usize| {
        let limit = if along == 0 {
            raster.width
        } else {
            raster.height
        };
        (((x - raster.origin[along]) / raster.cell).floor().max(0.0) as usize).min(limit - 1)
    };
    let half = 0.5 * raster.cell;
    let normals = [b - a, c - b, a - c].map(|edge| edge.perp());
    let spans = normals.map(|n| {
        let [x, y, z] = [n.dot(a), n.dot(b), n.dot(c)];
        (x.min(y).min(z), x.max(y).max(z))
    });
    for j in to_cell(lo.y, 1)..=to_cell(hi.y, 1) {
        for i in to_cell(lo.x, 0)..=to_cell(hi.x, 0) {
            let centre = raster.centre(i, j);
            let overlaps = normals.iter().zip(&spans).all(|(n, (low, high))| {
                let (mid, reach) = (n.dot(centre), half * (n.x.abs() + n.y.abs()));
                mid + reach >= *low && mid - reach <= *high
            });
            if overlaps {
                let k = raster.index(i, j);
                raster.filled[k] = true;
            }
        }
    }
}

/// Fills every cell whose centre is within `margin` and a cell and a half
/// of a filled cell's centre: a point on the grown region's boundary is
/// then at least `margin` from every filled cell (two half-diagonals
/// are under a cell and a half).
fn grow(raster: &mut Raster, margin: f64) {
    let (width, height) = (raster.width, raster.height);
    let reach = margin / raster.cell + 1.5;
    // Per column, the distance in cells to the nearest filled cell in it.
    let far = f64::INFINITY;
    let mut column = vec![far; width * height];
    for i in 0..width {
        let mut last = far;
        for j in 0..height {
            last = if raster.filled[raster.index(i, j)] {
                0.0
            } else {
                last + 1.0
            };
            column[j * width + i] = last;
        }
        let mut last = far;
        for j in (0..height).rev() {
            last = if raster.filled[raster.index(i, j)] {
                0.0
            } else {
                last + 1.0
            };
            let k = j * width + i;
            column[k] = column[k].min(last);
        }
    }
    // Across each row, the nearest of those (exact Euclidean distance).
    for j in 0..height {
        let row = &column[j * width..(j + 1) * width];
        for i in 0..width {
            let near = row.iter().enumerate().any(|(k, &dy)| {
                let dx = i as f64 - k as f64;
                dx * dx + dy * dy <= reach * reach
            });
            if near {
                raster.filled[j * width + i] = true;
            }
        }
    }
}

/// Fills one cell of every pair of empty cells that meet only at a
/// corner between two filled ones, so that the region's boundary never
/// touches itself.
fn close_pinches(raster: &mut Raster) {
    loop {
        let mut changed = false;
        for j in 0..raster.height.saturating_sub(1) {
            for i in 0..raster.width.saturating_sub(1) {
                let (i, j) = (i as isize, j as isize);
                let [a, b, c, d] =
                    [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(x, y)| raster.at(i + x, j + y));
                if a == d && b == c && a != b {
                    let (x, y) = if a { (i + 1, j) } else { (i, j) };
                    let k = raster.index(x as usize, y as usize);
                    raster.filled[k] = true;
                    changed = true;
                }
            }
        }
        if !changed {
            return;
        }
    }
}

/// How many separate (edge-connected) regions the filled cells make.
fn regions(raster: &Raster) -> usize {
    let mut seen = vec![false; raster.filled.len()];
    let mut count = 0;
    for start in 0..raster.filled.len() {
        if seen[start] || !raster.filled[start] {
            continue;
        }
        count += 1;
        let mut stack = vec![start];
        seen[start] = true;
        while let Some(k) = stack.pop() {
            let (i, j) = ((k % raster.width) as isize, (k / raster.width) as isize);
            for (x, y) in [(i - 1, j), (i + 1, j), (i, j - 1), (i, j + 1)] {
                if raster.at(x, y) {
                    let n = raster.index(x as usize, y as usize);
                    if !seen[n] {
                        seen[n] = true;
                        stack.push(n);
                    }
                }
            }
        }
    }
    count
}

/// The outer boundary of the one region, counter-clockwise, through the
/// cells' corners where it turns: the walk starts on the lowest row's first
/// cell, whose lower side faces the outside, so holes are left out.
fn trace(raster: &Raster) -> Vec<DVec2> {
    let corners_across = raster.width + 1;
    let corner = |i: usize, j: usize| j * corners_across + i;
    // Each corner on the boundary has one edge leaving it, with the region
    // on its left.
    let mut next = vec![usize::MAX; corners_across * (raster.height + 1)];
    let mut first = None;
    for j in 0..raster.height {
        for i in 0..raster.width {
            if !raster.filled[raster.index(i, j)] {
                continue;
            }
            let (x, y) = (i as isize, j as isize);
            let sides = [
                (!raster.at(x, y - 1), corner(i, j), corner(i + 1, j)),
                (!raster.at(x + 1, y), corner(i + 1, j), corner(i + 1, j + 1)),
                (!raster.at(x, y + 1), corner(i + 1, j + 1), corner(i, j + 1)),
                (!raster.at(x - 1, y), corner(i, j + 1), corner(i, j)),
            ];
            for (open, from, to) in sides {
                if open {
                    next[from] = to;
                    first.get_or_insert(from);
                }
            }
        }
    }
    let Some(first) = first else {
        return Vec::new();
    };
    let mut walk = vec![first];
    let mut at = next[first];
    while at != first && at != usize::MAX {
        walk.push(at);
        at = next[at];
    }
    // Only the corners where the boundary turns (in whole cells, exactly).
    let lattice = |k: usize| ((k % corners_across) as i64, (k / corners_across) as i64);
    let n = walk.len();
    (0..n)
        .filter(|&k| {
            let [(x0, y0), (x1, y1), (x2, y2)] =
                [walk[(k + n - 1) % n], walk[k], walk[(k + 1) % n]].map(lattice);
            (x1 - x0) * (y2 - y1) != (y1 - y0) * (x2 - x1)
        })
        .map(|k| {
            let (x, y) = lattice(walk[k]);
            raster.origin + DVec2::new(x as f64, y as f64) * raster.cell
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::polygon_checks::{area, contains, depth, is_simple};
    use super::*;

    /// A rectangle as two triangles.
    fn rectangle(lo: DVec2, hi: DVec2) -> [[DVec2; 3]; 2] {
        let (a, b, c, d) = (lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y));
        [[a, b, c], [a, c, d]]
    }

    /// Points on a lattice over the triangles' rectangles, their corners
    /// included.
    fn lattice(lo: DVec2, hi: DVec2) -> Vec<DVec2> {
        (0..=20)
            .flat_map(|i| {
                (0..=20).map(move |j| lo + (hi - lo) * DVec2::new(i as f64, j as f64) / 20.0)
            })
            .collect()
    }

    /// An L of arms 3 long and 1 wide: the outline holds it with the margin,
    /// is simple and counter-clockwise, leaves the L's notch outside, and is
    /// within a few cells of the L grown by the margin.
    #[test]
    fn an_l_is_traced_around_with_the_margin() {
        let margin = 0.1;
        let parts = [
            (DVec2::new(0.0, 0.0), DVec2::new(3.0, 1.0)),
            (DVec2::new(0.0, 1.0), DVec2::new(1.0, 3.0)),
        ];
        let triangles: Vec<[DVec2; 3]> = parts
            .iter()
            .flat_map(|&(lo, hi)| rectangle(lo, hi))
            .collect();
        let outline = traced_outline(triangles.iter().copied(), margin).unwrap();
        assert!(is_simple(&outline));
        assert!(area(&outline) > 0.0, "counter-clockwise");
        for (lo, hi) in parts {
            for p in lattice(lo, hi) {
                assert!(
                    depth(&outline, p) >= margin - 1e-12,
                    "{p} is {} inside",
                    depth(&outline, p)
                );
            }
        }
        assert!(
            !contains(&outline, DVec2::new(2.0, 2.0)),
            "the notch is filled"
        );
        // The L grown by the margin, with square corners.
        let m = margin;
        let grown = 2.0 * (3.0 + 2.0 * m) * (1.0 + 2.0 * m) - (1.0 + 2.0 * m).powi(2);
        let cell = (3.0 + 2.0 * m) / (RESOLUTION as f64 - 2.0 * BORDER_CELLS);
        let perimeter = 12.0;
        assert!(
            area(&outline) <= grown + 2.0 * cell * perimeter,
            "area {} against {grown}",
            area(&outline)
        );
    }

    /// A square ring's hole is filled; two squares far apart are two regions
    /// that one prism's outline cannot follow.
    #[test]
    fn holes_are_filled_and_separate_parts_refused() {
        let ring: Vec<[DVec2; 3]> = [
            (DVec2::new(0.0, 0.0), DVec2::new(4.0, 1.0)),
            (DVec2::new(0.0, 3.0), DVec2::new(4.0, 4.0)),
            (DVec2::new(0.0, 1.0), DVec2::new(1.0, 3.0)),
            (DVec2::new(3.0, 1.0), DVec2::new(4.0, 3.0)),
        ]
        .iter()
        .flat_map(|&(lo, hi)| rectangle(lo, hi))
        .collect();
        let outline = traced_outline(ring.iter().copied(), 0.05).unwrap();
        assert!(
            contains(&outline, DVec2::new(2.0, 2.0)),
            "the hole is filled"
        );
        assert!(is_simple(&outline));

        let apart: Vec<[DVec2; 3]> = [
            (DVec2::new(0.0, 0.0), DVec2::new(1.0, 1.0)),
            (DVec2::new(5.0, 0.0), DVec2::new(6.0, 1.0)),
        ]
        .iter()
        .flat_map(|&(lo, hi)| rectangle(lo, hi))
        .collect();
        assert!(traced_outline(apart.iter().copied(), 0.05).is_none());
        // Close enough for the margins to meet, they are one region.
        assert!(traced_outline(apart.iter().copied(), 2.6).is_some());
    }

    /// Tiny triangles scattered over a disc are each held with the margin,
    /// however they fall on the cells (a point near a cell's corner is
    /// where the growth's cell and a half is needed).
    #[test]
    fn scattered_points_are_each_held_with_the_margin() {
        let mut random = crate::geometry::procedural::SplitMix64(8);
        let margin = 0.03;
        let triangles: Vec<[DVec2; 3]> = (0..2_000)
            .map(|_| {
                let (r, angle) = (random.unit().sqrt(), std::f64::consts::TAU * random.unit());
                let p = DVec2::new(angle.cos(), angle.sin()) * r;
                [p, p + DVec2::new(1e-6, 0.0), p + DVec2::new(0.0, 1e-6)]
            })
            .collect();
        let outline = traced_outline(triangles.iter().copied(), margin).unwrap();
        assert!(is_simple(&outline));
        let shallowest = triangles
            .iter()
            .flatten()
            .map(|&p| depth(&outline, p))
            .fold(f64::INFINITY, f64::min);
        assert!(shallowest >= margin, "a point {shallowest} inside");
    }

    /// Cells that touch only at corners are joined, so that the region is
    /// one and its boundary never passes through a corner twice.
    #[test]
    fn cells_meeting_at_corners_are_joined() {
        let (width, height) = (7, 7);
        let mut raster = Raster {
            origin: DVec2::new(-1.0, 2.0),
            cell: 0.5,
            width,
            height,
            filled: vec![false; width * height],
        };
        let diamond = [(3, 2), (2, 3), (4, 3), (3, 4), (5, 4)];
        for (i, j) in diamond {
            let k = raster.index(i, j);
            raster.filled[k] = true;
        }
        close_pinches(&mut raster);
        assert_eq!(regions(&raster), 1);
        let outline = trace(&raster);
        assert!(is_simple(&outline));
        for (i, j) in diamond {
            assert!(depth(&outline, raster.centre(i, j)) >= 0.25 - 1e-12);
        }
    }

    /// A triangle seen edge-on is a segment across the view: only the cells
    /// along it are covered, not its bounding box.
    #[test]
    fn a_triangle_seen_edge_on_covers_its_segment() {
        let (a, b) = (DVec2::new(0.0, 0.0), DVec2::new(4.0, 3.0));
        let margin = 0.05;
        let outline = traced_outline([[a, 0.5 * (a + b), b]].into_iter(), margin).unwrap();
        for k in 0..=10 {
            let p = a + (b - a) * (k as f64 / 10.0);
            assert!(depth(&outline, p) >= margin - 1e-12);
        }
        let cell = (4.0 + 2.0 * margin) / (RESOLUTION as f64 - 2.0 * BORDER_CELLS);
        // A band along the segment, a few cells wider than the margins.
        let band = 5.0 * (2.0 * margin + 6.0 * cell) + 4.0 * margin * margin;
        assert!(
            area(&outline) <= band,
            "area {} over {band}",
            area(&outline)
        );
        assert!(!contains(&outline, DVec2::new(3.0, 0.5)));
    }
}

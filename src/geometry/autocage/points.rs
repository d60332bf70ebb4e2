//! A bounding-volume tree over the mesh's sample points, for the two questions
//! every change of the cage asks: does the region it sweeps hold a point, and
//! does a new face come closer to one than the clearance. Late in a
//! simplification one face spans tens of thousands of points; whole subtrees
//! are answered at once, so a check costs about the faces times the depth.

use crate::geometry::closest_point_on_triangle;
use glam::DVec3;

/// Points per leaf: below this, testing each is cheaper than splitting.
const LEAF_SIZE: usize = 16;

struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Points `first..last` of the reordered list belong to this node.
    first: u32,
    last: u32,
    /// Indices of the two children; 0 (the root, never a child) for a leaf.
    children: [u32; 2],
}

impl Node {
    fn centre(&self) -> DVec3 {
        (self.lo + self.hi) * 0.5
    }

    /// Radius of the sphere around the box.
    fn radius(&self) -> f64 {
        (self.hi - self.lo).length() * 0.5
    }

    fn overlaps(&self, lo: DVec3, hi: DVec3) -> bool {
        !(self.lo.cmpgt(hi).any() || self.hi.cmplt(lo).any())
    }
}

pub(super) struct PointTree {
    points: Vec<DVec3>,
    nodes: Vec<Node>,
}

impl PointTree {
    pub(super) fn new(mut points: Vec<DVec3>) -> PointTree {
        let mut nodes = Vec::with_capacity(2 * points.len() / LEAF_SIZE + 1);
        if !points.is_empty() {
            let count = points.len();
            build(&mut points, 0, count, &mut nodes);
        }
        PointTree { points, nodes }
    }

    /// Whether a point lies inside the closed surface made of `faces` (by the
    /// parity of crossings along a fixed ray, as `inside` decides).
    pub(super) fn any_enclosed(
        &self,
        faces: &[[DVec3; 3]],
        inside: impl Fn(DVec3, &[[DVec3; 3]]) -> bool,
    ) -> bool {
        let Some((lo, hi)) = bounds(faces) else {
            return false;
        };
        self.search(
            0,
            &|node| node.overlaps(lo, hi),
            &|node| {
                // A sphere that touches no face lies wholly on one side of the
                // surface, so its centre answers for every point in it.
                let (centre, radius) = (node.centre(), node.radius());
                if faces
                    .iter()
                    .all(|f| distance_squared(centre, f) > radius * radius)
                {
                    Some(inside(centre, faces))
                } else {
                    None
                }
            },
            &|p| p.cmpge(lo).all() && p.cmple(hi).all() && inside(p, faces),
        )
    }

    /// Whether a point is closer than `clearance` to one of `faces`.
    pub(super) fn any_within(&self, faces: &[[DVec3; 3]], clearance: f64) -> bool {
        let Some((lo, hi)) = bounds(faces) else {
            return false;
        };
        let pad = DVec3::splat(clearance);
        let (lo, hi) = (lo - pad, hi + pad);
        let near =
            |p: DVec3, reach: f64| faces.iter().any(|f| distance_squared(p, f) < reach * reach);
        self.search(
            0,
            &|node| node.overlaps(lo, hi),
            &|node| (!near(node.centre(), node.radius() + clearance)).then_some(false),
            &|p| near(p, clearance),
        )
    }

    /// Depth-first: `visit` prunes a node, `settle` answers for all of it when
    /// it can, and `test` decides single points in the leaves.
    fn search(
        &self,
        index: usize,
        visit: &dyn Fn(&Node) -> bool,
        settle: &dyn Fn(&Node) -> Option<bool>,
        test: &dyn Fn(DVec3) -> bool,
    ) -> bool {
        let Some(node) = self.nodes.get(index) else {
            return false;
        };
        if !visit(node) {
            return false;
        }
        if let Some(answer) = settle(node) {
            return answer;
        }
        if node.children[0] == 0 {
            return self.points[node.first as usize..node.last as usize]
                .iter()
                .any(|&p| test(p));
        }
        let [left, right] = node.children.map(|c| c as usize);
        self.search(left, visit, settle, test) || self.search(right, visit, settle, test)
    }
}

fn build(points: &mut [DVec3], first: usize, last: usize, nodes: &mut Vec<Node>) -> usize {
    let slice = &mut points[first..last];
    let (lo, hi) = slice
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let index = nodes.len();
    nodes.push(Node {
        lo,
        hi,
        first: first as u32,
        last: last as u32,
        children: [0, 0],
    });
    if slice.len() > LEAF_SIZE {
        let axis = (hi - lo).max_position();
        let middle = slice.len() / 2;
        slice.select_nth_unstable_by(middle, |a, b| a[axis].total_cmp(&b[axis]));
        let left = build(points, first, first + middle, nodes);
        let right = build(points, first + middle, last, nodes);
        nodes[index].children = [left as u32, right as u32];
    }
    index
}

fn bounds(faces: &[[DVec3; 3]]) -> Option<(DVec3, DVec3)> {
    let mut corners = faces.iter().flatten();
    let first = *corners.next()?;
    Some(corners.fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))))
}

fn distance_squared(p: DVec3, [a, b, c]: &[DVec3; 3]) -> f64 {
    closest_point_on_triangle(p, *a, *b, *c)
        .0
        .distance_squared(p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::autocage::checks::ray_hits_triangle;
    use crate::geometry::procedural::SplitMix64;

    fn random_points(count: usize, random: &mut SplitMix64) -> Vec<DVec3> {
        (0..count)
            .map(|_| DVec3::new(random.unit(), random.unit(), random.unit()))
            .collect()
    }

    /// Inside the tetrahedron by the signs of its four faces: an answer that
    /// does not use ray parity.
    fn inside_tetrahedron(p: DVec3, [a, b, c, d]: [DVec3; 4]) -> bool {
        let side = |u: DVec3, v: DVec3, w: DVec3| (v - u).cross(w - u).dot(p - u);
        let signs = [side(a, b, c), side(a, c, d), side(a, d, b), side(b, d, c)];
        signs.iter().all(|&s| s > 0.0) || signs.iter().all(|&s| s < 0.0)
    }

    fn parity(p: DVec3, faces: &[[DVec3; 3]]) -> bool {
        let crossings = faces.iter().filter(|f| ray_hits_triangle(p, **f)).count();
        crossings % 2 == 1
    }

    /// Whole subtrees are answered at once; the answers must be those of
    /// testing every point.
    #[test]
    fn answers_match_testing_every_point() {
        let mut random = SplitMix64(7);
        let points = random_points(5_000, &mut random);
        let tree = PointTree::new(points.clone());
        for _ in 0..200 {
            let corners = random_points(4, &mut random);
            let scale = 0.05 + 0.4 * random.unit();
            let centre = corners[0];
            let [a, b, c, d] = [0, 1, 2, 3].map(|i| centre + (corners[i] - centre) * scale);
            let faces = [[a, b, c], [a, c, d], [a, d, b], [b, d, c]];
            let expected = points.iter().any(|&p| inside_tetrahedron(p, [a, b, c, d]));
            assert_eq!(tree.any_enclosed(&faces, parity), expected);
            let clearance = 0.02 * random.unit();
            let expected = points.iter().any(|&p| {
                faces
                    .iter()
                    .any(|f| distance_squared(p, f) < clearance * clearance)
            });
            assert_eq!(tree.any_within(&faces, clearance), expected);
        }
    }
}

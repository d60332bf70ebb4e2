//! A bounding-volume tree over the mesh's sample points, for the two questions
//! every change of the cage asks: does the region it sweeps hold a point, and
//! does a new face come closer to one than the clearance. Late in a
//! simplification one face spans tens of thousands of points; whole subtrees
//! are answered at once, so a check costs about the faces times the depth.

use crate::geometry::closest_point_on_triangle;
use glam::DVec3;

/// Points per leaf: below this, testing each is cheaper than splitting.
const LEAF_SIZE: usize = 16;
/// Halves of at least this many points are built in parallel.
const PARALLEL_POINTS: usize = 4096;

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
        let placeholder = || Node {
            lo: DVec3::ZERO,
            hi: DVec3::ZERO,
            first: 0,
            last: 0,
            children: [0, 0],
        };
        let mut nodes: Vec<Node> = (0..node_count(points.len()))
            .map(|_| placeholder())
            .collect();
        if !points.is_empty() {
            build(&mut points, 0, &mut nodes, 0);
        }
        PointTree { points, nodes }
    }

    /// Whether a point lies inside the closed surface made of `faces` (by the
    /// parity of crossings along a fixed ray, as `inside` decides).
    pub(super) fn any_enclosed(
        &self,
        faces: &[[DVec3; 3]],
        inside: impl Fn(DVec3) -> bool,
    ) -> bool {
        let Some((lo, hi)) = bounds(faces) else {
            return false;
        };
        let planes = planes(faces);
        self.search(
            0,
            &|node| node.overlaps(lo, hi),
            &|node| {
                // A sphere that touches no face lies wholly on one side of the
                // surface, so its centre answers for every point in it.
                let (centre, radius) = (node.centre(), node.radius());
                if faces
                    .iter()
                    .zip(&planes)
                    .all(|(f, plane)| farther_than(centre, f, plane, radius))
                {
                    Some(inside(centre))
                } else {
                    None
                }
            },
            &|p| p.cmpge(lo).all() && p.cmple(hi).all() && inside(p),
        )
    }

    /// Whether a point is closer than `clearance` to one of `faces`.
    pub(super) fn any_within(&self, faces: &[[DVec3; 3]], clearance: f64) -> bool {
        self.first_within(faces, clearance).is_some()
    }

    /// A point closer than `clearance` to one of `faces`, if there is one.
    pub(super) fn first_within(&self, faces: &[[DVec3; 3]], clearance: f64) -> Option<DVec3> {
        // Each subtree tests only the faces near it: a face at the clearance
        // from the mesh keeps the search going down to the leaves under it,
        // but the other faces around a vertex are far from most of those.
        // More faces than a set holds (rare) are asked a set at a time.
        if faces.len() > FaceSet::BITS as usize {
            return faces
                .chunks(FaceSet::BITS as usize)
                .find_map(|chunk| self.first_within(chunk, clearance));
        }
        let (lo, hi) = bounds(faces)?;
        let pad = DVec3::splat(clearance);
        let query = NearQuery {
            faces,
            planes: planes(faces),
            clearance,
            lo: lo - pad,
            hi: hi + pad,
        };
        let all = FaceSet::MAX >> (FaceSet::BITS as usize - faces.len());
        self.first_near(0, &query, all)
    }

    /// `first_within` below node `index`, for the faces in `candidates`.
    fn first_near(&self, index: usize, query: &NearQuery, candidates: FaceSet) -> Option<DVec3> {
        let node = self.nodes.get(index)?;
        if !node.overlaps(query.lo, query.hi) {
            return None;
        }
        let (centre, reach) = (node.centre(), node.radius() + query.clearance);
        let near = query.near(centre, reach, candidates);
        if near == 0 {
            return None;
        }
        if node.children[0] == 0 {
            return self.points[node.first as usize..node.last as usize]
                .iter()
                .copied()
                .find(|&p| query.near(p, query.clearance, near) != 0);
        }
        let [left, right] = node.children.map(|c| c as usize);
        self.first_near(left, query, near)
            .or_else(|| self.first_near(right, query, near))
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

/// Nodes of the tree over `count` points: its shape depends on the count
/// alone (halves, down to leaves of at most [`LEAF_SIZE`]).
fn node_count(count: usize) -> usize {
    node_counts(count).0
}

/// The node counts for `n` and `n + 1` points: the halves of both are `n / 2`
/// or one more, so each level needs only the pair below it.
fn node_counts(n: usize) -> (usize, usize) {
    let single = |count: usize| usize::from(count > 0);
    if n < LEAF_SIZE {
        return (single(n), 1);
    }
    if n == LEAF_SIZE {
        // 17 points split into 8 and 9, a leaf each.
        return (1, 3);
    }
    let (half, half_plus_one) = node_counts(n / 2);
    if n.is_multiple_of(2) {
        (1 + 2 * half, 1 + half + half_plus_one)
    } else {
        (1 + half + half_plus_one, 1 + 2 * half_plus_one)
    }
}

/// Builds the subtree over `points` (which start at `first` in the whole
/// list) into `nodes`, in depth-first order from `index`: the left child
/// follows its parent and the right one follows the left subtree, so both
/// halves are built at once into their own parts of the list.
fn build(points: &mut [DVec3], first: usize, nodes: &mut [Node], index: usize) {
    // Tight bounds choose the axis: bounds cut from the parent's made the
    // simplification's queries half as slow again (FireHydrant).
    let (lo, hi) = point_bounds(points);
    let (node, below) = nodes.split_first_mut().expect("a node for every subtree");
    *node = Node {
        lo,
        hi,
        first: first as u32,
        last: (first + points.len()) as u32,
        children: [0, 0],
    };
    if points.len() > LEAF_SIZE {
        let axis = (hi - lo).max_position();
        let middle = points.len() / 2;
        // One comparison per axis: indexing by a runtime axis made this, the
        // tree's costliest step, a quarter slower (FireHydrant's samples).
        match axis {
            0 => points.select_nth_unstable_by(middle, |a, b| a.x.total_cmp(&b.x)),
            1 => points.select_nth_unstable_by(middle, |a, b| a.y.total_cmp(&b.y)),
            _ => points.select_nth_unstable_by(middle, |a, b| a.z.total_cmp(&b.z)),
        };
        let left_nodes = node_count(middle);
        let right_index = index + 1 + left_nodes;
        node.children = [index + 1, right_index].map(|c| c as u32);
        let (left_points, right_points) = points.split_at_mut(middle);
        let (left, right) = below.split_at_mut(left_nodes);
        // Small subtrees are built in turn: a task costs more than they do.
        if middle >= PARALLEL_POINTS {
            rayon::join(
                || build(left_points, first, left, index + 1),
                || build(right_points, first + middle, right, right_index),
            );
        } else {
            build(left_points, first, left, index + 1);
            build(right_points, first + middle, right, right_index);
        }
    }
}

/// A set of faces of one query, by index.
type FaceSet = u64;

/// The faces and clearance of one `first_within` query.
struct NearQuery<'a> {
    faces: &'a [[DVec3; 3]],
    planes: Vec<(DVec3, f64)>,
    clearance: f64,
    /// The faces' bounds grown by the clearance.
    lo: DVec3,
    hi: DVec3,
}

impl NearQuery<'_> {
    /// Those of `candidates` closer than `reach` to `p`.
    fn near(&self, p: DVec3, reach: f64, candidates: FaceSet) -> FaceSet {
        let mut near = 0;
        let mut left = candidates;
        while left != 0 {
            let i = left.trailing_zeros() as usize;
            left &= left - 1;
            if closer_than(p, &self.faces[i], &self.planes[i], reach) {
                near |= 1 << i;
            }
        }
        near
    }
}

fn point_bounds(points: &[DVec3]) -> (DVec3, DVec3) {
    points
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        })
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

/// Each face's unit normal and offset; a zero normal for a degenerate face.
fn planes(faces: &[[DVec3; 3]]) -> Vec<(DVec3, f64)> {
    faces
        .iter()
        .map(|[a, b, c]| {
            let normal = (*b - *a).cross(*c - *a).normalize_or_zero();
            (normal, normal.dot(*a))
        })
        .collect()
}

/// Whether `p` is closer than `clearance` to one of `faces`: for a few
/// points known to be near, before a whole query.
pub(super) fn point_within(p: DVec3, faces: &[[DVec3; 3]], clearance: f64) -> bool {
    faces
        .iter()
        .any(|face| distance_squared(p, face) < clearance * clearance)
}

/// Whether `p` is closer than `reach` to the face.
fn closer_than(p: DVec3, face: &[DVec3; 3], plane: &(DVec3, f64), reach: f64) -> bool {
    !plane_beyond(p, plane, reach) && distance_squared(p, face) < reach * reach
}

/// Whether `p` is farther than `reach` from the face.
fn farther_than(p: DVec3, face: &[DVec3; 3], plane: &(DVec3, f64), reach: f64) -> bool {
    plane_beyond(p, plane, reach) || distance_squared(p, face) > reach * reach
}

/// Whether `p` is farther than `reach` from the face's plane, and so from
/// the face: one dot product where the closest point costs tens of
/// operations, and most points a query visits are that far from the plane.
/// The margin is far above rounding, so the test never changes an answer.
fn plane_beyond(p: DVec3, &(normal, offset): &(DVec3, f64), reach: f64) -> bool {
    let height = normal.dot(p) - offset;
    height * height > reach * reach * (1.0 + 1e-9)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cagegen::checks::RayFace;
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
        let crossings = faces
            .iter()
            .filter(|f| RayFace::new(**f).hit_from(p))
            .count();
        crossings % 2 == 1
    }

    /// The closed form against the tree's definition, counted directly.
    #[test]
    fn node_counts_follow_the_halving() {
        fn counted(count: usize) -> usize {
            match count {
                0 => 0,
                1..=LEAF_SIZE => 1,
                _ => 1 + counted(count / 2) + counted(count - count / 2),
            }
        }
        for count in (0..2_000).chain([4_095, 4_096, 4_097, 65_537, 1_000_003]) {
            assert_eq!(node_count(count), counted(count), "{count} points");
        }
        let tree = PointTree::new(random_points(100_000, &mut SplitMix64(3)));
        assert_eq!(tree.nodes.len(), counted(100_000));
        // Every point is in exactly one leaf, in order.
        let mut next = 0;
        for node in tree.nodes.iter().filter(|n| n.children[0] == 0) {
            assert_eq!(node.first, next);
            next = node.last;
        }
        assert_eq!(next, 100_000);
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
            assert_eq!(tree.any_enclosed(&faces, |p| parity(p, &faces)), expected);
            let clearance = 0.02 * random.unit();
            let expected = points.iter().any(|&p| {
                faces
                    .iter()
                    .any(|f| distance_squared(p, f) < clearance * clearance)
            });
            assert_eq!(tree.any_within(&faces, clearance), expected);
            // The point it names is one of them, and near.
            if let Some(p) = tree.first_within(&faces, clearance) {
                assert!(points.contains(&p));
                assert!(point_within(p, &faces, clearance));
            }
        }
    }

    /// Queries of many faces, some far apart, and more than one face set
    /// holds: each face is tested only near it, and the answers must still
    /// be those of testing every point.
    #[test]
    fn many_faces_match_testing_every_point() {
        let mut random = SplitMix64(13);
        let points = random_points(5_000, &mut random);
        let tree = PointTree::new(points.clone());
        let mut answers = [0; 2];
        for count in [2, 40, 64, 65, 150] {
            for _ in 0..20 {
                let faces: Vec<[DVec3; 3]> = (0..count)
                    .map(|_| {
                        // Most faces lie away from the points, so that any
                        // one of them, the last too, can decide the answer.
                        let away = if random.unit() < 0.9 { 3.0 } else { 0.0 };
                        let centre = random_points(1, &mut random)[0] + DVec3::splat(away);
                        let c = random_points(3, &mut random);
                        [c[0], c[1], c[2]].map(|c| centre + (c - DVec3::splat(0.5)) * 0.1)
                    })
                    .collect();
                let clearance = 0.02 * random.unit();
                let expected = points.iter().any(|&p| {
                    faces
                        .iter()
                        .any(|f| distance_squared(p, f) < clearance * clearance)
                });
                assert_eq!(
                    tree.any_within(&faces, clearance),
                    expected,
                    "{count} faces"
                );
                answers[usize::from(expected)] += 1;
            }
        }
        assert!(
            answers.iter().all(|&n| n > 10),
            "both answers asked: {answers:?}"
        );
    }
}

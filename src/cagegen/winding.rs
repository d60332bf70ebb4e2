//! A bounding-volume tree over triangles for two queries that would otherwise
//! cost a pass over every triangle per point: the generalised winding number
//! (Barill et al. 2018: far clusters act as one dipole, near triangles are
//! summed exactly) and the distance to the surface.

use crate::geometry::closest_point_on_triangle;
use glam::DVec3;

/// Triangles in a leaf: below this, exact sums are cheaper than the tree.
const LEAF_SIZE: usize = 8;
/// A cluster counts as far when the query is this many cluster radii away; the
/// dipole's error then stays well under the 0.5 threshold the voxels use.
const FAR_RATIO: f64 = 2.5;

struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Area-weighted centre of the cluster and the sum of its area vectors.
    centre: DVec3,
    area_vector: DVec3,
    /// Largest distance from `centre` to a corner in the cluster.
    radius: f64,
    /// Range of `triangles` for a leaf; for an inner node, `first` is the left
    /// child's index and the right child follows it.
    first: u32,
    count: u32,
}

pub(super) struct TriangleTree {
    nodes: Vec<Node>,
    triangles: Vec<[DVec3; 3]>,
}

impl TriangleTree {
    pub(super) fn new(positions: &[DVec3], triangles: &[[u32; 3]]) -> TriangleTree {
        let mut corners: Vec<[DVec3; 3]> = triangles
            .iter()
            .map(|t| t.map(|i| positions[i as usize]))
            .collect();
        let mut nodes = Vec::with_capacity(2 * corners.len() / LEAF_SIZE + 2);
        nodes.push(leaf(&corners, 0, corners.len()));
        let mut pending = vec![0usize];
        while let Some(index) = pending.pop() {
            let (start, count) = (nodes[index].first as usize, nodes[index].count as usize);
            if count <= LEAF_SIZE {
                continue;
            }
            let slice = &mut corners[start..start + count];
            let extent = nodes[index].hi - nodes[index].lo;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let half = count / 2;
            slice.select_nth_unstable_by(half, |p, q| {
                let (cp, cq) = (p[0] + p[1] + p[2], q[0] + q[1] + q[2]);
                cp[axis].total_cmp(&cq[axis])
            });
            let left = nodes.len();
            nodes.push(leaf(&corners, start, half));
            nodes.push(leaf(&corners, start + half, count - half));
            nodes[index].first = left as u32;
            pending.extend([left, left + 1]);
        }
        TriangleTree {
            nodes,
            triangles: corners,
        }
    }

    fn is_leaf(node: &Node) -> bool {
        node.count as usize <= LEAF_SIZE
    }

    /// Generalised winding number at `q`: about 1 inside a closed outward
    /// surface, 0 outside, and in between near holes.
    pub(super) fn winding_number(&self, q: DVec3) -> f64 {
        if self.triangles.is_empty() {
            return 0.0;
        }
        let mut total = 0.0;
        let mut stack = vec![0usize];
        while let Some(index) = stack.pop() {
            let node = &self.nodes[index];
            let offset = node.centre - q;
            let distance = offset.length();
            if !Self::is_leaf(node) && distance > FAR_RATIO * node.radius {
                total += node.area_vector.dot(offset) / (distance * distance * distance);
            } else if Self::is_leaf(node) {
                let range = node.first as usize..(node.first + node.count) as usize;
                total += self.triangles[range]
                    .iter()
                    .map(|t| solid_angle(t, q))
                    .sum::<f64>();
            } else {
                stack.extend([node.first as usize, node.first as usize + 1]);
            }
        }
        total / (4.0 * std::f64::consts::PI)
    }

    /// Distance from `q` to the nearest triangle.
    pub(super) fn distance(&self, q: DVec3) -> f64 {
        self.distance_below(q, f64::INFINITY)
    }

    /// Whether a triangle is nearer to `q` than `limit`.
    pub(super) fn is_within(&self, q: DVec3, limit: f64) -> bool {
        self.distance_below(q, limit) < limit
    }

    /// The distance from `q` to the nearest triangle when it is below `limit`,
    /// otherwise `limit` or more; the search stops at the first triangle found
    /// nearer than the limit only when the limit is finite.
    fn distance_below(&self, q: DVec3, limit: f64) -> f64 {
        let early = limit.is_finite();
        let mut best = limit;
        let mut stack = vec![0usize];
        while let Some(index) = stack.pop() {
            let node = &self.nodes[index];
            let outside = (node.lo - q).max(q - node.hi).max(DVec3::ZERO);
            if outside.length_squared() >= best * best {
                continue;
            }
            if Self::is_leaf(node) {
                let range = node.first as usize..(node.first + node.count) as usize;
                for [a, b, c] in &self.triangles[range] {
                    let (closest, _) = closest_point_on_triangle(q, *a, *b, *c);
                    best = best.min(closest.distance(q));
                }
                if early && best < limit {
                    return best;
                }
            } else {
                // Nearer child first, so the farther one is more often pruned.
                let (l, r) = (node.first as usize, node.first as usize + 1);
                let centre_distance = |n: &Node| ((n.lo + n.hi) * 0.5).distance_squared(q);
                if centre_distance(&self.nodes[l]) < centre_distance(&self.nodes[r]) {
                    stack.extend([r, l]);
                } else {
                    stack.extend([l, r]);
                }
            }
        }
        best
    }
    /// The nearest `t` in `(0, max_t]` at which the ray `origin + t · direction`
    /// (unit direction) meets a triangle, either side.
    pub(super) fn first_hit(&self, origin: DVec3, direction: DVec3, max_t: f64) -> Option<f64> {
        let inverse = DVec3::ONE / direction;
        let entry = |node: &Node| {
            // Slab test: where the ray enters the node's box, if it does.
            let (t0, t1) = ((node.lo - origin) * inverse, (node.hi - origin) * inverse);
            let (near, far) = (t0.min(t1).max_element(), t0.max(t1).min_element());
            (far >= 0.0 && near <= far).then_some(near)
        };
        let mut best = max_t;
        let mut found = false;
        // The tree halves its triangles at each level, so 64 levels hold any mesh.
        let mut stack = [(0usize, 0.0f64); 64];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let (index, near) = stack[depth];
            if near > best {
                continue;
            }
            let node = &self.nodes[index];
            if Self::is_leaf(node) {
                let range = node.first as usize..(node.first + node.count) as usize;
                for triangle in &self.triangles[range] {
                    if let Some(t) = ray_triangle(origin, direction, triangle) {
                        if t > 0.0 && t <= best {
                            (best, found) = (t, true);
                        }
                    }
                }
            } else {
                // Nearer child on top, so that it is searched first.
                let (l, r) = (node.first as usize, node.first as usize + 1);
                let mut children = [(l, entry(&self.nodes[l])), (r, entry(&self.nodes[r]))];
                if children[0].1.unwrap_or(f64::INFINITY) < children[1].1.unwrap_or(f64::INFINITY) {
                    children.swap(0, 1);
                }
                for (child, near) in children {
                    if let Some(near) = near.filter(|&near| near <= best) {
                        stack[depth] = (child, near);
                        depth += 1;
                    }
                }
            }
        }
        found.then_some(best)
    }
}

/// Möller–Trumbore: the ray parameter where it crosses the triangle, if it does.
fn ray_triangle(origin: DVec3, direction: DVec3, [a, b, c]: &[DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (*b - *a, *c - *a);
    let p = direction.cross(e2);
    let det = e1.dot(p);
    if det.abs() <= 1e-300 {
        return None;
    }
    let s = origin - *a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = direction.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0).then(|| e2.dot(q) / det)
}

fn leaf(corners: &[[DVec3; 3]], start: usize, count: usize) -> Node {
    let slice = &corners[start..start + count];
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    let (mut area_vector, mut weighted, mut area_sum) = (DVec3::ZERO, DVec3::ZERO, 0.0);
    for [a, b, c] in slice {
        lo = lo.min(*a).min(*b).min(*c);
        hi = hi.max(*a).max(*b).max(*c);
        let vector = 0.5 * (*b - *a).cross(*c - *a);
        let area = vector.length();
        area_vector += vector;
        weighted += area * (*a + *b + *c) / 3.0;
        area_sum += area;
    }
    let centre = if area_sum > 0.0 {
        weighted / area_sum
    } else {
        (lo + hi) * 0.5
    };
    let radius = slice
        .iter()
        .flat_map(|t| t.iter())
        .map(|p| p.distance(centre))
        .fold(0.0, f64::max);
    Node {
        lo,
        hi,
        centre,
        area_vector,
        radius,
        first: start as u32,
        count: count as u32,
    }
}

/// Signed solid angle of triangle `t` seen from `q` (van Oosterom and
/// Strackee), positive when `q` is behind the triangle's front face.
fn solid_angle(t: &[DVec3; 3], q: DVec3) -> f64 {
    let (a, b, c) = (t[0] - q, t[1] - q, t[2] - q);
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let numerator = a.dot(b.cross(c));
    let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    2.0 * numerator.atan2(denominator)
}

//! What a collapse costs and where its merged vertex may go: the volume the
//! surface gains (the progressive hull's cost, Sander et al. 2000), and the
//! places tried, from the quadric of Garland and Heckbert (1997) and along
//! the edge, each pushed out until it is on or outside every face plane.

use super::simplify::State;
use glam::{DMat3, DVec3};

/// Plane quadric: vᵀAv + 2bᵀv + c, stored as A (symmetric), b and c.
#[derive(Clone, Copy, Default)]
pub(super) struct Quadric {
    a: DMat3,
    b: DVec3,
    c: f64,
}

impl Quadric {
    pub(super) fn plane(normal: DVec3, point: DVec3, weight: f64) -> Quadric {
        let d = -normal.dot(point);
        Quadric {
            a: DMat3::from_cols(normal * normal.x, normal * normal.y, normal * normal.z) * weight,
            b: normal * (d * weight),
            c: d * d * weight,
        }
    }

    pub(super) fn add(self, other: Quadric) -> Quadric {
        Quadric {
            a: self.a + other.a,
            b: self.b + other.b,
            c: self.c + other.c,
        }
    }

    /// The point of least error, when the quadric pins one down.
    fn optimum(&self) -> Option<DVec3> {
        let scale = (self.a.x_axis.x + self.a.y_axis.y + self.a.z_axis.z) / 3.0;
        let det = self.a.determinant();
        (scale > 0.0 && det.abs() > 1e-6 * scale.powi(3)).then(|| -(self.a.inverse() * self.b))
    }
}

/// The volume the surface gains when an edge (a, b) collapses to a point:
/// the progressive hull's cost (Sander et al. 2000), which keeps it tight.
/// What does not depend on the point is summed once per edge.
struct AddedVolume {
    before: f64,
    /// The faces that stay, with a or b marked to be replaced by the point.
    kept: Vec<[Option<DVec3>; 3]>,
}

impl AddedVolume {
    fn new(state: &State, a: usize, b: usize, star: &[u32]) -> AddedVolume {
        let volume = |[p, q, r]: [DVec3; 3]| p.dot(q.cross(r));
        let (a32, b32) = (a as u32, b as u32);
        AddedVolume {
            before: star
                .iter()
                .map(|&t| volume(state.corners(t as usize)))
                .sum(),
            kept: sized_for(
                star.len(),
                (star.iter())
                    .map(|&t| state.triangles[t as usize])
                    .filter(|tri| !(tri.contains(&a32) && tri.contains(&b32)))
                    .map(|tri| {
                        tri.map(|i| (i != a32 && i != b32).then(|| state.positions[i as usize]))
                    }),
            ),
        }
    }

    fn at(&self, position: DVec3) -> f64 {
        let after: f64 = self
            .kept
            .iter()
            .map(|tri| {
                let [p, q, r] = tri.map(|corner| corner.unwrap_or(position));
                p.dot(q.cross(r))
            })
            .sum();
        (after - self.before) / 6.0
    }
}

impl State<'_> {
    /// Where the merged vertex may go, best first: the quadric's optimum (when
    /// it is near the edge), points along the edge and its two ends, each
    /// pushed out along the star's mean normal until it is on or outside every
    /// face plane, ordered by the volume the collapse adds (measured in
    /// docs/cages.md: cages 20–40 % smaller than ordered by quadric error).
    pub(super) fn positions(&self, a: usize, b: usize) -> Vec<(f64, DVec3)> {
        let star = self.star(a, b);
        let cost = AddedVolume::new(self, a, b, &star);
        let planes: Vec<(DVec3, DVec3)> = sized_for(
            star.len(),
            star.iter().filter_map(|&t| {
                let [p, q, r] = self.corners(t as usize);
                let normal = (q - p).cross(r - p).try_normalize()?;
                Some((normal, p))
            }),
        );
        let Some(mean) = planes
            .iter()
            .fold(DVec3::ZERO, |sum, (n, _)| sum + *n)
            .try_normalize()
        else {
            return Vec::new();
        };
        let quadric = self.quadrics[a].add(self.quadrics[b]);
        let (pa, pb) = (self.positions[a], self.positions[b]);
        let middle = (pa + pb) * 0.5;
        let reach = pa.distance(pb);
        let optimum = quadric.optimum().filter(|p| p.distance(middle) <= reach);
        let along = [0.5, 0.0, 1.0, 0.25, 0.75].map(|t| Some(pa.lerp(pb, t)));
        let places = std::iter::once(optimum).chain(along).flatten();
        let mut found: Vec<(f64, DVec3)> = sized_for(
            6,
            places.filter_map(|start| {
                // Outward along `mean` by the least that satisfies every plane.
                let mut push: f64 = 0.0;
                for (normal, point) in &planes {
                    let distance = normal.dot(start - *point);
                    if distance >= 0.0 {
                        continue;
                    }
                    let rate = normal.dot(mean);
                    if rate < 1e-3 {
                        return None;
                    }
                    push = push.max(-distance / rate);
                }
                let position = start + mean * push;
                Some((cost.at(position), position))
            }),
        );
        found.sort_by(|x, y| x.0.total_cmp(&y.0));
        found
    }
}

/// Collect into a list made large enough at once: a filtered list grew
/// from nothing, and its reallocations were a tenth of the simplification's
/// time on the bundled scan (this runs for every candidate collapse).
pub(super) fn sized_for<T>(capacity: usize, items: impl Iterator<Item = T>) -> Vec<T> {
    let mut list = Vec::with_capacity(capacity);
    list.extend(items);
    list
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cagegen::points::PointTree;
    use crate::cagegen::simplify::Goal;
    use crate::geometry::cage::signed_volume;
    use crate::geometry::procedural::{icosphere, SplitMix64};

    /// Each place's cost is the change of the whole surface's volume when
    /// the edge collapses there, measured over the whole surface instead of
    /// the star, from another origin.
    #[test]
    fn collapse_costs_are_the_volume_they_add() {
        let sphere = icosphere(1.0, 1);
        let mut random = SplitMix64(11);
        let positions: Vec<DVec3> = (sphere.positions().iter())
            .map(|p| *p * (0.8 + 0.4 * random.unit()) + DVec3::new(3.0, -2.0, 1.0))
            .collect();
        let triangles = sphere.triangles().to_vec();
        let none = PointTree::new(Vec::new());
        let goal = Goal {
            target_vertices: 4,
            max_limit: 0,
            clearance: 0.01,
            diagonal: 2.0,
        };
        let state = State::new(
            positions.clone(),
            triangles.clone(),
            0.1,
            (&none, &none),
            &goal,
        );
        let before = signed_volume(&positions, &triangles);
        let mut checked = 0;
        for &[i, j, _] in &triangles {
            let (a, b) = (i.min(j), i.max(j));
            for (cost, place) in state.positions(a as usize, b as usize) {
                let mut moved = positions.clone();
                moved[a as usize] = place;
                let after: Vec<[u32; 3]> = (triangles.iter())
                    .filter(|t| !(t.contains(&a) && t.contains(&b)))
                    .map(|t| t.map(|k| if k == b { a } else { k }))
                    .collect();
                let change = signed_volume(&moved, &after) - before;
                assert!((cost - change).abs() < 1e-9, "{cost} against {change}");
                checked += 1;
            }
        }
        assert!(checked > 100);
    }
}

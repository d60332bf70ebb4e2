//! Collapses that leave the surface the same set of points. A voxel surface
//! is mostly flat patches and straight creases: moving a vertex onto a
//! neighbour there only retriangulates, so it needs no region checks and no
//! place in the collapse order.

use super::guard::min_angle;
use super::simplify::State;
use super::voxels::Envelope;
use glam::DVec3;

impl State<'_> {
    /// Moves vertices onto neighbours wherever [`Self::moving_keeps_surface`]
    /// holds and the link and shape checks pass, in passes over the vertices
    /// in order, until none moves or `target` vertices are left.
    pub(super) fn merge_keeping_surface(&mut self, envelope: &Envelope, target: usize) {
        loop {
            let before = self.alive_vertices;
            for v in 0..self.positions.len() {
                if !self.vertex_alive[v] {
                    continue;
                }
                if self.alive_vertices <= target {
                    return;
                }
                let mut choices: Vec<(f64, usize)> = self
                    .neighbours_keeping_surface(v)
                    .into_iter()
                    .map(|u| (self.narrowest_angle_moving(v, u), u))
                    .collect();
                // Widest narrowest angle first: fans of thin faces hold back later collapses.
                choices.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
                for (_, u) in choices {
                    if self.collapse(u, v, self.positions[u], envelope) {
                        break;
                    }
                }
            }
            if self.alive_vertices == before {
                return;
            }
        }
    }

    /// The narrowest angle of `v`'s faces once `v` is moved onto `u`.
    fn narrowest_angle_moving(&self, v: usize, u: usize) -> f64 {
        self.vertex_triangles[v]
            .iter()
            .map(|&t| self.triangles[t as usize])
            .filter(|tri| !tri.contains(&(u as u32)))
            .map(|tri| {
                min_angle(tri.map(|i| self.positions[if i as usize == v { u } else { i as usize }]))
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether moving `v` onto its neighbour `u` leaves the surface the same
    /// set of points, as long as no face flips ([`Self::neighbours_keeping_surface`]).
    pub(super) fn moving_keeps_surface(&self, v: usize, u: usize) -> bool {
        self.neighbours_keeping_surface(v).contains(&u)
    }

    /// The neighbours `v` may move onto, leaving the surface the same set of
    /// points as long as no face flips: any, when `v`'s faces lie in one
    /// plane; when they lie in two that meet along a line through `v`, its
    /// two neighbours on that line, on either side of it. The faces then
    /// become a fan from the neighbour over the same polygon in each plane.
    fn neighbours_keeping_surface(&self, v: usize) -> Vec<usize> {
        let at = self.positions[v];
        let mut planes: Vec<DVec3> = Vec::with_capacity(2);
        for &t in &self.vertex_triangles[v] {
            let [p, q, r] = self.corners(t as usize);
            let normal = (q - p).cross(r - p).normalize_or_zero();
            if normal == DVec3::ZERO {
                return Vec::new();
            }
            let in_plane = |n: DVec3| {
                n.dot(normal) > 0.0
                    && [p, q, r]
                        .iter()
                        .all(|x| n.dot(*x - at).abs() <= self.tolerance)
            };
            if !planes.iter().any(|&n| in_plane(n)) {
                if planes.len() == 2 || !in_plane(normal) {
                    return Vec::new();
                }
                planes.push(normal);
            }
        }
        let neighbours = self.neighbours(v);
        let [first, second] = match planes[..] {
            [_] => return neighbours,
            [first, second] => [first, second],
            _ => return Vec::new(),
        };
        if first.dot(second).abs() >= 1.0 - 1e-9 {
            return Vec::new();
        }
        let on_line = |x: DVec3| {
            first.dot(x - at).abs() <= self.tolerance && second.dot(x - at).abs() <= self.tolerance
        };
        let line: Vec<usize> = (neighbours.into_iter())
            .filter(|&x| on_line(self.positions[x]))
            .collect();
        match line[..] {
            [x, y] if (self.positions[x] - at).dot(self.positions[y] - at) < 0.0 => line,
            _ => Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cagegen::points::PointTree;
    use crate::cagegen::simplify::Goal;
    use crate::cagegen::surface::{boundary_face_count, boundary_surface};
    use crate::cagegen::voxels::Voxels;
    use crate::geometry::cage::signed_volume;
    use crate::geometry::classify::closest_point_on_triangle;

    /// The voxel surface of the cells for which `solid` holds, in a grid of
    /// `n` cells a side (with a ring of empty cells) of side 0.5, away from the origin.
    fn voxel_surface(n: usize, solid: impl Fn(usize, usize, usize) -> bool) -> Surface {
        let dims = [n + 2; 3];
        let mut inside = vec![false; dims[0] * dims[1] * dims[2]];
        for z in 1..=n {
            for y in 1..=n {
                for x in 1..=n {
                    inside[x + dims[0] * (y + dims[1] * z)] = solid(x - 1, y - 1, z - 1);
                }
            }
        }
        let voxels = Voxels {
            origin: DVec3::new(40.0, -7.0, 3.0),
            cell: 0.5,
            dims,
            inside,
        };
        let surface = boundary_surface(&voxels, boundary_face_count(&voxels));
        (surface.positions, surface.triangles)
    }

    type Surface = (Vec<DVec3>, Vec<[u32; 3]>);

    /// The simplification's state over `surface`, with no mesh points to keep.
    fn state_over<'a>((positions, triangles): Surface, none: &'a PointTree) -> State<'a> {
        let goal = Goal {
            target_vertices: 8,
            max_limit: 0,
            clearance: 0.1,
            diagonal: 10.0,
        };
        State::new(positions, triangles, 0.5, (none, none), &goal)
    }

    /// The voxel surface, and what is left of it once merged.
    fn merged(n: usize, solid: impl Fn(usize, usize, usize) -> bool) -> (Surface, Surface) {
        let (positions, triangles) = voxel_surface(n, solid);
        let none = PointTree::new(Vec::new());
        let mut state = state_over((positions.clone(), triangles.clone()), &none);
        let envelope = Envelope {
            origin: DVec3::ZERO,
            cell: 0.5,
            dims: [1, 1, 1],
            distance: vec![0],
            limit: 0,
        };
        state.merge_keeping_surface(&envelope, 8);
        let alive: Vec<[u32; 3]> = (0..state.triangles.len())
            .filter(|&t| state.triangle_alive[t])
            .map(|t| state.triangles[t])
            .collect();
        ((positions, triangles), (state.positions.clone(), alive))
    }

    fn distance_to(surface: (&[DVec3], &[[u32; 3]]), point: DVec3) -> f64 {
        surface
            .1
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| surface.0[i as usize]);
                point.distance(closest_point_on_triangle(point, a, b, c).0)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Merging leaves the same surface: the same volume, each surface's
    /// face centres on the other, and only the vertices where three or more
    /// planes meet (counted here from the cells) are needed.
    #[test]
    fn merging_a_voxel_surface_keeps_it_and_leaves_its_corners() {
        // An L-shaped block, 6 + 6 corners, with a block cut out of one of
        // its corners: that corner goes, and the cut has 7.
        let solid = |x: usize, y: usize, z: usize| {
            let l = x < 3 || y < 2;
            let notch = (1..3).contains(&x) && z >= 4 && y >= 4;
            l && !notch
        };
        let ((positions, triangles), (after, alive)) = merged(6, solid);
        let before_volume = signed_volume(&positions, &triangles);
        let after_volume = signed_volume(&after, &alive);
        assert!(
            (before_volume - after_volume).abs() < 1e-9 * before_volume,
            "{before_volume} {after_volume}"
        );
        let centre =
            |p: &[DVec3], t: &[u32; 3]| t.iter().map(|&i| p[i as usize]).sum::<DVec3>() / 3.0;
        for t in &triangles {
            assert!(distance_to((&after, &alive), centre(&positions, t)) < 1e-9);
        }
        for t in &alive {
            assert!(distance_to((&positions, &triangles), centre(&after, t)) < 1e-9);
        }
        let used: std::collections::BTreeSet<u32> = alive.iter().flatten().copied().collect();
        assert_eq!(
            used.len(),
            18,
            "{} of {} vertices left",
            used.len(),
            positions.len()
        );
    }

    /// A vertex in a face moves onto any neighbour; one on an edge only
    /// along the edge; a corner not at all.
    #[test]
    fn which_moves_keep_a_box() {
        let (positions, triangles) = voxel_surface(4, |_, _, _| true);
        let none = PointTree::new(Vec::new());
        let state = state_over((positions.clone(), triangles), &none);
        let lo = DVec3::new(40.5, -6.5, 3.5);
        let find = |offset: DVec3| {
            (0..positions.len())
                .find(|&i| positions[i] == lo + offset * 0.5)
                .unwrap()
        };
        let face = find(DVec3::new(2.0, 2.0, 0.0));
        assert!(state
            .neighbours(face)
            .iter()
            .all(|&u| state.moving_keeps_surface(face, u)));
        let edge = find(DVec3::new(2.0, 0.0, 0.0));
        let along: Vec<usize> = state
            .neighbours(edge)
            .into_iter()
            .filter(|&u| state.moving_keeps_surface(edge, u))
            .collect();
        let mut expected = vec![
            find(DVec3::new(1.0, 0.0, 0.0)),
            find(DVec3::new(3.0, 0.0, 0.0)),
        ];
        expected.sort_unstable();
        assert_eq!(along, expected);
        let corner = find(DVec3::ZERO);
        assert!(state
            .neighbours(corner)
            .iter()
            .all(|&u| !state.moving_keeps_surface(corner, u)));
    }
}

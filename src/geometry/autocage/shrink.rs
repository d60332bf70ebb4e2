//! Tightening after simplification: each vertex slides inward along its
//! normal as far as the same checks as the collapses allow, keeping the
//! clearance, so that the outward-only collapses' growth is taken back where
//! the mesh leaves room.

use super::simplify::State;
use glam::DVec3;

/// Fractions of the step tried for each vertex, largest first.
const TRIES: [f64; 5] = [1.0, 0.5, 0.25, 0.125, 0.0625];
const PASSES: usize = 4;

impl State<'_> {
    /// Slide vertices inward, `PASSES` times over all of them, by at most
    /// `step` each time, never closer than the clearance to a mesh point.
    pub(super) fn shrink(&mut self, step: f64) {
        for _ in 0..PASSES {
            let mut moved = false;
            for v in 0..self.positions.len() {
                if !self.vertex_alive[v] {
                    continue;
                }
                let Some(inward) = self.inward_normal(v) else {
                    continue;
                };
                let start = self.positions[v];
                moved |= TRIES
                    .iter()
                    .any(|t| self.try_move(v, start + inward * (step * t)));
            }
            if !moved {
                return;
            }
        }
    }

    fn inward_normal(&self, v: usize) -> Option<DVec3> {
        self.vertex_triangles[v]
            .iter()
            .map(|&t| {
                let [p, q, r] = self.corners(t as usize);
                (q - p).cross(r - p)
            })
            .sum::<DVec3>()
            .try_normalize()
            .map(|n| -n)
    }

    fn try_move(&mut self, v: usize, position: DVec3) -> bool {
        let star = self.vertex_triangles[v].clone();
        let replaced: Vec<(u32, [u32; 3])> = star
            .iter()
            .map(|&t| (t, self.triangles[t as usize]))
            .collect();
        let old_corners: Vec<[DVec3; 3]> = star.iter().map(|&t| self.corners(t as usize)).collect();
        let old = self.positions[v];
        self.positions[v] = position;
        let new_corners: Vec<[DVec3; 3]> = star.iter().map(|&t| self.corners(t as usize)).collect();
        let mut sorted_star = star.clone();
        sorted_star.sort_unstable();
        let accepted = self.shapes_are_good(&replaced, (v, usize::MAX), (old, old))
            && !self.crosses_anything(&replaced, &sorted_star)
            && !self.sweeps_over_vertices(v, v, old, &sorted_star, &new_corners)
            && !self.uncovers_mesh_points(&old_corners, &new_corners)
            && !self.covers_gap_points(&old_corners, &new_corners)
            && !self.near_mesh_points(&new_corners, self.clearance);
        if !accepted {
            self.positions[v] = old;
            return false;
        }
        for (t, [p, q, r]) in star.iter().zip(&new_corners) {
            self.triangle_hash
                .insert(*t, p.min(*q).min(*r), p.max(*q).max(*r));
        }
        self.vertex_hash.insert(v as u32, position, position);
        true
    }

    /// Whether a mesh point is closer than `clearance` to one of the faces.
    pub(super) fn near_mesh_points(&self, faces: &[[DVec3; 3]], clearance: f64) -> bool {
        self.mesh_points.any_within(faces, clearance)
    }
}

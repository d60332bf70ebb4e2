//! Tightening after simplification: each vertex slides inward along its
//! normal as far as the same checks as the collapses allow, keeping the
//! clearance, so that the outward-only collapses' growth is taken back where
//! the mesh leaves room.

use super::points::point_within;
use super::simplify::State;
use glam::DVec3;

/// Fractions of the step tried for each vertex, largest first.
const TRIES: [f64; 5] = [1.0, 0.5, 0.25, 0.125, 0.0625];
const PASSES: usize = 4;
/// Points remembered per vertex as having held it at the clearance.
const HELD_POINTS: usize = 4;
/// Fewer for the faces' normals, each of which costs as much as the vertex's.
const FACE_TRIES: [f64; 2] = [0.5, 0.125];

impl State<'_> {
    /// Slide vertices inward by at most `step` at a time, never closer than
    /// the clearance to a mesh point: up to `PASSES` passes, the first over
    /// every vertex, the next over those that moved and their neighbours.
    /// With `along_faces`, a vertex that cannot move along its normal tries
    /// each of its faces' inward normals: that tilts its other faces, which
    /// the gap points keep from swinging across a gap.
    pub(super) fn shrink(&mut self, step: f64, along_faces: bool) {
        // A vertex that could not move stays stuck until it or a neighbour
        // moves, so later passes try only those.
        let mut active = self.vertex_alive.clone();
        for _ in 0..PASSES {
            let mut moved = Vec::new();
            for v in self.active_vertices(&active) {
                let Some(inward) = self.inward_normal(v) else {
                    continue;
                };
                let start = self.positions[v];
                let mut directions = vec![inward];
                if along_faces {
                    // Along one face's inward normal instead: tilts the others.
                    directions.extend(self.face_normals(v));
                }
                let moved_here = directions.iter().enumerate().any(|(k, &direction)| {
                    let tries: &[f64] = if k == 0 { &TRIES } else { &FACE_TRIES };
                    tries
                        .iter()
                        .any(|t| self.try_move(v, start + direction * (step * t)))
                });
                if moved_here {
                    moved.push(v);
                }
            }
            if moved.is_empty() {
                return;
            }
            self.activate_around(&mut active, &moved);
        }
    }

    /// The next pass's vertices: those that moved and their neighbours.
    pub(super) fn activate_around(&self, active: &mut [bool], moved: &[usize]) {
        active.fill(false);
        for &v in moved {
            active[v] = true;
            for n in self.neighbours(v) {
                active[n] = true;
            }
        }
    }

    pub(super) fn active_vertices(&self, active: &[bool]) -> Vec<usize> {
        (0..active.len())
            .filter(|&v| active[v] && self.vertex_alive[v])
            .collect()
    }

    fn face_normals(&self, v: usize) -> Vec<DVec3> {
        self.vertex_triangles[v]
            .iter()
            .filter_map(|&t| {
                let [p, q, r] = self.corners(t as usize);
                (r - p).cross(q - p).try_normalize()
            })
            .collect()
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

    pub(super) fn try_move(&mut self, v: usize, position: DVec3) -> bool {
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
        // A point that held this vertex before is the likeliest refusal, and
        // the cheapest to find: it is asked before the faces are searched.
        let accepted = self.shapes_are_good(&replaced, (v, usize::MAX), (old, old))
            && !self.held_within(v, &new_corners)
            && !self.crosses_anything(&replaced, &sorted_star)
            && !self.sweeps_over_vertices(v, v, old, &sorted_star, &new_corners)
            && !self.keeps_no_clearance(v, &new_corners)
            && !self.moves_points_across(&old_corners, &new_corners);
        if !accepted {
            self.positions[v] = old;
            return false;
        }
        for (t, [p, q, r]) in star.iter().zip(&new_corners) {
            self.triangle_hash
                .insert(*t, p.min(*q).min(*r), p.max(*q).max(*r));
        }
        self.vertex_hash.insert(v as u32, position, position);
        self.refile_if_crowded();
        true
    }

    /// Whether a mesh point is closer than the clearance to one of the faces
    /// around `v`, remembering the point that is. Asked after
    /// [`Self::held_within`]: a vertex held by a face resting at the
    /// clearance is tried in direction after direction, and mostly the same
    /// point holds it.
    fn keeps_no_clearance(&mut self, v: usize, faces: &[[DVec3; 3]]) -> bool {
        let held = &mut self.holding_points[v];
        let Some(point) = self.mesh_points.first_within(faces, self.clearance) else {
            return false;
        };
        if held.len() == HELD_POINTS {
            held.remove(0);
        }
        held.push(point);
        true
    }

    /// Whether a point that held `v` before is closer than the clearance to
    /// one of the faces.
    fn held_within(&self, v: usize, faces: &[[DVec3; 3]]) -> bool {
        (self.holding_points[v].iter()).any(|&p| point_within(p, faces, self.clearance))
    }

    /// Whether a mesh point is closer than `clearance` to one of the faces.
    pub(super) fn near_mesh_points(&self, faces: &[[DVec3; 3]], clearance: f64) -> bool {
        self.mesh_points.any_within(faces, clearance)
    }
}

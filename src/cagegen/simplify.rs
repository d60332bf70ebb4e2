//! Outward-only simplification (progressive hulls, Sander et al. 2000): edge
//! collapses in order of the volume they add, where the new vertex must lie on
//! or outside the plane of every face around the edge, and the quadric of
//! Garland and Heckbert (1997) proposes one of the places it may go.
//! Each new surface then encloses the one before, and so the voxels and the
//! mesh. A collapse is refused when it would break the surface's link
//! condition, flip or squash a face, make two faces cross, or sweep over
//! another part of the surface.

use super::cost::{sized_for, Quadric};
use super::guard::SpatialHash;
use super::points::PointTree;
use super::voxels::Envelope;
use glam::DVec3;
use rayon::prelude::*;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

#[derive(PartialEq)]
struct Candidate {
    cost: f64,
    a: u32,
    b: u32,
    versions: (u32, u32),
}

impl Eq for Candidate {}

impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        // Least cost first in a max-heap; ties broken by vertex ids.
        other
            .cost
            .total_cmp(&self.cost)
            .then_with(|| (other.a, other.b).cmp(&(self.a, self.b)))
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

pub(super) struct Simplified {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    /// The envelope's limit at the end, in cells from the mesh's voxels.
    pub envelope_limit: u16,
}

pub(super) struct State<'a> {
    /// Per vertex, mesh points that kept it from moving (see `shrink`).
    pub(super) holding_points: Vec<Vec<DVec3>>,
    pub(super) positions: Vec<DVec3>,
    pub(super) triangles: Vec<[u32; 3]>,
    pub(super) triangle_alive: Vec<bool>,
    pub(super) vertex_triangles: Vec<Vec<u32>>,
    pub(super) vertex_alive: Vec<bool>,
    pub(super) quadrics: Vec<Quadric>,
    pub(super) versions: Vec<u32>,
    pub(super) alive_vertices: usize,
    pub(super) alive_triangles: usize,
    pub(super) triangle_hash: SpatialHash,
    pub(super) vertex_hash: SpatialHash,
    pub(super) triangles_at_rebuild: usize,
    /// The triangle hash's entries when it was last built.
    pub(super) entries_at_rebuild: usize,
    pub(super) seen_triangles: Vec<u32>,
    pub(super) seen_vertices: Vec<u32>,
    /// What the last query of a hash found (kept to be reused).
    pub(super) nearby: Vec<u32>,
    /// Points of the mesh (vertices and face centres) that must stay inside.
    pub(super) mesh_points: &'a PointTree,
    /// Points midway across gaps between parts of the mesh that must stay
    /// outside ([`super::gaps`]).
    pub(super) gap_points: &'a PointTree,
    /// Least distance from the mesh points that a change may leave.
    pub(super) clearance: f64,
    pub(super) stamp: u32,
    pub(super) tolerance: f64,
    pub(super) volume_tolerance: f64,
}

/// What the simplification aims for and may not go past.
pub(super) struct Goal {
    pub target_vertices: usize,
    /// The envelope's limit grows up to this many cells when stuck.
    pub max_limit: u16,
    /// Least distance from the mesh that tightening keeps.
    pub clearance: f64,
    pub diagonal: f64,
}

/// Collapse edges of the closed surface until it has the goal's vertices or no
/// collapse is allowed, then tighten it. Returns `None` when `progress` asks
/// to stop.
pub(super) fn simplify(
    (mesh_points, gap_points): (&PointTree, &PointTree),
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    mut envelope: Envelope,
    goal: &Goal,
    progress: &dyn Fn(f32) -> bool,
) -> Option<Simplified> {
    let points = (mesh_points, gap_points);
    let mut state = State::new(positions, triangles, envelope.cell, points, goal);
    let start = state.alive_vertices;
    // Flat patches and straight creases first, without the collapse order.
    state.merge_keeping_surface(&envelope, goal.target_vertices);
    let mut heap = state.all_candidates(&envelope);
    let mut steps = 0usize;
    let target = goal.target_vertices;
    let mut shrunk_at = None;
    while state.alive_vertices > target {
        let Some(entry) = heap.pop() else {
            // Stuck: tighten once, which makes room for more outward
            // collapses, and then let the cage move further from the mesh.
            if shrunk_at != Some(envelope.limit) {
                shrunk_at = Some(envelope.limit);
                state.shrink(2.0 * envelope.cell, false);
                heap = state.all_candidates(&envelope);
                continue;
            }
            if envelope.limit >= goal.max_limit {
                break;
            }
            envelope.limit = (envelope.limit + 1 + envelope.limit / 4).min(goal.max_limit);
            heap = state.all_candidates(&envelope);
            continue;
        };
        let (a, b) = (entry.a as usize, entry.b as usize);
        if !state.vertex_alive[a]
            || !state.vertex_alive[b]
            || entry.versions != (state.versions[a], state.versions[b])
        {
            continue;
        }
        // Faces nearby may have changed since this entry was made.
        let positions = state.positions(a, b);
        let Some(&(cost, _)) = positions.first() else {
            continue;
        };
        if cost > entry.cost + 1e-9 * entry.cost.abs() + state.volume_tolerance {
            heap.push(Candidate { cost, ..entry });
            continue;
        }
        if !positions
            .iter()
            .any(|&(_, p)| state.collapse(a, b, p, &envelope))
        {
            continue;
        }
        for n in state.neighbours(a) {
            let (i, j) = (a.min(n) as u32, a.max(n) as u32);
            if let Some(candidate) = state.candidate(i, j) {
                heap.push(candidate);
            }
        }
        steps += 1;
        if steps.is_multiple_of(512) {
            let done = (start - state.alive_vertices) as f32 / (start - target).max(1) as f32;
            if !progress(0.9 * done.min(1.0)) {
                return None;
            }
        }
    }
    if !progress(0.9) {
        return None;
    }
    state.shrink(2.0 * envelope.cell, true);
    state.polish(0.25 * envelope.cell);
    Some(state.finish(envelope.limit))
}

impl<'a> State<'a> {
    fn all_candidates(&self, envelope: &Envelope) -> BinaryHeap<Candidate> {
        let _ = envelope;
        let edges: Vec<(u32, u32)> = (0..self.triangles.len())
            .filter(|&t| self.triangle_alive[t])
            .flat_map(|t| {
                let t = self.triangles[t];
                [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]
            })
            .filter(|(i, j)| i < j)
            .collect();
        edges
            .par_iter()
            .filter_map(|&(a, b)| self.candidate(a, b))
            .collect::<Vec<_>>()
            .into()
    }

    pub(super) fn new(
        positions: Vec<DVec3>,
        triangles: Vec<[u32; 3]>,
        cell: f64,
        (mesh_points, gap_points): (&'a PointTree, &'a PointTree),
        goal: &Goal,
    ) -> State<'a> {
        let diagonal = goal.diagonal;
        let mut vertex_triangles = vec![Vec::new(); positions.len()];
        let mut quadrics = vec![Quadric::default(); positions.len()];
        for (t, tri) in triangles.iter().enumerate() {
            let [p, q, r] = tri.map(|i| positions[i as usize]);
            let vector = (q - p).cross(r - p);
            let area = 0.5 * vector.length();
            let plane = Quadric::plane(vector.normalize_or_zero(), p, area);
            for &i in tri {
                vertex_triangles[i as usize].push(t as u32);
                quadrics[i as usize] = quadrics[i as usize].add(plane);
            }
        }
        let count = positions.len();
        let mut state = State {
            triangle_alive: vec![true; triangles.len()],
            vertex_alive: vec![true; count],
            versions: vec![0; count],
            alive_vertices: count,
            alive_triangles: triangles.len(),
            triangle_hash: SpatialHash::new(2.0 * cell),
            vertex_hash: SpatialHash::new(2.0 * cell),
            triangles_at_rebuild: triangles.len(),
            entries_at_rebuild: 0,
            seen_triangles: vec![0; triangles.len()],
            seen_vertices: vec![0; count],
            nearby: Vec::new(),
            mesh_points,
            gap_points,
            clearance: goal.clearance,
            stamp: 0,
            tolerance: 1e-9 * diagonal,
            volume_tolerance: 1e-12 * diagonal.powi(3),
            positions,
            triangles,
            vertex_triangles,
            quadrics,
            holding_points: vec![Vec::new(); count],
        };
        // A start of a few large faces (a box, a prism) is filed in cells
        // as large as its edges.
        let size = state.mean_edge_length().max(2.0 * cell);
        state.rebuild_hashes(size);
        state
    }

    pub(super) fn corners(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|i| self.positions[i as usize])
    }

    pub(super) fn neighbours(&self, v: usize) -> Vec<usize> {
        let faces = &self.vertex_triangles[v];
        let mut out: Vec<usize> = sized_for(
            2 * faces.len(),
            (faces.iter())
                .flat_map(|&t| self.triangles[t as usize])
                .map(|i| i as usize)
                .filter(|&i| i != v),
        );
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Faces around a or b, each once.
    pub(super) fn star(&self, a: usize, b: usize) -> Vec<u32> {
        let mut star: Vec<u32> = self.vertex_triangles[a]
            .iter()
            .chain(&self.vertex_triangles[b])
            .copied()
            .collect();
        star.sort_unstable();
        star.dedup();
        star
    }

    fn candidate(&self, a: u32, b: u32) -> Option<Candidate> {
        let (cost, _) = *self.positions(a as usize, b as usize).first()?;
        Some(Candidate {
            cost,
            a,
            b,
            versions: (self.versions[a as usize], self.versions[b as usize]),
        })
    }

    /// Collapse edge (a, b) into `a` at `position` if every check passes.
    pub(super) fn collapse(
        &mut self,
        a: usize,
        b: usize,
        position: DVec3,
        envelope: &Envelope,
    ) -> bool {
        if !self.link_condition_holds(a, b) {
            return false;
        }
        let star = self.star(a, b);
        let replaced: Vec<(u32, [u32; 3])> = sized_for(
            star.len(),
            (star.iter())
                .filter(|&&t| {
                    let tri = self.triangles[t as usize];
                    !(tri.contains(&(a as u32)) && tri.contains(&(b as u32)))
                })
                .map(|&t| {
                    let tri =
                        (self.triangles[t as usize])
                            .map(|i| if i == b as u32 { a as u32 } else { i });
                    (t, tri)
                }),
        );
        let old_corners: Vec<[DVec3; 3]> = star.iter().map(|&t| self.corners(t as usize)).collect();
        let (old_a, old_b) = (self.positions[a], self.positions[b]);
        self.positions[a] = position;
        if !self.shapes_are_good(&replaced, (a, b), (old_a, old_b)) {
            self.positions[a] = old_a;
            return false;
        }
        // In a flat star, unflipped faces around a point of the same plane
        // cover exactly the region the old ones did: nothing else can change.
        // So do a vertex's faces moved onto a neighbour in their plane or
        // along a straight crease ([`super::flat`]).
        let flat = self.lies_in_plane_of(&old_corners, position)
            || (position == old_a && self.moving_keeps_surface(b, a));
        let accepted = flat
            || self.passes_region_checks(
                (a, b),
                position,
                &star,
                &old_corners,
                &replaced,
                envelope,
            );
        if !accepted {
            self.positions[a] = old_a;
            return false;
        }
        // Commit: remove the star, add the replacements.
        for &t in &star {
            self.triangle_alive[t as usize] = false;
            self.alive_triangles -= 1;
        }
        let mut touched = Vec::with_capacity(3 * star.len());
        for &t in &star {
            touched.extend(self.triangles[t as usize]);
        }
        touched.sort_unstable();
        touched.dedup();
        for (_, tri) in &replaced {
            let t = self.triangles.len() as u32;
            self.triangles.push(*tri);
            self.triangle_alive.push(true);
            self.seen_triangles.push(0);
            self.alive_triangles += 1;
            let [p, q, r] = tri.map(|i| self.positions[i as usize]);
            self.triangle_hash
                .insert(t, p.min(q).min(r), p.max(q).max(r));
        }
        for v in touched {
            let alive = &self.triangle_alive;
            self.vertex_triangles[v as usize].retain(|&t| alive[t as usize]);
        }
        let first_new = self.triangles.len() - replaced.len();
        for t in first_new..self.triangles.len() {
            for i in self.triangles[t] {
                self.vertex_triangles[i as usize].push(t as u32);
            }
        }
        self.vertex_alive[b] = false;
        self.vertex_triangles[b].clear();
        self.alive_vertices -= 1;
        self.quadrics[a] = self.quadrics[a].add(self.quadrics[b]);
        self.versions[a] += 1;
        self.versions[b] += 1;
        self.vertex_hash.insert(a as u32, position, position);
        if self.alive_triangles * 2 < self.triangles_at_rebuild {
            let size = self.mean_edge_length().max(self.triangle_hash.cell_size());
            self.rebuild_hashes(size);
        }
        true
    }

    /// The checks a collapse of (a, b) into `a`, already moved to `position`,
    /// must pass when it changes the region the surface covers.
    fn passes_region_checks(
        &mut self,
        (a, b): (usize, usize),
        position: DVec3,
        star: &[u32],
        old_corners: &[[DVec3; 3]],
        replaced: &[(u32, [u32; 3])],
        envelope: &Envelope,
    ) -> bool {
        let new_corners: Vec<[DVec3; 3]> = replaced
            .iter()
            .map(|(_, tri)| tri.map(|i| self.positions[i as usize]))
            .collect();
        new_corners.iter().all(|&f| envelope.allows_triangle(f))
            && !self.crosses_anything(replaced, star)
            && !self.sweeps_over_vertices(a, b, position, star, old_corners)
            && !self.moves_points_across(old_corners, &new_corners)
            && !self.near_mesh_points(&new_corners, self.clearance)
    }

    /// Whether every corner of `faces` and `point` lie in one plane (to the
    /// volume tolerance), with the faces all facing the same way.
    fn lies_in_plane_of(&self, faces: &[[DVec3; 3]], point: DVec3) -> bool {
        let Some(&[p, q, r]) = faces.first() else {
            return false;
        };
        let normal = (q - p).cross(r - p);
        let on_plane = |x: DVec3| normal.dot(x - p).abs() <= self.volume_tolerance;
        on_plane(point)
            && faces.iter().all(|&[u, v, w]| {
                (v - u).cross(w - u).dot(normal) > 0.0 && [u, v, w].into_iter().all(on_plane)
            })
    }

    fn mean_edge_length(&self) -> f64 {
        let (sum, count) = (0..self.triangles.len())
            .filter(|&t| self.triangle_alive[t])
            .map(|t| {
                let [p, q, r] = self.corners(t);
                p.distance(q).max(q.distance(r)).max(r.distance(p))
            })
            .fold((0.0, 0usize), |(s, c), l| (s + l, c + 1));
        sum / count.max(1) as f64
    }

    fn rebuild_hashes(&mut self, cell: f64) {
        self.triangle_hash = SpatialHash::new(cell);
        self.vertex_hash = SpatialHash::new(cell);
        for t in 0..self.triangles.len() {
            if self.triangle_alive[t] {
                let [p, q, r] = self.corners(t);
                self.triangle_hash
                    .insert(t as u32, p.min(q).min(r), p.max(q).max(r));
            }
        }
        for v in 0..self.positions.len() {
            if self.vertex_alive[v] {
                let p = self.positions[v];
                self.vertex_hash.insert(v as u32, p, p);
            }
        }
        self.triangles_at_rebuild = self.alive_triangles;
        self.entries_at_rebuild = self.triangle_hash.entries();
    }

    /// Rebuilds the hashes once the entries of moved faces outnumber the
    /// live ones several times: on a coarse cage, where each move files a
    /// few large faces again, queries spent a fifth of a run walking stale
    /// entries (a torus knot at N = 32). A rebuild walks every face there
    /// has been, so it waits for as many new entries as that.
    pub(super) fn refile_if_crowded(&mut self) {
        let entries = self.triangle_hash.entries();
        let added = entries.saturating_sub(self.entries_at_rebuild);
        if entries > 4 * self.entries_at_rebuild.max(1024) && added > self.triangles.len() {
            let size = self.mean_edge_length().max(self.triangle_hash.cell_size());
            self.rebuild_hashes(size);
        }
    }

    fn finish(self, envelope_limit: u16) -> Simplified {
        let mut remap = vec![u32::MAX; self.positions.len()];
        let mut positions = Vec::with_capacity(self.alive_vertices);
        for (v, p) in self.positions.iter().enumerate() {
            if self.vertex_alive[v] {
                remap[v] = positions.len() as u32;
                positions.push(*p);
            }
        }
        let triangles = (0..self.triangles.len())
            .filter(|&t| self.triangle_alive[t])
            .map(|t| self.triangles[t].map(|i| remap[i as usize]))
            .collect();
        Simplified {
            positions,
            triangles,
            envelope_limit,
        }
    }
}

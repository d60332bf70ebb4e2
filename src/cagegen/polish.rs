//! Polishing the finished cage: moves that lower the volume it encloses
//! under the same checks as the collapses. Sliding along the normal
//! ([`shrink`](super::shrink)) stops as soon as one face touches the
//! clearance; a face resting there can still turn about what holds it, and a
//! vertex can still slide within that face's plane or along an edge, which
//! keeps the faces on either side in theirs. Coarse cages (tens of vertices
//! for a whole model) are mostly such faces. Edge flips change which
//! diagonal of a pair of faces the cage folds along.

use super::simplify::State;
use crate::geometry::cage::signed_volume;
use crate::geometry::procedural::SplitMix64;
use glam::DVec3;

/// Passes over the vertices that moved, or whose neighbours did.
const MAX_PASSES: usize = 20;
/// A pass that takes back less than this share of the volume ends polishing.
const SETTLED: f64 = 2e-3;
/// Cages of at most this many vertices also try random directions.
const SMALL_CAGE: usize = 64;
const RANDOM_DIRECTIONS: usize = 24;

impl State<'_> {
    /// Move vertices in whichever direction lowers the enclosed volume, and
    /// flip edges that do, until a pass takes back less than `SETTLED` of
    /// it. A move starts with `smallest_step` and doubles while it passes.
    pub(super) fn polish(&mut self, smallest_step: f64) {
        let mut active = self.vertex_alive.clone();
        let mut before = self.enclosed_volume();
        for pass in 0..MAX_PASSES {
            let mut moved = Vec::new();
            for v in self.active_vertices(&active) {
                if self.polish_vertex(v, pass, smallest_step) {
                    moved.push(v);
                }
            }
            moved.extend(self.flip_edges());
            let after = self.enclosed_volume();
            if moved.is_empty() || before - after <= SETTLED * before.abs() {
                return;
            }
            self.activate_around(&mut active, &moved);
            before = after;
        }
    }

    fn enclosed_volume(&self) -> f64 {
        let alive: Vec<[u32; 3]> = (0..self.triangles.len())
            .filter(|&t| self.triangle_alive[t])
            .map(|t| self.triangles[t])
            .collect();
        signed_volume(&self.positions, &alive)
    }

    /// The enclosed volume is linear in one vertex's position (the others
    /// held): this is its gradient, a third of the area-weighted normals.
    fn volume_gradient(&self, v: usize) -> DVec3 {
        self.vertex_triangles[v]
            .iter()
            .map(|&t| {
                let [a, b, c] = self.corners(t as usize);
                (b - a).cross(c - a) / 6.0
            })
            .sum::<DVec3>()
    }

    /// Directions that lower the volume, steepest first: the gradient's, its
    /// part within each face's plane, and along each edge.
    fn descent_directions(&self, v: usize, pass: usize) -> Vec<DVec3> {
        let gradient = self.volume_gradient(v);
        let Some(down) = (-gradient).try_normalize() else {
            return Vec::new();
        };
        let mut directions = vec![down];
        for &t in &self.vertex_triangles[v] {
            let [a, b, c] = self.corners(t as usize);
            if let Some(normal) = (b - a).cross(c - a).try_normalize() {
                let slide = down - normal * down.dot(normal);
                directions.extend(slide.try_normalize());
            }
        }
        for n in self.neighbours(v) {
            if let Some(edge) = (self.positions[n] - self.positions[v]).try_normalize() {
                directions.push(if edge.dot(down) >= 0.0 { edge } else { -edge });
            }
        }
        if self.alive_vertices <= SMALL_CAGE {
            // A generating set search: on a coarse cage a vertex is often
            // held by several faces at once, and only directions between
            // the structured ones lead out. Seeded, so runs repeat.
            let mut random = SplitMix64((v as u64) << 32 | pass as u64);
            for _ in 0..RANDOM_DIRECTIONS {
                let d = DVec3::new(random.unit(), random.unit(), random.unit()) * 2.0 - 1.0;
                if let Some(d) = d.try_normalize() {
                    directions.push(if d.dot(down) >= 0.0 { d } else { -d });
                }
            }
        }
        // Nearly level directions would take back almost nothing.
        directions.retain(|d| d.dot(down) > 0.01);
        directions.sort_by(|x, y| y.dot(down).total_cmp(&x.dot(down)));
        directions.dedup_by(|x, y| x.dot(*y) > 0.999);
        directions
    }

    /// Along the steepest direction that is not blocked: a short step
    /// first, since most directions are blocked from the start (a face
    /// already at the clearance), then doubling while the steps pass.
    fn polish_vertex(&mut self, v: usize, pass: usize, smallest_step: f64) -> bool {
        let start = self.positions[v];
        let longest = self
            .neighbours(v)
            .iter()
            .map(|&n| self.positions[n].distance(start))
            .fold(0.0, f64::max);
        for direction in self.descent_directions(v, pass) {
            if !self.try_move(v, start + direction * smallest_step) {
                continue;
            }
            let mut step = smallest_step;
            while 2.0 * step <= 0.5 * longest {
                step *= 2.0;
                if !self.try_move(v, self.positions[v] + direction * step) {
                    break;
                }
            }
            return true;
        }
        false
    }

    /// One sweep of edge flips that lower the volume; returns the vertices
    /// whose faces changed.
    fn flip_edges(&mut self) -> Vec<usize> {
        let mut changed = Vec::new();
        for t in 0..self.triangles.len() {
            for k in 0..3 {
                if !self.triangle_alive[t] {
                    break;
                }
                let tri = self.triangles[t];
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if a < b {
                    if let Some(flipped) = self.try_flip(t as u32, a as usize, b as usize) {
                        changed.extend(flipped);
                    }
                }
            }
        }
        changed
    }

    /// Flip edge a→b of face `first` (a, b, c) and the face (b, a, d) across
    /// it to (c, a, d) and (d, b, c), when that lowers the volume and keeps
    /// every guarantee.
    fn try_flip(&mut self, first: u32, a: usize, b: usize) -> Option<[usize; 4]> {
        let tri = self.triangles[first as usize];
        let c = tri
            .into_iter()
            .find(|&i| i as usize != a && i as usize != b)? as usize;
        let second = *self.vertex_triangles[a].iter().find(|&&t| {
            let o = self.triangles[t as usize];
            t != first && o.contains(&(b as u32))
        })?;
        let d = self.triangles[second as usize]
            .into_iter()
            .find(|&i| i as usize != a && i as usize != b)? as usize;
        if c == d || self.neighbours(c).contains(&d) {
            return None;
        }
        // Each end keeps three neighbours, so no part turns into a flat pair.
        if self.neighbours(a).len() <= 3 || self.neighbours(b).len() <= 3 {
            return None;
        }
        let [pa, pb, pc, pd] = [a, b, c, d].map(|i| self.positions[i]);
        let change = (pd - pa).dot((pb - pa).cross(pc - pa)) / 6.0;
        if change >= -self.volume_tolerance {
            return None;
        }
        let new_first = [c as u32, a as u32, d as u32];
        let new_second = [d as u32, b as u32, c as u32];
        let replaced = [(first, new_first), (second, new_second)];
        let mut star = [first, second];
        star.sort_unstable();
        let old_corners = [self.corners(first as usize), self.corners(second as usize)];
        let new_corners = [[pc, pa, pd], [pd, pb, pc]];
        let accepted = self.shapes_are_good(&replaced, (usize::MAX, usize::MAX), (pa, pa))
            && !self.crosses_anything(&replaced, &star)
            && !self.sweeps_over_vertices(c, d, pd, &star, &old_corners[..1])
            && !self.moves_points_across(&old_corners, &new_corners)
            && !self.near_mesh_points(&new_corners, self.clearance);
        if !accepted {
            return None;
        }
        self.triangles[first as usize] = new_first;
        self.triangles[second as usize] = new_second;
        self.vertex_triangles[a].retain(|&t| t != second);
        self.vertex_triangles[b].retain(|&t| t != first);
        self.vertex_triangles[c].push(second);
        self.vertex_triangles[d].push(first);
        for (t, [p, q, r]) in star.iter().zip(if star[0] == first {
            new_corners
        } else {
            [new_corners[1], new_corners[0]]
        }) {
            self.triangle_hash
                .insert(*t, p.min(q).min(r), p.max(q).max(r));
        }
        for i in [a, b, c, d] {
            self.versions[i] += 1;
        }
        self.refile_if_crowded();
        Some([a, b, c, d])
    }
}

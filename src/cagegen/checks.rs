//! The checks every change of the simplified surface must pass: it stays a
//! manifold, no face flips or turns into a sliver, no two faces cross, no other
//! part is swallowed, and no point of the mesh ends up outside.

use super::guard::{inside_tetrahedron, min_angle};
use super::simplify::State;
use crate::geometry::intersect::triangles_cross;
use glam::DVec3;

/// New faces may not be sharper than this (unless the faces they replace were).
const MIN_ANGLE_DEGREES: f64 = 3.0;
/// A new face may turn at most this far from the face it replaces (cosine).
const MAX_TURN_COSINE: f64 = 0.0;

impl State<'_> {
    /// Whether a point that must keep its side lies between the old faces and
    /// the new ones: a mesh point, which would end up outside the cage, or a
    /// gap point, which would end up inside.
    pub(super) fn moves_points_across(&self, old: &[[DVec3; 3]], new: &[[DVec3; 3]]) -> bool {
        // The old and new faces bound the swept region; a ray from a point
        // crosses them an odd number of times exactly when it is inside.
        let faces: Vec<[DVec3; 3]> = old.iter().chain(new).copied().collect();
        let rays: Vec<RayFace> = faces.iter().map(|&f| RayFace::new(f)).collect();
        let swept = |q: DVec3| rays.iter().filter(|t| t.hit_from(q)).count() % 2 == 1;
        self.mesh_points.any_enclosed(&faces, swept) || self.gap_points.any_enclosed(&faces, swept)
    }

    /// The edge's two ends share exactly the two vertices opposite it, and
    /// those keep at least three neighbours: the surface stays a manifold and
    /// no part shrinks to a flat pair of faces.
    pub(super) fn link_condition_holds(&self, a: usize, b: usize) -> bool {
        let (na, nb) = (self.neighbours(a), self.neighbours(b));
        let shared: Vec<usize> = na.iter().copied().filter(|v| nb.contains(v)).collect();
        if shared.len() != 2 {
            return false;
        }
        shared.iter().all(|&v| self.neighbours(v).len() > 3)
    }

    pub(super) fn shapes_are_good(
        &self,
        replaced: &[(u32, [u32; 3])],
        (a, b): (usize, usize),
        (old_a, old_b): (DVec3, DVec3),
    ) -> bool {
        let min_angle_allowed = MIN_ANGLE_DEGREES.to_radians();
        replaced.iter().all(|(t, tri)| {
            let new = tri.map(|i| self.positions[i as usize]);
            let old = self.triangles[*t as usize].map(|i| match i as usize {
                i if i == a => old_a,
                i if i == b => old_b,
                i => self.positions[i],
            });
            let new_vector = (new[1] - new[0]).cross(new[2] - new[0]);
            let old_vector = (old[1] - old[0]).cross(old[2] - old[0]);
            if new_vector.length() <= self.tolerance * self.tolerance * 1e6 {
                return false;
            }
            if new_vector.dot(old_vector)
                <= MAX_TURN_COSINE * new_vector.length() * old_vector.length()
            {
                return false;
            }
            let angle = min_angle(new);
            angle >= min_angle_allowed || angle >= min_angle(old) * 0.999
        })
    }

    pub(super) fn crosses_anything(&mut self, replaced: &[(u32, [u32; 3])], star: &[u32]) -> bool {
        // One list for every query: growing a new one each time was a
        // noticeable share of the checks.
        let mut nearby = std::mem::take(&mut self.nearby);
        let crosses = self.crosses_any_nearby(replaced, star, &mut nearby);
        self.nearby = nearby;
        crosses
    }

    fn crosses_any_nearby(
        &mut self,
        replaced: &[(u32, [u32; 3])],
        star: &[u32],
        nearby: &mut Vec<u32>,
    ) -> bool {
        for (k, (_, tri)) in replaced.iter().enumerate() {
            let [p, q, r] = tri.map(|i| self.positions[i as usize]);
            let pad = DVec3::splat(self.tolerance);
            let (lo, hi) = (p.min(q).min(r) - pad, p.max(q).max(r) + pad);
            self.stamp += 1;
            // The query returns live faces only.
            self.triangle_hash.query(
                (lo, hi),
                &self.triangle_alive,
                (&mut self.seen_triangles, self.stamp),
                nearby,
            );
            for &other in nearby.iter() {
                let o = other as usize;
                if star.binary_search(&other).is_ok() {
                    continue;
                }
                // Most faces filed in the same cells are not even near.
                let [u, v, w] = self.corners(o);
                if u.max(v).max(w).cmplt(lo).any() || u.min(v).min(w).cmpgt(hi).any() {
                    continue;
                }
                if self.crosses(*tri, self.triangles[o]) {
                    return true;
                }
            }
            for (_, other) in &replaced[..k] {
                if self.crosses(*tri, *other) {
                    return true;
                }
            }
        }
        false
    }

    pub(super) fn crosses(&self, first: [u32; 3], second: [u32; 3]) -> bool {
        triangles_cross(
            first,
            second,
            &self.positions,
            self.volume_tolerance,
            self.tolerance,
        )
    }

    /// Whether the region between the old faces and the new vertex holds any
    /// other vertex: a collapse that swallows a whole other part crosses no face.
    pub(super) fn sweeps_over_vertices(
        &mut self,
        a: usize,
        b: usize,
        position: DVec3,
        star: &[u32],
        old_corners: &[[DVec3; 3]],
    ) -> bool {
        let (mut lo, mut hi) = (position, position);
        for corners in old_corners {
            for p in corners {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
        }
        let mut nearby = std::mem::take(&mut self.nearby);
        self.stamp += 1;
        self.vertex_hash.query(
            (lo, hi),
            &self.vertex_alive,
            (&mut self.seen_vertices, self.stamp),
            &mut nearby,
        );
        let sweeps = nearby.iter().any(|&v| {
            let v = v as usize;
            // Live vertices only, from the query.
            if v == a || v == b {
                return false;
            }
            let p = self.positions[v];
            if p.cmplt(lo).any() || p.cmpgt(hi).any() {
                return false;
            }
            if star
                .iter()
                .any(|&t| self.triangles[t as usize].contains(&(v as u32)))
            {
                return false;
            }
            old_corners
                .iter()
                .any(|corners| inside_tetrahedron(p, position, *corners, self.volume_tolerance))
        });
        self.nearby = nearby;
        sweeps
    }
}

/// A triangle, for whether the ray from a point along a fixed direction
/// (chosen to be parallel to no voxel face or edge) passes through it (Möller
/// and Trumbore). What does not depend on the ray's origin is computed once:
/// a check asks it of every sample near the faces.
pub(super) struct RayFace {
    a: DVec3,
    e1: DVec3,
    e2: DVec3,
    p: DVec3,
    det: f64,
}

impl RayFace {
    const DIRECTION: DVec3 = DVec3::new(0.573_462_1, 0.612_345_7, 0.544_125_3);

    pub(super) fn new([a, b, c]: [DVec3; 3]) -> RayFace {
        let (e1, e2) = (b - a, c - a);
        let p = Self::DIRECTION.cross(e2);
        RayFace {
            a,
            e1,
            e2,
            p,
            det: e1.dot(p),
        }
    }

    pub(super) fn hit_from(&self, origin: DVec3) -> bool {
        let det = self.det;
        if det.abs() < 1e-300 {
            return false;
        }
        let s = origin - self.a;
        let u = s.dot(self.p) / det;
        if !(0.0..=1.0).contains(&u) {
            return false;
        }
        let q = s.cross(self.e1);
        let v = Self::DIRECTION.dot(q) / det;
        if v < 0.0 || u + v > 1.0 {
            return false;
        }
        self.e2.dot(q) / det > 0.0
    }
}

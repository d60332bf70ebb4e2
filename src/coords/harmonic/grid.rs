//! One level of the harmonic solve's grid: where the cage crosses the grid lines,
//! which nodes are inside, and the cut-cell stencil of every inside node.
//!
//! The stencil is the symmetric cut-cell discretisation of Gibou, Fedkiw, Cheng and
//! Kang (2002): along each axis an arm to an inside neighbour has coefficient 1/h²;
//! an arm that the cage cuts at θh (0 < θ ≤ 1) ends at the crossing, where the value
//! is known (the hat functions of the crossed triangle), with coefficient 1/(θh²).
//! The matrix is symmetric and an M-matrix (so the discrete maximum principle holds:
//! weights are non-negative and sum to one), and a linear function is reproduced
//! exactly at every node: its two arms' terms cancel whatever θ is.

use crate::geometry::{closest_offset_on_triangle, Cage};
use glam::DVec3;

/// No unknown here: the node is outside the cage, or the arm is cut.
pub(super) const NONE: u32 = u32::MAX;
/// Arms shorter than this share of a cell are lengthened to it, bounding the
/// diagonal; the boundary then moves by at most this share of a cell.
const THETA_MIN: f64 = 1e-3;

/// Where a grid line crosses the cage: `s` along the line in cells from its first
/// node, and the hat values there (the barycentrics of the crossed triangle).
#[derive(Clone, Copy, Debug)]
pub(super) struct Crossing {
    pub s: f64,
    pub triangle: u32,
    pub barycentric: [f64; 3],
}

/// A cut arm: the unknown it belongs to, its coefficient `1/θ`, and the values at
/// the crossing.
#[derive(Clone, Copy, Debug)]
pub(super) struct CutArm {
    pub unknown: u32,
    pub coefficient: f32,
    pub corners: [u32; 3],
    pub barycentric: [f32; 3],
}

/// The grid's placement, shared by all levels (a level doubles `h`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Frame {
    pub origin: DVec3,
    pub h: f64,
    pub dims: [usize; 3],
}

impl Frame {
    pub fn node_count(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    pub fn index(&self, [x, y, z]: [usize; 3]) -> usize {
        x + self.dims[0] * (y + self.dims[1] * z)
    }

    pub fn coordinates(&self, index: usize) -> [usize; 3] {
        let x = index % self.dims[0];
        let y = (index / self.dims[0]) % self.dims[1];
        [x, y, index / (self.dims[0] * self.dims[1])]
    }

    pub fn position(&self, [x, y, z]: [usize; 3]) -> DVec3 {
        self.origin + self.h * DVec3::new(x as f64, y as f64, z as f64)
    }

    /// The next level's frame: twice the spacing, on every other node.
    pub fn coarser(&self) -> Frame {
        Frame {
            origin: self.origin,
            h: 2.0 * self.h,
            dims: self.dims.map(|n| (n - 1) / 2 + 1),
        }
    }
}

/// One level: the inside nodes (the unknowns) and their stencils.
pub(super) struct Level {
    pub frame: Frame,
    /// Per grid node: its unknown, or [`NONE`] outside the cage.
    pub unknown_of: Vec<u32>,
    /// Per unknown: its grid node.
    pub nodes: Vec<u32>,
    /// Per unknown: the sum of its arms' coefficients.
    pub diagonal: Vec<f32>,
    /// Per unknown, arms −x, +x, −y, +y, −z, +z: the neighbouring unknown, or
    /// [`NONE`] where the arm is cut.
    pub neighbours: Vec<[u32; 6]>,
    /// Every cut arm, for the right-hand sides (finest level only).
    pub cut_arms: Vec<CutArm>,
}

/// Crossings of every grid line along `axis`, sorted along each line. Lines are
/// indexed by their coordinates on the other two axes `(axis+1, axis+2) % 3`.
fn line_crossings(cage: &Cage, frame: &Frame, axis: usize) -> Vec<Vec<Crossing>> {
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    let (nb, nc) = (frame.dims[b], frame.dims[c]);
    let mut lines = vec![Vec::new(); nb * nc];
    for (t, corners) in cage.triangles().iter().enumerate() {
        let q = corners.map(|k| (cage.positions()[k as usize] - frame.origin) / frame.h);
        let lo = |axis: usize| q.iter().map(|p| p[axis]).fold(f64::INFINITY, f64::min);
        let hi = |axis: usize| q.iter().map(|p| p[axis]).fold(f64::NEG_INFINITY, f64::max);
        let range = |axis: usize, n: usize| {
            let first = lo(axis).ceil().max(0.0) as usize;
            let last = (hi(axis).floor().max(-1.0) + 1.0).min(n as f64) as usize;
            first..last.max(first)
        };
        // Twice the projected signed area; zero for a triangle along the axis.
        let area =
            (q[1][b] - q[0][b]) * (q[2][c] - q[0][c]) - (q[2][b] - q[0][b]) * (q[1][c] - q[0][c]);
        if area == 0.0 {
            continue;
        }
        for jc in range(c, nc) {
            for jb in range(b, nb) {
                let (u, v) = (jb as f64, jc as f64);
                // Barycentrics of (u, v) in the projected triangle.
                let edge = |i: usize, k: usize| {
                    (q[k][b] - q[i][b]) * (v - q[i][c]) - (q[k][c] - q[i][c]) * (u - q[i][b])
                };
                let weights = [edge(1, 2), edge(2, 0), edge(0, 1)].map(|w| w / area);
                if weights.iter().any(|&w| w < 0.0) {
                    continue;
                }
                let s = weights[0] * q[0][axis] + weights[1] * q[1][axis] + weights[2] * q[2][axis];
                lines[jb + nb * jc].push(Crossing {
                    s,
                    triangle: t as u32,
                    barycentric: weights,
                });
            }
        }
    }
    for line in &mut lines {
        line.sort_by(|a, b| a.s.total_cmp(&b.s));
    }
    lines
}

/// The line along `axis` through node `[x, y, z]`, and the node's place on it.
fn line_of(frame: &Frame, axis: usize, node: [usize; 3]) -> (usize, usize) {
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    (node[b] + frame.dims[b] * node[c], node[axis])
}

/// Which grid nodes are inside the cage: odd crossings before them along x.
pub(super) fn inside_nodes(cage: &Cage, frame: &Frame) -> (Vec<bool>, [Vec<Vec<Crossing>>; 3]) {
    let lines = [0, 1, 2].map(|axis| line_crossings(cage, frame, axis));
    let mut inside = vec![false; frame.node_count()];
    for (index, flag) in inside.iter_mut().enumerate() {
        let node = frame.coordinates(index);
        let (line, at) = line_of(frame, 0, node);
        let before = lines[0][line].partition_point(|crossing| crossing.s < at as f64);
        *flag = before % 2 == 1;
    }
    (inside, lines)
}

impl Level {
    /// The level on `frame`; `with_cut_arms` keeps the data for right-hand sides.
    pub fn new(cage: &Cage, frame: Frame, with_cut_arms: bool) -> Level {
        let (inside, lines) = inside_nodes(cage, &frame);
        let mut unknown_of = vec![NONE; frame.node_count()];
        let mut nodes = Vec::new();
        for (index, _) in inside.iter().enumerate().filter(|(_, &inside)| inside) {
            unknown_of[index] = nodes.len() as u32;
            nodes.push(index as u32);
        }
        let mut diagonal = vec![0.0f32; nodes.len()];
        let mut neighbours = vec![[NONE; 6]; nodes.len()];
        let mut cut_arms = Vec::new();
        for (unknown, &index) in nodes.iter().enumerate() {
            let node = frame.coordinates(index as usize);
            for (arm, slot) in neighbours[unknown].iter_mut().enumerate() {
                let (axis, forward) = (arm / 2, arm % 2 == 1);
                let (line, at) = line_of(&frame, axis, node);
                let crossings = &lines[axis][line];
                let at = at as f64;
                let first_cut = if forward {
                    let k = crossings.partition_point(|c| c.s <= at);
                    crossings.get(k).filter(|c| c.s <= at + 1.0)
                } else {
                    let k = crossings.partition_point(|c| c.s < at);
                    k.checked_sub(1)
                        .map(|k| &crossings[k])
                        .filter(|c| c.s >= at - 1.0)
                };
                let mut neighbour_node = node;
                neighbour_node[axis] = if forward {
                    node[axis] + 1
                } else {
                    node[axis] - 1
                };
                let neighbour = unknown_of[frame.index(neighbour_node)];
                let cut = match (first_cut, neighbour) {
                    (None, NONE) => Some(nearest_crossing(cage, crossings, at, &frame, node)),
                    (None, _) => None,
                    (Some(crossing), _) => Some(*crossing),
                };
                match cut {
                    None => {
                        *slot = neighbour;
                        diagonal[unknown] += 1.0;
                    }
                    Some(crossing) => {
                        let theta = (crossing.s - at).abs().clamp(THETA_MIN, 1.0);
                        let coefficient = (1.0 / theta) as f32;
                        diagonal[unknown] += coefficient;
                        if with_cut_arms {
                            cut_arms.push(CutArm {
                                unknown: unknown as u32,
                                coefficient,
                                corners: cage.triangles()[crossing.triangle as usize],
                                barycentric: crossing.barycentric.map(|w| w as f32),
                            });
                        }
                    }
                }
            }
        }
        Level {
            frame,
            unknown_of,
            nodes,
            diagonal,
            neighbours,
            cut_arms,
        }
    }

    pub fn unknowns(&self) -> usize {
        self.nodes.len()
    }
}

/// An outside neighbour with no crossing in between: the lines along different
/// axes disagree by rounding. Take the line's nearest crossing, or failing that the
/// closest point of the cage, as the boundary one cell away.
fn nearest_crossing(
    cage: &Cage,
    crossings: &[Crossing],
    at: f64,
    frame: &Frame,
    node: [usize; 3],
) -> Crossing {
    if let Some(nearest) = crossings
        .iter()
        .min_by(|a, b| (a.s - at).abs().total_cmp(&(b.s - at).abs()))
    {
        return Crossing {
            s: at + 1.0,
            ..*nearest
        };
    }
    let (triangle, barycentric) = closest_hat_values(cage, frame.position(node));
    Crossing {
        s: at + 1.0,
        triangle,
        barycentric,
    }
}

/// The triangle nearest to `x` and the barycentrics of the nearest point on it: the
/// hat functions' values there.
pub(super) fn closest_hat_values(cage: &Cage, x: DVec3) -> (u32, [f64; 3]) {
    let mut best = (f64::INFINITY, 0, [1.0, 0.0, 0.0]);
    for t in 0..cage.triangle_count() {
        let [a, b, c] = cage.triangle(t);
        let (offset, barycentric) = closest_offset_on_triangle(x, a, b, c);
        let distance = offset.length_squared();
        if distance < best.0 {
            best = (distance, t as u32, barycentric.to_array());
        }
    }
    (best.1, best.2)
}
